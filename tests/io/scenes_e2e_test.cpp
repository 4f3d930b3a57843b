// End to end: the paper scenes, read from their files, built and run for a short while, stay
// physically sane (inside the tank, bounded speeds, finite values, sensible neighbor counts),
// emitters add whole batches on schedule, and results do not depend on the thread count.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include <sph/core/parallel.h>
#include <sph/scene/builders.h>
#include <sph/scene/scene_reader.h>

#include "support/scenes.h"
#include "support/thread_count.h"

namespace sph {
namespace {

using test::paper_scene;

struct Expect {
  double min_mean_neighbors, max_mean_neighbors;
};

/// Restores the thread count at scope exit.
using test::ThreadCount;

template <int D, class R>
void check_state(const Simulation<D, R>& sim, const Expect& ex, const std::string& what) {
  SCOPED_TRACE(what);
  const auto& p = sim.params();
  const auto& ps = sim.particles();
  const std::size_t n = ps.size();
  ASSERT_GT(n, 0u);

  // Inside the container, give or take one particle radius (the walls are penalty springs).
  const double tol = p.particle_radius;
  std::size_t outside = 0;
  for (std::size_t i = 0; i < n; ++i)
    for (int d = 0; d < D; ++d) {
      const double x = static_cast<double>(ps.position[i][d]);
      if (x < p.container.lo[d] - tol || x > p.container.hi[d] + tol) {
        if (outside++ < 5)
          ADD_FAILURE() << "particle id " << ps.id[i] << " outside the container on axis " << d << ": " << x
                        << " not in [" << p.container.lo[d] << ", " << p.container.hi[d] << "] +- " << tol;
      }
    }
  EXPECT_EQ(outside, 0u) << "particle coordinates outside the container";

  // Speeds: at most 3x the free-fall speed over the container height, plus emitter speed.
  int up = 0;
  for (int d = 1; d < D; ++d)
    if (std::abs(p.gravity[d]) > std::abs(p.gravity[up])) up = d;
  const double height = p.container.hi[up] - p.container.lo[up];
  double emitter_speed = 0;
  for (const auto& e : p.emitters) emitter_speed = std::max(emitter_speed, e.speed);
  const double g = std::sqrt(static_cast<double>(dot(p.gravity, p.gravity)));
  const double speed_bound = 3.0 * std::sqrt(2.0 * g * height) + emitter_speed;
  EXPECT_LT(sim.max_speed(), speed_bound);

  // Finite everywhere; densities positive (every particle has been through a density pass).
  std::size_t bad = 0;
  double rho_min = INFINITY, rho_max = -INFINITY, rho_sum = 0, p_max = 0;
  for (std::size_t i = 0; i < n; ++i) {
    bool ok = std::isfinite(static_cast<double>(ps.density[i])) && std::isfinite(static_cast<double>(ps.pressure[i])) &&
              ps.density[i] > 0;
    for (int d = 0; d < D; ++d)
      ok = ok && std::isfinite(static_cast<double>(ps.position[i][d])) &&
           std::isfinite(static_cast<double>(ps.velocity[i][d])) &&
           std::isfinite(static_cast<double>(ps.acceleration[i][d]));
    if (!ok) ++bad;
    rho_min = std::min(rho_min, static_cast<double>(ps.density[i]));
    rho_max = std::max(rho_max, static_cast<double>(ps.density[i]));
    rho_sum += static_cast<double>(ps.density[i]);
    p_max = std::max(p_max, static_cast<double>(ps.pressure[i]));
  }
  EXPECT_EQ(bad, 0u) << "particles with non-finite state or non-positive density";

  const double ke = sim.kinetic_energy();
  EXPECT_TRUE(std::isfinite(ke));
  EXPECT_GT(ke, 0.0);

  const StepInfo& last = sim.last_step();
  const double mean_neighbors = static_cast<double>(last.neighbors.pairs_stored) / static_cast<double>(n);
  EXPECT_GE(mean_neighbors, ex.min_mean_neighbors);
  EXPECT_LE(mean_neighbors, ex.max_mean_neighbors);

  std::printf(
      "  %s: %zu particles, t = %.4g s, max speed %.3f m/s (bound %.2f), KE %.4g, mean neighbors %.2f, "
      "density %.1f..%.1f (mean %.1f), max pressure %.4g\n",
      what.c_str(), n, sim.time(), sim.max_speed(), speed_bound, ke, mean_neighbors, rho_min, rho_max,
      rho_sum / static_cast<double>(n), p_max);
}

// The sanity runs use one thread: results do not depend on the thread count (the determinism
// tests below check that bitwise), and OpenMP teams slow down by 10x or more when the cores are
// oversubscribed (ctest -j, a busy machine), since every step has several parallel regions.
constexpr int kSanityThreads = 1;

template <int D, class R>
void run_scene(const std::string& name, std::int64_t steps, const Expect& ex) {
  ThreadCount restore;
  set_num_threads(kSanityThreads);
  const auto t0 = std::chrono::steady_clock::now();
  const SceneDesc desc = read_scene_file(paper_scene(name));
  ASSERT_EQ(desc.dimension, D);
  Simulation<D, R> sim = make_simulation<D, R>(desc);
  const std::size_t initial = sim.particles().size();
  const std::int64_t checkpoint = std::max<std::int64_t>(1, steps / 3);
  for (std::int64_t s = 0; s < steps; ++s) {
    ASSERT_NO_THROW(sim.step()) << name << " at step " << s;
    if (sim.params().emitters.empty()) {
      ASSERT_EQ(sim.particles().size(), initial);
    }
    if ((s + 1) % checkpoint == 0 && s + 1 < steps) {
      // Intermediate checks, without the neighbor range (emitter scenes start sparse).
      check_state(sim, Expect{0.0, 1e9}, name + " at step " + std::to_string(s + 1));
      if (::testing::Test::HasFatalFailure() || ::testing::Test::HasNonfatalFailure()) return;
    }
  }
  EXPECT_EQ(sim.steps_done(), steps);
  check_state(sim, ex, name + " after " + std::to_string(steps) + " steps");
  const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("  %s: %lld steps in %.2f s with %d threads\n", name.c_str(), static_cast<long long>(steps), sec,
              num_threads());
}

TEST(ScenesE2E, DamBreak2D) {
  run_scene<2, double>("dam_break_2d", 1500, {4, 20});
  const SceneDesc desc = read_scene_file(paper_scene("dam_break_2d"));
  EXPECT_EQ(count_block_particles<2>(desc.body<2>()), 3200u);
}

TEST(ScenesE2E, DamBreak2DFloat) { run_scene<2, float>("dam_break_2d", 1500, {4, 20}); }

TEST(ScenesE2E, Block3D) {
  run_scene<3, double>("block_3d", 600, {10, 60});
  const SceneDesc desc = read_scene_file(paper_scene("block_3d"));
  EXPECT_EQ(count_block_particles<3>(desc.body<3>()), 4000u);
}

TEST(ScenesE2E, TankFill3D) {
  ThreadCount restore;
  set_num_threads(kSanityThreads);
  const SceneDesc desc = read_scene_file(paper_scene("tank_fill_3d"));
  Simulation<3, double> sim = make_simulation<3, double>(desc);
  ASSERT_EQ(sim.particles().size(), 0u);
  ASSERT_EQ(sim.params().emitters.size(), 1u);
  const auto& em = sim.params().emitters[0];
  const std::size_t batch = static_cast<std::size_t>(em.width * em.height);
  ASSERT_EQ(batch, 36u);
  ASSERT_EQ(em.every_steps, 16);
  const std::int64_t steps = 1200;
  for (std::int64_t s = 0; s < steps; ++s) {
    const StepInfo& info = sim.step();
    // Batches at the start of steps 0, 16, 32, ...: after step s, s / 16 + 1 batches.
    const std::size_t batches = static_cast<std::size_t>(s / 16 + 1);
    ASSERT_EQ(sim.particles().size(), batch * batches) << "after step " << s;
    ASSERT_EQ(info.emitted, s % 16 == 0 ? batch : 0u) << "step " << s;
    ASSERT_EQ(info.particles, sim.particles().size());
    ASSERT_EQ(sim.emitter_states()[0].emitted, static_cast<std::int64_t>(batch * batches));
  }
  check_state(sim, Expect{10, 60}, "tank_fill_3d after 1200 steps");
  // Ids are 0..N-1 (never reused, nothing removed).
  std::vector<std::uint32_t> ids = sim.particles().id;
  std::sort(ids.begin(), ids.end());
  for (std::size_t i = 0; i < ids.size(); ++i) ASSERT_EQ(ids[i], i);
}

template <int D, class R>
Simulation<D, R> run_with_threads(const SceneDesc& desc, int threads, std::int64_t steps) {
  set_num_threads(threads);
  Simulation<D, R> sim = make_simulation<D, R>(desc);
  for (std::int64_t s = 0; s < steps; ++s) sim.step();
  return sim;
}

TEST(ScenesE2E, Block3DIsBitwiseIdenticalFor1And2Threads) {
  ThreadCount restore;
  const SceneDesc desc = read_scene_file(paper_scene("block_3d"));
  const auto a = run_with_threads<3, double>(desc, 1, 100);
  const auto b = run_with_threads<3, double>(desc, 2, 100);
  const auto& pa = a.particles();
  const auto& pb = b.particles();
  ASSERT_EQ(pa.size(), pb.size());
  EXPECT_TRUE(pa.id == pb.id) << "particle order differs";
  EXPECT_TRUE(pa.position == pb.position) << "positions differ";
  EXPECT_TRUE(pa.velocity == pb.velocity) << "velocities differ";
  EXPECT_TRUE(pa.density == pb.density) << "densities differ";
  EXPECT_TRUE(pa.pressure == pb.pressure) << "pressures differ";
  EXPECT_TRUE(pa.acceleration == pb.acceleration) << "accelerations differ";
  EXPECT_EQ(a.kinetic_energy(), b.kinetic_energy());
  EXPECT_TRUE(a.momentum() == b.momentum());
  EXPECT_EQ(a.max_speed(), b.max_speed());
  EXPECT_EQ(a.last_step().neighbors.pairs_stored, b.last_step().neighbors.pairs_stored);
}

TEST(ScenesE2E, TankFill3DIsBitwiseIdenticalFor1And2Threads) {
  // With an emitter the particle count changes during the run (new chunks appear).
  ThreadCount restore;
  const SceneDesc desc = read_scene_file(paper_scene("tank_fill_3d"));
  const auto a = run_with_threads<3, double>(desc, 1, 300);
  const auto b = run_with_threads<3, double>(desc, 2, 300);
  ASSERT_EQ(a.particles().size(), b.particles().size());
  EXPECT_TRUE(a.particles().position == b.particles().position);
  EXPECT_TRUE(a.particles().velocity == b.particles().velocity);
  EXPECT_EQ(a.kinetic_energy(), b.kinetic_energy());
}

}  // namespace
}  // namespace sph
