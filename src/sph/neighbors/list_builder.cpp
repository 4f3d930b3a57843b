#include <sph/neighbors/list_builder.h>

#include <algorithm>
#include <cstring>

#include <sph/core/parallel.h>

namespace sph {

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
    for (std::size_t i = begin; i < end; ++i) {
      const Vec<D, R> xi = positions[i];
      const std::size_t before = buf.size();
      grid.for_each_candidate(xi, [&](std::uint32_t j) {
        if (j == i) return;
        if (norm2(xi - positions[j]) < r2) buf.push_back(j);
      });
      counts_[i] = static_cast<std::uint32_t>(buf.size() - before);
    }
  });

  // Offsets by prefix sum, then copy each chunk's buffer to its place.
  out.offsets.resize(n + 1);
  out.offsets[0] = 0;
  for (std::size_t i = 0; i < n; ++i) out.offsets[i + 1] = out.offsets[i] + counts_[i];
  out.indices.resize(out.offsets[n]);
  parallel_for(chunks, [&](std::size_t c) {
    const auto& buf = chunk_indices_[c];
    if (!buf.empty()) std::memcpy(out.indices.data() + out.offsets[c * kChunkSize], buf.data(), buf.size() * sizeof(std::uint32_t));
  });
}

template class ListBuilder<2, float>;
template class ListBuilder<2, double>;
template class ListBuilder<3, float>;
template class ListBuilder<3, double>;

}  // namespace sph
