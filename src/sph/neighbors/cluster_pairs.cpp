#include <sph/neighbors/cluster_pairs.h>

#include <algorithm>
#include <cmath>

#include <sph/core/error.h>
#include <sph/core/parallel.h>
#include <sph/core/storage.h>

namespace sph {

template <int D, std::floating_point R>
void ClusterPairs<D, R>::clear() {
  particles_ = pairs_ = 0;
  slots_.clear();
  begin_.clear();
  end_.clear();
}

template <int D, std::floating_point R>
void ClusterPairs<D, R>::build(const UniformGrid<D, R>& grid, std::span<const Vec<D, R>> positions, R radius) {
  SPH_CHECK(radius > R(0) && std::isfinite(radius), "cluster radius must be positive and finite");
  const std::size_t n = positions.size();
  SPH_CHECK(n < kEmpty / kSize, "too many particles for 32-bit cluster slots");
  clear();
  particles_ = n;
  if (n == 0) return;

  // The particles' box (min and max are exact: the same in any order).
  Vec<D, R> lo = positions[0], hi = positions[0];
  for (const Vec<D, R>& x : positions)
    for (int d = 0; d < D; ++d) {
      lo[d] = std::min(lo[d], x[d]);
      hi[d] = std::max(hi[d], x[d]);
    }
  // Columns' side: a cube holding kSize particles at the density of the grid's occupied cells;
  // widened while there would be more columns than particles (a stray particle far away).
  const double occupied =
      static_cast<double>(grid.occupied_cells()) * std::pow(static_cast<double>(grid.cell_size()), D);
  double side = std::pow(kSize * occupied / static_cast<double>(n), 1.0 / D);
  if (!(side > 0) || !std::isfinite(side)) side = static_cast<double>(radius);
  std::int64_t ncol[D > 1 ? D - 1 : 1] = {};
  std::size_t columns = 1;
  for (;;) {
    double count = 1;
    for (int d = 0; d + 1 < D; ++d) count *= std::floor(static_cast<double>(hi[d] - lo[d]) / side) + 1.0;
    if (count <= static_cast<double>(n) + 64.0) break;
    side *= 1.5;
  }
  const R inv_side = static_cast<R>(1.0 / side);
  for (int d = 0; d + 1 < D; ++d) {
    ncol[d] = static_cast<std::int64_t>(std::floor(static_cast<double>(hi[d] - lo[d]) / side)) + 1;
    columns *= static_cast<std::size_t>(ncol[d]);
  }
  // (the same rounding for a particle's column and for a search's range: both are monotone in x)
  const auto column_coord = [&](R x, int d) {
    const R t = (x - lo[d]) * inv_side;
    if (!(t >= R(0))) return std::int64_t{0};
    const R last = static_cast<R>(ncol[d] - 1);
    return static_cast<std::int64_t>(t < last ? t : last);
  };
  const auto column_index = [&](const Vec<D, R>& x) {
    std::int64_t c = 0;
    for (int d = D - 2; d >= 0; --d) c = c * ncol[d] + column_coord(x[d], d);
    return static_cast<std::uint32_t>(c);
  };

  // Particles by column (a stable counting sort), then along the last axis within each column.
  resize_with_room(cluster_of_, n);
  parallel_for(n, [&](std::size_t i) { cluster_of_[i] = column_index(positions[i]); });
  assign_with_room(column_start_, columns + 1, 0u);
  for (std::size_t i = 0; i < n; ++i) ++column_start_[cluster_of_[i] + 1];
  for (std::size_t c = 0; c < columns; ++c) column_start_[c + 1] += column_start_[c];
  resize_with_room(order_, n);
  {
    std::vector<std::uint32_t>& cursor = begin_;  // (scratch: the lists' offsets are written below)
    resize_with_room(cursor, columns);
    std::copy(column_start_.begin(), column_start_.end() - 1, cursor.begin());
    for (std::size_t i = 0; i < n; ++i) order_[cursor[cluster_of_[i]]++] = static_cast<std::uint32_t>(i);
  }
  parallel_for(columns, [&](std::size_t c) {
    std::sort(order_.begin() + column_start_[c], order_.begin() + column_start_[c + 1],
              [&](std::uint32_t a, std::uint32_t b) {
                const R za = positions[a][D - 1], zb = positions[b][D - 1];
                return za < zb || (za == zb && a < b);
              });
  });

  // Clusters: each column's particles kSize at a time.
  assign_with_room(column_cluster_, columns + 1, 0u);
  for (std::size_t c = 0; c < columns; ++c)
    column_cluster_[c + 1] = column_cluster_[c] + (column_start_[c + 1] - column_start_[c] + kSize - 1) / kSize;
  const std::size_t clusters = column_cluster_[columns];
  assign_with_room(slots_, clusters * kSize, kEmpty);
  parallel_for(columns, [&](std::size_t c) {
    const std::size_t first = column_start_[c], count = column_start_[c + 1] - first;
    for (std::size_t k = 0; k < count; ++k) slots_[column_cluster_[c] * kSize + k] = order_[first + k];
  });
  parallel_for(slots_.size(), [&](std::size_t k) {
    if (slots_[k] != kEmpty) cluster_of_[slots_[k]] = static_cast<std::uint32_t>(k / kSize);
  });
  resize_with_room(lo_, clusters);
  resize_with_room(hi_, clusters);
  parallel_for(clusters, [&](std::size_t k) {
    Vec<D, R> a = positions[slots_[k * kSize]], b = a;
    for (int s = 1; s < kSize; ++s)
      if (const std::uint32_t p = slots_[k * kSize + s]; p != kEmpty)
        for (int d = 0; d < D; ++d) {
          a[d] = std::min(a[d], positions[p][d]);
          b[d] = std::max(b[d], positions[p][d]);
        }
    lo_[k] = a;
    hi_[k] = b;
  });

  // Lists: the columns within reach of a cluster's box (a hair wider than the radius, so that
  // rounding in the column coordinates cannot leave one out), up each column the clusters whose
  // range along the last axis overlaps (they are sorted along it), and of those the ones whose
  // box gap is under the radius.
  const R reach = radius * (R(1) + R(1e-4));
  const R r2 = radius * radius;
  const std::size_t nchunks = (clusters + kChunkClusters - 1) / kChunkClusters;
  if (chunks_.size() < nchunks) {  // (spare chunks, for clusters to come)
    const std::size_t old = chunks_.size();
    chunks_.resize(nchunks + nchunks / 4 + 4);
    for (std::size_t k = old; k < chunks_.size(); ++k) chunks_[k].reserve(longest_chunk_ + longest_chunk_ / 4 + 64);
  }
  resize_with_room(begin_, clusters);
  resize_with_room(end_, clusters);
  assign_with_room(chunk_pairs_, nchunks, std::size_t{0});
  // Up a column, clusters' bottoms and tops increase: for the clusters of one column taken in
  // order, the first cluster of a neighbor column that reaches up to the box's bottom only moves
  // up. Each neighbor column within kWindow columns keeps that cursor (found by binary search
  // when a chunk or a column starts); beyond the window (a radius of many columns), each cluster
  // searches again.
  const auto first_reaching = [&](std::size_t col, R bottom) {
    std::size_t b = column_cluster_[col], count = column_cluster_[col + 1] - b;
    while (count > 0) {
      const std::size_t half = count / 2;
      if (hi_[b + half][D - 1] < bottom) {
        b += half + 1;
        count -= half + 1;
      } else {
        count = half;
      }
    }
    return static_cast<std::uint32_t>(b);
  };
  constexpr std::int64_t kWindow = 4;      // columns each side
  constexpr int kSlots = D == 3 ? 81 : 9;  // (2 kWindow + 1)^(D - 1)
  const auto scan = [&](std::size_t k, std::size_t col, std::uint32_t& cursor, std::vector<std::uint32_t>& out) {
    const R bottom = lo_[k][D - 1] - reach, top = hi_[k][D - 1] + reach;
    const std::size_t e = column_cluster_[col + 1];
    std::size_t m = cursor;
    while (m < e && hi_[m][D - 1] < bottom) ++m;
    cursor = static_cast<std::uint32_t>(m);
    for (; m < e && !(lo_[m][D - 1] > top); ++m) {
      R gap2 = 0;
      for (int d = 0; d < D; ++d) {
        R g = lo_[m][d] - hi_[k][d];
        const R g2 = lo_[k][d] - hi_[m][d];
        if (g2 > g) g = g2;
        if (g < R(0)) g = R(0);
        gap2 = gap2 + g * g;
      }
      if (gap2 < r2) out.push_back(static_cast<std::uint32_t>(m));
    }
  };
  parallel_for(nchunks, [&](std::size_t ch) {
    std::vector<std::uint32_t>& out = chunks_[ch];
    const std::size_t kb = ch * kChunkClusters, ke = std::min(clusters, kb + kChunkClusters);
    // (a chunk shorter than the longest a chunk has been takes room for a quarter more: a chunk
    // whose clusters change from build to build does not allocate at each build)
    if (out.capacity() < longest_chunk_) out.reserve(longest_chunk_ + longest_chunk_ / 4 + 64);
    out.clear();
    // The column of cluster kb, and the cursors of its neighbor columns (unset: kEmpty).
    std::size_t col = static_cast<std::size_t>(
        std::upper_bound(column_cluster_.begin(), column_cluster_.begin() + static_cast<std::ptrdiff_t>(columns) + 1,
                         static_cast<std::uint32_t>(kb)) -
        column_cluster_.begin() - 1);
    std::uint32_t cursor[kSlots];
    std::fill(cursor, cursor + kSlots, kEmpty);
    for (std::size_t k = kb; k < ke; ++k) {
      if (k >= column_cluster_[col + 1]) {
        while (k >= column_cluster_[col + 1]) ++col;
        std::fill(cursor, cursor + kSlots, kEmpty);
      }
      const auto cx = static_cast<std::int64_t>(col % static_cast<std::size_t>(ncol[0]));
      const auto cy = D == 3 ? static_cast<std::int64_t>(col / static_cast<std::size_t>(ncol[0])) : std::int64_t{0};
      begin_[k] = static_cast<std::uint32_t>(out.size());
      const std::int64_t x0 = column_coord(lo_[k][0] - reach, 0), x1 = column_coord(hi_[k][0] + reach, 0);
      std::int64_t y0 = 0, y1 = 0;
      if constexpr (D == 3) y0 = column_coord(lo_[k][1] - reach, 1), y1 = column_coord(hi_[k][1] + reach, 1);
      for (std::int64_t y = y0; y <= y1; ++y)
        for (std::int64_t x = x0; x <= x1; ++x) {
          const auto other = static_cast<std::size_t>(D == 3 ? y * ncol[0] + x : x);
          if (x - cx >= -kWindow && x - cx <= kWindow && y - cy >= -kWindow && y - cy <= kWindow) {
            const std::int64_t slot = (D == 3 ? (y - cy + kWindow) * (2 * kWindow + 1) : 0) + (x - cx + kWindow);
            std::uint32_t& c = cursor[slot];
            if (c == kEmpty) c = first_reaching(other, lo_[k][D - 1] - reach);
            scan(k, other, c, out);
          } else {
            std::uint32_t c = first_reaching(other, lo_[k][D - 1] - reach);
            scan(k, other, c, out);
          }
        }
      end_[k] = static_cast<std::uint32_t>(out.size());
    }
    chunk_pairs_[ch] = out.size();
  });
  for (std::size_t p : chunk_pairs_) pairs_ += p;
  for (std::size_t p : chunk_pairs_) longest_chunk_ = std::max(longest_chunk_, p);
}

template <int D, std::floating_point R>
std::size_t ClusterPairs<D, R>::memory_bytes() const {
  std::size_t bytes = 0;
  for (const auto& c : chunks_) bytes += c.capacity() * sizeof(std::uint32_t);
  bytes += (slots_.capacity() + cluster_of_.capacity() + column_start_.capacity() + column_cluster_.capacity() +
            order_.capacity() + begin_.capacity() + end_.capacity()) *
           sizeof(std::uint32_t);
  bytes += (lo_.capacity() + hi_.capacity()) * sizeof(Vec<D, R>);
  return bytes;
}

template class ClusterPairs<2, float>;
template class ClusterPairs<2, double>;
template class ClusterPairs<3, float>;
template class ClusterPairs<3, double>;

}  // namespace sph
