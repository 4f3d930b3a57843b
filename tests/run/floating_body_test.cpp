// Floating rigid bodies (Obstacles[].dynamic): a box of half the water's density floats at
// Archimedes' draft, one of the water's density stays where it is, fluid and body exchange
// momentum exactly (with boundary particles and with penalty walls), a body dropped on the floor
// rests on it, and runs are the same for any thread count and resume bit for bit.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <sph/core/parallel.h>
#include <sph/run/driver.h>
#include <sph/scene/scene_reader.h>

#include "support/resume.h"
#include "support/solids.h"
#include "support/temp_dir.h"
#include "support/thread_count.h"

namespace sph {
namespace {

using test::deepest_inside;
using test::slurp;
using test::TempDir;

/// A 2D tank 1.2 m wide of water at rest (spacing 2 cm, DFSPH, boundary particles) with a box
/// 0.4 m x 0.2 m of `density` whose bottom is at `bottom`, the water filled around it to `level`.
SceneDesc tank_with_box(double density, double bottom, double level, double stop,
                        const std::string& extra_configuration = "") {
  const double top = bottom + 0.2;
  std::string blocks = fmt::format(
      R"({{ "start": [0, 0], "end": [0.4, {0}] }}, {{ "start": [0.8, 0], "end": [1.2, {0}] }},
         {{ "start": [0.4, 0], "end": [0.8, {1}] }})",
      level, bottom);
  if (level > top) blocks += fmt::format(R"(, {{ "start": [0.4, {}], "end": [0.8, {}] }})", top, level);
  const std::string text = fmt::format(R"({{
    "version": 1, "name": "floating", "dimension": 2,
    "Configuration": {{ "precision": "double", "timeStepSize": 0.004, "stopAt": {}, "particleRadius": 0.01,
      "kernelRadius": 0.04, "gravitation": [0, -9.81], "boundaryHandling": "particles", "kernel": "cubic",
      "simulationMethod": "dfsph", "cflMaxTimeStepSize": 0.01, "outputFps": 10{} }},
    "Fluid": {{ "density0": 1000, "viscosity": 1.0 }},
    "Container": {{ "start": [0, 0], "end": [1.2, 0.8] }},
    "FluidBlocks": [ {} ],
    "Obstacles": [ {{ "start": [0.4, {}], "end": [0.8, {}], "dynamic": true, "density": {} }} ]
  }})",
                                       stop, extra_configuration, blocks, bottom, top, density);
  return parse_scene(text, "floating.json");
}

/// Whether the run of `desc` has reached its end (a time, or fixed steps' count).
bool finished(const SceneDesc& desc, const Simulation<2, double>& sim) {
  return desc.end_time > 0 ? sim.time() >= desc.end_time * (1 - 1e-12) : sim.steps_done() >= desc.steps;
}

/// Runs `desc` to its end: the body's centre height and the free surface's away from it, averaged
/// over the second half of the run, its largest tilt then (rad), and the deepest particle inside
/// it over the run (checked every 10 steps).
struct Settled {
  double mean_y = 0, deepest = -1e300, tilt = 0, level = 0;
  std::size_t particles = 0;
};
Settled settle(const SceneDesc& desc) {
  RunDriver<2, double> run(desc, RunSettings{});
  const Simulation<2, double>& sim = run.simulation();
  Settled out;
  double sum = 0;
  int count = 0;
  while (!finished(desc, sim)) {
    run.step();
    if (sim.steps_done() % 10 == 0) out.deepest = std::max(out.deepest, deepest_inside(sim));
    if (sim.time() > 0.5 * desc.end_time) {  // (these scenes end at a time)
      sum += sim.bodies().at(0).position[1];
      ++count;
      out.tilt = std::max(out.tilt, std::abs(2 * std::asin(sim.bodies()[0].orientation[3])));
      // The free surface away from the body: each column's top particle plus a radius (columns of
      // a spacing, 6 cm to 30 cm from either wall).
      std::vector<double> top(60, -1);
      for (const auto& x : sim.particles().position) {
        const int c = static_cast<int>(x[0] / 0.02);
        if (c >= 0 && c < 60) top[static_cast<std::size_t>(c)] = std::max(top[static_cast<std::size_t>(c)], x[1]);
      }
      double level = 0;
      int cols = 0;
      for (int c = 3; c < 57; ++c)
        if (c < 15 || c > 44) level += top[static_cast<std::size_t>(c)] + 0.01, ++cols;
      out.level += level / cols;
    }
  }
  EXPECT_TRUE(sim.health().warnings().empty());
  out.mean_y = sum / count;
  out.level /= count;
  out.particles = sim.particles().size();
  return out;
}

