#pragma once
/// \file NeighborLists: full per-particle neighbor lists in flat storage (offsets + indices).

#include <cstdint>
#include <span>
#include <vector>

namespace sph {

/// Full neighbor lists: particle i's neighbors (never i itself) are
/// indices[offsets[i] .. offsets[i+1]). Both directions of a pair are stored.
struct NeighborLists {
  std::vector<std::uint64_t> offsets{0};
  std::vector<std::uint32_t> indices;

  std::size_t particle_count() const { return offsets.size() - 1; }
  /// Number of stored (directed) entries: twice the number of pairs for symmetric lists.
  std::size_t entry_count() const { return indices.size(); }
  std::span<const std::uint32_t> of(std::size_t i) const {
    return {indices.data() + offsets[i], static_cast<std::size_t>(offsets[i + 1] - offsets[i])};
  }
  void clear() {
    offsets.assign(1, 0);
    indices.clear();
  }
};

}  // namespace sph
