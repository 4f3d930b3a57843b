// Physical properties of the solver: momentum conservation without walls and gravity, a
// hydrostatic tank that settles to p = rho0 g depth, and emitter bookkeeping.

#include <cmath>
#include <cstdio>
#include <random>

#include <algorithm>
#include <limits>

#include <gtest/gtest.h>

#include <sph/core/error.h>
#include <sph/core/kernels.h>
#include <sph/core/parallel.h>
#include <sph/solver/simulation.h>
#include <sph/solver/time_step.h>
#include <sph/solver/wcsph.h>

namespace sph {
namespace {

template <int D>
SimulationParams<D> water_params(double r) {
  SimulationParams<D> p;
  p.particle_radius = r;
  p.kernel_radius = 4 * r;
  p.time_step = 2e-4;
  p.fluid.rest_density = 1000;
  p.fluid.stiffness = 1000;
  p.fluid.viscosity = 1.0;
  p.particle_mass = lattice_mass<D>(1000, 2 * r, 4 * r);
  p.walls.stiffness = 2e5;
  p.walls.damping = 200;
  return p;
}

/// A free blob on a jittered lattice with a random velocity field, far from any wall.
template <int D, class R>
ParticleSet<D, R> blob(const SimulationParams<D>& p, int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.2, 0.2), vel(-0.5, 0.5);
  ParticleSet<D, R> ps;
  ps.mass = static_cast<R>(p.particle_mass);
  const double dx = 2 * p.particle_radius;
  const int nz = D == 3 ? n : 1;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        Vec<D, R> x, v;
        const int idx[3] = {i, j, k};
        for (int d = 0; d < D; ++d) {
          x[d] = static_cast<R>((idx[d] + jitter(rng)) * dx);
          v[d] = static_cast<R>(vel(rng));
        }
        ps.add(x, v);
      }
  return ps;
}

template <int D, class R>
void check_momentum_conserved(int n, int steps, double tol, NeighborMode mode = NeighborMode::Standard,
                              GradientCorrection correction = GradientCorrection::None,
                              PressureForce form = PressureForce::Paper) {
  SimulationParams<D> p = water_params<D>(0.01);
  p.neighbors = mode;
  p.fluid.pressure_force = form;
  p.fluid.gradient_correction = correction;
  p.fluid.negative_pressure = NegativePressure::Allow;  // both signs of pressure exercised
  // The paper's (spiky) force with unclamped pressure on a jittered blob gains energy (the
  // health monitor would fail the run for it); this test is about momentum: measure only.
  p.health_failures = false;
  p.container.lo = Vec<D, double>::filled(-100);
  p.container.hi = Vec<D, double>::filled(100);
  Simulation<D, R> sim(p, blob<D, R>(p, n, 11));
  const Vec<D, double> p0 = sim.momentum();
  double scale = 0;  // sum of |m v|: the size of the round-off to expect
  for (std::size_t i = 0; i < sim.particles().size(); ++i)
    scale += sim.particles().mass * norm(vec_cast<double>(sim.particles().velocity[i]));
  for (int s = 0; s < steps; ++s) sim.step();
  const Vec<D, double> p1 = sim.momentum();
  EXPECT_GT(sim.kinetic_energy(), 0.0);
  EXPECT_LT(norm(p1 - p0), tol * scale) << "momentum drift " << norm(p1 - p0) << " of " << scale;
  // The flow did something: velocities changed.
  EXPECT_GT(sim.last_step().neighbors.pairs_stored, 0u);
}

