#pragma once
/// \file UniformGrid: dense cells over the particles' bounding box, filled by counting sort.

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <sph/core/storage.h>
#include <sph/core/vec.h>

namespace sph {

/// A uniform grid of square (cubic) cells over the bounding box of a point set, rebuilt from
/// scratch by build(). Cells are dense (every cell in the box exists), particles are sorted by
/// cell with a stable counting sort, so queries visit candidates in a fixed order.
///
/// The cell size is at least the search radius, so the neighbors of a point within the radius
/// lie in the 3^D cells around its own. If the box would need more than `max_cells` cells (a
/// stray particle far away), the cell size is enlarged: queries stay exact, only slower.
template <int D, std::floating_point R>
class UniformGrid {
 public:
  using V = Vec<D, R>;

  /// Sorts `positions` into cells of size >= radius. radius must be > 0 and finite.
  void build(std::span<const V> positions, R radius);

  const std::array<std::int64_t, D>& dims() const { return dims_; }

  /// The cell (linear index, x fastest) whose stencil holds every grid point within the radius
  /// of x: for one of the grid's points, the cell the build put it in (the build computes each
  /// point's cell with this function); for a query point that is not one of them (boundary
  /// lists: fluid particles against the grid of the boundary samples), a point outside the
  /// grid's box maps to the nearest cell on its edge, whose stencil still holds every point within
  /// the radius (cells are at least the radius).
  std::uint32_t cell_containing(const V& x) const {
    std::uint32_t l = 0;
    for (int d = D - 1; d >= 0; --d) {
      // Clamped before the conversion, so that a far-away (or non-finite) x is well defined
      // (32 bits: every cell index fits, checked by the build).
      const R t = (x[d] - origin_[d]) * inv_cell_;
      const R last = static_cast<R>(dims_[d] - 1);
      const auto k = static_cast<std::uint32_t>(t >= R(0) ? (t < last ? t : last) : R(0));
      l = l * static_cast<std::uint32_t>(dims_[d]) + k;
    }
    return l;
  }
  /// cell_containing() of x[0], ..., x[n - 1], written to out (a chunk's at once, before its
  /// lists: a loop the compiler can vectorize).
  void cells_containing(const V* x, std::size_t n, std::uint32_t* out) const {
    for (std::size_t i = 0; i < n; ++i) out[i] = cell_containing(x[i]);
  }
  /// Point indices in cell-sorted order (stable within a cell), followed by kPad zeros.
  const std::uint32_t* sorted() const { return sorted_; }
  /// Coordinate d of the points in cell-sorted order, followed by kPad zeros: candidates of
  /// one row of cells are contiguous here, ready for vector loads.
  const R* sorted_coord(int d) const { return coords_[static_cast<std::size_t>(d)]; }

  /// Readable padding after the sorted arrays, so that vector loads may run past the end.
  static constexpr std::size_t kPad = 16;
  /// Most row ranges stencil_ranges() returns: 3 in 2D, 9 in 3D.
  static constexpr int kMaxRanges = D == 3 ? 9 : 3;

  /// The candidates of every point in `cell`: the 3^D cells around it, as up to kMaxRanges
  /// contiguous ranges [begin[k], end[k]) of sorted positions (one per row of cells along x,
  /// empty rows skipped), in a fixed order. Returns the number of ranges.
  int stencil_ranges(std::uint32_t cell, std::uint32_t* begin, std::uint32_t* end) const {
    // (in 32 bits, which every cell index and extent fits, and without a division for the last
    // axis: a 64-bit division was a fifth of the list build's own time, outside the distance tests)
    std::int64_t c[D];
    std::uint32_t rest = cell;
    for (int d = 0; d + 1 < D; ++d) {
      const auto n = static_cast<std::uint32_t>(dims_[d]);
      c[d] = rest % n;
      rest /= n;
    }
    c[D - 1] = rest;
    const std::int64_t x0 = c[0] > 0 ? c[0] - 1 : 0;
    const std::int64_t x1 = c[0] + 1 < dims_[0] ? c[0] + 1 : dims_[0] - 1;
    const std::int64_t y0 = c[1] > 0 ? c[1] - 1 : 0;
    const std::int64_t y1 = c[1] + 1 < dims_[1] ? c[1] + 1 : dims_[1] - 1;
    std::int64_t z0 = 0, z1 = 0;
    if constexpr (D == 3) {
      z0 = c[2] > 0 ? c[2] - 1 : 0;
      z1 = c[2] + 1 < dims_[2] ? c[2] + 1 : dims_[2] - 1;
    }
    int k = 0;
    for (std::int64_t z = z0; z <= z1; ++z)
      for (std::int64_t y = y0; y <= y1; ++y) {
        const std::int64_t row = (D == 3 ? z * dims_[1] + y : y) * dims_[0];
        const std::uint32_t b = cell_start_[static_cast<std::size_t>(row + x0)];
        const std::uint32_t e = cell_start_[static_cast<std::size_t>(row + x1) + 1];
        begin[k] = b;
        end[k] = e;
        k += e > b ? 1 : 0;
      }
    return k;
  }

