// DFSPH's solver on hand-made particle sets (dfsph.h): its factor beta is the diagonal of its
// operator, computed here directly from the kernel's gradients (with and without the
// kernel-gradient correction); its density solve removes a compression and its divergence solve
// a convergent flow; both keep the total momentum (no walls, no gravity); a solve gives the
// same bits for any thread count; and the gain of a Jacobi step, which scales the steps on wide
// supports, is the largest eigenvalue of the operator over its diagonal on a lattice.

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include <sph/core/parallel.h>
#include <sph/core/particle_set.h>
#include <sph/neighbors/neighbor_lists.h>
#include <sph/neighbors/standard.h>
#include <sph/solver/dfsph.h>
#include <sph/solver/gradient_correction.h>
#include <sph/solver/params.h>
#include <sph/solver/smoothing.h>
#include <sph/solver/wcsph.h>

#include "support/thread_count.h"

namespace sph {
namespace {

using test::ThreadCount;

constexpr double kSpacing = 0.01;
constexpr double kH = 0.025;  // 2.5 spacings, as the validation's 2D DFSPH tank
constexpr double kRho0 = 1000.0;

FluidParams cubic() {
  FluidParams f;
  f.kernel = KernelKind::Cubic;
  f.rest_density = kRho0;
  return f;
}

/// A block of side n particles on a lattice of `scale` spacings (below 1: compressed), jittered
/// by up to `jitter` spacings, with masses that give the unjittered lattice at 1 spacing rest
/// density, and the velocities v(x).
template <int D, class V>
ParticleSet<D, double> block(int n, double scale, double jitter, unsigned seed, V&& v) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-jitter * kSpacing, jitter * kSpacing);
  const double m = lattice_mass<D>(kRho0, kSpacing, kH, KernelKind::Cubic);
  ParticleSet<D, double> ps;
  ps.mass = m;
  const int total = D == 2 ? n * n : n * n * n;
  for (int k = 0; k < total; ++k) {
    Vec<D, double> x;
    int rest = k;
    for (int d = 0; d < D; ++d) {
      x[d] = (rest % n + 0.5) * kSpacing * scale + u(rng);
      rest /= n;
    }
    ps.add(x, v(x));
  }
  return ps;
}

/// Every pair closer than 1.2 h, both ways (lists hold some pairs beyond h, as verlet's do).
template <int D>
NeighborLists all_pairs(const ParticleSet<D, double>& ps) {
  return brute_force_lists<D, double>(ps.position, 1.2 * kH);
}

/// Whether x is more than `margin` spacings inside a block of side n spacings (from the origin).
template <int D>
bool inside(const Vec<D, double>& x, int n, double margin) {
  for (int d = 0; d < D; ++d)
    if (!(x[d] > margin * kSpacing && x[d] < (n - margin) * kSpacing)) return false;
  return true;
}

/// m_j grad W_ij as DFSPH's pairs should take it: corrected by (L_i + L_j) / 2, written out here
/// as a matrix product (L empty: the plain gradient).
template <int D>
Vec<D, double> pair_gradient(const ParticleSet<D, double>& ps, const std::vector<double>& L,
                             const SmoothingKernels<D, double>& k, std::size_t i, std::size_t j) {
  const Vec<D, double> g = k.gradient(ps.position[i] - ps.position[j]);
  if (L.empty()) return g * ps.mass;
  Vec<D, double> out{};
  for (int r = 0; r < D; ++r)
    for (int c = 0; c < D; ++c) out[r] += 0.5 * (L[i * D * D + r * D + c] + L[j * D * D + r * D + c]) * g[c];
  return out * ps.mass;
}