TEST(FloatingBody, HalfTheWatersDensityFloatsAtArchimedesDraft) {
  // Density 500, 0.2 m tall: its draft is 0.1 m. Started 2 cm from its balance (bottom at 0.32 m
  // in water to 0.42 m, which its draft would leave level).
  const Settled s = settle(tank_with_box(500, 0.34, 0.42, 3.0));
  // The draft: from the free surface away from the body (each column's top particle plus a
  // radius, averaged like the body's height) to the body's bottom.
  const double bottom = s.mean_y - 0.1, draft = s.level - bottom;
  std::printf("draft %.5f m (Archimedes: 0.1 m), level %.5f m, tilt %.4f rad, deepest %.5f m\n", draft, s.level, s.tilt,
              s.deepest);
  EXPECT_NEAR(draft, 0.1, 0.05 * 0.1) << "bottom " << bottom << " m";
  EXPECT_LT(s.tilt, 0.05);  // (a box twice as wide as tall floats upright)
  EXPECT_LE(s.deepest, 0.5 * 0.01);
}

TEST(FloatingBody, TheWatersDensityNeitherRisesNorSinks) {
  // Submerged, 0.1 m below the surface and 0.1 m above the floor, with each boundary pressure (the
  // samples' pressure doubles their coupling to the box: without the box's answer in DFSPH's
  // solves, "mirror" and "extrapolate" lifted it 3.2 and 3.5 cm in a second).
  for (const char* pressure : {"none", "mirror", "extrapolate"}) {
    SCOPED_TRACE(pressure);
    const Settled s =
        settle(tank_with_box(1000, 0.1, 0.5, 1.0, fmt::format(R"(, "boundaryPressure": "{}")", pressure)));
    EXPECT_NEAR(s.mean_y, 0.2, 0.01);  // within a particle radius of where it started
    EXPECT_LE(s.deepest, 0.5 * 0.01);
  }
}

TEST(FloatingBody, DfsphPredictsWhatTheStepGivesABodyBesidesTheFluid) {
  // DFSPH's strong coupling predicts each body's velocity change from gravity, its contacts and the
  // gyroscopic term (Simulation::predict_bodies). A 3D box spinning off its axes, dropped onto the
  // floor far from the fluid (so that the fluid gives it nothing): each step's predicted change is
  // what the step then does to it.
  const SceneDesc desc = parse_scene(R"({
    "version": 1, "name": "predict", "dimension": 3,
    "Configuration": { "precision": "double", "stopAt": 0.3, "particleRadius": 0.01, "kernelRadius": 0.04,
      "gravitation": [0, -9.81, 0], "boundaryHandling": "particles", "kernel": "cubic",
      "simulationMethod": "dfsph", "cflMaxTimeStepSize": 0.005, "outputFps": 0 },
    "Fluid": { "density0": 1000, "viscosity": 1.0 },
    "Container": { "start": [0, 0, 0], "end": [1.0, 0.4, 0.4] },
    "FluidBlocks": [ { "start": [0.8, 0, 0.3], "end": [1.0, 0.06, 0.4] } ],
    "Obstacles": [ { "start": [0.05, 0.002, 0.1], "end": [0.25, 0.08, 0.25], "dynamic": true, "density": 700,
                     "angularVelocity": [0.5, 0.3, 2.0] } ]
  })",
                                     "predict.json");
  RunDriver<3, double> run(desc, RunSettings{});
  const Simulation<3, double>& sim = run.simulation();
  int contacts = 0;
  double turned = 0;
  while (sim.time() < desc.end_time * (1 - 1e-12)) {
    const RigidBodyState<3> before = sim.bodies().at(0);
    const double start = sim.time();
    run.step();
    const double dt = sim.time() - start;
    const auto& predicted = sim.body_responses()[0];
    const RigidBodyState<3>& after = sim.bodies()[0];
    for (int d = 0; d < 3; ++d) {
      EXPECT_NEAR(after.velocity[d] - before.velocity[d], predicted.velocity_change[d], 1e-12) << sim.steps_done();
      EXPECT_NEAR(after.angular_velocity[d] - before.angular_velocity[d], predicted.angular_velocity_change[d], 1e-12)
          << sim.steps_done();
    }
    contacts += std::abs(predicted.velocity_change[1] + 9.81 * dt) > 1e-9;  // (the floor pushed)
    turned = std::max(turned, std::sqrt(norm2(predicted.angular_velocity_change)));
  }
  EXPECT_GE(contacts, 5);
  EXPECT_GT(turned, 1e-4);  // (rad/s: the gyroscopic term, or the floor's moment, turned it)
}

