#pragma once
// Neighbor lists compared as sets: a list's indices sorted.

#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

namespace sph::test {

/// The indices of `s`, ascending.
inline std::vector<std::uint32_t> sorted(std::span<const std::uint32_t> s) {
  std::vector<std::uint32_t> v(s.begin(), s.end());
  std::sort(v.begin(), v.end());
  return v;
}

}  // namespace sph::test
