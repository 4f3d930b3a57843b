// Checkpoints and resume as a user meets them: `sph run --checkpoint-every N`, Ctrl-C or
// SIGTERM (finish the step, write a checkpoint, say how to resume), kill -9 at any moment (no
// half-written file visible), and `sph run --resume DIR` giving exactly the frames of a run that
// was never interrupted.

#include <chrono>
#include <csignal>
#include <filesystem>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sph/io/checkpoint.h>

#include "support/expect.h"
#include "support/run_sph.h"
#include "support/scenes.h"

namespace {

using sph::test::kDamBreak;
using sph::test::kTank;

namespace fs = std::filesystem;
using sph::test::CommandResult;
using sph::test::slurp;
using sph::test::SphProcess;
using sph::test::TempDir;

class Resume : public testing::Test {
 protected:
  CommandResult sph(const std::vector<std::string>& args) {
    return sph::test::run_sph(args, tmp_.path(), tmp_ / "stderr.txt");
  }
  fs::path at(const std::string& name) const { return tmp_ / name; }

  /// Waits until `file` exists (true) or `seconds` pass (false).
  static bool wait_for(const fs::path& file, double seconds) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) {
      if (fs::exists(file)) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return false;
  }

  /// The step of the checkpoint in DIR, from the summary the run wrote or from a resume's log.
  static std::int64_t summary_steps(const fs::path& dir) {
    return nlohmann::json::parse(slurp(dir / "summary.json")).at("steps").get<std::int64_t>();
  }

  /// Every frame file and frames.pvd of two runs are byte for byte the same.
  static void expect_same_frames(const fs::path& a, const fs::path& b) {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(a / "frames")) names.push_back(e.path().filename().string());
    std::vector<std::string> names_b;
    for (const auto& e : fs::directory_iterator(b / "frames")) names_b.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    std::sort(names_b.begin(), names_b.end());
    ASSERT_EQ(names, names_b);
    ASSERT_GE(names.size(), 2u);
    for (const auto& n : names) EXPECT_TRUE(slurp(a / "frames" / n) == slurp(b / "frames" / n)) << n << " differs";
    EXPECT_EQ(slurp(a / "frames.pvd"), slurp(b / "frames.pvd"));
  }

  /// No visible file of a run directory is partial: frames and the collection are complete XML.
  static void expect_whole_files(const fs::path& dir) {
    for (const auto& e : fs::recursive_directory_iterator(dir)) {
      const std::string name = e.path().filename().string();
      if (!e.is_regular_file() || name[0] == '.') continue;  // hidden: temporaries
      const std::string text = slurp(e.path());
      if (e.path().extension() == ".vtu" || e.path().extension() == ".pvd") {
        EXPECT_NE(text.rfind("</VTKFile>"), std::string::npos) << e.path() << " is cut short";
      }
    }
  }

  TempDir tmp_;
};

TEST_F(Resume, CheckpointEveryThenResumeGivesTheFramesOfAnUninterruptedRun) {
  // The tank: an emitter adds particles every 16 steps; 150 is mid-interval. The continuation
  // runs on one thread, the others on two.
  for (const std::string mode : {"adaptive", "verlet", "standard"}) {
    SCOPED_TRACE(mode);
    const std::string full = "full_" + mode, part = "part_" + mode;
    ASSERT_EQ(
        sph({"run", kTank, "--neighbors", mode, "--steps", "300", "--threads", "2", "--no-progress", "-o", full}).code,
        0);
    CommandResult r = sph({"run", kTank, "--neighbors", mode, "--steps", "150", "--threads", "2", "--no-progress",
                           "--checkpoint-every", "40", "-o", part});
    ASSERT_EQ(r.code, 0) << r.err;
    ASSERT_TRUE(fs::is_regular_file(at(part) / "checkpoint.sphc"));
    r = sph({"run", "--resume", part, "--steps", "300", "--threads", "1", "--no-progress"});
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_CONTAINS(r.err, "resumed at step 150");
    expect_same_frames(at(full), at(part));
    const auto s = nlohmann::json::parse(slurp(at(part) / "summary.json"));
    EXPECT_EQ(s.at("status"), "completed");
    EXPECT_EQ(s.at("steps"), 300);
    EXPECT_EQ(s.at("resumed_at_steps"), nlohmann::json::array({150}));
    EXPECT_EQ(s.at("last_checkpoint_step"), 300) << "the resumed run goes on checkpointing every 40 and at the end";
    // stats.csv: one row per step, the same values (timings aside) as the uninterrupted run.
    const auto rows = [](const std::string& csv) {
      std::vector<std::string> out;
      std::size_t b = 0;
      for (std::size_t e; (e = csv.find('\n', b)) != std::string::npos; b = e + 1) {
        std::string line = csv.substr(b, e - b);
        std::size_t comma = 0;
        for (int k = 0; k < 12 && comma != std::string::npos; ++k) comma = line.find(',', comma + 1);
        out.push_back(line.substr(0, comma));
      }
      return out;
    };
    EXPECT_EQ(rows(slurp(at(full) / "stats.csv")), rows(slurp(at(part) / "stats.csv")));
  }
}

