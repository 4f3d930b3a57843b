// The step engine's performance machinery must not change what a user gets: no allocation in
// a steady-state step (checked by counting operator new), Morton reordering keeps every
// particle (by id) and the physics, and every neighbor mode gives bitwise-identical results for
// 1 and 2 threads, with reordering and in float and double.

#include <array>
#include <atomic>
#include <cstdlib>
#include <map>
#include <new>
#include <sstream>

#include <gtest/gtest.h>

#include <sph/core/parallel.h>
#include <sph/core/state_stream.h>
#include <sph/solver/simulation.h>
#include <sph/solver/wcsph.h>

#include "support/thread_count.h"

// Counts every allocation in this test program (forwarding to malloc).
namespace {
std::atomic<std::uint64_t> g_allocations{0};
}
// GCC cannot see that these replace the global operators as a matched set.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace sph {
namespace {

using test::ThreadCount;

/// A 3D column of water collapsing in a box (dam break), n^3 particles.
template <class R>
Simulation<3, R> dam_break(int n, NeighborMode mode, int reorder_period) {
  SimulationParams<3> p;
  p.particle_radius = 0.01;
  p.kernel_radius = 0.04;
  p.time_step = 4e-4;
  p.fluid.rest_density = 1000;
  p.fluid.stiffness = 900;
  p.fluid.viscosity = 3.0;
  p.particle_mass = lattice_mass<3>(1000, 0.02, 0.04);
  p.walls.stiffness = 2e5;
  p.walls.damping = 300;
  p.gravity[1] = -9.81;
  p.container.lo = Vec<3, double>::filled(0);
  p.container.hi = {{0.02 * n * 2.5, 0.02 * n * 1.5, 0.02 * n}};
  p.neighbors = mode;
  p.full_rebuild_period = 200;
  p.reorder_period = reorder_period;
  ParticleSet<3, R> ps;
  ps.mass = R(p.particle_mass);
  // Added column by column (x slowest): far from Morton order, so reordering does something.
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) ps.add(Vec<3, R>{R(0.01 + 0.02 * i), R(0.01 + 0.02 * j), R(0.01 + 0.02 * k)}, {});
  return Simulation<3, R>(p, std::move(ps));
}

class NoAllocation : public ::testing::TestWithParam<NeighborMode> {};

TEST_P(NoAllocation, SteadyStateStepsAllocateNothing) {
  ThreadCount restore;
  set_num_threads(2);
  auto sim = dam_break<float>(12, GetParam(), 20);
  std::size_t rebuilt = 0;           // lists rebuilt over the measured steps
  const auto step_and_stats = [&] {  // what `sph run` does each step
    rebuilt += sim.step().neighbors.lists_rebuilt;
    (void)sim.kinetic_energy_and_max_speed();
    (void)sim.momentum();
  };
  for (int s = 0; s < 45; ++s) step_and_stats();  // warm-up, two reorders included
  // A collapsing dam break's lists grow (by half over its first 300 steps), and growing lists
  // may allocate. So the 60 measured steps run twice from the same state: the first time the
  // buffers grow to what these steps need, the second time they must allocate nothing.
  std::stringstream saved;
  StateWriter out(saved);
  sim.save_state(out);
  for (int s = 0; s < 60; ++s) step_and_stats();
  StateReader in(saved, out.written(), "saved state");
  sim.load_state(in);
  rebuilt = 0;
  const std::uint64_t before = g_allocations.load();
  for (int s = 0; s < 60; ++s) step_and_stats();  // three more reorders, verlet rebuilds, adaptive partial rebuilds
  EXPECT_EQ(g_allocations.load() - before, 0u) << "allocations inside steps";
  EXPECT_GT(sim.kinetic_energy(), 0.0);  // it did move
  EXPECT_GT(rebuilt, 0u);                // and rebuilt lists
}

INSTANTIATE_TEST_SUITE_P(Modes, NoAllocation,
                         ::testing::Values(NeighborMode::Standard, NeighborMode::Adaptive, NeighborMode::Verlet,
                                           NeighborMode::Tracked, NeighborMode::AdaptiveExact,
                                           NeighborMode::VerletClusters),
                         [](const auto& info) { return std::string(to_string(info.param)); });