TEST(Conservation, MomentumWithoutWallsOrGravity2D) { check_momentum_conserved<2, double>(20, 200, 1e-12); }
TEST(Conservation, MomentumWithoutWallsOrGravity3D) { check_momentum_conserved<3, double>(10, 100, 1e-12); }
TEST(Conservation, MomentumWithoutWallsOrGravity3DFloat) { check_momentum_conserved<3, float>(10, 100, 1e-5); }
// The corrected gradient (L_i + L_j) / 2 grad W_ij keeps each pair's forces equal and opposite.
TEST(Conservation, MomentumWithCorrectedGradient2D) {
  check_momentum_conserved<2, double>(20, 200, 1e-12, NeighborMode::Standard, GradientCorrection::Renormalize);
}
TEST(Conservation, MomentumWithCorrectedGradient3D) {
  check_momentum_conserved<3, double>(10, 100, 1e-12, NeighborMode::Standard, GradientCorrection::Renormalize);
}
TEST(Conservation, MomentumWithVariationalForce2D) {
  check_momentum_conserved<2, double>(20, 200, 1e-12, NeighborMode::Standard, GradientCorrection::None,
                                      PressureForce::Variational);
}
TEST(Conservation, MomentumWithVariationalForceAndCorrectedGradient3D) {
  check_momentum_conserved<3, double>(10, 100, 1e-12, NeighborMode::Standard, GradientCorrection::Renormalize,
                                      PressureForce::Variational);
}
TEST(Conservation, MomentumWithVerletLists2D) {
  check_momentum_conserved<2, double>(20, 200, 1e-12, NeighborMode::Verlet);
}
TEST(Conservation, MomentumWithVerletLists3D) {
  check_momentum_conserved<3, double>(10, 100, 1e-12, NeighborMode::Verlet);
}
TEST(Conservation, MomentumWithVerletClusterPairs2D) {
  check_momentum_conserved<2, double>(20, 200, 1e-12, NeighborMode::VerletClusters);
}
TEST(Conservation, MomentumWithVerletClusterPairs3D) {
  check_momentum_conserved<3, double>(10, 100, 1e-12, NeighborMode::VerletClusters);
}

/// The largest change of the total energy (kinetic + the EOS's internal energy of the summed
/// densities) of an inviscid free blob over `steps` steps, relative to the largest kinetic
/// energy (the jittered blob's pressure sets it moving: the energy in play). No walls, no gravity, no viscosity,
/// unclamped pressure: nothing dissipates, so what changes is the discretization's error.
template <int D>
double inviscid_energy_change(PressureForce form, int n, int steps, double dt) {
  SimulationParams<D> p = water_params<D>(0.01);
  p.fluid.pressure_force = form;
  p.fluid.viscosity = 0;
  p.fluid.negative_pressure = NegativePressure::Allow;
  p.time_step = dt;
  // The spiky gradient's force gains energy, which this test measures (the health monitor
  // would fail that run): the monitor only measures here.
  p.health_failures = false;
  p.container.lo = Vec<D, double>::filled(-100);
  p.container.hi = Vec<D, double>::filled(100);
  Simulation<D, double> sim(p, blob<D, double>(p, n, 5));
  const double k = p.fluid.stiffness, rho0 = p.fluid.rest_density;
  const Poly6Kernel<D, double> poly6(p.kernel_radius);
  // e(rho) = k (ln(rho / rho0) + rho0 / rho - 1): de/drho = p / rho^2 for p = k (rho - rho0),
  // with the densities summed (all pairs) at the current positions.
  const auto total = [&] {
    const auto& P = sim.particles();
    double e = 0;
    for (std::size_t i = 0; i < P.size(); ++i) {
      double rho = 0;
      for (std::size_t j = 0; j < P.size(); ++j) rho += P.mass * poly6.w_r2(norm2(P.position[i] - P.position[j]));
      e += P.mass * (0.5 * norm2(P.velocity[i]) + k * (std::log(rho / rho0) + rho0 / rho - 1));
    }
    return e;
  };
  sim.step();
  const double e0 = total();
  double worst = 0, peak_ke = sim.kinetic_energy();
  for (int s = 1; s < steps; ++s) {
    sim.step();
    worst = std::max(worst, std::abs(total() - e0));
    peak_ke = std::max(peak_ke, sim.kinetic_energy());
  }
  EXPECT_GT(sim.kinetic_energy(), 0.0);
  std::printf("%s: largest |E - E0| / peak KE = %.3g\n",
              form == PressureForce::Variational ? "variational" : "symmetric", worst / peak_ke);
  return worst / peak_ke;
}

// With poly6's gradient the pressure force is minus the gradient of the internal energy of the
// poly6 densities, so the total energy changes only by the time step's error (2 % here, 6 % at
// four times the step); the spiky gradient's force is not the gradient of that energy, and the
// total grows by 70-90 % of the kinetic energy in play.
TEST(Conservation, VariationalForceConservesEnergyWithoutViscosity2D) {
  const double variational = inviscid_energy_change<2>(PressureForce::Variational, 20, 800, 2.5e-5);
  const double symmetric = inviscid_energy_change<2>(PressureForce::Symmetric, 20, 800, 2.5e-5);
  EXPECT_LT(variational, 0.05);
  EXPECT_GT(symmetric, 10 * variational);
}
TEST(Conservation, VariationalForceConservesEnergyWithoutViscosity3D) {
  const double variational = inviscid_energy_change<3>(PressureForce::Variational, 10, 400, 2.5e-5);
  const double symmetric = inviscid_energy_change<3>(PressureForce::Symmetric, 10, 400, 2.5e-5);
  EXPECT_LT(variational, 0.05);
  EXPECT_GT(symmetric, 10 * variational);
}

