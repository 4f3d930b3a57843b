#pragma once
/// \file NeighborLists: full per-particle neighbor lists, stored per chunk of particles.

#include <cstdint>
#include <span>
#include <vector>

#include <sph/core/parallel.h>

namespace sph {

class StateWriter;
class StateReader;

template <int D, std::floating_point R>
class ListBuilder;

/// Full neighbor lists: of(i) holds particle i's neighbors (never i itself). Both directions
/// of a pair are stored.
///
/// Storage follows the fixed particle chunks of parallel_chunks (kChunkSize particles each):
/// chunk c's lists lie one after the other in their own buffer, so a builder can write each
/// chunk's lists in place, in parallel, without a second copy of all lists and without
/// knowing the other chunks' sizes. A chunk's buffer may be longer than its lists (room kept
/// from earlier builds, so that steady-state rebuilds allocate nothing).
class NeighborLists {
 public:
  /// Entries after the end of each list that may be read (never used): every chunk buffer
  /// ends with at least this many, and every stored value is a valid particle index, so
  /// vector loops may load whole blocks of indices and mask the lanes past the end.
  static constexpr std::size_t kPadding = 16;

  std::size_t particle_count() const { return end_.size(); }
  /// Number of stored (directed) entries: twice the number of pairs for symmetric lists.
  std::size_t entry_count() const { return entries_; }
  std::span<const std::uint32_t> of(std::size_t i) const {
    const std::uint32_t begin = i % kChunkSize != 0 ? end_[i - 1] : 0;
    return {chunks_[i / kChunkSize].data() + begin, end_[i] - begin};
  }
  void clear() {
    chunks_.clear();
    end_.clear();
    entries_ = 0;
  }
  /// Bytes of memory held (capacity, not just what is in use).
  std::size_t memory_bytes() const;

  /// Checks the padding promise: every chunk's buffer holds kPadding entries after its last
  /// list, all of them indices below particle_count() (tests).
  bool padding_is_valid() const;

  /// Lists given explicitly, one vector per particle (tests, brute force).
  static NeighborLists from(const std::vector<std::vector<std::uint32_t>>& lists);

  /// Writes the lists (not the spare room) for a checkpoint.
  void save(StateWriter& out) const;
  /// Replaces the lists with what save() wrote; throws sph::Error if they are inconsistent
  /// (an index out of range, offsets that go backwards). Indices are of the listed particles
  /// themselves, or (index_limit > 0: boundary lists) below index_limit.
  void load(StateReader& in, std::size_t index_limit = 0);

  /// The same lists, in the same order (storage layout and spare room do not matter).
  friend bool operator==(const NeighborLists& a, const NeighborLists& b);

 private:
  template <int D, std::floating_point R>
  friend class ListBuilder;

  std::vector<std::vector<std::uint32_t>> chunks_;  // chunk c: lists of particles [c K, (c+1) K)
  std::vector<std::uint32_t> end_;  // end of list i in its chunk's buffer (it starts where i - 1's ends)
  std::size_t entries_ = 0;
};

}  // namespace sph
