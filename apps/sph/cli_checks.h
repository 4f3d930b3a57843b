#pragma once
// Checks of command-line values shared by the subcommands, with messages that say what is
// expected in words (CLI11's own range checks print the limits of a double: 310 digits).

#include <cmath>
#include <filesystem>
#include <string>

#include <CLI/CLI.hpp>

#include <sph/core/error.h>

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

/// Refuses an output directory given as "" (which would mean the current directory) or as the
/// root of the file system (whose files a run or a render would replace), naming `flag`.
inline void check_output_path(const std::string& path, const std::string& flag) {
  if (path.empty())
    throw Error("an empty directory name; expected the directory to write to, e.g. -o out/my_run", flag);
  std::error_code ec;
  const std::filesystem::path p = std::filesystem::absolute(path, ec).lexically_normal();
  if (!ec && p.relative_path().empty())
    throw Error("\"" + path + "\" is the root of the file system; expected a directory of its own, e.g. -o out/my_run",
                flag);
}

}  // namespace sph::app
