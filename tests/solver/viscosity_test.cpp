// The implicit viscosity solve (viscosity.h): it solves the backward Euler system of the force
// pass's own viscosity term (checked against that pass, an independent vector code path), keeps
// the momentum, damps at steps where the explicit term blows up, and gives the same bits for any
// thread count.

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include <sph/core/parallel.h>
#include <sph/core/particle_set.h>
#include <sph/neighbors/neighbor_lists.h>
#include <sph/neighbors/standard.h>
#include <sph/solver/params.h>
#include <sph/solver/viscosity.h>
#include <sph/solver/wcsph.h>

#include "support/thread_count.h"

namespace sph {
namespace {

using test::ThreadCount;

constexpr double kDx = 0.01;
constexpr double kSupport = 0.02;

/// A jittered lattice block of side n particles, with a sheared, swirling velocity field and some
/// other acceleration already in ps.acceleration (the step's gravity and pressure, say).
template <int D>
ParticleSet<D, double> sheared_block(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.2 * kDx, 0.2 * kDx), noise(-0.3, 0.3);
  ParticleSet<D, double> ps;
  ps.mass = 0.1;
  const int total = D == 2 ? n * n : n * n * n;
  for (int k = 0; k < total; ++k) {
    Vec<D, double> x, v;
    int rest = k;
    for (int d = 0; d < D; ++d) {
      x[d] = (rest % n + 0.5) * kDx + jitter(rng);
      rest /= n;
    }
    v[0] = std::sin(x[1] * 40.0) + noise(rng);
    v[1] = std::cos(x[0] * 30.0) + noise(rng);
    if constexpr (D == 3) v[2] = x[0] * x[1] * 100.0 + noise(rng);
    ps.add(x, v);
  }
  for (std::size_t i = 0; i < ps.size(); ++i) {
    ps.density[i] = 1000.0 * (1 + 0.01 * noise(rng));
    for (int d = 0; d < D; ++d) ps.acceleration[i][d] = 5.0 * noise(rng);
  }
  return ps;
}

/// Every pair closer than 1.2 h, both ways (lists hold some pairs beyond h, as verlet's do).
template <int D>
NeighborLists pairs_of(const ParticleSet<D, double>& ps) {
  return brute_force_lists<D, double>(ps.position, 1.2 * kSupport);
}

/// `tolerance`: the solve's, as a fraction of its starting residual.
FluidParams viscous(KernelKind kernel, double mu, double tolerance) {
  FluidParams f;
  f.kernel = kernel;
  f.viscosity = mu;
  f.viscosity_solve = ViscositySolve::Implicit;
  f.viscosity_max_iterations = 10000;
  f.viscosity_max_error = 100 * tolerance;
  return f;
}

/// The force pass's explicit viscous accelerations at the velocities v (no pressure, no gravity,
/// no walls).
template <int D>
std::vector<Vec<D, double>> explicit_viscosity(ParticleSet<D, double> ps, const NeighborLists& lists,
                                               const std::vector<Vec<D, double>>& v, FluidParams fluid) {
  fluid.viscosity_solve = ViscositySolve::Explicit;
  ps.velocity = v;
  const std::vector<Box<D>> no_obstacles;
  Vec<D, double> lo, hi;
  for (int d = 0; d < D; ++d) lo[d] = -100, hi[d] = 100;
  const WallContact<D, double> no_walls({lo, hi}, no_obstacles, 0.0, WallParams{});
  compute_accelerations<D, double>(ps, lists, kSupport, fluid, Vec<D, double>{}, no_walls, {}, 0.0, {}, 0.0, false);
  return ps.acceleration;
}

template <int D>
void check_backward_euler(KernelKind kernel) {
  SCOPED_TRACE(::testing::Message() << D << "D, kernel " << static_cast<int>(kernel));
  ParticleSet<D, double> ps = sheared_block<D>(D == 2 ? 12 : 6, 7);
  const NeighborLists lists = pairs_of(ps);
  const double dt = 2e-3, mu = 20.0;  // 13x the explicit limit 0.125 h^2 rho0 / mu = 2.5e-4 s
  const FluidParams fluid = viscous(kernel, mu, 1e-12);
  std::vector<Vec<D, double>> v_star(ps.size());
  for (std::size_t i = 0; i < ps.size(); ++i) v_star[i] = ps.velocity[i] + ps.acceleration[i] * dt;
  ImplicitViscosity<D, double> solver;
  const SolveStats stats = solver.solve(ps, lists, kSupport, fluid, dt);
  EXPECT_TRUE(stats.converged);
  EXPECT_GT(stats.iterations, 0);
  std::vector<Vec<D, double>> v(ps.size());
  for (std::size_t i = 0; i < ps.size(); ++i) v[i] = ps.velocity[i] + ps.acceleration[i] * dt;
  // v - dt a_visc(v) = v*, with a_visc the force pass's term at the new velocities.
  const std::vector<Vec<D, double>> a = explicit_viscosity(ps, lists, v, fluid);
  double worst = 0, change = 0;
  for (std::size_t i = 0; i < ps.size(); ++i) {
    worst = std::max(worst, norm(v[i] - a[i] * dt - v_star[i]));
    change = std::max(change, norm(v[i] - v_star[i]));
  }
  EXPECT_GT(change, 0.1);  // (the viscosity does change the velocities)
  EXPECT_LT(worst, 1e-9 * change);
  // Momentum: sum m v = sum m v* (each pair's terms are equal and opposite).
  Vec<D, double> p_new{}, p_star{};
  double scale = 0;
  for (std::size_t i = 0; i < ps.size(); ++i) {
    p_new += v[i] * ps.mass;
    p_star += v_star[i] * ps.mass;
    scale += ps.mass * norm(v_star[i]);
  }
  EXPECT_LT(norm(p_new - p_star), 1e-12 * scale);
}

TEST(ImplicitViscosity, SolvesTheBackwardEulerSystemOfTheForcePassesTermAndKeepsMomentum) {
  for (KernelKind k : {KernelKind::Paper, KernelKind::Cubic, KernelKind::Wendland}) {
    check_backward_euler<2>(k);
    check_backward_euler<3>(k);
  }
}

/// Kinetic energy of velocities v with the particles' masses.
template <int D>
double kinetic(const ParticleSet<D, double>& ps, const std::vector<Vec<D, double>>& v) {
  double e = 0;
  for (std::size_t i = 0; i < ps.size(); ++i) e += 0.5 * ps.mass * norm2(v[i]);
  return e;
}

TEST(ImplicitViscosity, DampsAtStepsWhereTheExplicitTermBlowsUp) {
  ParticleSet<2, double> ps = sheared_block<2>(14, 3);
  for (auto& a : ps.acceleration) a = {};
  const NeighborLists lists = pairs_of(ps);
  const FluidParams fluid = viscous(KernelKind::Cubic, 20.0, 1e-6);
  const double dt = 2.5e-2;  // 100x the explicit limit
  const double before = kinetic(ps, ps.velocity);
  // Explicit: v + dt a_visc(v), five times; the step is far past its limit, so it grows.
  std::vector<Vec<2, double>> v = ps.velocity;
  for (int k = 0; k < 5; ++k) {
    const std::vector<Vec<2, double>> a = explicit_viscosity(ps, lists, v, fluid);
    for (std::size_t i = 0; i < v.size(); ++i) v[i] += a[i] * dt;
  }
  EXPECT_GT(kinetic(ps, v), 100 * before);
  // Implicit: each solve takes energy out.
  ImplicitViscosity<2, double> solver;
  double last = before;
  for (int k = 0; k < 5; ++k) {
    for (auto& a : ps.acceleration) a = {};
    solver.solve(ps, lists, kSupport, fluid, dt);
    for (std::size_t i = 0; i < ps.size(); ++i) ps.velocity[i] += ps.acceleration[i] * dt;
    const double now = kinetic(ps, ps.velocity);
    EXPECT_LT(now, last);
    last = now;
  }
  EXPECT_LT(last, 0.5 * before);
}

TEST(ImplicitViscosity, SameBitsForAnyThreadCount) {
  ThreadCount restore;
  const ParticleSet<3, double> start = sheared_block<3>(11, 5);  // 1,331 particles: two chunks
  const NeighborLists lists = pairs_of(start);
  const FluidParams fluid = viscous(KernelKind::Wendland, 20.0, 1e-8);
  std::vector<std::vector<Vec<3, double>>> results;
  std::vector<int> iterations;
  for (int threads : {1, 2, 3}) {
    set_num_threads(threads);
    ParticleSet<3, double> ps = start;
    ImplicitViscosity<3, double> solver;
    iterations.push_back(solver.solve(ps, lists, kSupport, fluid, 2e-3).iterations);
    results.push_back(ps.acceleration);
  }
  EXPECT_GT(iterations[0], 2);
  for (std::size_t k = 1; k < results.size(); ++k) {
    EXPECT_EQ(iterations[k], iterations[0]);
    EXPECT_TRUE(results[k] == results[0]) << "threads run " << k;
  }
}

}  // namespace
}  // namespace sph
