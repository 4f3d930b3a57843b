// Runs of CFL steps (Configuration.cflMethod "cfl"): each step takes the limits of the state it
// starts from, steps end exactly on frame times and the end time, emitter batches falling inside
// a step come with the next one where their layers have flown, a stopped run resumes bit for
// bit, and the thread count changes nothing.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <sph/core/parallel.h>
#include <sph/run/driver.h>
#include <sph/run/resume.h>
#include <sph/scene/scene_reader.h>
#include <sph/solver/nozzle.h>

#include "support/resume.h"
#include "support/temp_dir.h"
#include "support/thread_count.h"

namespace sph {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

/// The paper's 2D dam break to `stop` seconds in CFL steps, `fps` frames per second.
SceneDesc dam_break_cfl(double stop, double fps, const std::string& mode = "standard") {
  return read_scene_file(SPH_SOURCE_DIR "/scenes/paper/dam_break_2d.json",
                         {"Configuration.cflMethod=\"cfl\"", "Configuration.stopAt=" + std::to_string(stop),
                          "Configuration.outputEveryNSteps=0", "Configuration.outputFps=" + std::to_string(fps),
                          "Configuration.neighbors=\"" + mode + "\""});
}

using test::ThreadCount;

TEST(CflSteps, EachStepKeepsToTheLimitsOfTheStateItStartsFrom) {
  const SceneDesc desc = dam_break_cfl(0.15, 40);
  RunDriver<2, double> run(desc, RunSettings{});
  const SimulationParams<2>& p = run.simulation().params();
  const double d = 2 * p.particle_radius, c0 = std::sqrt(p.fluid.stiffness), h = p.kernel_radius;
  double last = 0.5 * p.time_step, smallest = 1e9, largest = 0;
  int steps = 0;
  while (run.simulation().time() < 0.15 * (1 - 1e-12)) {
    // The fastest particle as the step's rule sees it: |v| + (last step) |a|.
    double u = 0;
    for (std::size_t i = 0; i < run.simulation().particles().size(); ++i)
      u = std::max(u, std::sqrt(norm2(run.simulation().particles().velocity[i])) +
                          last * std::sqrt(norm2(run.simulation().particles().acceleration[i])));
    const double expected = run.simulation().next_time_step();
    const StepInfo& info = run.step();
    ASSERT_LE(info.dt, p.cfl.factor * 0.4 * d / u * (1 + 1e-12)) << "advective limit, step " << info.step;
    ASSERT_LE(info.dt, 0.8 * 0.4 * h / (c0 + u) * (1 + 1e-12)) << "acoustic limit, step " << info.step;
    ASSERT_LE(info.dt, 2 * last * (1 + 1e-12)) << "growth limit, step " << info.step;
    ASSERT_LE(info.dt, expected) << "a barrier only shortens a step";
    last = expected;
    smallest = std::min(smallest, info.dt), largest = std::max(largest, info.dt);
    ++steps;
  }
  EXPECT_EQ(run.simulation().time(), 0.15) << "the last step ends on the end time exactly";
  // The column's collapse speeds the fluid up: the steps shrink as it does.
  EXPECT_LT(smallest, 0.9 * largest);
  EXPECT_GT(steps, 100);
}

TEST(CflSteps, FramesComeExactlyOnTheirTimes) {
  TempDir tmp;
  const double fps = 200;
  const SceneDesc desc = dam_break_cfl(0.05, fps);
  EXPECT_EQ(desc.end_time, 0.05);
  RunDriver<2, double> run(desc, RunSettings{tmp / "run"});
  std::vector<double> times;
  const RunResult r = run.run({}, [&](Simulation<2, double>& sim, const StepInfo&) { times.push_back(sim.time()); });
  ASSERT_EQ(r.status, RunStatus::Completed) << r.message;
  EXPECT_EQ(times.back(), 0.05);
  // Every frame time k / fps is the end of some step, exactly.
  for (int k = 1; k <= 10; ++k)
    EXPECT_TRUE(std::find(times.begin(), times.end(), static_cast<double>(k) / fps) != times.end()) << "frame " << k;
  EXPECT_EQ(run.output()->frames_written(), 11u);
}

TEST(CflSteps, ARunEndsAtItsEndTimeWhateverStepsTheFramesShortened) {
  // Steps held at 1.4e-4 s and a frame every 4 ms: each frame's last steps are shortened to end
  // on it (29 steps a frame where 28.6 would do), more steps in all than stopAt / the smallest
  // step. Such a run once stopped at that count, short of its end time, and called itself done.
  TempDir tmp;
  SceneDesc desc = read_scene_file(
      SPH_SOURCE_DIR "/scenes/paper/dam_break_2d.json",
      {"Configuration.cflMethod=\"cfl\"", "Configuration.stopAt=0.04", "Configuration.cflMinTimeStepSize=1.4e-4",
       "Configuration.cflMaxTimeStepSize=1.4e-4", "Configuration.outputEveryNSteps=0", "Configuration.outputFps=250"});
  RunDriver<2, double> run(desc, RunSettings{tmp / "run"});
  const RunResult r = run.run({}, {});
  ASSERT_EQ(r.status, RunStatus::Completed) << r.message;
  EXPECT_EQ(run.simulation().time(), 0.04);
  EXPECT_GT(r.steps_done, static_cast<std::int64_t>(std::ceil(0.04 / 1.4e-4)));
  EXPECT_LE(r.steps_done, desc.steps) << "the estimate the progress bar shows is an upper bound";
  EXPECT_EQ(run.output()->frames_written(), 11u);
}

TEST(CflSteps, EmitterBatchesAreEmittedAtTheStepThatReachesThemWhereTheirLayersHaveFlown) {
  // The paper's tank: a 6 x 6 batch every emitEveryNSteps * timeStepSize = 16 * 3e-4 s.
  const double stop = 0.05, period = 16 * 3e-4;
  const SceneDesc desc = read_scene_file(
      SPH_SOURCE_DIR "/scenes/paper/tank_fill_3d.json",
      {"Configuration.cflMethod=\"cfl\"", "Configuration.stopAt=0.05", "Configuration.outputEveryNSteps=0"});
  RunDriver<3, double> run(desc, RunSettings{});
  std::vector<double> starts;
  std::size_t emitted = 0, shortened = 0;
  double last_dt = 0;
  while (run.simulation().time() < stop * (1 - 1e-12)) {
    const double t = run.simulation().time();
    const StepInfo& info = run.step();
    // Batch k (time k p) comes with the first step starting at or after it.
    const auto due = static_cast<std::size_t>(std::floor(t / period + 1e-9)) + 1;
    emitted += info.emitted;
    EXPECT_EQ(emitted, 36 * due) << "the step starting at " << t;
    // Steps do not shorten for batches: only the end time (and the rule's own limits) cut one.
    if (last_dt > 0 && info.dt < 0.5 * last_dt && run.simulation().time() < stop * (1 - 1e-12)) ++shortened;
    last_dt = info.dt;
    starts.push_back(t);
  }
  EXPECT_EQ(shortened, 0u);
  // Before this rule a step ended on every batch time: now most batch times fall inside steps.
  std::size_t inside = 0;
  for (double k = 1; k * period < stop; ++k)
    inside += std::find_if(starts.begin(), starts.end(), [&](double t) { return std::abs(t - k * period) < 1e-12; }) ==
              starts.end();
  EXPECT_GT(inside, 5u);
}

TEST(CflSteps, AStepLongerThanTheEmitterPeriodEmitsEveryBatchWhereItsLayerHasFlown) {
  // No gravity and layers farther apart than a spacing (density below rest, pressure clamped at
  // zero, equal velocities): nothing acts on the emitted particles, which fly at the nozzle's
  // speed. Steps of 2.5 emitter periods: each emits two or three batches.
  const double period = 16 * 3e-4, dt = 2.5 * period;
  const SceneDesc desc = read_scene_file(SPH_SOURCE_DIR "/scenes/paper/tank_fill_3d.json",
                                         {"Configuration.cflMethod=\"cfl\"", "Configuration.gravitation=[0,0,0]",
                                          "Configuration.cflMinTimeStepSize=" + std::to_string(dt),
                                          "Configuration.cflMaxTimeStepSize=" + std::to_string(dt),
                                          "Configuration.stopAt=0.048", "Configuration.outputEveryNSteps=0"});
  RunDriver<3, double> run(desc, RunSettings{});
  const EmitterParams<3>& e = run.simulation().params().emitters.at(0);
  const auto [u, w] = nozzle_axes<3>(e.direction);
  for (int step = 1; step <= 4; ++step) {
    run.step();
    const double t = run.simulation().time();
    EXPECT_NEAR(t, step * dt, 1e-15) << "no step shortened";
    const ParticleSet<3, double>& ps = run.simulation().particles();
    // Batches 0 .. floor((t - dt) / p): those due by the step's start.
    const auto batches = static_cast<std::size_t>(std::floor((t - dt) / period + 1e-9)) + 1;
    ASSERT_EQ(ps.size(), 36 * batches) << "step " << step;
    double worst = 0;
    for (std::size_t i = 0; i < ps.size(); ++i) {
      const std::uint64_t m = ps.id[i];  // (the m-th particle emitted: 36 a layer, a across, b up)
      const auto k = static_cast<double>(m / 36);
      const Vec<3, double> nozzle = nozzle_position<3>(e, u, w, static_cast<int>(m % 6), static_cast<int>(m / 6 % 6));
      worst = std::max(worst, norm(ps.position[i] - (nozzle + e.direction * (e.speed * (t - k * period)))));
      EXPECT_EQ(ps.velocity[i], e.direction * e.speed) << "particle " << m;
    }
    EXPECT_LT(worst, 1e-12) << "step " << step;
  }
}

TEST(CflSteps, AStoppedRunResumesBitForBit) {
  TempDir tmp;
  const SceneDesc desc = dam_break_cfl(0.04, 250, "adaptive");
  const std::vector<std::string> names = test::expect_resume_gives_the_same_files<2>(
      desc, tmp.path(), 37, {"frames.pvd"}, [](const RunResult& stopped, const RunToResume& r) {
        EXPECT_NE(stopped.message.find("(t = "), std::string::npos) << stopped.message;
        EXPECT_EQ(r.desc.end_time, 0.04);
      });
  EXPECT_EQ(names.size(), 11u);
}

TEST(CflSteps, TheThreadCountChangesNothing) {
  ThreadCount restore;
  const SceneDesc desc = dam_break_cfl(0.03, 0);
  std::vector<std::vector<Vec<2, double>>> positions;
  std::vector<double> times;
  for (int threads : {1, 2}) {
    set_num_threads(threads);
    RunDriver<2, double> run(desc, RunSettings{});
    while (run.simulation().time() < 0.03 * (1 - 1e-12)) run.step();
    positions.push_back(run.simulation().particles().position);
    times.push_back(static_cast<double>(run.simulation().steps_done()));
  }
  EXPECT_EQ(times[0], times[1]);
  EXPECT_TRUE(positions[0] == positions[1]);
}

}  // namespace
}  // namespace sph
