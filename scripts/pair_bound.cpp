// The pair loops' arithmetic against their gathers, on one core (docs/performance.md, "The pair
// loops against the machine"; built and run by scripts/pair_bound.sh).
//
// The density and force passes' per-pair arithmetic of the sph bench dam break (paper kernels:
// poly6 density; Eq. 5's pressure form with the spiky gradient, Eq. 6's viscosity; 3D), written
// as wcsph.cpp writes it with simd::Pack, over pairs whose neighbor data sit in a small block of
// memory that stays in the core's L2 cache. Each pass is timed twice: neighbor data read with
// contiguous loads (what a cluster-pair or cell-sorted layout would allow) and gathered through an
// index list (what the per-particle lists do). No main memory is touched, so the first figure is
// the arithmetic's own cost and the second adds what the gather instructions cost; the bench's
// pair visits per core-second (sph bench --suite steps) add the cache misses of a real run.
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <numeric>
#include <random>
#include <vector>

#include <sph/core/simd.h>

namespace {

using sph::simd::Mask;
using sph::simd::Pack;

constexpr std::size_t kPairs = 4096;  // 9 arrays of 4096 lanes: 147 KB (float), 295 KB (double)

template <class R>
struct PairData {
  std::vector<R> x, y, z, rho, m, vx, vy, vz, p;
  std::vector<std::uint32_t> idx;  // a shuffled order of the pairs, for the gathers
  explicit PairData(std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    for (auto* a : {&x, &y, &z, &rho, &m, &vx, &vy, &vz, &p}) a->resize(kPairs + 64);
    for (std::size_t k = 0; k < kPairs + 64; ++k) {
      x[k] = R(0.03 * u(rng)), y[k] = R(0.03 * u(rng)),
      z[k] = R(0.03 * u(rng));  // within h = 0.04 of the origin mostly
      rho[k] = R(1000 + 5 * u(rng)), m[k] = R(0.008), p[k] = R(900 * (3 + u(rng)));
      vx[k] = R(u(rng)), vy[k] = R(u(rng)), vz[k] = R(u(rng));
    }
    idx.resize(kPairs + 64);
    std::iota(idx.begin(), idx.end(), 0u);
    std::shuffle(idx.begin(), idx.begin() + kPairs, rng);
  }
};

template <class R, bool kGather>
Pack<R> get(const std::vector<R>& a, const std::uint32_t* idx, std::size_t k) {
  if constexpr (kGather)
    return Pack<R>::template gather<1>(a.data(), idx + k, 0);
  else
    return Pack<R>::load(a.data() + k);
}

/// One pass of the density arithmetic over every pair; returns the lane sums.
template <class R, bool kGather>
Pack<R> density(const PairData<R>& d, const Pack<R> (&xi)[3], R h) {
  using P = Pack<R>;
  constexpr int W = sph::simd::kLanes<R>;
  const P h2 = P::set1(h * h), zero = P::set1(0), norm = P::set1(R(315.0 / (64 * 3.14159265358979 * 1.6e-5 * 1.6e-5)));
  P sum = zero;
  const std::uint32_t* idx = d.idx.data();
  for (std::size_t k = 0; k < kPairs; k += W) {
    const P rx = xi[0] - get<R, kGather>(d.x, idx, k), ry = xi[1] - get<R, kGather>(d.y, idx, k),
            rz = xi[2] - get<R, kGather>(d.z, idx, k);
    const P r2 = P::set1(0) + rx * rx + ry * ry + rz * rz;
    const Mask in = r2 < h2;
    const P dd = h2 - r2;
    sum = sum + select(in, get<R, kGather>(d.m, idx, k) * (norm * dd * dd * dd), zero);
  }
  return sum;
}

/// One pass of the force arithmetic (paper's pressure form, spiky gradient, Eq. 6 viscosity).
template <class R, bool kGather>
Pack<R> forces(const PairData<R>& d, const Pack<R> (&xi)[3], const Pack<R> (&vi)[3], R h) {
  using P = Pack<R>;
  constexpr int W = sph::simd::kLanes<R>;
  const P hv = P::set1(h), h2 = P::set1(h * h), zero = P::set1(0), one = P::set1(1), minus_one = P::set1(-1),
          half = P::set1(R(0.5)), grad_c = P::set1(R(-3 * 15 / (3.14159265358979 * 4.096e-9))),
          pi_half = P::set1(R(0.5 * 2700 / 1000)), inv_rhoi = P::set1(R(1e-3)), visc = P::set1(R(3e-3 * 45 / 4.096e-9));
  const std::uint32_t* idx = d.idx.data();
  P acc[3] = {zero, zero, zero};
  for (std::size_t k = 0; k < kPairs; k += W) {
    P rij[3];
    rij[0] = xi[0] - get<R, kGather>(d.x, idx, k), rij[1] = xi[1] - get<R, kGather>(d.y, idx, k);
    rij[2] = xi[2] - get<R, kGather>(d.z, idx, k);
    const P r2 = P::set1(0) + rij[0] * rij[0] + rij[1] * rij[1] + rij[2] * rij[2];
    const Mask near = r2 < h2;
    const P r = sqrt(select(near, r2, h2));
    const P dh = hv - r;
    const P inv_rhoj = one / get<R, kGather>(d.rho, idx, k);
    const P mj = get<R, kGather>(d.m, idx, k);
    const P vj[3] = {get<R, kGather>(d.vx, idx, k), get<R, kGather>(d.vy, idx, k), get<R, kGather>(d.vz, idx, k)};
    const P pj = get<R, kGather>(d.p, idx, k);
    const P pij = (pi_half + half * pj * inv_rhoi) * inv_rhoj;
    const Mask apart = near & (r2 > zero);
    const P fp = select(apart, (grad_c * dh * dh / select(apart, r, one)) * (minus_one * mj * pij), zero);
    const P fv = select(near, visc * mj * inv_rhoj * dh, zero);
    for (int c = 0; c < 3; ++c) acc[c] = acc[c] + (rij[c] * fp + (vj[c] - vi[c]) * fv);
  }
  return acc[0] + acc[1] + acc[2];
}

template <class R, bool kGather, bool kForces>
double ns_per_pair(const PairData<R>& d) {
  using P = Pack<R>;
  const R h = R(0.04);
  double best = 1e30, sink = 0;
  for (int trial = 0; trial < 7; ++trial) {
    constexpr int kRepeats = 400;
    P total = P::set1(0);
    const auto t0 = std::chrono::steady_clock::now();
    for (int rep = 0; rep < kRepeats; ++rep) {
      const R shift = R(1e-6) * static_cast<R>(rep);  // each repeat's particle i differs
      const P xi[3] = {P::set1(shift), P::set1(-shift), P::set1(R(0.5) * shift)};
      const P vi[3] = {P::set1(R(0.1)), P::set1(shift), P::set1(R(-0.2))};
      total = total + (kForces ? forces<R, kGather>(d, xi, vi, h) : density<R, kGather>(d, xi, h));
    }
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    best = std::min(best, 1e9 * s / (kRepeats * static_cast<double>(kPairs)));
    sink += static_cast<double>(sph::simd::sum_lanes(total));
  }
  if (sink == 12345.678) std::puts("");  // keeps the work
  return best;
}

template <class R>
void report(const char* name) {
  const PairData<R> d(7);
  const double dl = ns_per_pair<R, false, false>(d), dg = ns_per_pair<R, true, false>(d);
  const double fl = ns_per_pair<R, false, true>(d), fg = ns_per_pair<R, true, true>(d);
  std::printf(
      "%-6s  density: %.3f ns/pair loaded, %.3f gathered   forces: %.3f ns/pair loaded, %.3f gathered   "
      "both passes: %.3f loaded, %.3f gathered (%.0f and %.0f M pair visits/s per core)\n",
      name, dl, dg, fl, fg, (dl + fl) / 2, (dg + fg) / 2, 2e3 / (dl + fl), 2e3 / (dg + fg));
}

}  // namespace

int main() {
  std::printf("pair arithmetic on one core, %zu pairs held in cache, best of 7 runs of 400 passes (SIMD: %s)\n", kPairs,
              SPH_SIMD_AVX512 ? "AVX-512" : "scalar lanes");
  report<float>("float");
  report<double>("double");
}