/// Without gravity, a block of fluid thrown at a free box: `method` "dfsph" (boundary particles)
/// or "wcsph" (penalty walls).
SceneDesc collision(const std::string& method) {
  const bool dfsph = method == "dfsph";
  const std::string text = fmt::format(R"({{
    "version": 1, "name": "collision", "dimension": 2,
    "Configuration": {{ "precision": "double", "timeStepSize": {}, "stopAt": 0.35, "particleRadius": 0.01,
      "kernelRadius": 0.04, "gravitation": [0, 0], "outputFps": 0{} }},
    "Fluid": {{ "density0": 1000, "stiffness": 2000, "viscosity": 1.0 }},
    "Container": {{ "start": [0, 0], "end": [2, 2] }},
    "FluidBlocks": [ {{ "start": [0.4, 0.8], "end": [0.7, 1.1], "velocity": [2, 0.3] }} ],
    "Obstacles": [ {{ "start": [1.0, 0.9], "end": [1.1, 1.2], "dynamic": true, "density": 700,
                     "angularVelocity": 0.5 }} ]
  }})",
                                       dfsph ? 0.002 : 0.0002,
                                       dfsph ? R"(, "boundaryHandling": "particles", "kernel": "cubic",
      "simulationMethod": "dfsph")"
                                             : R"(, "cflMethod": "none")");
  return parse_scene(text, "collision.json");
}

TEST(FloatingBody, FluidAndBodyExchangeMomentumExactly) {
  for (const std::string method : {"dfsph", "wcsph"}) {
    SCOPED_TRACE(method);
    const SceneDesc desc = collision(method);
    RunDriver<2, double> run(desc, RunSettings{});
    const Simulation<2, double>& sim = run.simulation();
    const auto total = [&] {
      const double m = sim.body_masses()[0].mass;
      return sim.momentum() + sim.bodies()[0].velocity * m;
    };
    const Vec<2, double> p0 = total();
    while (!finished(desc, sim)) run.step();
    const Vec<2, double> p1 = total();
    // The fluid hit the box: it moves along +x, and took most of the fluid's momentum away.
    const double body_px = sim.bodies()[0].velocity[0] * sim.body_masses()[0].mass;
    EXPECT_GT(body_px, 0.05 * p0[0]);
    for (int d = 0; d < 2; ++d) EXPECT_NEAR(p1[d], p0[d], 1e-9 * std::abs(p0[0])) << "axis " << d;
    // Nowhere near a wall: only the fluid touched the box.
    for (const auto& x : sim.particles().position) EXPECT_GT(std::min({x[0], x[1], 2 - x[0], 2 - x[1]}), 0.1);
  }
}

TEST(FloatingBody, In3DFluidAndATurningBodyExchangeMomentumExactly) {
  // A block thrown off-centre at a box that spins about a tilted axis, without gravity.
  const SceneDesc desc = parse_scene(R"({
    "version": 1, "name": "collision_3d", "dimension": 3,
    "Configuration": { "precision": "double", "timeStepSize": 0.004, "stopAt": 0.3, "particleRadius": 0.02,
      "kernelRadius": 0.08, "gravitation": [0, 0, 0], "outputFps": 0, "boundaryHandling": "particles",
      "kernel": "cubic", "simulationMethod": "dfsph" },
    "Fluid": { "density0": 1000, "viscosity": 1.0 },
    "Container": { "start": [0, 0, 0], "end": [2, 2, 2] },
    "FluidBlocks": [ { "start": [0.4, 0.8, 0.8], "end": [0.64, 1.04, 1.04], "velocity": [2, 0, 0] } ],
    "Obstacles": [ { "start": [0.9, 0.85, 0.7], "end": [1.1, 1.25, 1.1], "dynamic": true, "density": 600,
                     "angularVelocity": [0.5, 1, -0.5] } ]
  })",
                                     "collision_3d.json");
  RunDriver<3, double> run(desc, RunSettings{});
  const Simulation<3, double>& sim = run.simulation();
  const auto total = [&] { return sim.momentum() + sim.bodies()[0].velocity * sim.body_masses()[0].mass; };
  const Vec<3, double> p0 = total();
  while (sim.time() < desc.end_time * (1 - 1e-12)) run.step();
  const Vec<3, double> p1 = total();
  EXPECT_GT(sim.bodies()[0].velocity[0] * sim.body_masses()[0].mass, 0.05 * p0[0]);
  for (int d = 0; d < 3; ++d) EXPECT_NEAR(p1[d], p0[d], 1e-9 * std::abs(p0[0])) << "axis " << d;
  const auto& q = sim.bodies()[0].orientation;
  EXPECT_NEAR(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3], 1.0, 1e-14);
}