/// beta_i = |sum_j m_j g_ij|^2 + m_i sum_j m_j |g_ij|^2, directly, for the particles with at least
/// two spacings of fluid on every side (the others may sit on beta's floor).
template <int D>
void check_factors(bool corrected) {
  const int n = D == 2 ? 12 : 7;
  ParticleSet<D, double> ps = block<D>(n, 1.0, 0.15, 3, [](const Vec<D, double>&) { return Vec<D, double>{}; });
  const NeighborLists lists = all_pairs(ps);
  const FluidParams fluid = cubic();
  const SmoothingKernels<D, double> k(fluid, kH);
  compute_density_pressure<D, double>(ps, lists, kH, fluid);
  std::vector<double> L;
  if (corrected) gradient_corrections<D, double>(ps, lists, k, {}, kRho0, L);
  DfsphSolver<D, double> solver(DfsphParams{}, ps, kSpacing);
  solver.compute_factors(ps, lists, k, {}, L);
  int checked = 0;
  for (std::size_t i = 0; i < ps.size(); ++i) {
    if (!inside(ps.position[i], n, 2.4)) continue;
    Vec<D, double> sum{};
    double squares = 0;
    for (const std::uint32_t j : lists.of(i)) {
      if (norm2(ps.position[i] - ps.position[j]) >= kH * kH) continue;
      const Vec<D, double> mg = pair_gradient(ps, L, k, i, j);
      sum += mg;
      squares += norm2(mg) / ps.mass;
    }
    const double beta = norm2(sum) + ps.mass * squares;
    EXPECT_NEAR(solver.factors()[i], beta, 1e-12 * beta) << D << "D, particle " << i;
    ++checked;
  }
  EXPECT_GE(checked, D == 2 ? 40 : 8);
  if (corrected) {  // (the correction is applied: the interior's L is not the identity)
    double off = 0;
    for (std::size_t q = 0; q < L.size(); ++q) off = std::max(off, std::abs(L[q] - ((q % (D + 1)) == 0 ? 1.0 : 0.0)));
    EXPECT_GT(off, 0.01);
  }
}

TEST(DfsphSolver, FactorIsTheOperatorsDiagonal2D) { check_factors<2>(false); }
TEST(DfsphSolver, FactorIsTheOperatorsDiagonal3D) { check_factors<3>(false); }
TEST(DfsphSolver, FactorWithCorrectedGradientsIsTheOperatorsDiagonal2D) { check_factors<2>(true); }
TEST(DfsphSolver, FactorWithCorrectedGradientsIsTheOperatorsDiagonal3D) { check_factors<3>(true); }

/// The total momentum change sum_i m_i dv_i against the size of the changes, sum_i m_i |dv_i|.
template <int D>
double momentum_ratio(const ParticleSet<D, double>& ps, const std::vector<Vec<D, double>>& dv) {
  Vec<D, double> total{};
  double size = 0;
  for (std::size_t i = 0; i < ps.size(); ++i) total += dv[i] * ps.mass, size += ps.mass * std::sqrt(norm2(dv[i]));
  return std::sqrt(norm2(total)) / size;
}

/// The mean compression max(rho_i - rho0, 0) / rho0 of the summed densities.
template <int D>
double compression(ParticleSet<D, double>& ps, const NeighborLists& lists) {
  compute_density_pressure<D, double>(ps, lists, kH, cubic());
  double sum = 0;
  for (const double rho : ps.density) sum += std::max(rho - kRho0, 0.0) / kRho0;
  return sum / static_cast<double>(ps.size());
}

