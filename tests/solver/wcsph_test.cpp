// Paper Eq. 7 inside the force pass: exactly the particles of listed pairs whose predicted
// distance |x_i - x_j + dt (u_i - u_j)| exceeds h are flagged, both i and j, even when only
// one of them lists the other; the pairs-within-h count; and the simulation-level contract
// that adaptive with a full-rebuild period of 1 is the standard algorithm, bit for bit; the force
// pass's copy of 1 / rho and p in lent memory.

#include <algorithm>
#include <cstring>
#include <vector>

#include <gtest/gtest.h>

#include <sph/core/parallel.h>
#include <sph/core/storage.h>
#include <sph/neighbors/standard.h>
#include <sph/solver/simulation.h>
#include <sph/solver/wcsph.h>

#include "support/blob.h"

namespace sph {
namespace {

using V2 = Vec<2, double>;

// The force pass over lists reads each neighbor's 1 / rho and p from a copy it makes in the memory
// it is given (NeighborStrategy::scratch_until_update): the accelerations are the same bits with
// lent memory that held anything (NaN bytes here), lent memory too small (it grows), and none (the
// pass's own), with Eq. 6's viscosity and with Monaghan's (which also reads each rho_j).
template <int D, class R>
void expect_forces_whatever_the_scratch_held(ViscosityModel model) {
  test::Blob<D, R> blob(D == 3 ? 10 : 30, 5);
  const R h = static_cast<R>(blob.h);
  FluidParams fluid;
  fluid.stiffness = 200;
  fluid.rest_density = 1000;
  fluid.viscosity = 0.5;
  fluid.negative_pressure = NegativePressure::Allow;
  fluid.viscosity_model = model;
  StandardNeighbors<D, R> neighbors(h);
  neighbors.update(blob.ps);
  compute_density_pressure<D, R>(blob.ps, neighbors.lists(), h, fluid, {});
  const test::FarWalls<D, R> far;
  const auto accelerations = [&](ScratchBuffer* scratch) {
    ParticleSet<D, R> ps = blob.ps;
    compute_accelerations<D, R>(ps, neighbors.lists(), h, fluid, far.gravity, far.walls, {}, R(1e-4), {}, R(0), true,
                                nullptr, scratch);
    return ps.acceleration;
  };
  const std::vector<Vec<D, R>> own = accelerations(nullptr);
  ScratchBuffer garbage, small;
  garbage.reserve(2 * blob.ps.size() * sizeof(R));
  std::uint8_t* bytes = garbage.place<std::uint8_t>(0, garbage.capacity());
  std::fill_n(bytes, garbage.capacity(), std::uint8_t{0xff});
  small.reserve(64);
  const auto same = [](const std::vector<Vec<D, R>>& a, const std::vector<Vec<D, R>>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec<D, R>)) == 0;
  };
  EXPECT_TRUE(same(own, accelerations(&garbage)));
  EXPECT_TRUE(same(own, accelerations(&small)));
  EXPECT_GE(small.capacity(), 2 * blob.ps.size() * sizeof(R));
  double largest = 0;
  for (const auto& a : own) largest = std::max(largest, static_cast<double>(norm(a)));
  EXPECT_GT(largest, 1.0) << "the block's pressures and viscosity must move it";
}

TEST(ForcePass, AccelerationsAreTheSameWhateverTheLentMemoryHeld) {
  for (ViscosityModel model : {ViscosityModel::Paper, ViscosityModel::Artificial}) {
    expect_forces_whatever_the_scratch_held<3, float>(model);
    expect_forces_whatever_the_scratch_held<2, double>(model);
  }
}

