#include <sph/neighbors/list_builder.h>

#include <algorithm>
#include <cstring>

#include <sph/core/error.h>
#include <sph/core/parallel.h>

namespace sph {

template <int D, std::floating_point R>
std::uint32_t ListBuilder<D, R>::gather(const UniformGrid<D, R>& grid, std::span<const Vec<D, R>> positions, R r2,
                                        std::size_t i, std::vector<std::uint32_t>& buf) {
  const Vec<D, R> xi = positions[i];
  const std::size_t before = buf.size();
  grid.for_each_candidate(xi, [&](std::uint32_t j) {
    if (j == i) return;
    if (norm2(xi - positions[j]) < r2) buf.push_back(j);
  });
  return static_cast<std::uint32_t>(buf.size() - before);
}

template <int D, std::floating_point R>
void ListBuilder<D, R>::set_offsets(std::size_t n, NeighborLists& out) const {
  out.offsets.resize(n + 1);
  out.offsets[0] = 0;
  for (std::size_t i = 0; i < n; ++i) out.offsets[i + 1] = out.offsets[i] + counts_[i];
  out.indices.resize(out.offsets[n]);
}

template <int D, std::floating_point R>
void ListBuilder<D, R>::build(const UniformGrid<D, R>& grid, std::span<const Vec<D, R>> positions, R radius,
                              NeighborLists& out) {
  const std::size_t n = positions.size();
  const R r2 = radius * radius;
  const std::size_t chunks = chunk_count(n);
  if (chunk_indices_.size() < chunks) chunk_indices_.resize(chunks);
  counts_.resize(n);

  // Pass 1: each fixed chunk of particles gathers its lists into its own buffer.
  parallel_chunks(n, [&](std::size_t c, std::size_t begin, std::size_t end) {
    auto& buf = chunk_indices_[c];
    buf.clear();
    for (std::size_t i = begin; i < end; ++i) counts_[i] = gather(grid, positions, r2, i, buf);
  });

  // Offsets by prefix sum, then copy each chunk's buffer to its place.
  set_offsets(n, out);
  parallel_for(chunks, [&](std::size_t c) {
    const auto& buf = chunk_indices_[c];
    if (!buf.empty())
      std::memcpy(out.indices.data() + out.offsets[c * kChunkSize], buf.data(), buf.size() * sizeof(std::uint32_t));
  });
}

template <int D, std::floating_point R>
void ListBuilder<D, R>::rebuild_some(const UniformGrid<D, R>& grid, std::span<const Vec<D, R>> positions, R radius,
                                     std::span<const std::uint8_t> rebuild, NeighborLists& lists) {
  const std::size_t n = positions.size();
  const std::size_t old_n = lists.particle_count();
  SPH_CHECK(rebuild.size() == n && old_n <= n, "rebuild flags must cover every particle");
  const R r2 = radius * radius;
  const std::size_t chunks = chunk_count(n);
  if (chunk_indices_.size() < chunks) chunk_indices_.resize(chunks);
  counts_.resize(n);

  // Pass 1: new lists of the marked particles, per chunk; old lengths for the others.
  parallel_chunks(n, [&](std::size_t c, std::size_t begin, std::size_t end) {
    auto& buf = chunk_indices_[c];
    buf.clear();
    for (std::size_t i = begin; i < end; ++i) {
      if (rebuild[i] || i >= old_n)
        counts_[i] = gather(grid, positions, r2, i, buf);
      else
        counts_[i] = static_cast<std::uint32_t>(lists.offsets[i + 1] - lists.offsets[i]);
    }
  });

  // Pass 2: merge old and new lists into the scratch storage, then swap it in.
  NeighborLists& out = scratch_;
  set_offsets(n, out);
  parallel_chunks(n, [&](std::size_t c, std::size_t begin, std::size_t end) {
    const std::uint32_t* fresh = chunk_indices_[c].data();
    for (std::size_t i = begin; i < end; ++i) {
      std::uint32_t* dst = out.indices.data() + out.offsets[i];
      const std::size_t len = counts_[i];
      if (len == 0) continue;
      if (rebuild[i] || i >= old_n) {
        std::memcpy(dst, fresh, len * sizeof(std::uint32_t));
        fresh += len;
      } else {
        std::memcpy(dst, lists.indices.data() + lists.offsets[i], len * sizeof(std::uint32_t));
      }
    }
  });
  std::swap(lists, out);
}

template class ListBuilder<2, float>;
template class ListBuilder<2, double>;
template class ListBuilder<3, float>;
template class ListBuilder<3, double>;

}  // namespace sph