/// A block squeezed to 97 % of its spacing, at rest, no gravity, no walls: the density solve's
/// accelerations, applied for one step, leave a small part of the compression (the solve is the
/// linearized one), never pull (p >= 0), and sum to no force.
template <int D>
void check_density_solve(bool corrected) {
  ParticleSet<D, double> ps =
      block<D>(D == 2 ? 14 : 7, 0.97, 0.05, 5, [](const Vec<D, double>&) { return Vec<D, double>{}; });
  const NeighborLists lists = all_pairs(ps);
  const double before = compression(ps, lists);
  ASSERT_GT(before, 0.01);
  const SmoothingKernels<D, double> k(cubic(), kH);
  std::vector<double> L;
  if (corrected) gradient_corrections<D, double>(ps, lists, k, {}, kRho0, L);
  DfsphParams params;
  params.max_error = 0.001;
  params.max_iterations = 500;
  DfsphSolver<D, double> solver(params, ps, kSpacing);
  solver.compute_factors(ps, lists, k, {}, L);
  const double dt = 1e-3;
  const SolveStats stats = solver.density_solve(ps, kRho0, dt);
  EXPECT_TRUE(stats.converged) << stats.iterations << " iterations, error " << stats.error << " %";
  EXPECT_LE(stats.error, params.max_error);
  for (const double p : ps.pressure) EXPECT_GE(p, 0.0);
  EXPECT_LT(momentum_ratio(ps, ps.acceleration), 1e-12);
  // One step with those accelerations (the velocities start at zero).
  for (std::size_t i = 0; i < ps.size(); ++i) ps.position[i] += ps.acceleration[i] * (dt * dt);
  const double after = compression(ps, lists);
  EXPECT_LT(after, 0.2 * before) << "compression " << before << " -> " << after;
}

TEST(DfsphSolver, DensitySolveRemovesACompressionAndKeepsMomentum2D) { check_density_solve<2>(false); }
TEST(DfsphSolver, DensitySolveRemovesACompressionAndKeepsMomentum3D) { check_density_solve<3>(false); }
TEST(DfsphSolver, DensitySolveWithCorrectedGradientsRemovesACompressionAndKeepsMomentum2D) {
  check_density_solve<2>(true);
}
TEST(DfsphSolver, DensitySolveWithCorrectedGradientsRemovesACompressionAndKeepsMomentum3D) {
  check_density_solve<3>(true);
}

/// A block flowing in toward its centre (v = -c (x - centre)): the divergence solve's velocity
/// change leaves a small part of the density rate where the neighbourhood is full, and keeps the
/// momentum.
template <int D>
void check_divergence_solve(bool corrected) {
  const int n = D == 2 ? 14 : 7;
  const double centre = 0.5 * n * kSpacing;
  ParticleSet<D, double> ps = block<D>(n, 1.0, 0.05, 9, [&](const Vec<D, double>& x) {
    Vec<D, double> v;
    for (int d = 0; d < D; ++d) v[d] = -0.5 * (x[d] - centre);
    return v;
  });
  const NeighborLists lists = all_pairs(ps);
  const FluidParams fluid = cubic();
  compute_density_pressure<D, double>(ps, lists, kH, fluid);
  const SmoothingKernels<D, double> k(fluid, kH);
  std::vector<double> L;
  if (corrected) gradient_corrections<D, double>(ps, lists, k, {}, kRho0, L);
  // The density rate sum_j m_j (v_i - v_j) . grad W_ij of the inner particles (the solve leaves
  // out particles without a full neighbourhood).
  const auto inner_rate = [&] {
    double sum = 0;
    for (std::size_t i = 0; i < ps.size(); ++i) {
      if (!inside(ps.position[i], n, 2.6)) continue;
      for (const std::uint32_t j : lists.of(i))
        if (norm2(ps.position[i] - ps.position[j]) < kH * kH)
          sum += dot(ps.velocity[i] - ps.velocity[j], pair_gradient(ps, L, k, i, j));
    }
    return sum;
  };
  const double before = inner_rate();
  ASSERT_GT(before, 0.0);
  const std::vector<Vec<D, double>> v0 = ps.velocity;
  DfsphParams params;
  params.max_error_v = 0.01;
  params.max_iterations_v = 500;
  DfsphSolver<D, double> solver(params, ps, kSpacing);
  solver.compute_factors(ps, lists, k, {}, L);
  const SolveStats stats = solver.divergence_solve(ps, kRho0, 1e-3);
  EXPECT_TRUE(stats.converged) << stats.iterations << " iterations, error " << stats.error << " %/s";
  std::vector<Vec<D, double>> dv(ps.size());
  for (std::size_t i = 0; i < ps.size(); ++i) dv[i] = ps.velocity[i] - v0[i];
  EXPECT_LT(momentum_ratio(ps, dv), 1e-12);
  EXPECT_LT(inner_rate(), 0.05 * before);
}

