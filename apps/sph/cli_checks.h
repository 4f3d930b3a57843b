#pragma once
// Checks of command-line values shared by the subcommands, with messages that say what is
// expected in words (CLI11's own range checks print the limits of a double: 310 digits).

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <exception>
#include <filesystem>
#include <initializer_list>
#include <sstream>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <sph/core/error.h>
#include <sph/io/run_directory.h>
#include <sph/neighbors/neighbor_mode.h>

namespace sph::app {

/// A CLI11 check that the value is a finite number > 0; `what` names it in the message, e.g.
/// "a frame rate in frames per simulated second" gives "expected a positive number (a frame
/// rate ...), got 0".
inline CLI::Validator positive_number(const std::string& what) {
  return CLI::Validator(
      [what](std::string& text) -> std::string {
        double x = 0;
        if (CLI::detail::lexical_cast(text, x) && std::isfinite(x) && x > 0) return {};
        return "expected a positive number (" + what + "), got " + text;
      },
      "POSITIVE");
}

/// A CLI11 check that the value names a neighbor mode, with parse_neighbor_mode's message (the
/// modes, and the one a misspelling was probably meant to be).
inline CLI::Validator neighbor_mode_check() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        try {
          parse_neighbor_mode(text);
          return {};
        } catch (const Error& e) {
          return e.message();
        }
      },
      "MODE");
}

/// A CLI11 check that the value is not empty, for options whose absence means a default: given as
/// "" (an unset shell variable, `--range "$RANGE"`) the option would otherwise be taken as left
/// out. `expected` says what to give, e.g. "LO,HI with LO < HI, e.g. 0,2.5".
inline CLI::Validator not_empty(const std::string& expected) {
  return CLI::Validator(
      [expected](std::string& text) -> std::string {
        return text.empty() ? "an empty value; expected " + expected + ", or leave the option out" : std::string();
      },
      "");
}

/// A CLI11 check that the value is a number from `lo` to `hi` (a whole number if T is integral),
/// with a message that says so: CLI11's CLI::Range says "Value abc not in range ..." for a value
/// that is not a number at all.
template <class T>
CLI::Validator in_range(T lo, T hi) {
  std::string expected;
  if constexpr (std::is_integral_v<T>)
    expected = fmt::format("a whole number from {} to {}", lo, hi);
  else
    expected = fmt::format("a number from {} to {}", lo, hi);
  return CLI::Validator(
      [lo, hi, expected](std::string& text) -> std::string {
        T x{};
        if (!CLI::detail::lexical_cast(text, x)) return "expected " + expected + ", got \"" + text + "\"";
        if constexpr (!std::is_integral_v<T>)
          if (!std::isfinite(x)) return "expected " + expected + ", got " + text;
        if (x < lo || x > hi) return "expected " + expected + ", got " + text;
        return {};
      },
      "IN [" + fmt::format("{} - {}", lo, hi) + "]");
}

/// Refuses a --set of a key that a flag also sets (--steps and --set Configuration.numberOfSteps):
/// the later would hide the other, and a bad value in it. `flag_keys`: {key path, the flag that
/// sets it or nullptr when that flag was not given}.
inline void check_set_flag_conflicts(const std::vector<std::string>& sets,
                                     std::initializer_list<std::pair<const char*, const char*>> flag_keys) {
  for (const std::string& set : sets)
    for (const auto& [key, flag] : flag_keys)
      if (flag && set.substr(0, set.find('=')) == key)
        throw Error(fmt::format("--set {} and {} both set it; give one of them", key, flag), "--set");
}

/// The frame indices a command works on (sph render, sph surface): "all", "first", "last", or a comma list of indices
/// (negative ones count from the end: -1 is the last).
inline std::vector<std::size_t> parse_frames(const std::string& s, std::size_t count) {
  std::vector<std::size_t> out;
  if (s == "all") {
    for (std::size_t k = 0; k < count; ++k) out.push_back(k);
    return out;
  }
  std::stringstream ss(s == "first" ? std::string("0") : s == "last" ? std::string("-1") : s);
  for (std::string item; std::getline(ss, item, ',');) {
    long long k = 0;
    std::size_t used = 0;
    try {
      k = std::stoll(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size())
      throw Error(fmt::format("\"{}\" is not a frame list; expected all, first, last or frame numbers separated by "
                              "commas (negative ones count from the end), e.g. 0,50,-1",
                              s),
                  "--frames");
    const long long n = static_cast<long long>(count);
    if (k < -n || k >= n)
      throw Error(
          fmt::format("frame {} does not exist: the run has frames 0 to {} (or -{} to -1 from the end)", k, n - 1, n),
          "--frames");
    out.push_back(static_cast<std::size_t>(k < 0 ? n + k : k));
  }
  if (out.empty())  // "" (an empty list): nothing to do is a mistake, not a success
    throw Error("an empty frame list; expected all, first, last or frame numbers separated by commas, e.g. 0,50,-1",
                "--frames");
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

}  // namespace sph::app