/// A 2D tank 1.2 m x 0.8 m with gravity, DFSPH and boundary particles, its fluid a small block
/// out of the way in a corner, and `obstacles` (the Obstacles array's entries).
SceneDesc dry_tank(const std::string& name, const std::string& obstacles) {
  return parse_scene(fmt::format(R"({{
    "version": 1, "name": "{}", "dimension": 2,
    "Configuration": {{ "precision": "double", "timeStepSize": 0.004, "stopAt": 1.0, "particleRadius": 0.01,
      "kernelRadius": 0.04, "gravitation": [0, -9.81], "boundaryHandling": "particles", "kernel": "cubic",
      "simulationMethod": "dfsph", "outputFps": 0 }},
    "Container": {{ "start": [0, 0], "end": [1.2, 0.8] }},
    "FluidBlocks": [ {{ "start": [0, 0], "end": [0.1, 0.1] }} ],
    "Obstacles": [ {} ]
  }})",
                                 name, obstacles),
                     name + ".json");
}

TEST(FloatingBody, ABodyDroppedOnTheFloorRestsOnIt) {
  // The fluid is far off, in a corner; the box falls 0.1 m onto the container's floor.
  const SceneDesc desc =
      dry_tank("drop", R"({ "start": [0.6, 0.1], "end": [0.9, 0.2], "dynamic": true, "density": 500 })");
  RunDriver<2, double> run(desc, RunSettings{});
  const Simulation<2, double>& sim = run.simulation();
  double lowest = 1;
  while (!finished(desc, sim)) {
    run.step();
    lowest = std::min(lowest, sim.bodies()[0].position[1] - 0.05);
  }
  const RigidBodyState<2>& b = sim.bodies()[0];
  // At rest on the floor: its bottom within a quarter spacing of it, and never far below it.
  EXPECT_NEAR(b.position[1] - 0.05, 0.0, 0.005);
  EXPECT_GT(lowest, -0.01);
  EXPECT_LT(std::sqrt(norm2(b.velocity)), 0.01);
  EXPECT_NEAR(b.position[0], 0.75, 1e-6);  // (it fell straight)
  // The energy watch is on (a floating body's energy counts with the fluid's): the body's fall
  // turns its potential energy into kinetic and the contact's damping takes it, so the total never
  // rises above its start, and ends at least the body's weight times its fall lower (the small
  // block of fluid in the corner spreads out too).
  EXPECT_TRUE(health_scene(sim.params()).closed);
  const double e0 = sim.health().initial_energy(), fall = 0.1 * sim.body_masses()[0].mass * 9.81;
  EXPECT_LE(sim.health().max_energy(), e0 + 1e-3 * fall);
  EXPECT_LT(sim.last_step().health.energy, e0 - 0.95 * fall);
}

/// The deepest any corner of one obstacle is inside another (m; negative: none is).
double deepest_corner(const Simulation<2, double>& sim) {
  const SimulationParams<2>& p = sim.params();
  const std::vector<RigidPose<2>> poses = sim.obstacle_poses();
  double deepest = -1e300;
  for (std::size_t a = 0; a < p.obstacles.size(); ++a)
    for (std::size_t b = 0; b < p.obstacles.size(); ++b)
      for (int c = 0; a != b && c < 4; ++c) {
        const Vec<2, double> X =
            poses[b].to_rest(poses[a].place(box_corner<2>(p.obstacles[a].lo, p.obstacles[a].hi, c)));
        double depth = 1e300;
        for (int d = 0; d < 2; ++d) depth = std::min({depth, X[d] - p.obstacles[b].lo[d], p.obstacles[b].hi[d] - X[d]});
        deepest = std::max(deepest, depth);
      }
  return deepest;
}

