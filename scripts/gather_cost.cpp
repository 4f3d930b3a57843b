// What the force pass over per-particle lists pays to read a register of neighbors' values, on one
// core: the positions, velocities, densities and pressures by one gather instruction per component
// (as until 2026-12-06), the positions and velocities by simd::gather_vectors and the two scalars
// by gathers, and everything by gather_vectors (the two scalars side by side, as the pass reads
// 1 / rho and p now). 4 M pairs whose indices lie within a window of 2,000 particles around a
// moving centre (as a Morton-ordered scene's neighbors do), ns per pair, for floats and doubles.
// docs/performance.md, "Neighbors' values loaded, not gathered"; run by scripts/gather_cost.sh.

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <random>
#include <vector>

#include <sph/core/simd.h>

namespace {

template <class R>
void measure(std::size_t n) {
  using P = sph::simd::Pack<R>;
  constexpr int W = sph::simd::kLanes<R>;
  constexpr std::size_t kPairs = std::size_t{1} << 22;
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<R> pos(3 * n), vel(3 * n), rho(n), prs(n), side(2 * n);
  for (R& x : pos) x = static_cast<R>(u(rng));
  for (R& x : vel) x = static_cast<R>(u(rng));
  for (std::size_t i = 0; i < n; ++i) {
    rho[i] = static_cast<R>(1000 + u(rng)), prs[i] = static_cast<R>(u(rng));
    side[2 * i] = R(1) / rho[i], side[2 * i + 1] = prs[i];
  }
  std::vector<std::uint32_t> idx(kPairs);
  for (std::size_t q = 0; q < kPairs; ++q) idx[q] = static_cast<std::uint32_t>(((q / 32) + rng() % 2000) % n);
  double ns[3];
  R sink = 0;
  for (int variant = 0; variant < 3; ++variant) {
    const auto start = std::chrono::steady_clock::now();
    P acc = P::set1(R(0));
    for (std::size_t q = 0; q < kPairs; q += W) {
      const std::uint32_t* k = idx.data() + q;
      P x[3], v[3], a, b;
      if (variant == 0) {
        for (int d = 0; d < 3; ++d) x[d] = P::template gather<3>(pos.data(), k, d);
        for (int d = 0; d < 3; ++d) v[d] = P::template gather<3>(vel.data(), k, d);
      } else {
        sph::simd::gather_vectors<3>(pos.data(), k, x);
        sph::simd::gather_vectors<3>(vel.data(), k, v);
      }
      if (variant < 2) {
        a = P::template gather<1>(rho.data(), k, 0);
        b = P::template gather<1>(prs.data(), k, 0);
      } else {
        P s[2];
        sph::simd::gather_vectors<2>(side.data(), k, s);
        a = s[0], b = s[1];
      }
      acc = acc + x[0] * v[0] + x[1] * v[1] + x[2] * v[2] + a * b;
    }
    ns[variant] = std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start).count() /
                  static_cast<double>(kPairs);
    sink += sph::simd::sum_lanes(acc);
  }
  std::printf(
      "%-6s %9zu particles: 8 gathers %.3f ns a pair, positions and velocities loaded %.3f, all loaded %.3f%s\n",
      sizeof(R) == 4 ? "float" : "double", n, ns[0], ns[1], ns[2], sink == R(12345) ? " " : "");
}

}  // namespace

int main() {
  for (std::size_t n : {std::size_t{16384}, std::size_t{1000000}}) {
    measure<float>(n);
    measure<double>(n);
  }
}
