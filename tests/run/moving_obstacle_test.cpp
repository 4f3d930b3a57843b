// Moving obstacles (Obstacles[].motion): the wave flume's paddle makes waves of its own period,
// no fluid particle gets inside a moving solid (the signed distance, checked in every frame), a
// stirrer sets the fluid turning its way, and the runs are deterministic and resume bit for bit,
// with boundary particles and with penalty walls.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

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
using test::TempDir;

using test::ThreadCount;

/// Whether the time is on the scene's frame schedule (CFL steps land on it exactly).
bool on_frame(double t, double fps) { return std::abs(t * fps - std::round(t * fps)) < 1e-6; }

TEST(MovingObstacle, TheFlumesPaddleMakesWavesOfItsPeriodAndNoParticleGetsInside) {
  TempDir tmp;
  const SceneDesc desc = read_scene_file(SPH_SOURCE_DIR "/scenes/examples/wave_flume_2d.json");
  RunDriver<2, double> run(desc, RunSettings{tmp / "flume"});  // (its frames: steps land on their times)
  const Simulation<2, double>& sim = run.simulation();
  const SimulationParams<2>& p = sim.params();
  ASSERT_EQ(p.obstacles.size(), 1u);
  const double period = p.motions.at(0).period, fps = desc.output.fps, probe = 2.0;
  ASSERT_GT(fps, 0);
  std::vector<double> times, heights;
  double deepest = -1e300;
  RunCallbacks each_step;
  each_step.progress = [&](std::int64_t, std::size_t) {
    if (!on_frame(sim.time(), fps)) return;
    deepest = std::max(deepest, deepest_inside(sim));
    // The surface at the probe: the highest particle within 5 cm of it.
    double top = -1;
    for (const auto& x : sim.particles().position)
      if (std::abs(x[0] - probe) < 0.05) top = std::max(top, x[1]);
    times.push_back(sim.time());
    heights.push_back(top);
  };
  const RunResult result = run.run(each_step);
  // No health warning: no particle left the container or went into the paddle past the
  // monitor's tolerance, nothing blew up.
  ASSERT_EQ(result.status, RunStatus::Completed) << result.message;
  EXPECT_TRUE(result.warnings.empty()) << result.message;
  // (docs/physics.md, "Moving obstacles": no particle centre deeper than half a radius)
  EXPECT_LE(deepest, 0.5 * p.particle_radius);
  // The period at the probe: the mean spacing of the surface's up-crossings of its mean, once
  // the waves have arrived (after 3 s).
  std::vector<double> t, e;
  for (std::size_t k = 0; k < times.size(); ++k)
    if (times[k] >= 3.0) t.push_back(times[k]), e.push_back(heights[k]);
  ASSERT_GT(t.size(), 40u);
  double mean = 0;
  for (const double v : e) mean += v / static_cast<double>(e.size());
  std::vector<double> ups;
  for (std::size_t k = 0; k + 1 < e.size(); ++k)
    if (e[k] < mean && e[k + 1] >= mean) ups.push_back(t[k] + (t[k + 1] - t[k]) * (mean - e[k]) / (e[k + 1] - e[k]));
  ASSERT_GE(ups.size(), 4u);
  const double measured = (ups.back() - ups.front()) / static_cast<double>(ups.size() - 1);
  EXPECT_NEAR(measured, period, 0.05 * period) << "up-crossings " << ups.size();
  // The waves are waves, not noise: at least a spacing high.
  const auto [lo, hi] = std::minmax_element(e.begin(), e.end());
  EXPECT_GT(*hi - *lo, 2 * p.particle_radius);
}