TEST(DfsphSolver, DivergenceSolveStopsAConvergentFlowAndKeepsMomentum2D) { check_divergence_solve<2>(false); }
TEST(DfsphSolver, DivergenceSolveStopsAConvergentFlowAndKeepsMomentum3D) { check_divergence_solve<3>(false); }
TEST(DfsphSolver, DivergenceSolveWithCorrectedGradientsStopsAConvergentFlowAndKeepsMomentum2D) {
  check_divergence_solve<2>(true);
}

TEST(DfsphSolver, SameBitsForAnyThreadCount) {
  ThreadCount restore;
  std::vector<std::vector<Vec<3, double>>> acc;
  std::vector<std::vector<double>> pressure;
  for (int threads : {1, 2, 3}) {
    set_num_threads(threads);
    ParticleSet<3, double> ps = block<3>(9, 0.97, 0.1, 11, [](const Vec<3, double>&) { return Vec<3, double>{}; });
    const NeighborLists lists = all_pairs(ps);
    const SmoothingKernels<3, double> k(cubic(), kH);
    compute_density_pressure<3, double>(ps, lists, kH, cubic());
    std::vector<double> L;
    gradient_corrections<3, double>(ps, lists, k, {}, kRho0, L);
    DfsphSolver<3, double> solver(DfsphParams{}, ps, kSpacing);
    solver.compute_factors(ps, lists, k, {}, L);
    (void)solver.density_solve(ps, kRho0, 1e-3);
    acc.push_back(ps.acceleration);
    pressure.push_back(ps.pressure);
  }
  EXPECT_TRUE(acc[0] == acc[1] && acc[0] == acc[2]);
  EXPECT_TRUE(pressure[0] == pressure[1] && pressure[0] == pressure[2]);
}

