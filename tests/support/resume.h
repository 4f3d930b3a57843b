#pragma once
// A run stopped and resumed gives the files of a run never stopped: the tests of each feature
// whose state a checkpoint must carry (CFL steps, DFSPH, moving obstacles, floating bodies).

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <sph/run/driver.h>
#include <sph/run/resume.h>

#include "support/temp_dir.h"

namespace sph::test {

/// Runs `desc` whole into dir/full, and into dir/part stopped after `stop_after` steps (by its stop
/// callback) and resumed from the checkpoint to its end. Expects both to complete and to hold the
/// same frame files (frames/), each byte for byte, and the same `files` of the run directory
/// (frames.pvd, bodies.csv, ...). `stopped`, if given, sees the interrupted run's result and what
/// open_run_to_resume found. Returns the frame file names (empty if a run failed).
template <int D>
std::vector<std::string> expect_resume_gives_the_same_files(
    const SceneDesc& desc, const std::filesystem::path& dir, std::int64_t stop_after,
    const std::vector<std::string>& files = {},
    const std::function<void(const RunResult&, const RunToResume&)>& stopped = {}) {
  {
    RunDriver<D, double> full(desc, RunSettings{dir / "full"});
    const RunResult r = full.run();
    EXPECT_EQ(r.status, RunStatus::Completed) << r.message;
    if (r.status != RunStatus::Completed) return {};
  }
  RunCallbacks stop;
  stop.stop_requested = [stop_after](std::int64_t done) {
    return done == stop_after ? std::string("a test") : std::string();
  };
  RunResult interrupted;
  {
    RunDriver<D, double> part(desc, RunSettings{dir / "part"});
    interrupted = part.run(stop);
    EXPECT_EQ(interrupted.status, RunStatus::Interrupted) << interrupted.message;
    if (interrupted.status != RunStatus::Interrupted) return {};
  }
  RunToResume r = open_run_to_resume(dir / "part");
  if (stopped) stopped(interrupted, r);
  RunDriver<D, double> resumed(r.desc, *r.checkpoint, RunSettings{dir / "part", r.checkpoint_every});
  const RunResult done = resumed.run();
  EXPECT_EQ(done.status, RunStatus::Completed) << done.message;
  const std::vector<std::string> names = entries(dir / "full" / "frames");
  EXPECT_EQ(names, entries(dir / "part" / "frames"));
  for (const auto& n : names)
    EXPECT_TRUE(slurp(dir / "full" / "frames" / n) == slurp(dir / "part" / "frames" / n)) << n << " differs";
  for (const auto& f : files) {
    EXPECT_TRUE(std::filesystem::exists(dir / "full" / f)) << f;
    EXPECT_TRUE(slurp(dir / "full" / f) == slurp(dir / "part" / f)) << f << " differs";
  }
  return names;
}

}  // namespace sph::test