/// A coarse stirred tank: a vertical plate turning about the tank's vertical axis in water at
/// rest, `method` "dfsph" (boundary particles) or "wcsph" (penalty walls).
SceneDesc stirred_tank(const std::string& method, double stop) {
  const bool dfsph = method == "dfsph";
  const std::string text = std::string(R"({
    "version": 1, "name": "stirred", "dimension": 3,
    "Configuration": { "precision": "double", "timeStepSize": )") +
                           (dfsph ? "0.004" : "0.0005") + R"(, "particleRadius": 0.02,
      "kernelRadius": 0.08, "gravitation": [0, -9.81, 0], "outputFps": 0, "stopAt": )" +
                           std::to_string(stop) +
                           (dfsph ? R"(, "boundaryHandling": "particles", "kernel": "cubic",
      "simulationMethod": "dfsph")"
                                  : R"(, "cflMethod": "none")") +
                           R"( },
    "Fluid": { "density0": 1000, "stiffness": 1000, "viscosity": 2.0 },
    "Container": { "start": [0, 0, 0], "end": [0.6, 0.5, 0.6] },
    "FluidBlocks": [
      { "start": [0, 0, 0], "end": [0.6, 0.08, 0.6] },
      { "start": [0, 0.08, 0], "end": [0.6, 0.28, 0.24] },
      { "start": [0, 0.08, 0.36], "end": [0.6, 0.28, 0.6] },
      { "start": [0, 0.08, 0.24], "end": [0.12, 0.28, 0.36] },
      { "start": [0.48, 0.08, 0.24], "end": [0.6, 0.28, 0.36] } ],
    "Obstacles": [ { "start": [0.14, 0.1, 0.26], "end": [0.46, 0.45, 0.34],
      "motion": { "type": "rotation", "axis": [0, 1, 0], "center": [0.3, 0.25, 0.3], "angularVelocity": 5.0,
                  "rampTime": 0.2 } } ]
  })";
  return parse_scene(text, "stirred.json");
}

/// The fluid's angular momentum about the stirrer's axis (y through its centre), kg m^2/s.
double spin_about_axis(const Simulation<3, double>& sim) {
  const auto& ps = sim.particles();
  double l = 0;
  for (std::size_t i = 0; i < ps.size(); ++i) {
    const double rx = ps.position[i][0] - 0.3, rz = ps.position[i][2] - 0.3;
    l += ps.mass * (rz * ps.velocity[i][0] - rx * ps.velocity[i][2]);  // (r x v) . y
  }
  return l;
}

TEST(MovingObstacle, AStirrerTurnsTheFluidItsWayWithEitherBoundary) {
  for (const std::string method : {"dfsph", "wcsph"}) {
    SCOPED_TRACE(method);
    const SceneDesc desc = stirred_tank(method, 0.4);
    RunDriver<3, double> run(desc, RunSettings{});
    const Simulation<3, double>& sim = run.simulation();
    double deepest = -1e300;
    while (desc.end_time > 0 ? sim.time() < desc.end_time * (1 - 1e-12) : sim.steps_done() < desc.steps) {
      run.step();
      if (sim.steps_done() % 20 == 0) deepest = std::max(deepest, deepest_inside(sim));
    }
    // A plate turning counter-clockwise about +y gives the fluid angular momentum along +y; the
    // fluid's mass times the plate tip's speed times its reach bounds it from above.
    const double l = spin_about_axis(sim);
    const double mass = static_cast<double>(sim.particles().mass) * static_cast<double>(sim.particles().size());
    EXPECT_GT(l, 0.01 * mass * 5.0 * 0.16 * 0.16);
    EXPECT_LT(l, mass * 5.0 * 0.16 * 0.16);
    EXPECT_LE(deepest, 0.5 * sim.params().particle_radius);
  }
}

TEST(MovingObstacle, TheThreadCountChangesNothing) {
  ThreadCount restore;
  for (const std::string method : {"dfsph", "wcsph"}) {
    SCOPED_TRACE(method);
    const SceneDesc desc = stirred_tank(method, 0.05);
    std::vector<std::vector<Vec<3, double>>> positions;
    for (int threads : {1, 2}) {
      set_num_threads(threads);
      RunDriver<3, double> run(desc, RunSettings{});
      for (int k = 0; k < 12; ++k) run.step();
      positions.push_back(run.simulation().particles().position);
    }
    EXPECT_TRUE(positions[0] == positions[1]);
  }
}