  /// The cells' side (at least the radius).
  R cell_size() const { return R(1) / inv_cell_; }
  /// Cells holding at least one point.
  std::size_t occupied_cells() const {
    std::size_t k = 0;
    for (std::size_t c = 0; c + 1 < cell_start_.size(); ++c) k += cell_start_[c + 1] > cell_start_[c] ? 1 : 0;
    return k;
  }
  /// Maximum number of dense cells, relative to the point count (plus a constant).
  static constexpr std::size_t kMaxCellsPerPoint = 8;

  /// The grid's memory for its per-point arrays (the sorted indices and coordinates: 4 + D
  /// sizeof(R) bytes a point), lent as scratch to a caller that builds the grid again before it
  /// is queried (the Morton reorder's sort: the reorder invalidates the lists, so the next update
  /// builds the grid first). Its contents are lost. It gets the room a build of n points needs
  /// first, so that the build after the caller's use does not allocate (a block outgrown and
  /// freed can stay resident); with n = 0, the room it has (the last build's). Also lent between a
  /// neighbor strategy's updates (NeighborStrategy::scratch_until_update).
  ScratchBuffer& lend_scratch(std::size_t n) {
    store_.reserve(bytes_for(n));
    sorted_ = nullptr;
    coords_ = {};
    return store_;
  }

 private:
  /// Sets origin_, inv_cell_ and dims_ for `positions` (cells of size >= radius, at most
  /// kMaxCellsPerPoint per point plus a constant); returns the number of cells.
  std::size_t lay_out_cells(std::span<const V> positions, R radius);
  /// Fills cell_start_ and sorted_ (a stable counting sort of the points by cell), with each
  /// point's cell kept where the coordinates go next.
  void sort_by_cell(std::span<const V> positions, std::size_t cells);
  /// Where the coordinates start in store_, and each axis's stride, for n points (each array
  /// padded with kPad and aligned).
  static std::size_t coords_offset(std::size_t n) {
    return ScratchBuffer::round_up((n + kPad) * sizeof(std::uint32_t));
  }
  static std::size_t coord_stride(std::size_t n) { return ScratchBuffer::round_up((n + kPad) * sizeof(R)); }
  static std::size_t bytes_for(std::size_t n) { return coords_offset(n) + D * coord_stride(n); }
  V origin_{};
  R inv_cell_ = 0;
  std::array<std::int64_t, D> dims_{};
  std::vector<std::uint32_t> cell_start_;    // size cells + 1
  std::vector<std::uint32_t> block_cursor_;  // parallel counting sort: per block and cell
  // store_ holds the point indices sorted by cell (stable), then the coordinates in that order
  // (each + kPad); while the sort runs, each point's cell where the coordinates go.
  ScratchBuffer store_;
  std::uint32_t* sorted_ = nullptr;
  std::array<R*, D> coords_{};
  std::vector<V> box_lo_, box_hi_;  // bounding box of each chunk of points
};

extern template class UniformGrid<2, float>;
extern template class UniformGrid<2, double>;
extern template class UniformGrid<3, float>;
extern template class UniformGrid<3, double>;

}  // namespace sph