TEST(PairExitTest, FlagsBothParticlesOfExactlyThePairsPredictedToLeave) {
  const double h = 1.0, dt = 0.2;
  ParticleSet<2, double> ps;
  ps.mass = 1.0;
  ps.add(V2{0, 0}, V2{0, 0});      // 0
  ps.add(V2{0.9, 0}, V2{1, 0});    // 1: leaves 0: predicted distance 0.9 + 0.2 = 1.1 > h
  ps.add(V2{0, 0.5}, V2{0, 0});    // 2: stays 0.5 from 0
  ps.add(V2{3, 3}, V2{0, 0});      // 3: alone
  ps.add(V2{3.5, 3}, V2{-2, 0});   // 4: passes through 5 but stays within h of it
  ps.add(V2{3.9, 3}, V2{0, 0});    // 5: predicted |x4 - x5 + dt (u4 - u5)| = |-0.4 - 0.4| = 0.8 < h
  ps.add(V2{10, 10}, V2{0, 0});    // 6: listed by 7 only (asymmetric lists)
  ps.add(V2{10.5, 10}, V2{5, 0});  // 7: predicted 0.5 + 1.0 = 1.5 > h
  // Lists as an adaptive run may have them: 1 does not list 0 back, 6 does not list 7.
  //                                         0       1   2    3   4    5    6   7
  const NeighborLists lists = NeighborLists::from({{1, 2}, {}, {0}, {}, {5}, {4}, {}, {6}});
  ASSERT_EQ(lists.particle_count(), ps.size());
  std::vector<std::uint8_t> flags(ps.size(), 0);
  FluidParams fluid;
  fluid.stiffness = 1;
  const std::uint64_t within = compute_density_pressure<2, double>(ps, lists, h, fluid);
  // The Eq. 7 test runs in the force pass, which gathers every neighbor's velocity anyway.
  const std::vector<Box<2>> no_obstacles;
  const WallContact<2, double> no_walls({V2{-100, -100}, V2{100, 100}}, no_obstacles, 0.0, WallParams{});
  compute_accelerations<2, double>(ps, lists, h, fluid, V2{}, no_walls, flags, dt);
  const std::vector<std::uint8_t> expected{1, 1, 0, 0, 0, 0, 1, 1};
  EXPECT_EQ(flags, expected);
  // Listed pairs closer than h: 0->1 (0.9), 0->2 (0.5), 2->0, 4->5 (0.4), 5->4, 7->6 (0.5).
  EXPECT_EQ(within, 6u);

  // Without flags the test is skipped and the forces are the same; flags are only ever set.
  const auto acc_with_test = ps.acceleration;
  compute_accelerations<2, double>(ps, lists, h, fluid, V2{}, no_walls);
  EXPECT_TRUE(ps.acceleration == acc_with_test);
  std::vector<std::uint8_t> all(ps.size(), 1);
  compute_accelerations<2, double>(ps, lists, h, fluid, V2{}, no_walls, all, dt);
  EXPECT_EQ(all, std::vector<std::uint8_t>(ps.size(), 1));
}

TEST(PairExitTest, ListedPairsBeyondHAddNoDensity) {
  // Verlet and stale adaptive lists hold pairs beyond h: they must not change the density.
  ParticleSet<2, double> ps;
  ps.mass = 1.0;
  ps.add(V2{0, 0}, V2{});
  ps.add(V2{1.2, 0}, V2{});
  const NeighborLists with = NeighborLists::from({{1}, {0}});
  const NeighborLists without = NeighborLists::from({{}, {}});
  FluidParams fluid;
  fluid.stiffness = 1;
  EXPECT_EQ((compute_density_pressure<2, double>(ps, with, 1.0, fluid)), 0u);
  const auto rho_with = ps.density;
  compute_density_pressure<2, double>(ps, without, 1.0, fluid);
  EXPECT_EQ(rho_with, ps.density);
}

SimulationParams<2> column_params(NeighborMode mode, int period) {
  SimulationParams<2> p;
  p.particle_radius = 0.005;
  p.kernel_radius = 0.02;
  p.time_step = 1.5e-4;
  p.fluid.stiffness = 1600;
  p.fluid.viscosity = 2;
  p.particle_mass = lattice_mass<2>(1000, 0.01, 0.02);
  p.gravity = V2{0, -9.81};
  p.container.lo = V2{0, 0};
  p.container.hi = V2{0.6, 0.4};
  p.walls.stiffness = 1e6;
  p.walls.damping = 500;
  p.neighbors = mode;
  p.full_rebuild_period = period;
  EmitterParams<2> e;  // particles appear during the run too
  e.origin = V2{0.4, 0.3};
  e.direction = V2{0, -1};
  e.speed = 1.0;
  e.width = 4;
  e.spacing = 0.01;
  e.every_steps = 70;
  e.max_particles = 200;
  p.emitters.push_back(e);
  return p;
}