TEST(MovingObstacle, AStoppedRunResumesBitForBit) {
  TempDir tmp;
  // The flume, with verlet lists (which rebuild their boundary lists on their own schedule) and
  // a stop in the paddle's ramp.
  const SceneDesc desc =
      read_scene_file(SPH_SOURCE_DIR "/scenes/examples/wave_flume_2d.json",
                      {"Configuration.stopAt=0.3", "Configuration.outputFps=50", "Configuration.neighbors=\"verlet\""});
  const std::vector<std::string> names =
      test::expect_resume_gives_the_same_files<2>(desc, tmp.path(), 23, {"solids.pvd"});
  // 16 frames, each with the paddle's surface (solids_NNNNNN.vtp), identical byte for byte.
  ASSERT_EQ(names.size(), 32u);
  EXPECT_EQ(std::count_if(names.begin(), names.end(), [](const std::string& n) { return n.starts_with("solids_"); }),
            16);
}

TEST(MovingObstacle, EveryNeighborModeSeesTheSameBoundaryPairs) {
  // The boundary lists of a moving obstacle are rebuilt every step in every mode: the audit
  // finds no fluid-boundary pair missed.
  for (const char* mode : {"standard", "verlet", "adaptive", "tracked", "adaptive_exact"}) {
    SCOPED_TRACE(mode);
    SceneDesc desc = read_scene_file(
        SPH_SOURCE_DIR "/scenes/examples/wave_flume_2d.json",
        {"Configuration.stopAt=0.6", "Configuration.outputFps=0",
         std::string("Configuration.neighbors=\"") + mode + "\"", "Configuration.fullRebuildPeriod=50"});
    desc.body<2>().sim.audit = true;  // (sph run --audit)
    RunDriver<2, double> run(desc, RunSettings{});
    std::uint64_t missed = 0;
    while (run.simulation().time() < desc.end_time * (1 - 1e-12)) {
      const StepInfo& info = run.step();
      ASSERT_TRUE(info.audited);
      missed += info.boundary_audit.missed_pairs;
    }
    EXPECT_EQ(missed, 0u);
  }
}

}  // namespace
}  // namespace sph

namespace sph {
namespace {

TEST(MovingObstacle, AdaptiveRebuildsTheListsNearAMovingBodyEveryStep) {
  // The paper's Section 6: with flagNearMovingBodies (the default) the particles by the paddle
  // have their lists rebuilt every step; without it only Eq. 7's flags (and the period) do.
  std::vector<std::uint64_t> rebuilt;
  std::uint64_t near = 0;
  for (const char* flag : {"true", "false"}) {
    const SceneDesc desc =
        read_scene_file(SPH_SOURCE_DIR "/scenes/examples/wave_flume_2d.json",
                        {"Configuration.stopAt=1.5", "Configuration.outputFps=0",
                         "Configuration.neighbors=\"adaptive\"", "Configuration.fullRebuildPeriod=100000",
                         "Configuration.reorderPeriod=0", std::string("Configuration.flagNearMovingBodies=") + flag});
    RunDriver<2, double> run(desc, RunSettings{});
    std::uint64_t total = 0;
    // Steps 100 to 149 (the paddle is moving; the first step builds every list).
    for (int k = 0; k < 150; ++k) {
      const StepInfo& info = run.step();
      if (k < 100) continue;
      total += info.neighbors.lists_rebuilt;
      if (flag == std::string("true")) {
        // At least the particles within h of the paddle's face were rebuilt in this step (they
        // were flagged in the last one).
        const Simulation<2, double>& sim = run.simulation();
        const RigidPose<2> pose = pose_at(sim.params().motions[0], sim.time());
        std::uint64_t close = 0;
        for (const auto& x : sim.particles().position)
          close += pose.to_rest(x)[0] < sim.params().obstacles[0].hi[0] + 0.5 * sim.params().kernel_radius;
        near += close;
      }
    }
    rebuilt.push_back(total);
  }
  EXPECT_GT(near, 0u);
  EXPECT_GE(rebuilt[0], rebuilt[1] + near / 2);
}

}  // namespace
}  // namespace sph