TEST(Reorder, KeepsEveryParticleAndOrdersThemAlongTheCurve) {
  auto sim = dam_break<double>(10, NeighborMode::Standard, 1000);
  std::map<std::uint64_t, Vec<3, double>> before;
  for (std::size_t i = 0; i < sim.particles().size(); ++i) before[sim.particles().id[i]] = sim.particles().position[i];
  const StepInfo& info = sim.step();  // step 0 reorders
  EXPECT_TRUE(info.reordered);
  const auto& P = sim.particles();
  ASSERT_EQ(P.size(), before.size());
  std::size_t moved_in_memory = 0;
  double step_sum = 0;
  for (std::size_t i = 0; i < P.size(); ++i) {
    ASSERT_EQ(before.count(P.id[i]), 1u);
    // One step of motion: every particle is still near where it was.
    EXPECT_LT(std::sqrt(norm2(P.position[i] - before[P.id[i]])), 1e-3);
    moved_in_memory += P.id[i] != i ? 1 : 0;
    if (i > 0) step_sum += std::sqrt(norm2(P.position[i] - P.position[i - 1]));
  }
  EXPECT_GT(moved_in_memory, P.size() / 2);
  // Consecutive particles are close in space: the mean gap is about two spacings.
  EXPECT_LT(step_sum / static_cast<double>(P.size() - 1), 0.045);
  EXPECT_FALSE(sim.step().reordered);
}

TEST(Reorder, DoesNotChangeThePhysicsBeyondRoundOff) {
  auto a = dam_break<double>(10, NeighborMode::Standard, 0);
  auto b = dam_break<double>(10, NeighborMode::Standard, 7);
  for (int s = 0; s < 50; ++s) a.step(), b.step();
  std::map<std::uint64_t, Vec<3, double>> pa;
  for (std::size_t i = 0; i < a.particles().size(); ++i) pa[a.particles().id[i]] = a.particles().position[i];
  double worst = 0;
  for (std::size_t i = 0; i < b.particles().size(); ++i)
    worst = std::max(worst, std::sqrt(norm2(b.particles().position[i] - pa[b.particles().id[i]])));
  EXPECT_LT(worst, 1e-9) << "reordering should only change the summation order";
  EXPECT_NEAR(a.kinetic_energy(), b.kinetic_energy(), 1e-9 * a.kinetic_energy());
}

template <class R>
void expect_fluid_then_walls() {
  auto sim = dam_break<R>(8, NeighborMode::Standard, 0);
  for (int s = 0; s < 30; ++s) sim.step();  // particles now touch the floor and the left wall
  SimulationParams<3> p = sim.params();
  const R h = static_cast<R>(p.kernel_radius);
  const NeighborLists& lists = sim.neighbors().lists();
  const std::vector<Box<3>> no_obstacles;
  const WallContact<3, R> no_walls({Vec<3, double>::filled(-1e3), Vec<3, double>::filled(1e3)}, no_obstacles,
                                   static_cast<R>(p.particle_radius), p.walls);
  // The container's walls alone (the pass pushes a register of particles at a time), then with an
  // obstacle among the particles (one particle at a time).
  const std::vector<Box<3>> obstacles = {{{{0.05, 0.0, 0.0}}, {{0.1, 0.05, 0.16}}}};
  for (const std::vector<Box<3>>* solid : std::array{&no_obstacles, &obstacles}) {
    ParticleSet<3, R> a = sim.particles(), b = sim.particles();
    std::vector<std::uint8_t> fa(a.size(), 0), fb(b.size(), 0);
    compute_density_pressure<3, R>(a, lists, h, p.fluid);
    compute_density_pressure<3, R>(b, lists, h, p.fluid);
    const Vec<3, R> g = vec_cast<R>(p.gravity);
    const R dt = static_cast<R>(p.time_step);
    compute_accelerations<3, R>(a, lists, h, p.fluid, g, no_walls, fa, dt);
    const WallContact<3, R> walls(p.container, *solid, static_cast<R>(p.particle_radius), p.walls);
    for (std::size_t i = 0; i < a.size(); ++i) a.acceleration[i] += walls(a.position[i], a.velocity[i]);
    compute_accelerations<3, R>(b, lists, h, p.fluid, g, walls, fb, dt);
    EXPECT_TRUE(a.acceleration == b.acceleration) << solid->size() << " obstacles";
    EXPECT_EQ(fa, fb);
    std::size_t touching = 0;
    for (std::size_t i = 0; i < a.size(); ++i) touching += norm2(walls(a.position[i], a.velocity[i])) > 0 ? 1 : 0;
    EXPECT_GT(touching, 10u) << "the walls must be part of the comparison";
  }
}

TEST(FusedPasses, AccelerationsEqualFluidThenWallsBitForBit) {
  // compute_accelerations runs forces and walls in one pass; it must give the fluid's values
  // (the same pass with walls that touch no particle) plus each particle's wall contact.
  expect_fluid_then_walls<double>();
  expect_fluid_then_walls<float>();
}

