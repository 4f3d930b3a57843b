// Runs of CFL steps (Configuration.cflMethod "cfl"): each step takes the limits of the state it
// starts from, steps end exactly on frame times, emission times and the end time, a stopped run
// resumes bit for bit, and the thread count changes nothing.

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

TEST(CflSteps, EmitterBatchesComeOnTheirTimes) {
  // The paper's tank: a 6 x 6 batch every emitEveryNSteps * timeStepSize = 16 * 3e-4 s.
  const double stop = 0.05, period = 16 * 3e-4;
  const SceneDesc desc = read_scene_file(
      SPH_SOURCE_DIR "/scenes/paper/tank_fill_3d.json",
      {"Configuration.cflMethod=\"cfl\"", "Configuration.stopAt=0.05", "Configuration.outputEveryNSteps=0"});
  RunDriver<3, double> run(desc, RunSettings{});
  std::vector<double> emitted_at;
  while (run.simulation().time() < stop * (1 - 1e-12)) {
    const double t = run.simulation().time();
    if (run.step().emitted > 0) emitted_at.push_back(t);
  }
  // Batches at 0, p, 2p, ... before the end (a batch is emitted as the step starting on it begins).
  const auto batches = static_cast<std::size_t>(std::ceil(stop / period - 1e-9));
  ASSERT_EQ(emitted_at.size(), batches);
  for (std::size_t k = 0; k < batches; ++k)
    EXPECT_NEAR(emitted_at[k], static_cast<double>(k) * period, 1e-12) << "batch " << k;
  EXPECT_EQ(run.simulation().particles().size(), 36 * batches);
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
