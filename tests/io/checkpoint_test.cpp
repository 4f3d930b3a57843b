// Checkpoints: a run resumed from one is bitwise identical to a run never interrupted (every
// neighbor mode, an emitter scene, a Morton reorder after the checkpoint, another thread
// count), and a corrupt, truncated or foreign file is refused with a message saying so.

#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <sph/core/error.h>
#include <sph/core/parallel.h>
#include <sph/io/checkpoint.h>
#include <sph/io/run_output.h>
#include <sph/scene/builders.h>
#include <sph/scene/scene_reader.h>

#include "support/scenes.h"
#include "support/temp_dir.h"
#include "support/thread_count.h"

namespace sph {
namespace {

using sph::test::kDamBreak;

namespace fs = std::filesystem;
using test::TempDir;

const std::string kTank = SPH_SOURCE_DIR "/scenes/paper/tank_fill_3d.json";

using test::ThreadCount;

SceneDesc scene(const std::string& file, const std::string& mode, const std::string& precision, int steps) {
  return read_scene_file(file,
                         {"Configuration.neighbors=\"" + mode + "\"", "Configuration.precision=\"" + precision + "\"",
                          "Configuration.numberOfSteps=" + std::to_string(steps)});
}

/// Runs desc for `stop` steps writing a checkpoint, resumes it in a new simulation with another
/// thread count and runs on to `total`; compares with an uninterrupted run.
template <int D, std::floating_point R>
void expect_resume_is_bitwise(const SceneDesc& desc, std::int64_t stop, std::int64_t total) {
  ThreadCount restore;
  set_num_threads(2);
  Simulation<D, R> straight = make_simulation<D, R>(desc);
  for (std::int64_t s = 0; s < total; ++s) straight.step();

  TempDir tmp;
  const fs::path dir = tmp / "run";
  {
    Simulation<D, R> first = make_simulation<D, R>(desc);
    prepare_output_directory(dir);
    RunOutput<D, R> out(dir, desc, {"x", 2});
    out.begin(first);
    for (std::int64_t s = 0; s < stop; ++s) out.after_step(first, first.step(), false);
    write_checkpoint(dir, desc, first, out, 1.0, 0);
    // Steps after the checkpoint that the "crash" loses.
    for (int s = 0; s < 7; ++s) first.step();
  }

  set_num_threads(1);
  CheckpointReader ck(dir / kCheckpointFile);
  EXPECT_EQ(ck.header().step, stop);
  EXPECT_EQ(ck.header().dimension, D);
  const SceneDesc again = parse_scene(ck.header().scene_json, ck.header().scene_source);
  EXPECT_TRUE(again == desc) << "the checkpoint holds the run's scene";
  Simulation<D, R> resumed = make_simulation<D, R>(again);
  RunOutput<D, R> out(dir, again, {"x", 1});
  EXPECT_EQ(ck.restore(resumed, out), "");
  EXPECT_EQ(resumed.steps_done(), stop);
  for (std::int64_t s = stop; s < total; ++s) out.after_step(resumed, resumed.step(), s + 1 == total);

  const auto& a = straight.particles();
  const auto& b = resumed.particles();
  ASSERT_EQ(a.size(), b.size());
  EXPECT_TRUE(a.id == b.id);
  EXPECT_TRUE(a.position == b.position);
  EXPECT_TRUE(a.velocity == b.velocity);
  EXPECT_TRUE(a.density == b.density);
  EXPECT_TRUE(a.pressure == b.pressure);
  EXPECT_TRUE(a.initial_position == b.initial_position);
  EXPECT_TRUE(straight.neighbors().lists() == resumed.neighbors().lists());
  EXPECT_EQ(straight.emitter_states().size(), resumed.emitter_states().size());
  for (std::size_t k = 0; k < straight.emitter_states().size(); ++k) {
    EXPECT_EQ(straight.emitter_states()[k].emitted, resumed.emitter_states()[k].emitted);
    EXPECT_EQ(straight.emitter_states()[k].next_step, resumed.emitter_states()[k].next_step);
  }
}

class ResumeMode : public testing::TestWithParam<std::string> {};

// The tank's emitter adds a layer every 16 steps; step 137 is mid-interval for the emitter and
// for the adaptive mode's full rebuilds, and the Morton reorder at step 200 comes after it.
TEST_P(ResumeMode, EmitterSceneResumesBitwise3dDouble) {
  expect_resume_is_bitwise<3, double>(scene(kTank, GetParam(), "double", 260), 137, 260);
}

TEST_P(ResumeMode, EmitterSceneResumesBitwise3dFloat) {
  expect_resume_is_bitwise<3, float>(scene(kTank, GetParam(), "float", 230), 176, 230);
}

TEST_P(ResumeMode, DamBreakResumesBitwise2d) {
  expect_resume_is_bitwise<2, double>(scene(kDamBreak, GetParam(), "double", 150), 61, 150);
}

INSTANTIATE_TEST_SUITE_P(Modes, ResumeMode,
                         testing::Values("standard", "adaptive", "verlet", "verlet_clusters", "brute_force"));

TEST(Checkpoint, ResumingBeforeTheFirstStepAndAfterAnEmissionStepWorks) {
  // Step 0 (nothing updated yet) and step 16 (the emitter's second batch just added).
  expect_resume_is_bitwise<3, double>(scene(kTank, "adaptive", "double", 40), 0, 40);
  expect_resume_is_bitwise<3, double>(scene(kTank, "verlet", "double", 40), 17, 40);
}

// --- Refused files --------------------------------------------------------------------------

class BadCheckpoint : public testing::Test {
 protected:
  void SetUp() override {
    desc_ = scene(kDamBreak, "adaptive", "double", 20);
    dir_ = tmp_ / "run";
    Simulation<2, double> sim = make_simulation<2, double>(desc_);
    prepare_output_directory(dir_);
    RunOutput<2, double> out(dir_, desc_, {"adaptive", 1});
    out.begin(sim);
    for (int s = 0; s < 10; ++s) out.after_step(sim, sim.step(), false);
    write_checkpoint(dir_, desc_, sim, out, 0.5, 5);
    file_ = dir_ / kCheckpointFile;
    good_ = test::slurp(file_);
  }