TEST(Reorder, ParticlesEmittedOnAReorderStepAreTheLastOnes) {
  // Reorder and emission on the same step: the new particles must still be at the end (sph
  // compare perturbs [n - emitted, n) after each step).
  auto params = dam_break<double>(6, NeighborMode::Adaptive, 8).params();
  // The emitter piles its layers (0.5 m/s every 4 steps: a tenth of a spacing apart) so that
  // emission meets reordering often; not a physical flow, so the health monitor only measures.
  params.health_failures = false;
  EmitterParams<3> e;
  e.origin = {{0.2, 0.1, 0.06}};
  e.direction = {{0, -1, 0}};
  e.speed = 0.5;
  e.width = e.height = 3;
  e.spacing = 0.02;
  e.every_steps = 4;
  e.max_particles = 200;
  params.emitters.push_back(e);
  Simulation<3, double> sim(params, dam_break<double>(6, NeighborMode::Adaptive, 8).particles());
  int both = 0;
  for (int s = 0; s < 40; ++s) {
    const StepInfo& info = sim.step();
    const auto& P = sim.particles();
    if (info.reordered && info.emitted > 0) ++both;
    for (std::size_t i = P.size() - info.emitted; i < P.size(); ++i)
      ASSERT_GE(P.id[i], P.next_id() - info.emitted) << "step " << s << ": index " << i << " is an old particle";
  }
  EXPECT_GE(both, 4) << "the test must cover steps that reorder and emit";
}

TEST(ParticleSetPermute, RejectsARepeatedIndex) {
  ParticleSet<2, double> ps;
  ps.mass = 1.0;
  for (int i = 0; i < 3; ++i) ps.add(Vec<2, double>::filled(i), {});
  const std::vector<std::uint32_t> bad{0, 0, 2};
  EXPECT_THROW(ps.permute(bad), std::logic_error);
  EXPECT_EQ(ps.id[1], 1u) << "a refused permutation must leave the set unchanged";
}

/// Runs the same dam break with 1 thread and with each of `threads`: every field, bit for bit.
template <class R>
void expect_thread_independent(NeighborMode mode, int n, int steps, std::vector<int> threads) {
  ThreadCount restore;
  set_num_threads(1);
  auto a = dam_break<R>(n, mode, 25);
  for (int s = 0; s < steps; ++s) a.step();
  for (int t : threads) {
    SCOPED_TRACE(std::to_string(t) + " threads");
    set_num_threads(t);
    auto b = dam_break<R>(n, mode, 25);
    for (int s = 0; s < steps; ++s) b.step();
    EXPECT_TRUE(a.particles().id == b.particles().id);
    EXPECT_TRUE(a.particles().position == b.particles().position);
    EXPECT_TRUE(a.particles().velocity == b.particles().velocity);
    EXPECT_TRUE(a.particles().density == b.particles().density);
    EXPECT_TRUE(a.particles().pressure == b.particles().pressure);
    EXPECT_TRUE(a.neighbors().lists() == b.neighbors().lists());
    EXPECT_EQ(a.kinetic_energy(), b.kinetic_energy());
    // (the stats row's one pass gives what the two reductions give, bit for bit)
    EXPECT_EQ(b.kinetic_energy_and_max_speed(), std::pair(a.kinetic_energy(), a.max_speed()));
    EXPECT_GT(a.max_speed(), 0.0);
  }
}

// 1,728 particles: two chunks of the parallel loops.
TEST(Determinism, EveryModeIsBitwiseIdenticalFor1To4ThreadsDouble) {
  for (NeighborMode m : {NeighborMode::Standard, NeighborMode::Adaptive, NeighborMode::Verlet, NeighborMode::Tracked,
                         NeighborMode::AdaptiveExact, NeighborMode::VerletClusters}) {
    SCOPED_TRACE(std::string(to_string(m)));
    expect_thread_independent<double>(m, 12, 120, {2, 3, 4});
  }
}

TEST(Determinism, EveryModeIsBitwiseIdenticalFor1To4ThreadsFloat) {
  for (NeighborMode m : {NeighborMode::Standard, NeighborMode::Adaptive, NeighborMode::Verlet, NeighborMode::Tracked,
                         NeighborMode::AdaptiveExact, NeighborMode::VerletClusters}) {
    SCOPED_TRACE(std::string(to_string(m)));
    expect_thread_independent<float>(m, 12, 120, {2, 3, 4});
  }
}

// 8,000 particles: 8 chunks, shared unevenly by 3 threads; 40 steps cross a Morton reorder
// (every 25). (The grid's parallel block sort is checked for thread independence in
// tests/neighbors/list_builder_test.cpp.)
TEST(Determinism, EveryModeIsBitwiseIdenticalFor1And3ThreadsOn8Chunks) {
  for (NeighborMode m : {NeighborMode::Standard, NeighborMode::Adaptive, NeighborMode::Verlet, NeighborMode::Tracked,
                         NeighborMode::AdaptiveExact, NeighborMode::VerletClusters}) {
    SCOPED_TRACE(std::string(to_string(m)));
    expect_thread_independent<double>(m, 20, 40, {3});
  }
}

}  // namespace
}  // namespace sph