/// Settles a water column and returns the mean of p / (rho0 g depth) over particles more than
/// two layers below the surface and one kernel radius away from the side walls; checks that
/// the tank came to rest and that the interior density stays within 1 % of rho0.
template <int D>
double settled_pressure_ratio(PressureForce form, int columns, int layers,
                              GradientCorrection correction = GradientCorrection::None, double density_tol = 0.01) {
  SimulationParams<D> p = water_params<D>(0.005);
  p.fluid.viscosity = 5.0;
  p.fluid.pressure_force = form;
  p.fluid.gradient_correction = correction;
  p.gravity[1] = -9.81;
  const double dx = 2 * p.particle_radius;
  p.container.lo = Vec<D, double>::filled(0);
  p.container.hi = Vec<D, double>::filled(columns * dx);
  p.container.hi[1] = 2 * layers * dx;
  ParticleSet<D, double> ps;
  ps.mass = p.particle_mass;
  const int nz = D == 3 ? columns : 1;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < layers; ++j)
      for (int i = 0; i < columns; ++i) {
        Vec<D, double> x;
        x[0] = (i + 0.5) * dx;
        x[1] = (j + 0.5) * dx;
        if constexpr (D == 3) x[2] = (k + 0.5) * dx;
        ps.add(x, {});
      }
  Simulation<D, double> sim(p, std::move(ps));
  EXPECT_TRUE(check_time_step<D>(p).empty());
  const int steps = static_cast<int>(1.5 / p.time_step);  // 1.5 s of settling
  for (int s = 0; s < steps; ++s) sim.step();
  EXPECT_LT(sim.max_speed(), 0.1) << "tank has not settled";

  // Free surface: mean height of the top layer of particles plus half a spacing.
  const auto& P = sim.particles();
  double top = 0;
  for (const auto& x : P.position) top = std::max(top, x[1]);
  double surface_sum = 0;
  int surface_n = 0;
  for (const auto& x : P.position)
    if (x[1] > top - 0.5 * dx) surface_sum += x[1], ++surface_n;
  const double surface = surface_sum / surface_n + 0.5 * dx;
  double ratio_sum = 0, rho_dev_max = 0;
  int compared = 0;
  for (std::size_t i = 0; i < P.size(); ++i) {
    const double d = surface - P.position[i][1];
    bool interior = d > 2 * dx;
    for (int a = 0; a < D; ++a)
      if (a != 1)
        interior =
            interior && P.position[i][a] > p.kernel_radius && P.position[i][a] < p.container.hi[a] - p.kernel_radius;
    if (!interior) continue;
    rho_dev_max = std::max(rho_dev_max, std::abs(P.density[i] / 1000.0 - 1.0));
    ratio_sum += P.pressure[i] / (1000.0 * 9.81 * d);
    ++compared;
  }
  EXPECT_GT(compared, 10);
  EXPECT_LT(rho_dev_max, density_tol) << "interior density deviates by " << rho_dev_max;
  ::testing::Test::RecordProperty("pressure_ratio", std::to_string(ratio_sum / compared));
  std::printf("settled p / (rho0 g depth) = %.3f over %d particles\n", ratio_sum / compared, compared);
  return ratio_sum / compared;
}