  /// Expects the checkpoint as it is now on disk to be refused with `what` in the message.
  void expect_refused(const std::string& what) {
    try {
      CheckpointReader ck(file_);
      Simulation<2, double> sim = make_simulation<2, double>(desc_);
      RunOutput<2, double> out(dir_, desc_, {"adaptive", 1});
      ck.restore(sim, out);
      FAIL() << "accepted";
    } catch (const Error& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(what), std::string::npos) << msg;
      EXPECT_NE(msg.find(file_.string()), std::string::npos) << "the message names the file: " << msg;
    }
  }

  TempDir tmp_;
  SceneDesc desc_;
  fs::path dir_, file_;
  std::string good_;
};

TEST_F(BadCheckpoint, TheGoodFileIsAccepted) {
  CheckpointReader ck(file_);
  EXPECT_EQ(ck.header().step, 10);
  EXPECT_EQ(ck.header().checkpoint_every, 5);
  EXPECT_EQ(ck.header().scene_source, kDamBreak);
  Simulation<2, double> sim = make_simulation<2, double>(desc_);
  RunOutput<2, double> out(dir_, desc_, {"adaptive", 1});
  EXPECT_EQ(ck.restore(sim, out), "");
  EXPECT_EQ(sim.steps_done(), 10);
}

TEST_F(BadCheckpoint, MissingFile) {
  fs::remove(file_);
  expect_refused("no checkpoint here");
}

TEST_F(BadCheckpoint, EmptyFile) {
  test::spit(file_, "");
  expect_refused("not an sph checkpoint");
}

TEST_F(BadCheckpoint, ForeignFile) {
  test::spit(file_, "{\"this\": \"is a scene, not a checkpoint\"}\n");
  expect_refused("not an sph checkpoint");
}

TEST_F(BadCheckpoint, AnyFlippedByteInThePayloadFailsTheChecksum) {
  for (std::size_t at : {std::size_t{20}, good_.size() / 3, good_.size() / 2, good_.size() - 30}) {
    std::string bad = good_;
    bad[at] = static_cast<char>(bad[at] ^ 0x10);
    test::spit(file_, bad);
    SCOPED_TRACE("byte " + std::to_string(at));
    expect_refused("checksum does not match");
  }
}

TEST_F(BadCheckpoint, TruncatedAnywhere) {
  for (std::size_t len : {std::size_t{12}, std::size_t{40}, good_.size() / 2, good_.size() - 1}) {
    test::spit(file_, good_.substr(0, len));
    SCOPED_TRACE("length " + std::to_string(len));
    expect_refused("truncated");
  }
}

TEST_F(BadCheckpoint, AnotherFormatVersion) {
  std::string bad = good_;
  bad[8] = static_cast<char>(bad[8] + 1);
  test::spit(file_, bad);
  expect_refused("format version " + std::to_string(kCheckpointVersion + 1));
}

TEST_F(BadCheckpoint, AnOlderFormatVersionSaysSo) {
  // Version 1 kept a list of .vtu files where version 2 keeps the frame schedule.
  std::string bad = good_;
  const std::uint32_t v1 = 1;
  std::memcpy(bad.data() + 8, &v1, sizeof v1);
  test::spit(file_, bad);
  expect_refused("format version 1; this sph");
  expect_refused("written by an older sph");
}

TEST_F(BadCheckpoint, AnotherByteOrder) {
  std::string bad = good_;
  std::swap(bad[12], bad[15]);
  std::swap(bad[13], bad[14]);
  test::spit(file_, bad);
  expect_refused("byte order");
}

TEST_F(BadCheckpoint, ACheckpointOfAnotherModeIsRefusedByTheState) {
  // A consistent file (checksum good) restored into a simulation of another mode.
  CheckpointReader ck(file_);
  const SceneDesc other = scene(kDamBreak, "verlet", "double", 20);
  Simulation<2, double> sim = make_simulation<2, double>(other);
  RunOutput<2, double> out(dir_, other, {"verlet", 1});
  EXPECT_THROW(ck.restore(sim, out), Error);
}

TEST(CheckpointWrite, ReplacesThePreviousOneAtomicallyAndLeavesNoTemporaryFile) {
  TempDir tmp;
  const SceneDesc desc = scene(kDamBreak, "standard", "double", 20);
  const fs::path dir = tmp / "run";
  Simulation<2, double> sim = make_simulation<2, double>(desc);
  prepare_output_directory(dir);
  RunOutput<2, double> out(dir, desc, {"standard", 1});
  out.begin(sim);
  for (int k = 1; k <= 3; ++k) {
    for (int s = 0; s < 4; ++s) out.after_step(sim, sim.step(), false);
    write_checkpoint(dir, desc, sim, out, 0.0, 4);
    EXPECT_EQ(CheckpointReader(dir / kCheckpointFile).header().step, 4 * k);
  }
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
}

}  // namespace
}  // namespace sph
