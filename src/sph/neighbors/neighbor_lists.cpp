#include <sph/neighbors/neighbor_lists.h>

#include <algorithm>

#include <sph/core/error.h>
#include <sph/core/parallel.h>
#include <sph/core/state_stream.h>

namespace sph {

void NeighborLists::add_chunk_entries(std::span<std::uint64_t> work) const {
  SPH_CHECK(work.size() == chunk_count(particle_count()), "one work figure per chunk of the lists' particles");
  if (begin_.empty()) {  // (lists one after the other from the chunk's start: its last list's end)
    for (std::size_t c = 0; c < work.size(); ++c) work[c] += end_[std::min(particle_count(), (c + 1) * kChunkSize) - 1];
    return;
  }
  parallel_chunks(particle_count(), [&](std::size_t c, std::size_t b, std::size_t e) {
    std::uint64_t entries = 0;
    for (std::size_t i = b; i < e; ++i) entries += end_[i] - begin(i);
    work[c] += entries;
  });
}

std::size_t NeighborLists::memory_bytes() const {
  std::size_t bytes = chunks_.capacity() * sizeof(chunks_[0]) +
                      (begin_.capacity() + end_.capacity() + cap_.capacity()) * sizeof(std::uint32_t);
  for (const auto& c : chunks_) bytes += c.capacity() * sizeof(std::uint32_t);
  return bytes;
}

NeighborLists NeighborLists::from(const std::vector<std::vector<std::uint32_t>>& lists) {
  NeighborLists out;
  const std::size_t n = lists.size();
  out.chunks_.resize(chunk_count(n));
  out.end_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    auto& chunk = out.chunks_[i / kChunkSize];
    SPH_CHECK(chunk.size() + lists[i].size() < (std::size_t{1} << 32), "neighbor list chunk too large");
    chunk.insert(chunk.end(), lists[i].begin(), lists[i].end());
    out.end_[i] = static_cast<std::uint32_t>(chunk.size());
    out.entries_ += lists[i].size();
  }
  for (auto& chunk : out.chunks_) chunk.resize(chunk.size() + kPadding, 0);
  return out;
}

bool NeighborLists::padding_is_valid() const {
  const std::size_t n = particle_count();
  for (std::size_t c = 0; c < chunks_.size(); ++c) {
    const std::size_t last = std::min(n, (c + 1) * kChunkSize) - 1;
    const std::size_t end = begin(last) + capacity(last);
    if (chunks_[c].size() < end + kPadding) return false;
    for (std::size_t i = c * kChunkSize; i <= last; ++i)  // a list's unused room, too
      for (std::size_t k = end_[i]; k < begin(i) + capacity(i); ++k)
        if (chunks_[c][k] >= n) return false;
    for (std::size_t k = end; k < end + kPadding; ++k)
      if (chunks_[c][k] >= n) return false;
  }
  return true;
}

void NeighborLists::save(StateWriter& out) const {
  // Compact: each chunk's lists one after the other (offsets as if without room), then the
  // capacities (empty without room of their own), from which load() lays the room out again.
  const std::size_t n = end_.size();
  std::vector<std::uint32_t> end(n);
  std::vector<std::uint32_t> data;
  for (std::size_t i = 0; i < n; ++i) end[i] = (i % kChunkSize != 0 ? end[i - 1] : 0) + (end_[i] - begin(i));
  out.put(end);
  for (std::size_t c = 0; c < chunks_.size(); ++c) {
    data.clear();
    for (std::size_t i = c * kChunkSize; i < std::min(n, (c + 1) * kChunkSize); ++i) {
      const auto l = of(i);
      data.insert(data.end(), l.begin(), l.end());
    }
    out.put(data);
  }
  out.put(cap_);
}

void NeighborLists::load(StateReader& in, std::size_t index_limit) {
  // (the chunks' buffers are kept, with their capacity: loading lists does not undo their growth)
  begin_.clear();
  cap_.clear();
  entries_ = 0;
  in.get(end_);
  const std::size_t n = end_.size();
  const std::size_t limit = index_limit > 0 ? index_limit : n;
  chunks_.resize(chunk_count(n));
  for (std::size_t c = 0; c < chunks_.size(); ++c) {
    const std::size_t first = c * kChunkSize, last = std::min(n, first + kChunkSize) - 1;
    for (std::size_t i = first + 1; i <= last; ++i)
      in.expect(end_[i - 1] <= end_[i], "neighbor list offsets go backwards");
    std::vector<std::uint32_t>& chunk = chunks_[c];
    in.get(chunk);
    in.expect(chunk.size() == end_[last], "a neighbor list chunk of the wrong length");
    for (std::uint32_t j : chunk) in.expect(j < limit, "a neighbor index out of range");
    entries_ += chunk.size();
    chunk.resize(chunk.size() + kPadding, 0);
  }
  std::vector<std::uint32_t> cap;
  in.get(cap);
  in.expect(cap.empty() || cap.size() == n, "neighbor list capacities do not match the lists");
  if (cap.empty()) return;
  for (std::size_t i = 0; i < n; ++i) in.expect(cap[i] >= end_[i] - begin(i), "a neighbor list over its capacity");
  // (with room: the starts of the compact layout, which relayout_chunk lays the room into)
  begin_.resize(n);
  for (std::size_t i = 0; i < n; ++i) begin_[i] = i % kChunkSize != 0 ? end_[i - 1] : 0;
  cap_ = std::move(cap);
  std::vector<std::uint32_t> scratch;
  for (std::size_t c = 0; c < chunks_.size(); ++c) relayout_chunk(c, scratch, [](std::size_t) { return 0; });
}

bool operator==(const NeighborLists& a, const NeighborLists& b) {
  if (&a == &b) return true;
  if (a.particle_count() != b.particle_count() || a.entry_count() != b.entry_count()) return false;
  for (std::size_t i = 0; i < a.particle_count(); ++i) {
    const auto x = a.of(i), y = b.of(i);
    if (!std::equal(x.begin(), x.end(), y.begin(), y.end())) return false;
  }
  return true;
}

}  // namespace sph