// Monaghan's symmetric form approximates grad(p) / rho: pressure settles near rho0 g depth.
// The remaining excess (about 15 % at h = 2 dx) is the spiky gradient's discretization error:
// sum_j V_j (x_j - x_i) grad W_ij is 0.87 I on this lattice instead of I (docs/physics.md).
TEST(Hydrostatic, SymmetricFormSettlesToRho0GDepth2D) {
  const double r = settled_pressure_ratio<2>(PressureForce::Symmetric, 20, 20);
  EXPECT_GT(r, 0.95);
  EXPECT_LT(r, 1.3);
}
TEST(Hydrostatic, SymmetricFormSettlesToRho0GDepth3D) {
  const double r = settled_pressure_ratio<3>(PressureForce::Symmetric, 8, 10);
  EXPECT_GT(r, 0.95);
  EXPECT_LT(r, 1.3);
}
// With the gradient renormalized (GradientCorrection::Renormalize) the discrete gradient of a
// linear pressure is exact in the interior, and the 15 % excess goes. The corrected force is not
// the gradient of an energy, so the tank rings longer: after 1.5 s the 2D interior density still
// strays by up to 1.1 % (docs/validation.md).
TEST(Hydrostatic, CorrectedGradientSettlesToRho0GDepth2D) {
  const double r = settled_pressure_ratio<2>(PressureForce::Symmetric, 20, 20, GradientCorrection::Renormalize, 0.015);
  EXPECT_GT(r, 0.95);
  EXPECT_LT(r, 1.05);
}
TEST(Hydrostatic, CorrectedGradientSettlesToRho0GDepth3D) {
  const double r = settled_pressure_ratio<3>(PressureForce::Symmetric, 8, 10, GradientCorrection::Renormalize);
  EXPECT_GT(r, 0.95);
  EXPECT_LT(r, 1.05);
}
// The variational form (poly6's gradient) is nearly consistent on the lattice at h = 2 dx:
// sum_j V_j (x_j - x_i) grad W_ij is I in 2D and 1.05 I in 3D, against the spiky gradient's
// 0.87 I and 0.95 I. The column settles near rho0 g depth (0.96 and 0.93 measured) without the
// corrected force's ringing.
TEST(Hydrostatic, VariationalFormSettlesToRho0GDepth2D) {
  const double r = settled_pressure_ratio<2>(PressureForce::Variational, 20, 20);
  EXPECT_GT(r, 0.9);
  EXPECT_LT(r, 1.05);
}
TEST(Hydrostatic, VariationalFormSettlesToRho0GDepth3D) {
  const double r = settled_pressure_ratio<3>(PressureForce::Variational, 8, 10);
  EXPECT_GT(r, 0.9);
  EXPECT_LT(r, 1.05);
}
// The paper's Eq. 5 form (p_i + p_j) / 2 approximates grad(p) / 2 in the interior, so the
// pressure that holds the column up is about twice rho0 g depth.
TEST(Hydrostatic, PaperFormSettlesToTwiceRho0GDepth2D) {
  const double r = settled_pressure_ratio<2>(PressureForce::Paper, 20, 20);
  EXPECT_GT(r, 1.9);
  EXPECT_LT(r, 2.6);
}

TEST(Emitter, AddsOneBatchEveryNStepsUntilTheLimit) {
  SimulationParams<3> p = water_params<3>(0.01);
  p.container.lo = Vec<3, double>::filled(0);
  p.container.hi = Vec<3, double>::filled(1);
  EmitterParams<3> e;
  e.origin = {{0.5, 0.5, 0.5}};
  e.direction = {{0, -1, 0}};
  e.speed = 2.0;
  e.width = 3;
  e.height = 2;
  e.spacing = 0.02;
  e.every_steps = 16;
  e.max_particles = 40;
  p.emitters.push_back(e);
  p.time_step = 1e-3;
  Simulation<3, double> sim(p, {});
  std::vector<std::size_t> counts;
  for (int s = 0; s < 120; ++s) counts.push_back(sim.step().particles);
  EXPECT_EQ(counts[0], 6u);
  EXPECT_EQ(counts[15], 6u);
  EXPECT_EQ(counts[16], 12u);
  EXPECT_EQ(counts[16 * 6], 40u);  // 7th batch is partial: 6 * 6 = 36, then 4 more
  EXPECT_EQ(counts.back(), 40u);
  EXPECT_EQ(sim.emitter_states()[0].emitted, 40);
  // Emitted particles move along the direction and are centered on the nozzle.
  const auto& P = sim.particles();
  EXPECT_NEAR(P.initial_position[0][1], 0.5, 1e-12);
  double cx = 0;
  for (int i = 0; i < 6; ++i)
    cx += P.initial_position[static_cast<std::size_t>(i)][0] + P.initial_position[static_cast<std::size_t>(i)][2];
  EXPECT_NEAR(cx / 6, 1.0, 1e-12);
  EXPECT_EQ(P.id.back(), 39u);
}

TEST(Simulation, BlowUpIsReportedWithStepAndParticle) {
  SimulationParams<2> p = water_params<2>(0.01);
  p.container.lo = Vec<2, double>::filled(0);
  p.container.hi = Vec<2, double>::filled(1);
  ParticleSet<2, double> ps;
  ps.mass = p.particle_mass;
  ps.add({{0.5, 0.5}}, {{1e9, 0}});  // far beyond any physical speed
  Simulation<2, double> sim(p, std::move(ps));
  try {
    sim.step();
    FAIL() << "expected a blow-up error";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("step 1 "), std::string::npos) << m;  // (the first step, stats.csv's row 1)
    EXPECT_NE(m.find("particle id 0"), std::string::npos) << m;
    EXPECT_NE(m.find("speed"), std::string::npos) << m;
  }
}