// Frames by simulated time in the legacy VTK and PLY formats: the schedule's state lives in the
// checkpoint. dt = 1.5e-4 s at 1000 frames/s: step 60 is on the schedule (tick 9), step 50 is
// not, so the run that stopped at 50 wrote a frame there that the longer run must not have.
TEST_F(Resume, FramesBySimulatedTimeInEveryFormatResumeBitwise) {
  const std::vector<std::string> frames{"--format", "vtk,ply,vtu", "--fields", "velocity,id,pressure", "--fps", "1000"};
  const auto run = [&](std::vector<std::string> args) {
    args.insert(args.begin(), {"run", kDamBreak, "--threads", "2", "--no-progress"});
    args.insert(args.end(), frames.begin(), frames.end());
    return sph(args);
  };
  ASSERT_EQ(run({"--steps", "120", "-o", "full"}).code, 0);
  for (const std::string stop : {"50", "60"}) {
    SCOPED_TRACE("stopped at " + stop);
    const std::string part = "part" + stop;
    CommandResult r = run({"--steps", stop, "--checkpoint-every", "20", "-o", part});
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(fs::exists(at(part) / "frames" / "frame_000008.ply")) << "the last step's frame";
    r = sph({"run", "--resume", part, "--steps", "120", "--threads", "1", "--no-progress"});
    ASSERT_EQ(r.code, 0) << r.err;
    expect_same_frames(at("full"), at(part));
    EXPECT_EQ(nlohmann::json::parse(slurp(at(part) / "summary.json")).at("frames"),
              nlohmann::json::parse(slurp(at("full") / "summary.json")).at("frames"));
  }
}

class StopSignal : public Resume, public testing::WithParamInterface<int> {};

TEST_P(StopSignal, FinishesTheStepWritesACheckpointAndResumesBitwise) {
  const int sig = GetParam();
  // A run far too long to finish: it is stopped once its second frame exists.
  SphProcess run({"run", kDamBreak, "--neighbors", "adaptive", "--steps", "100000000", "--no-progress", "-o", "part"},
                 tmp_.path(), at("part.log"));
  ASSERT_TRUE(run.started());
  ASSERT_TRUE(wait_for(at("part") / "frames" / "frame_000001.vtu", 120)) << slurp(at("part.log"));
  run.signal(sig);
  EXPECT_EQ(run.wait(), 128 + sig) << slurp(at("part.log"));
  const std::string log = slurp(at("part.log"));
  EXPECT_CONTAINS(log, sig == SIGINT ? "interrupted by SIGINT" : "interrupted by SIGTERM");
  EXPECT_CONTAINS(log, "sph run --resume part");
  EXPECT_TRUE(fs::is_regular_file(at("part") / "checkpoint.sphc"));
  EXPECT_TRUE(fs::is_regular_file(at("part") / "stats.csv"));
  const std::int64_t stopped = summary_steps(at("part"));
  EXPECT_CONTAINS(slurp(at("part") / "summary.json"), "interrupted by");
  expect_whole_files(at("part"));

  // Continue 250 steps past the stop and compare with a straight run of the same length.
  const std::string total = std::to_string(stopped + 250);
  CommandResult r = sph({"run", "--resume", "part", "--steps", total, "--no-progress"});
  ASSERT_EQ(r.code, 0) << r.err;
  ASSERT_EQ(sph({"run", kDamBreak, "--neighbors", "adaptive", "--steps", total, "--no-progress", "-o", "full"}).code,
            0);
  expect_same_frames(at("full"), at("part"));
}

