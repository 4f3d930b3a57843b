#pragma once
/// \file NeighborLists: full per-particle neighbor lists, stored per chunk of particles.

#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

#include <sph/core/parallel.h>

namespace sph {

class StateWriter;
class StateReader;

template <int D, std::floating_point R>
class ListBuilder;
template <int D, std::floating_point R>
class TrackedNeighbors;

/// Full neighbor lists: of(i) holds particle i's neighbors (never i itself). Both directions
/// of a pair are stored.
///
/// Storage follows the fixed particle chunks of parallel_chunks (kChunkSize particles each):
/// chunk c's lists lie one after the other in their own buffer, so a builder can write each
/// chunk's lists in place, in parallel, without a second copy of all lists and without
/// knowing the other chunks' sizes. A chunk's buffer may be longer than its lists (room kept
/// from earlier builds, so that steady-state rebuilds allocate nothing).
///
/// Lists may also keep room of their own (the tracked modes insert into other particles' lists):
/// list i then starts at begin(i) and has capacity(i) slots, of which it uses the first
/// of(i).size(); the unused slots hold valid indices, like the padding.
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
    const std::uint32_t b = begin(i);
    return {chunks_[i / kChunkSize].data() + b, end_[i] - b};
  }
  /// Where list i starts in its chunk's buffer: lists without room of their own lie one after
  /// the other, each from the last one's end (no start is stored: 4 bytes a particle); lists with
  /// room keep their starts.
  std::uint32_t begin(std::size_t i) const {
    if (!begin_.empty()) return begin_[i];
    return i % kChunkSize != 0 ? end_[i - 1] : 0;
  }
  /// Slots list i may fill before its chunk is laid out again (its size without room of its own).
  std::size_t capacity(std::size_t i) const { return cap_.empty() ? end_[i] - begin(i) : cap_[i]; }
  /// Whether the lists keep room of their own (capacity() beyond their size).
  bool has_room() const { return !cap_.empty(); }
  void clear() {
    chunks_.clear();
    begin_.clear();
    end_.clear();
    cap_.clear();
    entries_ = 0;
  }
  /// Bytes of memory held (capacity, not just what is in use).
  std::size_t memory_bytes() const;
  /// Adds each chunk's entries to work[c] (one figure per chunk of kChunkSize particles, the
  /// chunks of parallel_chunks; for balance_loops).
  void add_chunk_entries(std::span<std::uint64_t> work) const;

  /// Checks the padding promise: every chunk's buffer holds kPadding entries after its last
  /// list, all of them indices below particle_count() (tests).
  bool padding_is_valid() const;

  /// Lists given explicitly, one vector per particle (tests, brute force).
  static NeighborLists from(const std::vector<std::vector<std::uint32_t>>& lists);

  /// Writes the lists and each list's capacity (not the spare room itself) for a checkpoint.
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
  template <int D, std::floating_point R>
  friend class TrackedNeighbors;

  /// Lays chunk c out again, list after list from its start, each with room for
  /// max(its capacity, new_cap(i)) entries (tracked lists that outgrew their room).
  template <class NewCap>
  void relayout_chunk(std::size_t c, std::vector<std::uint32_t>& scratch, const NewCap& new_cap);

  std::vector<std::vector<std::uint32_t>> chunks_;  // chunk c: lists of particles [c K, (c+1) K)
  std::vector<std::uint32_t> begin_;  // lists with room: start of list i in its chunk's buffer; else empty
  std::vector<std::uint32_t> end_;    // end of list i in its chunk's buffer
  std::vector<std::uint32_t> cap_;    // lists with room of their own: capacity of list i; else empty
  std::size_t entries_ = 0;
};

template <class NewCap>
void NeighborLists::relayout_chunk(std::size_t c, std::vector<std::uint32_t>& scratch, const NewCap& new_cap) {
  const std::size_t b = c * kChunkSize, e = std::min(end_.size(), b + kChunkSize);
  std::vector<std::uint32_t>& buf = chunks_[c];
  scratch.assign(buf.begin(), buf.end());
  std::size_t need = 0;
  for (std::size_t i = b; i < e; ++i) need += std::max<std::size_t>(capacity(i), new_cap(i));
  if (buf.size() < need + kPadding) buf.resize(need + kPadding + need / 16);
  std::uint32_t at = 0;
  for (std::size_t i = b; i < e; ++i) {
    const std::uint32_t len = end_[i] - begin_[i];
    const auto cap = static_cast<std::uint32_t>(std::max<std::size_t>(capacity(i), new_cap(i)));
    std::copy_n(scratch.data() + begin_[i], len, buf.data() + at);
    std::fill_n(buf.data() + at + len, cap - len, 0u);
    begin_[i] = at;
    end_[i] = at + len;
    if (!cap_.empty()) cap_[i] = cap;
    at += cap;
  }
  std::fill_n(buf.data() + at, kPadding, 0u);
}

}  // namespace sph