// jacobi_gain against the operator itself: power iteration of D^-1 A on a periodic square
// lattice of 64 x 64 sites (unit masses, (A s)_i = -sum_j (a_i - a_j) . g_ij with a_i = -sum_j
// (s_i + s_j) g_ij, g_ij = grad W(x_i - x_j), D = sum_j |g_ij|^2 the same at every site), whose
// modes are the wave numbers jacobi_gain samples. The Rayleigh quotient never exceeds the
// largest eigenvalue and comes within 0.5 % of it here.
TEST(DfsphSolver, JacobiGainIsTheLargestEigenvalueOfTheOperatorOverItsDiagonal) {
  constexpr int kN = 64;
  for (const double spacings : {2.0, 3.0}) {
    const double h = spacings * kSpacing;
    const SmoothingKernels<2, double> k(cubic(), h);
    const auto grad = [&](const Vec<2, double>& r) { return k.gradient(r); };
    const double gain = jacobi_gain<2>(kSpacing, h, grad);
    // The lattice's offsets within h and their gradients.
    std::vector<std::array<int, 2>> off;
    std::vector<Vec<2, double>> g;
    double diag = 0;
    const int reach = static_cast<int>(std::ceil(spacings));
    for (int a = -reach; a <= reach; ++a)
      for (int b = -reach; b <= reach; ++b) {
        const Vec<2, double> r{a * kSpacing, b * kSpacing};
        if ((a == 0 && b == 0) || norm2(r) >= h * h) continue;
        off.push_back({a, b});
        g.push_back(grad(r));
        diag += norm2(g.back());
      }
    const auto site = [](int x, int y) { return static_cast<std::size_t>(((y + kN) % kN) * kN + (x + kN) % kN); };
    std::vector<double> s(kN * kN), as(kN * kN);
    std::vector<Vec<2, double>> a(kN * kN);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1, 1);
    for (double& v : s) v = u(rng);
    double rayleigh = 0;
    for (int it = 0; it < 400; ++it) {
      for (int y = 0; y < kN; ++y)
        for (int x = 0; x < kN; ++x) {
          Vec<2, double> ai{};
          for (std::size_t q = 0; q < off.size(); ++q)  // g_ij = grad W(x_i - x_j), x_j = x_i - r
            ai -= g[q] * (s[site(x, y)] + s[site(x - off[q][0], y - off[q][1])]);
          a[site(x, y)] = ai;
        }
      double ss = 0, sas = 0;
      for (int y = 0; y < kN; ++y)
        for (int x = 0; x < kN; ++x) {
          double v = 0;
          for (std::size_t q = 0; q < off.size(); ++q)
            v -= dot(a[site(x, y)] - a[site(x - off[q][0], y - off[q][1])], g[q]);
          as[site(x, y)] = v / diag;
          ss += s[site(x, y)] * s[site(x, y)];
          sas += s[site(x, y)] * as[site(x, y)];
        }
      rayleigh = sas / ss;
      double norm = 0;
      for (double v : as) norm += v * v;
      for (std::size_t i = 0; i < s.size(); ++i) s[i] = as[i] / std::sqrt(norm);
    }
    EXPECT_GE(gain, rayleigh * (1 - 1e-9)) << spacings << " spacings";
    EXPECT_LE(gain, rayleigh * 1.005) << spacings << " spacings";
    EXPECT_GT(gain, 1.0);
  }
  // Wider supports have larger gains (the reason for the scale).
  const auto cubic_gain = [](int dim, double spacings) {
    const double h = spacings * kSpacing;
    if (dim == 2) {
      const SmoothingKernels<2, double> k(cubic(), h);
      return jacobi_gain<2>(kSpacing, h, [&](const Vec<2, double>& r) { return k.gradient(r); });
    }
    const SmoothingKernels<3, double> k(cubic(), h);
    return jacobi_gain<3>(kSpacing, h, [&](const Vec<3, double>& r) { return k.gradient(r); });
  };
  EXPECT_LT(cubic_gain(2, 2.0), cubic_gain(2, 3.0));
  EXPECT_LT(cubic_gain(3, 2.0), cubic_gain(3, 3.0));
}

// The solver scales its steps by min(1, 4 / gain): whole on the shipped scenes' supports (2 to
// 2.5 spacings), scaled on wider ones.
TEST(DfsphSolver, JacobiStepsAreScaledOnWideSupportsOnly) {
  const auto relaxation = [](double spacings) {
    ParticleSet<3, double> ps = block<3>(6, 1.0, 0.1, 11, [](const Vec<3, double>&) { return Vec<3, double>{}; });
    const double h = spacings * kSpacing;
    const NeighborLists lists = all_pairs(ps);
    const SmoothingKernels<3, double> k(cubic(), h);
    compute_density_pressure<3, double>(ps, lists, h, cubic());
    DfsphSolver<3, double> solver(DfsphParams{}, ps, kSpacing);
    EXPECT_EQ(solver.relaxation(), 1.0);
    solver.compute_factors(ps, lists, k, {});
    const double gain = jacobi_gain<3>(kSpacing, h, [&](const Vec<3, double>& r) { return k.gradient(r); });
    EXPECT_DOUBLE_EQ(solver.relaxation(), std::min(1.0, 4.0 / gain));
    return solver.relaxation();
  };
  EXPECT_EQ(relaxation(2.0), 1.0);
  EXPECT_EQ(relaxation(2.15), 1.0);
  EXPECT_LT(relaxation(3.0), 0.6);
}

}  // namespace
}  // namespace sph