INSTANTIATE_TEST_SUITE_P(Signals, StopSignal, testing::Values(SIGINT, SIGTERM),
                         [](const testing::TestParamInfo<int>& i) { return i.param == SIGINT ? "Int" : "Term"; });

TEST_F(Resume, KillNineAtAnyMomentLeavesOnlyWholeFilesAndTheRunResumes) {
  std::mt19937 rng(2026);
  for (int attempt = 0; attempt < 3; ++attempt) {
    SCOPED_TRACE("attempt " + std::to_string(attempt));
    const std::string dir = "k" + std::to_string(attempt);
    SphProcess run({"run", kDamBreak, "--neighbors", "verlet", "--steps", "100000000", "--checkpoint-every", "23",
                    "--no-progress", "-o", dir},
                   tmp_.path(), at(dir + ".log"));
    ASSERT_TRUE(wait_for(at(dir) / "checkpoint.sphc", 120)) << slurp(at(dir + ".log"));
    std::this_thread::sleep_for(std::chrono::milliseconds(std::uniform_int_distribution<int>(0, 400)(rng)));
    run.signal(SIGKILL);
    EXPECT_EQ(run.wait(), 128 + SIGKILL);
    expect_whole_files(at(dir));
    EXPECT_FALSE(fs::exists(at(dir) / "summary.json"));

    // The checkpoint is whole (the reader verifies its checksum) and at a multiple of 23.
    const std::int64_t ck = sph::CheckpointReader(at(dir) / "checkpoint.sphc").header().step;
    ASSERT_GE(ck, 23);
    EXPECT_EQ(ck % 23, 0);
    const std::string total = std::to_string(ck + 120);
    const CommandResult r = sph({"run", "--resume", dir, "--steps", total, "--no-progress"});
    ASSERT_EQ(r.code, 0) << r.err;
    for (const auto& e : fs::directory_iterator(at(dir)))
      EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << "stale temporary " << e.path();
    ASSERT_EQ(
        sph({"run", kDamBreak, "--neighbors", "verlet", "--steps", total, "--no-progress", "-o", dir + "full"}).code,
        0);
    expect_same_frames(at(dir + "full"), at(dir));
  }
}

// --- Mistakes -------------------------------------------------------------------------------