TEST(FloatingBody, BodiesMeetEachOtherAndTheRestingObstacles) {
  // Without gravity, two boxes meet head on (1 m/s apart, off-centre), far from the fluid: they
  // bounce apart, no corner gets a spacing deep into the other, and their momentum is kept. Then,
  // with gravity, a box dropped onto a resting obstacle stays on top of it.
  const SceneDesc meet = parse_scene(R"({
    "version": 1, "name": "meet", "dimension": 2,
    "Configuration": { "precision": "double", "timeStepSize": 0.004, "stopAt": 1.0, "particleRadius": 0.01,
      "kernelRadius": 0.04, "gravitation": [0, 0], "boundaryHandling": "particles", "kernel": "cubic",
      "simulationMethod": "dfsph", "outputFps": 0 },
    "Fluid": { "density0": 1000, "stiffness": 1000, "viscosity": 1.0 },
    "Container": { "start": [0, 0], "end": [2, 1] },
    "FluidBlocks": [ { "start": [0, 0], "end": [0.1, 0.1] } ],
    "Obstacles": [ { "start": [0.6, 0.5], "end": [0.8, 0.6], "dynamic": true, "density": 500, "velocity": [0.5, 0] },
                   { "start": [1.2, 0.53], "end": [1.4, 0.63], "dynamic": true, "density": 800, "velocity": [-0.5, 0] } ]
  })",
                                     "meet.json");
  {
    RunDriver<2, double> run(meet, RunSettings{});
    const Simulation<2, double>& sim = run.simulation();
    const auto momentum = [&] {
      return sim.bodies()[0].velocity * sim.body_masses()[0].mass +
             sim.bodies()[1].velocity * sim.body_masses()[1].mass;
    };
    const Vec<2, double> p0 = momentum();
    double deepest = -1;
    while (!finished(meet, sim)) {
      run.step();
      deepest = std::max(deepest, deepest_corner(sim));
    }
    std::printf("deepest corner %.4f m, closing 1 m/s, parting %.4f m/s\n", deepest,
                sim.bodies()[1].velocity[0] - sim.bodies()[0].velocity[0]);
    EXPECT_GT(deepest, 0);     // they did meet
    EXPECT_LT(deepest, 0.02);  // by less than a spacing
    // and parted again (the contact's damping takes most of the closing speed: restitution ~0.16)
    EXPECT_GT(sim.bodies()[1].velocity[0] - sim.bodies()[0].velocity[0], 0.05);
    const Vec<2, double> p1 = momentum();
    for (int d = 0; d < 2; ++d) EXPECT_NEAR(p1[d], p0[d], 1e-12) << d;
  }
  const SceneDesc stack = dry_tank("stack", R"({ "start": [0.5, 0], "end": [1.0, 0.2] },
      { "start": [0.6, 0.3], "end": [0.9, 0.4], "dynamic": true, "density": 500 })");
  RunDriver<2, double> run(stack, RunSettings{});
  const Simulation<2, double>& sim = run.simulation();
  while (!finished(stack, sim)) run.step();
  const RigidBodyState<2>& b = sim.bodies()[0];
  EXPECT_NEAR(b.position[1] - 0.05, 0.2, 0.005);  // its bottom on the obstacle's top
  EXPECT_LT(std::sqrt(norm2(b.velocity)), 0.01);
}

using test::ThreadCount;

TEST(FloatingBody, TheThreadCountChangesNothingAndAStoppedRunResumesBitForBit) {
  ThreadCount restore;
  TempDir tmp;
  const SceneDesc desc = tank_with_box(500, 0.36, 0.42, 0.5);
  set_num_threads(1);
  {
    RunDriver<2, double> one(desc, RunSettings{tmp / "one_thread"});
    ASSERT_EQ(one.run().status, RunStatus::Completed);
  }
  // Two threads, whole and stopped and resumed: all three write the same files.
  set_num_threads(2);
  const std::vector<std::string> names =
      test::expect_resume_gives_the_same_files<2>(desc, tmp.path(), 37, {"bodies.csv"});
  EXPECT_EQ(names.size(), 12u);  // frames at 0, 0.1, ..., 0.5 s, each with the solids
  for (const auto& n : names)
    EXPECT_TRUE(slurp(tmp / "one_thread" / "frames" / n) == slurp(tmp / "full" / "frames" / n)) << n << " differs";
  // bodies.csv: a row per frame.
  const std::string csv = slurp(tmp / "one_thread" / "bodies.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1 + 6);
  EXPECT_TRUE(csv == slurp(tmp / "full" / "bodies.csv"));
}

}  // namespace
}  // namespace sph