ParticleSet<2, double> column(const SimulationParams<2>& p) {
  ParticleSet<2, double> ps;
  ps.mass = p.particle_mass;
  for (int j = 0; j < 30; ++j)
    for (int i = 0; i < 15; ++i) ps.add(V2{0.01 + 0.01 * i, 0.01 + 0.01 * j}, V2{});
  return ps;
}

TEST(AdaptiveSimulation, FullRebuildPeriodOneIsBitwiseTheStandardAlgorithm) {
  Simulation<2, double> standard(column_params(NeighborMode::Standard, 200),
                                 column(column_params(NeighborMode::Standard, 200)));
  Simulation<2, double> adaptive(column_params(NeighborMode::Adaptive, 1),
                                 column(column_params(NeighborMode::Adaptive, 1)));
  for (int s = 0; s < 600; ++s) {
    standard.step();
    adaptive.step();
    ASSERT_EQ(adaptive.last_step().neighbors.lists_rebuilt, adaptive.particles().size());
  }
  EXPECT_GT(standard.particles().size(), 450u) << "the emitter should have added particles";
  EXPECT_TRUE(standard.particles().position == adaptive.particles().position);
  EXPECT_TRUE(standard.particles().velocity == adaptive.particles().velocity);
  EXPECT_TRUE(standard.particles().density == adaptive.particles().density);
}

TEST(AdaptiveSimulation, DefaultPeriodRebuildsFewListsAndDiffersOnlySlightly) {
  Simulation<2, double> standard(column_params(NeighborMode::Standard, 200),
                                 column(column_params(NeighborMode::Standard, 200)));
  Simulation<2, double> adaptive(column_params(NeighborMode::Adaptive, 200),
                                 column(column_params(NeighborMode::Adaptive, 200)));
  std::uint64_t rebuilt = 0, possible = 0;
  for (int s = 0; s < 400; ++s) {
    standard.step();
    adaptive.step();
    rebuilt += adaptive.last_step().neighbors.lists_rebuilt;
    possible += adaptive.particles().size();
  }
  EXPECT_LT(rebuilt, possible / 2) << "adaptive should rebuild far fewer lists than standard";
  EXPECT_GT(rebuilt, 2 * adaptive.particles().size()) << "beyond the two full rebuilds, some flagged lists";
  EXPECT_FALSE(standard.particles().position == adaptive.particles().position) << "stale lists change something";
  // ...but not much: the mean position difference stays far below a particle spacing.
  double sum = 0;
  for (std::size_t i = 0; i < standard.particles().size(); ++i)
    sum += norm(standard.particles().position[i] - adaptive.particles().position[i]);
  EXPECT_LT(sum / static_cast<double>(standard.particles().size()), 0.005);
}

TEST(AdaptiveSimulation, ResultsDoNotDependOnTheThreadCount) {
  const int saved = num_threads();
  std::vector<V2> pos[2];
  for (NeighborMode mode : {NeighborMode::Adaptive, NeighborMode::Verlet}) {
    for (int t : {1, 2}) {
      set_num_threads(t);
      Simulation<2, double> sim(column_params(mode, 200), column(column_params(mode, 200)));
      for (int s = 0; s < 300; ++s) sim.step();
      pos[t - 1] = sim.particles().position;
    }
    EXPECT_TRUE(pos[0] == pos[1]) << to_string(mode);
  }
  set_num_threads(saved);
}

TEST(Simulation, PerturbPositionsMovesEachParticleByTheAmplitudeWhateverItsIndex) {
  auto p = column_params(NeighborMode::Standard, 200);
  Simulation<2, double> a(p, column(p));
  const auto before = a.particles().position;
  a.perturb_positions(10, 1e-6, 42);
  for (std::size_t i = 0; i < 10; ++i) EXPECT_EQ(a.particles().position[i], before[i]);
  for (std::size_t i = 10; i < before.size(); ++i)
    EXPECT_NEAR(norm(a.particles().position[i] - before[i]), 1e-6, 1e-15);
  Simulation<2, double> b(p, column(p));
  b.perturb_positions(0, 1e-6, 42);
  EXPECT_EQ(a.particles().position[20], b.particles().position[20]) << "same id and seed, same displacement";
  b.perturb_positions(0, 1e-6, 43);
  EXPECT_NE(a.particles().position[20], b.particles().position[20]);
}

}  // namespace
}  // namespace sph
