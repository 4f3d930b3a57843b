#include <sph/neighbors/uniform_grid.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include <sph/core/error.h>
#include <sph/core/parallel.h>

namespace sph {

template <int D, std::floating_point R>
void UniformGrid<D, R>::build(std::span<const V> positions, R radius) {
  SPH_CHECK(radius > R(0) && std::isfinite(radius), "grid radius must be positive and finite");
  SPH_CHECK(positions.size() < std::numeric_limits<std::uint32_t>::max(), "too many points for 32-bit indices");
  const std::size_t cells = lay_out_cells(positions, radius);
  sort_by_cell(positions, cells);
  // Coordinates in sorted order, one array per axis (where the cells were: they are not needed
  // any more, cell_containing() computes a point's again).
  const std::size_t n = positions.size();
  for (int d = 0; d < D; ++d)
    coords_[static_cast<std::size_t>(d)] =
        store_.place<R>(coords_offset(n) + static_cast<std::size_t>(d) * coord_stride(n), n + kPad);
  parallel_for(n, [&](std::size_t k) {
    const V& x = positions[sorted_[k]];
    for (int d = 0; d < D; ++d) coords_[static_cast<std::size_t>(d)][k] = x[d];
  });
  for (R* c : coords_) std::fill(c + n, c + n + kPad, R(0));
}

template <int D, std::floating_point R>
std::size_t UniformGrid<D, R>::lay_out_cells(std::span<const V> positions, R radius) {
  const std::size_t n = positions.size();
  // Bounding box (min/max are exact, so the result does not depend on evaluation order).
  V lo = V::filled(R(0)), hi = V::filled(R(0));
  if (n > 0) {
    const std::size_t chunks = chunk_count(n);
    box_lo_.resize(chunks);
    box_hi_.resize(chunks);
    parallel_chunks(n, [&](std::size_t c, std::size_t b, std::size_t e) {
      V l = positions[b], h = positions[b];
      for (std::size_t i = b + 1; i < e; ++i)
        for (int d = 0; d < D; ++d) {
          l[d] = std::min(l[d], positions[i][d]);
          h[d] = std::max(h[d], positions[i][d]);
        }
      box_lo_[c] = l;
      box_hi_[c] = h;
    });
    lo = box_lo_[0];
    hi = box_hi_[0];
    for (std::size_t c = 1; c < chunks; ++c)
      for (int d = 0; d < D; ++d) {
        lo[d] = std::min(lo[d], box_lo_[c][d]);
        hi[d] = std::max(hi[d], box_hi_[c][d]);
      }
  }
  for (int d = 0; d < D; ++d)
    SPH_CHECK(std::isfinite(lo[d]) && std::isfinite(hi[d]), "non-finite particle position given to the grid");

  // Cell size: the radius plus a margin for rounding in the cell computation, so that two
  // points closer than the radius never land more than one cell apart.
  R max_abs = 0, max_extent = 0;
  for (int d = 0; d < D; ++d) {
    max_abs = std::max({max_abs, std::abs(lo[d]), std::abs(hi[d])});
    max_extent = std::max(max_extent, hi[d] - lo[d]);
  }
  R cs = radius * (R(1) + R(1e-4)) + R(16) * std::numeric_limits<R>::epsilon() * (max_abs + max_extent);

  // Cap the number of dense cells.
  const double max_cells = static_cast<double>(kMaxCellsPerPoint * n + 4096);
  for (;;) {
    double cells = 1;
    for (int d = 0; d < D; ++d) cells *= std::floor(static_cast<double>(hi[d] - lo[d]) / cs) + 1.0;
    if (cells <= max_cells) break;
    cs *= R(1.5);
  }

  origin_ = lo;
  inv_cell_ = R(1) / cs;
  std::size_t cells = 1;
  for (int d = 0; d < D; ++d) {
    dims_[d] = static_cast<std::int64_t>(std::floor((hi[d] - lo[d]) * inv_cell_)) + 1;
    cells *= static_cast<std::size_t>(dims_[d]);
  }

  SPH_CHECK(cells < std::numeric_limits<std::uint32_t>::max(), "too many grid cells for 32-bit cell indices");
  return cells;
}

template <int D, std::floating_point R>
void UniformGrid<D, R>::sort_by_cell(std::span<const V> positions, std::size_t cells) {
  const std::size_t n = positions.size();
  // Counting sort by cell, stable in the point index.
  store_.reserve(bytes_for(n));
  sorted_ = store_.place<std::uint32_t>(0, n + kPad);
  coords_ = {};
  std::uint32_t* const cell_of = store_.place<std::uint32_t>(coords_offset(n), n);
  parallel_chunks(n, [&](std::size_t, std::size_t b, std::size_t e) {
    cells_containing(positions.data() + b, e - b, cell_of + b);
  });
  cell_start_.assign(cells + 1, 0);
  // A stable sort by cell has one result, however it is computed: with several threads, each
  // of B contiguous blocks of points counts its cells, a prefix over (cell, block) gives each
  // block its own cursors, and the blocks scatter in parallel. Only when the B histograms are
  // small next to the points (they are kept between builds).
  const std::size_t blocks = std::min<std::size_t>(static_cast<std::size_t>(num_threads()), 64);
  if (blocks > 1 && n >= 16384 && blocks * cells <= n / 2) {
    block_cursor_.resize(blocks * cells);
    const auto range = [&](std::size_t b) { return std::pair{n * b / blocks, n * (b + 1) / blocks}; };
    parallel_for(blocks, [&](std::size_t b) {
      std::uint32_t* count = block_cursor_.data() + b * cells;
      std::fill(count, count + cells, 0u);
      const auto [first, last] = range(b);
      for (std::size_t i = first; i < last; ++i) ++count[cell_of[i]];
    });
    std::uint32_t running = 0;
    for (std::size_t c = 0; c < cells; ++c) {
      cell_start_[c] = running;
      for (std::size_t b = 0; b < blocks; ++b) {
        std::uint32_t& k = block_cursor_[b * cells + c];
        const std::uint32_t count = k;
        k = running;
        running += count;
      }
    }
    cell_start_[cells] = running;
    parallel_for(blocks, [&](std::size_t b) {
      std::uint32_t* cursor = block_cursor_.data() + b * cells;
      const auto [first, last] = range(b);
      for (std::size_t i = first; i < last; ++i) sorted_[cursor[cell_of[i]]++] = static_cast<std::uint32_t>(i);
    });
  } else {
    for (std::size_t i = 0; i < n; ++i) ++cell_start_[cell_of[i] + 1];
    for (std::size_t c = 0; c < cells; ++c) cell_start_[c + 1] += cell_start_[c];
    // Scatter using a running cursor per cell (cell_start_ shifted by one, then restored).
    for (std::size_t i = 0; i < n; ++i) sorted_[cell_start_[cell_of[i]]++] = static_cast<std::uint32_t>(i);
    for (std::size_t c = cells; c > 0; --c) cell_start_[c] = cell_start_[c - 1];
    cell_start_[0] = 0;
  }
  std::fill(sorted_ + n, sorted_ + n + kPad, 0u);
}

template class UniformGrid<2, float>;
template class UniformGrid<2, double>;
template class UniformGrid<3, float>;
template class UniformGrid<3, double>;

}  // namespace sph
