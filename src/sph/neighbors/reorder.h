#pragma once
/// \file MortonOrder: a permutation that sorts points along a Z-order (Morton) curve, so that
/// particles close in space are close in memory (neighbor search and the SPH loops then read
/// memory almost sequentially, even after a flow has scrambled the particle order).

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <sph/core/storage.h>
#include <sph/core/vec.h>

namespace sph {

/// Computes Morton-order permutations. Keeps its scratch buffers between calls.
template <int D, std::floating_point R>
class MortonOrder {
 public:
  /// Returns the permutation perm (of positions.size()) such that perm[k] is the index of the
  /// point that comes k-th along the Z-order curve of cells of size `cell` over the points'
  /// bounding box. Points in the same cell keep their relative order (stable), so the result
  /// depends only on the input. Non-finite positions are a bug upstream (the solver stops a
  /// blow-up first): refused with std::logic_error (SPH_CHECK). cell must be > 0.
  /// `lent`: memory the sort takes its keys and permutations from (two copies of each: 16 bytes a
  /// point with 32-bit keys, 24 with 64-bit ones) before its own (UniformGrid::lend_scratch);
  /// null: its own only.
  /// The result lies in that memory: valid until the next call, or until the lent memory is used
  /// again.
  std::span<const std::uint32_t> compute(std::span<const Vec<D, R>> positions, R cell, ScratchBuffer* lent = nullptr);

 private:
  template <class Key>
  std::span<const std::uint32_t> sort_by_key(std::span<const Vec<D, R>> positions, const Vec<D, R>& lo, R inv,
                                             std::uint32_t max_coord, ScratchBuffer* lent);

  ScratchBuffer own_;  // what the lent memory could not hold
  std::vector<std::uint32_t> histogram_;
};

/// Interleaves the low bits of cell coordinates into a Morton key (21 bits per axis in 3D,
/// 32 in 2D).
std::uint64_t morton_key(std::uint32_t x, std::uint32_t y);
std::uint64_t morton_key(std::uint32_t x, std::uint32_t y, std::uint32_t z);

extern template class MortonOrder<2, float>;
extern template class MortonOrder<2, double>;
extern template class MortonOrder<3, float>;
extern template class MortonOrder<3, double>;

}  // namespace sph
