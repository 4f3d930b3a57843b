#include <sph/neighbors/reorder.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include <sph/core/error.h>
#include <sph/core/parallel.h>

namespace sph {

namespace {
/// Spreads the low 32 bits of v to the even bits of a 64-bit word.
std::uint64_t spread2(std::uint64_t v) {
  v &= 0xffffffffull;
  v = (v | (v << 16)) & 0x0000ffff0000ffffull;
  v = (v | (v << 8)) & 0x00ff00ff00ff00ffull;
  v = (v | (v << 4)) & 0x0f0f0f0f0f0f0f0full;
  v = (v | (v << 2)) & 0x3333333333333333ull;
  v = (v | (v << 1)) & 0x5555555555555555ull;
  return v;
}
/// Spreads the low 21 bits of v to every third bit of a 64-bit word.
std::uint64_t spread3(std::uint64_t v) {
  v &= 0x1fffffull;
  v = (v | (v << 32)) & 0x1f00000000ffffull;
  v = (v | (v << 16)) & 0x1f0000ff0000ffull;
  v = (v | (v << 8)) & 0x100f00f00f00f00full;
  v = (v | (v << 4)) & 0x10c30c30c30c30c3ull;
  v = (v | (v << 2)) & 0x1249249249249249ull;
  return v;
}
}  // namespace

std::uint64_t morton_key(std::uint32_t x, std::uint32_t y) { return spread2(x) | (spread2(y) << 1); }
std::uint64_t morton_key(std::uint32_t x, std::uint32_t y, std::uint32_t z) {
  return spread3(x) | (spread3(y) << 1) | (spread3(z) << 2);
}

template <int D, std::floating_point R>
std::span<const std::uint32_t> MortonOrder<D, R>::compute(std::span<const Vec<D, R>> positions, R cell,
                                                          ScratchBuffer* lent) {
  SPH_CHECK(cell > R(0) && std::isfinite(cell), "Morton cell size must be positive and finite");
  SPH_CHECK(positions.size() < std::numeric_limits<std::uint32_t>::max(), "too many points for 32-bit indices");
  const std::size_t n = positions.size();
  if (n == 0) return {};

  Vec<D, R> lo = positions[0];
  for (const auto& x : positions)
    for (int d = 0; d < D; ++d) lo[d] = std::min(lo[d], x[d]);
  bool finite = true;
  for (const auto& x : positions) finite = finite && all_finite(x);
  SPH_CHECK(finite, "non-finite particle position given to the Morton order");

  // Keys from cell coordinates; coordinates beyond the key's bits share the last cell (order
  // stays valid, only coarser, for absurdly elongated point sets).
  Vec<D, R> hi = positions[0];
  for (const auto& x : positions)
    for (int d = 0; d < D; ++d) hi[d] = std::max(hi[d], x[d]);
  constexpr std::uint32_t kMaxCoord = D == 3 ? (1u << 21) - 1 : 0xffffffffu;
  const R inv = R(1) / cell;
  std::uint32_t top = 0;  // largest cell coordinate
  for (int d = 0; d < D; ++d) {
    const R f = (hi[d] - lo[d]) * inv;
    top = std::max(top, f < R(kMaxCoord) ? static_cast<std::uint32_t>(f) : kMaxCoord);
  }
  int bits = 0;
  while (bits < 32 && (top >> bits) != 0) ++bits;
  // 32-bit keys whenever they are enough (half the memory and passes of 64-bit ones).
  if (bits * D <= 32) return sort_by_key<std::uint32_t>(positions, lo, inv, kMaxCoord, lent);
  return sort_by_key<std::uint64_t>(positions, lo, inv, kMaxCoord, lent);
}

template <int D, std::floating_point R>
template <class Key>
std::span<const std::uint32_t> MortonOrder<D, R>::sort_by_key(std::span<const Vec<D, R>> positions, const Vec<D, R>& lo,
                                                              R inv, std::uint32_t max_coord, ScratchBuffer* lent) {
  const std::size_t n = positions.size();
  // Four arrays, the permutation and its second copy, then the keys and theirs: each in the lent
  // memory while it has room left, the rest in this sort's own.
  const std::size_t bytes[4] = {ScratchBuffer::round_up(n * sizeof(std::uint32_t)),
                                ScratchBuffer::round_up(n * sizeof(std::uint32_t)),
                                ScratchBuffer::round_up(n * sizeof(Key)), ScratchBuffer::round_up(n * sizeof(Key))};
  ScratchBuffer* where[4];
  std::size_t offset[4], lent_used = 0, own_used = 0;
  for (int a = 0; a < 4; ++a) {
    if (lent && lent_used + bytes[a] <= lent->capacity()) {
      where[a] = lent;
      offset[a] = lent_used;
      lent_used += bytes[a];
    } else {
      lent = nullptr;  // (in order: the arrays after one that did not fit are this sort's own)
      where[a] = &own_;
      offset[a] = own_used;
      own_used += bytes[a];
    }
  }
  own_.reserve(own_used);
  std::uint32_t* const perm = where[0]->place<std::uint32_t>(offset[0], n);
  std::uint32_t* const tmp = where[1]->place<std::uint32_t>(offset[1], n);
  Key* const keys = where[2]->place<Key>(offset[2], n);
  Key* const keys_tmp = where[3]->place<Key>(offset[3], n);
  parallel_for(n, [&](std::size_t i) {
    std::uint32_t c[D];
    for (int d = 0; d < D; ++d) {
      const R f = (positions[i][d] - lo[d]) * inv;
      c[d] = f < R(max_coord) ? static_cast<std::uint32_t>(f) : max_coord;
    }
    if constexpr (D == 2)
      keys[i] = static_cast<Key>(morton_key(c[0], c[1]));
    else
      keys[i] = static_cast<Key>(morton_key(c[0], c[1], c[2]));
  });

  // LSD radix sort of (key, index), 8 bits per pass, only over the bits some key uses.
  Key all = 0;
  for (std::size_t i = 0; i < n; ++i) all |= keys[i];
  int passes = 0;
  while (passes < static_cast<int>(sizeof(Key)) && (static_cast<std::uint64_t>(all) >> (8 * passes)) != 0) ++passes;
  for (std::size_t i = 0; i < n; ++i) perm[i] = static_cast<std::uint32_t>(i);
  histogram_.resize(256);
  // Each pass scatters from one copy into the other.
  Key *key = keys, *key_out = keys_tmp;
  std::uint32_t *index = perm, *index_out = tmp;
  for (int p = 0; p < passes; ++p) {
    const int shift = 8 * p;
    std::fill(histogram_.begin(), histogram_.end(), 0u);
    for (std::size_t i = 0; i < n; ++i) ++histogram_[(key[i] >> shift) & 0xff];
    std::uint32_t sum = 0;
    for (auto& h : histogram_) {
      const std::uint32_t c = h;
      h = sum;
      sum += c;
    }
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint32_t dst = histogram_[(key[i] >> shift) & 0xff]++;
      key_out[dst] = key[i];
      index_out[dst] = index[i];
    }
    std::swap(key, key_out);
    std::swap(index, index_out);
  }
  return {index, n};
}

template class MortonOrder<2, float>;
template class MortonOrder<2, double>;
template class MortonOrder<3, float>;
template class MortonOrder<3, double>;

}  // namespace sph
