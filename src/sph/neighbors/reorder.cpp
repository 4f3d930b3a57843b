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
void MortonOrder<D, R>::compute(std::span<const Vec<D, R>> positions, R cell, std::vector<std::uint32_t>& perm) {
  SPH_CHECK(cell > R(0) && std::isfinite(cell), "Morton cell size must be positive and finite");
  SPH_CHECK(positions.size() < std::numeric_limits<std::uint32_t>::max(), "too many points for 32-bit indices");
  const std::size_t n = positions.size();
  perm.resize(n);
  if (n == 0) return;

  Vec<D, R> lo = positions[0];
  for (const auto& x : positions)
    for (int d = 0; d < D; ++d) lo[d] = std::min(lo[d], x[d]);
  for (int d = 0; d < D; ++d) SPH_CHECK(std::isfinite(lo[d]), "non-finite particle position given to the Morton order");

  // Keys from cell coordinates; coordinates beyond the key's bits share the last cell (order
  // stays valid, only coarser, for absurdly elongated point sets).
  constexpr std::uint32_t kMaxCoord = D == 3 ? (1u << 21) - 1 : 0xffffffffu;
  const R inv = R(1) / cell;
  keys_.resize(n);
  bool finite = true;
  parallel_for(n, [&](std::size_t i) {
    std::uint32_t c[D];
    for (int d = 0; d < D; ++d) {
      const R f = (positions[i][d] - lo[d]) * inv;
      c[d] = f < R(kMaxCoord) ? static_cast<std::uint32_t>(f) : kMaxCoord;  // NaN also lands here
    }
    if constexpr (D == 2)
      keys_[i] = morton_key(c[0], c[1]);
    else
      keys_[i] = morton_key(c[0], c[1], c[2]);
  });
  for (const auto& x : positions) finite = finite && all_finite(x);
  SPH_CHECK(finite, "non-finite particle position given to the Morton order");

  // LSD radix sort of (key, index), 8 bits per pass, only over the bits some key uses.
  std::uint64_t all = 0;
  for (std::uint64_t k : keys_) all |= k;
  int passes = 0;
  while (passes < 8 && (all >> (8 * passes)) != 0) ++passes;
  for (std::size_t i = 0; i < n; ++i) perm[i] = static_cast<std::uint32_t>(i);
  keys_tmp_.resize(n);
  tmp_.resize(n);
  histogram_.resize(256);
  for (int p = 0; p < passes; ++p) {
    const int shift = 8 * p;
    std::fill(histogram_.begin(), histogram_.end(), 0u);
    for (std::size_t i = 0; i < n; ++i) ++histogram_[(keys_[i] >> shift) & 0xff];
    std::uint32_t sum = 0;
    for (auto& h : histogram_) {
      const std::uint32_t c = h;
      h = sum;
      sum += c;
    }
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint32_t dst = histogram_[(keys_[i] >> shift) & 0xff]++;
      keys_tmp_[dst] = keys_[i];
      tmp_[dst] = perm[i];
    }
    keys_.swap(keys_tmp_);
    perm.swap(tmp_);
  }
}

template class MortonOrder<2, float>;
template class MortonOrder<2, double>;
template class MortonOrder<3, float>;
template class MortonOrder<3, double>;

}  // namespace sph
