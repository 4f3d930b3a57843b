// RunDriver and open_run_to_resume in this process: a run stopped by its stop callback and
// resumed gives exactly the files of a run never stopped; a stop request writes a checkpoint;
// the statuses; resuming a finished run is refused; step() (the Python module's loop) gives the
// steps of run(), and particles_moved() makes the next step rebuild every list.

#include <algorithm>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sph/core/error.h>
#include <sph/run/driver.h>
#include <sph/run/memory.h>
#include <sph/run/resume.h>
#include <sph/scene/scene_reader.h>

#include "support/temp_dir.h"

namespace sph {
namespace {

namespace fs = std::filesystem;
using test::entries;
using test::slurp;
using test::TempDir;

constexpr std::int64_t kSteps = 60;

/// The 2D dam break, `kSteps` steps, a frame every 7 steps, in `mode`.
SceneDesc dam_break(const std::string& mode, std::int64_t steps = kSteps) {
  return read_scene_file(SPH_SOURCE_DIR "/scenes/paper/dam_break_2d.json",
                         {"Configuration.numberOfSteps=" + std::to_string(steps), "Configuration.outputEveryNSteps=7",
                          "Configuration.neighbors=\"" + mode + "\""});
}

/// A stop callback that asks to stop once `at` steps are done.
RunCallbacks stop_at(std::int64_t at) {
  RunCallbacks c;
  c.stop_requested = [at](std::int64_t done) { return done == at ? std::string("a test") : std::string(); };
  return c;
}

/// stats.csv without the timing columns (t_grid and after), which differ between any two runs.
std::vector<std::string> stats_rows(const fs::path& file) {
  std::vector<std::string> out;
  const std::string csv = slurp(file);
  std::size_t b = 0;
  for (std::size_t e; (e = csv.find('\n', b)) != std::string::npos; b = e + 1) {
    const std::string line = csv.substr(b, e - b);
    std::size_t comma = 0;
    for (int k = 0; k < 12 && comma != std::string::npos; ++k) comma = line.find(',', comma + 1);
    out.push_back(line.substr(0, comma));
  }
  return out;
}

/// summary.json without what depends on the clock or on how the run was cut (timings, the
/// resume history, the checkpoint step).
nlohmann::json summary_facts(const fs::path& dir) {
  nlohmann::json s = nlohmann::json::parse(slurp(dir / "summary.json"));
  // (run_id: each run has its own; the resumed run keeps the id of the run it continues)
  for (const char* k : {"wall_seconds", "phase_seconds", "resumed_at_steps", "last_checkpoint_step", "run_id"})
    s.erase(k);
  return s;
}

/// Every file under frames/ and frames.pvd are the same bytes in both directories.
void expect_same_frames(const fs::path& a, const fs::path& b) {
  const std::vector<std::string> names = entries(a / "frames");
  ASSERT_EQ(names, entries(b / "frames"));
  ASSERT_GE(names.size(), 5u);
  for (const auto& n : names) EXPECT_TRUE(slurp(a / "frames" / n) == slurp(b / "frames" / n)) << n << " differs";
  EXPECT_EQ(slurp(a / "frames.pvd"), slurp(b / "frames.pvd"));
}

RunResult run_new(const SceneDesc& desc, const fs::path& dir, const RunCallbacks& callbacks = {},
                  std::int64_t checkpoint_every = 0) {
  RunDriver<2, double> run(desc, RunSettings{dir, checkpoint_every});
  return run.run(callbacks);
}

RunResult resume(const fs::path& dir, std::int64_t steps = 0) {
  RunToResume r = open_run_to_resume(dir, steps);
  RunDriver<2, double> run(r.desc, *r.checkpoint, RunSettings{dir, r.checkpoint_every});
  EXPECT_EQ(run.first_step(), r.checkpoint->header().step);
  EXPECT_EQ(run.resume_warning(), "");
  return run.run();
}

class StopAndResume : public testing::TestWithParam<const char*> {};

TEST_P(StopAndResume, GivesTheFilesOfARunNeverStopped) {
  TempDir tmp;
  const SceneDesc desc = dam_break(GetParam());
  const RunResult full = run_new(desc, tmp / "full");
  ASSERT_EQ(full.status, RunStatus::Completed) << full.message;
  EXPECT_EQ(full.message, "completed");
  EXPECT_EQ(full.steps_done, kSteps);

  for (const std::int64_t k : {std::int64_t{1}, std::int64_t{23}, std::int64_t{28}, kSteps - 1}) {
    SCOPED_TRACE("stopped after step " + std::to_string(k));
    const fs::path part = tmp / ("part" + std::to_string(k));
    const RunResult stopped = run_new(desc, part, stop_at(k));
    ASSERT_EQ(stopped.status, RunStatus::Interrupted);
    EXPECT_EQ(stopped.steps_done, k);
    EXPECT_EQ(stopped.stop_cause, "a test");
    EXPECT_EQ(stopped.message, "interrupted by a test after step " + std::to_string(k) + " of 60");
    EXPECT_EQ(nlohmann::json::parse(slurp(part / "summary.json")).at("status"), stopped.message);
    ASSERT_TRUE(fs::is_regular_file(part / kCheckpointFile)) << "a stop request writes a checkpoint";

    const RunResult resumed = resume(part);
    ASSERT_EQ(resumed.status, RunStatus::Completed) << resumed.message;
    EXPECT_EQ(resumed.first_step, k);
    EXPECT_EQ(resumed.steps_done, kSteps);
    expect_same_frames(tmp / "full", part);
    EXPECT_EQ(stats_rows(tmp / "full" / "stats.csv"), stats_rows(part / "stats.csv"));
    EXPECT_EQ(summary_facts(tmp / "full"), summary_facts(part));
    EXPECT_EQ(nlohmann::json::parse(slurp(part / "summary.json")).at("resumed_at_steps"), nlohmann::json::array({k}));
  }
}

INSTANTIATE_TEST_SUITE_P(Modes, StopAndResume,
                         testing::Values("standard", "adaptive", "tracked", "adaptive_exact", "verlet_clusters"));

TEST(RunDriver, StopsTwiceAndResumesTwiceBitwise) {
  TempDir tmp;
  const SceneDesc desc = dam_break("adaptive");
  ASSERT_EQ(run_new(desc, tmp / "full").status, RunStatus::Completed);
  ASSERT_EQ(run_new(desc, tmp / "part", stop_at(10)).status, RunStatus::Interrupted);
  {
    RunToResume r = open_run_to_resume(tmp / "part");
    RunDriver<2, double> run(r.desc, *r.checkpoint, RunSettings{tmp / "part", 0});
    const RunResult second = run.run(stop_at(41));
    EXPECT_EQ(second.status, RunStatus::Interrupted);
    EXPECT_EQ(second.first_step, 10);
    EXPECT_EQ(second.steps_done, 41);
  }
  ASSERT_EQ(resume(tmp / "part").status, RunStatus::Completed);
  expect_same_frames(tmp / "full", tmp / "part");
  EXPECT_EQ(stats_rows(tmp / "full" / "stats.csv"), stats_rows(tmp / "part" / "stats.csv"));
  EXPECT_EQ(nlohmann::json::parse(slurp(tmp / "part" / "summary.json")).at("resumed_at_steps"),
            nlohmann::json::array({10, 41}));
}

// A run keeps each particle's initial position only where something reads it: frames that hold
// it, or every_field (Python). Without them the run's results are the same, and it stops and
// resumes bitwise (its checkpoint has no such field).
TEST(RunDriver, KeepsTheInitialPositionsOnlyWhereSomethingReadsThem) {
  TempDir tmp;
  const auto keeps = [](const SceneDesc& desc, const RunSettings& settings) {
    return RunDriver<2, double>(desc, settings).simulation().particles().keeps_initial_positions();
  };
  const SceneDesc framed = dam_break("standard", 20);  // (its frames hold every field)
  EXPECT_TRUE(keeps(framed, RunSettings{tmp / "framed", 0}));
  EXPECT_FALSE(keeps(framed, RunSettings{})) << "no directory: no frames";
  RunSettings every;
  every.every_field = true;
  EXPECT_TRUE(keeps(framed, every));
  const SceneDesc unframed = read_scene_file(SPH_SOURCE_DIR "/scenes/paper/dam_break_2d.json",
                                             {"Configuration.numberOfSteps=20", "Configuration.outputEveryNSteps=0"});
  EXPECT_FALSE(keeps(unframed, RunSettings{tmp / "unframed", 0}));

  const SceneDesc without =
      read_scene_file(SPH_SOURCE_DIR "/scenes/paper/dam_break_2d.json",
                      {"Configuration.numberOfSteps=" + std::to_string(kSteps), "Configuration.outputEveryNSteps=7",
                       "Configuration.outputFields=[\"velocity\", \"id\"]"});
  EXPECT_FALSE(keeps(without, RunSettings{tmp / "probe", 0}));
  ASSERT_EQ(run_new(without, tmp / "full").status, RunStatus::Completed);
  {
    RunSettings kept{tmp / "kept", 0};
    kept.every_field = true;
    RunDriver<2, double> run(without, kept);
    ASSERT_TRUE(run.simulation().particles().keeps_initial_positions());
    ASSERT_EQ(run.run().status, RunStatus::Completed);
  }
  expect_same_frames(tmp / "full", tmp / "kept");
  EXPECT_EQ(stats_rows(tmp / "full" / "stats.csv"), stats_rows(tmp / "kept" / "stats.csv"));
  ASSERT_EQ(run_new(without, tmp / "part", stop_at(23)).status, RunStatus::Interrupted);
  ASSERT_EQ(resume(tmp / "part").status, RunStatus::Completed);
  expect_same_frames(tmp / "full", tmp / "part");
  EXPECT_EQ(stats_rows(tmp / "full" / "stats.csv"), stats_rows(tmp / "part" / "stats.csv"));
}

TEST(RunDriver, ARequestDuringTheLastStepLetsTheRunComplete) {
  TempDir tmp;
  int polls = 0;
  RunCallbacks c;
  c.stop_requested = [&](std::int64_t) {
    ++polls;
    return std::string("always");
  };
  RunDriver<2, double> run(dam_break("standard", 1), RunSettings{tmp / "o", 0});
  const RunResult r = run.run(c);
  EXPECT_EQ(r.status, RunStatus::Completed);
  EXPECT_EQ(polls, 0) << "the last step is never interrupted, so the callback is not asked";
  EXPECT_FALSE(fs::exists(tmp / "o" / kCheckpointFile)) << "no cadence, no stop: no checkpoint";
}

TEST(RunDriver, CheckpointsOnItsCadenceAndAtTheLastStep) {
  TempDir tmp;
  std::vector<std::int64_t> progress;
  RunCallbacks c;
  c.progress = [&](std::int64_t done, std::size_t particles) {
    progress.push_back(done);
    EXPECT_GT(particles, 0u);
  };
  const RunResult r = run_new(dam_break("standard", 25), tmp / "o", c, 10);
  ASSERT_EQ(r.status, RunStatus::Completed);
  ASSERT_EQ(progress.size(), 25u);
  EXPECT_EQ(progress.front(), 1);
  EXPECT_EQ(progress.back(), 25);
  const auto s = nlohmann::json::parse(slurp(tmp / "o" / "summary.json"));
  EXPECT_EQ(s.at("last_checkpoint_step"), 25);
  CheckpointReader ck(tmp / "o" / kCheckpointFile);
  EXPECT_EQ(ck.header().step, 25);
  EXPECT_EQ(ck.header().checkpoint_every, 10);
}

TEST(RunDriver, ARunWithoutADirectoryWritesNothingAndStillStops) {
  TempDir tmp;
  const fs::path cwd = fs::current_path();
  fs::current_path(tmp.path());
  int observed = 0;
  RunDriver<2, float> run(dam_break("verlet", 30), RunSettings{});
  EXPECT_EQ(run.output(), nullptr);
  run.advance(5);
  EXPECT_EQ(run.simulation().steps_done(), 5);
  const RunResult r = run.run(stop_at(12), [&](Simulation<2, float>& sim, const StepInfo& info) {
    ++observed;
    EXPECT_EQ(info.step + 1, sim.steps_done());
  });
  fs::current_path(cwd);
  EXPECT_EQ(r.status, RunStatus::Interrupted);
  EXPECT_EQ(r.steps_done, 12);
  EXPECT_EQ(observed, 7) << "steps 6 to 12";
  EXPECT_TRUE(entries(tmp.path()).empty());
}

TEST(RunDriver, StepGivesTheStepsOfRunAndGoesOnPastTheScenesLast) {
  TempDir tmp;
  RunDriver<2, double> ran(dam_break("adaptive", 30), RunSettings{tmp / "o", 0});
  ran.run();
  RunDriver<2, double> stepped(dam_break("adaptive", 30), RunSettings{});
  for (int k = 0; k < 30; ++k) EXPECT_EQ(stepped.step().step, k);
  EXPECT_EQ(stepped.simulation().particles().position, ran.simulation().particles().position);
  EXPECT_EQ(stepped.simulation().particles().velocity, ran.simulation().particles().velocity);
  EXPECT_EQ(stepped.step().step, 30) << "no limit at the scene's numberOfSteps";
  EXPECT_THROW(ran.step(), std::logic_error) << "a run with a directory steps through run() only";
}

TEST(RunDriver, ParticlesMovedRebuildsEveryListInTheNextStep) {
  RunDriver<2, double> run(dam_break("adaptive", 30), RunSettings{});
  for (int k = 0; k < 5; ++k) run.step();
  const std::size_t n = run.simulation().particles().size();
  EXPECT_LT(run.step().neighbors.lists_rebuilt, n) << "adaptive: only the flagged lists";
  for (auto& v : run.simulation().edit_particles().velocity) v[0] += 0.5;
  run.simulation().particles_moved();
  EXPECT_EQ(run.step().neighbors.lists_rebuilt, n);
  EXPECT_LT(run.step().neighbors.lists_rebuilt, n);
}

TEST(RunDriver, AFailedStepIsReturnedWithItsMessage) {
  TempDir tmp;
  // 30 km/s: far above the sound speed (40 m/s), so the health monitor fails the first step.
  SceneDesc desc = read_scene_file(
      SPH_SOURCE_DIR "/scenes/paper/dam_break_2d.json",
      {"Configuration.numberOfSteps=2000", "Configuration.outputEveryNSteps=0", "FluidBlocks[0].velocity=[30000,0]"});
  RunDriver<2, double> run(desc, RunSettings{tmp / "o", 0});
  const RunResult r = run.run();
  ASSERT_EQ(r.status, RunStatus::Failed) << r.message;
  EXPECT_FALSE(r.error.empty());
  EXPECT_EQ(r.message, "failed: " + r.error);
  EXPECT_NE(r.error.find("went supersonic at step 1"), std::string::npos) << r.error;
  EXPECT_EQ(r.steps_done, 1) << "the step that failed, step 0, is counted";
  EXPECT_EQ(nlohmann::json::parse(slurp(tmp / "o" / "summary.json")).at("status"), r.message);
}

TEST(RunDriver, StatusNames) {
  EXPECT_EQ(to_string(RunStatus::Completed), "completed");
  EXPECT_EQ(to_string(RunStatus::Interrupted), "interrupted");
  EXPECT_EQ(to_string(RunStatus::Failed), "failed");
}

TEST(OpenRunToResume, RefusesAFinishedRunAndLeavesItAlone) {
  TempDir tmp;
  ASSERT_EQ(run_new(dam_break("standard", 20), tmp / "done", {}, 10).status, RunStatus::Completed);
  const std::string before = slurp(tmp / "done" / "summary.json");
  try {
    open_run_to_resume(tmp / "done");
    FAIL() << "expected sph::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("already did all its 20 steps"), std::string::npos) << e.what();
    EXPECT_EQ(e.where(), (tmp / "done").string());
  }
  try {
    open_run_to_resume(tmp / "done", 20);
    FAIL() << "expected sph::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("--steps 20 is not beyond the checkpoint"), std::string::npos) << e.what();
  }
  EXPECT_EQ(slurp(tmp / "done" / "summary.json"), before);
  // A larger total continues it.
  const RunResult more = resume(tmp / "done", 30);
  EXPECT_EQ(more.status, RunStatus::Completed);
  EXPECT_EQ(more.first_step, 20);
  EXPECT_EQ(more.steps_done, 30);
}

TEST(OpenRunToResume, RefusesAMissingDirectoryOrCheckpoint) {
  TempDir tmp;
  EXPECT_THROW(open_run_to_resume(tmp / "nothing"), Error);
  ASSERT_EQ(run_new(dam_break("standard", 3), tmp / "no_checkpoint").status, RunStatus::Completed);
  EXPECT_THROW(open_run_to_resume(tmp / "no_checkpoint"), Error);
}

TEST(Memory, KnowsThisMachineAndRefusesAnImpossibleScene) {
  EXPECT_GT(physical_memory_bytes(), 0) << "Linux: /proc/meminfo has MemTotal";
  EXPECT_NO_THROW(check_fits_in_memory(dam_break("standard")));
  // 1.18e9 particles: about 360 GB, more than any test machine has.
  const SceneDesc huge = read_scene_file(
      SPH_SOURCE_DIR "/scenes/paper/block_3d.json",
      {"Configuration.particleRadius=0.00015", "Configuration.kernelRadius=0.0006", "Configuration.timeStepSize=1e-6"});
  try {
    check_fits_in_memory(huge);
    FAIL() << "expected sph::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("more than this machine's"), std::string::npos) << e.what();
    EXPECT_EQ(e.where(), huge.source);
  }
  const auto build = [&] { RunDriver<3, double> run(huge, RunSettings{}); };
  EXPECT_THROW(build(), Error) << "the driver asks before building anything";
}

}  // namespace
}  // namespace sph