TEST(Simulation, NonFiniteValuesAreReportedInTheStepTheyAppear) {
  SimulationParams<2> p = water_params<2>(0.01);
  p.container.lo = Vec<2, double>::filled(0);
  p.container.hi = Vec<2, double>::filled(1);
  ParticleSet<2, double> ps;
  ps.mass = p.particle_mass;
  ps.add({{0.5, 0.5}}, {});
  ps.add({{0.2, 0.2}}, {});
  Simulation<2, double> sim(p, std::move(ps));
  for (int s = 0; s < 3; ++s) sim.step();  // steps 1 to 3
  // A NaN appearing in particle id 1's velocity (as an overflow would leave it). Its index is
  // looked up: the Morton reorder of step 0 may have moved it.
  auto& ps1 = const_cast<ParticleSet<2, double>&>(sim.particles());
  const auto at = static_cast<std::size_t>(std::find(ps1.id.begin(), ps1.id.end(), 1u) - ps1.id.begin());
  ps1.velocity[at][0] = std::numeric_limits<double>::quiet_NaN();
  try {
    sim.step();
    FAIL() << "expected a blow-up error";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("step 4 "), std::string::npos) << m;  // the fourth step, stats.csv's row 4
    EXPECT_NE(m.find("particle id 1"), std::string::npos) << m;
    EXPECT_NE(m.find("position is not finite"), std::string::npos) << m;
  }
}

TEST(TimeStep, WarnsNearAndRefusesBeyondTheAcousticLimit) {
  SimulationParams<3> p = water_params<3>(0.01);
  const double c = std::sqrt(p.fluid.stiffness), h = p.kernel_radius;
  p.time_step = 0.3 * h / c;
  p.walls.stiffness = 1;
  p.walls.damping = 0;
  EXPECT_TRUE(check_time_step<3>(p).empty());
  p.time_step = 0.6 * h / c;
  EXPECT_EQ(check_time_step<3>(p).size(), 1u);
  p.time_step = 1.2 * h / c;
  EXPECT_THROW(check_time_step<3>(p), Error);
}

}  // namespace
}  // namespace sph

namespace sph {
namespace {

TEST(Walls, ObstacleHoldsAFallingParticleAndNeverPulls) {
  SimulationParams<2> p = water_params<2>(0.01);
  p.gravity[1] = -9.81;
  p.container.lo = Vec<2, double>::filled(0);
  p.container.hi = Vec<2, double>::filled(1);
  p.obstacles.push_back({{{0.4, 0.2}}, {{0.6, 0.3}}});
  ParticleSet<2, double> ps;
  ps.mass = p.particle_mass;
  ps.add({{0.5, 0.6}}, {});   // falls onto the obstacle's top face
  ps.add({{0.05, 0.6}}, {});  // falls beside it, onto the container floor
  Simulation<2, double> sim(p, std::move(ps));
  for (int s = 0; s < 10000; ++s) sim.step();  // 2 s: both come to rest
  const auto& P = sim.particles();
  // Particles may have been reordered in memory: find them by id.
  const std::size_t on_top = P.id[0] == 0 ? 0 : 1, beside = 1 - on_top;
  ASSERT_EQ(P.id[on_top], 0u);
  EXPECT_NEAR(P.position[on_top][1], 0.3 + p.particle_radius, 0.01);  // rests on the top face
  EXPECT_NEAR(P.position[on_top][0], 0.5, 1e-9);                      // no sideways push
  EXPECT_NEAR(P.position[beside][1], p.particle_radius, 0.01);        // rests on the floor
  EXPECT_LT(sim.max_speed(), 0.05);
}

TEST(Walls, ContactForceIsNeverAttractive) {
  SimulationParams<2> p = water_params<2>(0.01);
  p.container.lo = Vec<2, double>::filled(0);
  p.container.hi = Vec<2, double>::filled(1);
  p.walls.damping = 1e4;  // strong damping: a plain damped spring would pull a leaving particle back
  ParticleSet<2, double> ps;
  ps.mass = p.particle_mass;
  ps.add({{0.5, 0.005}}, {{0, 3.0}});  // inside the contact zone, moving away
  const WallContact<2, double> contact(p.container, p.obstacles, 0.01, p.walls);
  EXPECT_GE(contact(ps.position[0], ps.velocity[0])[1], 0.0);
}

}  // namespace
}  // namespace sph
