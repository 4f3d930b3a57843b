#pragma once
/// \file closest_name: the known name a mistyped one was probably meant to be, for "did you mean"
/// in messages (scene keys, command-line options and commands).

#include <algorithm>
#include <cctype>
#include <concepts>
#include <cstddef>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace sph {

/// The edit distance between a and b, letter case ignored: insertions, deletions, substitutions
/// and swaps of two neighbouring letters (optimal string alignment) each count one.
inline std::size_t edit_distance(std::string_view a, std::string_view b) {
  const auto lower = [](char c) { return static_cast<char>(std::tolower(static_cast<unsigned char>(c))); };
  const std::size_t n = a.size(), m = b.size();
  std::vector<std::size_t> d((n + 1) * (m + 1));
  const auto at = [&](std::size_t i, std::size_t j) -> std::size_t& { return d[i * (m + 1) + j]; };
  for (std::size_t i = 0; i <= n; ++i) at(i, 0) = i;
  for (std::size_t j = 0; j <= m; ++j) at(0, j) = j;
  for (std::size_t i = 1; i <= n; ++i)
    for (std::size_t j = 1; j <= m; ++j) {
      const std::size_t cost = lower(a[i - 1]) == lower(b[j - 1]) ? 0 : 1;
      at(i, j) = std::min({at(i - 1, j) + 1, at(i, j - 1) + 1, at(i - 1, j - 1) + cost});
      if (i > 1 && j > 1 && lower(a[i - 1]) == lower(b[j - 2]) && lower(a[i - 2]) == lower(b[j - 1]))
        at(i, j) = std::min(at(i, j), at(i - 2, j - 2) + 1);
    }
  return at(n, m);
}

/// The candidate `name` was most likely meant to be: the closest by edit_distance, if that is at
/// most 1 for names of up to 4 letters, 2 up to 8 and 3 beyond (a misspelling, not another
/// word). Empty when none is that close, when two are equally close, or when `name` is a
/// candidate itself.
inline std::string closest_name(std::string_view name, std::span<const std::string> candidates) {
  const std::size_t limit = name.size() <= 4 ? 1 : name.size() <= 8 ? 2 : 3;
  std::string best;
  std::size_t best_distance = limit + 1;
  bool tie = false;
  for (const std::string& c : candidates) {
    if (c == name) return {};
    const std::size_t dist = edit_distance(name, c);
    if (dist < best_distance) {
      best = c, best_distance = dist, tie = false;
    } else if (dist == best_distance && c != best) {
      tie = true;
    }
  }
  return best_distance <= limit && !tie ? best : std::string();
}

/// " (did you mean QUOTE NAME QUOTE?)" for closest_name's answer, or "" when it has none.
inline std::string did_you_mean(std::string_view name, std::span<const std::string> candidates,
                                std::string_view quote = "\"") {
  const std::string best = closest_name(name, candidates);
  if (best.empty()) return {};
  return " (did you mean " + std::string(quote) + best + std::string(quote) + "?)";
}

/// did_you_mean over any range of names (a table's `const char*`s, string_views).
template <class Names>
requires(!std::convertible_to<const Names&, std::span<const std::string>>) inline std::string
    did_you_mean(std::string_view name, const Names& names, std::string_view quote = "\"") {
  std::vector<std::string> candidates;
  for (const auto& n : names) candidates.emplace_back(n);
  return did_you_mean(name, std::span<const std::string>(candidates), quote);
}

}  // namespace sph