TEST_F(Resume, MistakesAreRefusedWithOneMessageAndExitCode2) {
  ASSERT_EQ(sph({"run", kDamBreak, "--steps", "20", "--checkpoint-every", "10", "--no-progress", "-o", "done"}).code,
            0);
  ASSERT_EQ(sph({"run", kDamBreak, "--steps", "5", "--no-progress", "-o", "nock"}).code, 0);
  const std::string before = slurp(at("done") / "summary.json");
  struct Case {
    std::vector<std::string> args;
    std::string expect;
  };
  const std::vector<Case> cases{
      {{"run", "--resume", "done", kDamBreak}, "a SCENE file cannot be given with it"},
      {{"run", "--resume", "done", "--set", "Fluid.viscosity=2"}, "--set cannot be given with it"},
      {{"run", "--resume", "done", "--neighbors", "verlet"}, "--neighbors cannot be given"},
      {{"run", "--resume", "done", "-o", "elsewhere"}, "-o/--output cannot be given"},
      {{"run", "--resume", "done", "--format", "ply"}, "--format cannot be given"},
      {{"run", "--resume", "done", "--fields", "id"}, "--fields cannot be given"},
      {{"run", "--resume", "done", "--every", "3"}, "--every cannot be given"},
      {{"run", "--resume", "done", "--fps", "30"}, "--fps cannot be given"},
      {{"run", "--resume", "done", "--surface"}, "--surface cannot be given"},
      {{"run", kDamBreak, "--surface-format", "ply"}, "--surface-format: applies to the surfaces of --surface"},
      // A --set of what a flag sets: the flag hid it, a bad value in it too.
      {{"run", kDamBreak, "--steps", "2", "--set", "Configuration.numberOfSteps=abc"},
       "--set Configuration.numberOfSteps and --steps both set it"},
      {{"compare", kDamBreak, "--steps", "2", "--set", "Configuration.numberOfSteps=0"},
       "--set Configuration.numberOfSteps and --steps both set it"},
      {{"run", "--resume", "missing_dir"}, "missing_dir: no such directory"},
      {{"run", "--resume", "nock"}, "no checkpoint here"},
      {{"run", "--resume", "done"}, "already did all its 20 steps"},
      {{"run", "--resume", "done", "--steps", "20"}, "--steps 20 is not beyond the checkpoint, which is at step 20"},
      {{"run"}, "needs a scene file: sph run SCENE.json (or --resume DIR"},
      {{"run", kDamBreak, "--checkpoint-every", "0"}, "--checkpoint-every"},
  };
  for (const auto& c : cases) {
    const CommandResult r = sph(c.args);
    std::string joined;
    for (const auto& a : c.args) joined += a + " ";
    EXPECT_EQ(r.code, 2) << joined << "\n" << r.err;
    EXPECT_CONTAINS(r.err, c.expect);
    EXPECT_EQ(r.err.find("terminate"), std::string::npos) << r.err;
  }
  EXPECT_EQ(slurp(at("done") / "summary.json"), before) << "a refused resume leaves the run untouched";
  EXPECT_FALSE(fs::exists(at("elsewhere")));

  // A frame of the run removed: a resumed run would list it in frames.pvd (and sph render refuse
  // the run), so the resume is refused before anything is written.
  fs::copy(at("done"), at("lost"), fs::copy_options::recursive);
  fs::remove(at("lost") / "frames" / "frame_000000.vtu");
  const std::string pvd = slurp(at("lost") / "frames.pvd");
  const CommandResult lost = sph({"run", "--resume", "lost", "--steps", "40"});
  EXPECT_EQ(lost.code, 2) << lost.err;
  EXPECT_CONTAINS(lost.err, "lost/frames/frame_000000.vtu: is missing: the run wrote frames 0 to");
  EXPECT_EQ(slurp(at("lost") / "summary.json"), before);
  EXPECT_EQ(slurp(at("lost") / "frames.pvd"), pvd);

  // A corrupt checkpoint: refused, run untouched.
  std::string ck = slurp(at("done") / "checkpoint.sphc");
  ck[ck.size() / 2] = static_cast<char>(ck[ck.size() / 2] ^ 1);
  sph::test::spit(at("done") / "checkpoint.sphc", ck);
  const CommandResult r = sph({"run", "--resume", "done", "--steps", "40"});
  EXPECT_EQ(r.code, 2);
  EXPECT_CONTAINS(r.err, "checksum does not match");
  EXPECT_EQ(slurp(at("done") / "summary.json"), before);
}

TEST_F(Resume, ANewRunInTheDirectoryRemovesTheOldCheckpoint) {
  ASSERT_EQ(sph({"run", kDamBreak, "--steps", "10", "--checkpoint-every", "5", "--no-progress", "-o", "d"}).code, 0);
  ASSERT_TRUE(fs::exists(at("d") / "checkpoint.sphc"));
  ASSERT_EQ(sph({"run", kDamBreak, "--steps", "3", "--no-progress", "-o", "d"}).code, 0);
  EXPECT_FALSE(fs::exists(at("d") / "checkpoint.sphc")) << "it belonged to the previous run";
}

}  // namespace
