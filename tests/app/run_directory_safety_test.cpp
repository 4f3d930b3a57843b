// No data loss in a run directory (issue 15, item 4): a finished run is never recomputed or cut
// short by --resume, a checkpoint resumes only into the directory of its own run, a new run does
// not delete an unfinished run's checkpoint unless --overwrite, the pictures of an earlier run do
// not survive beside a new run's frames, `sph render -o DIR` removes only what a render makes,
// and scene files that are not scenes (huge, a device, a FIFO) are refused.

#include <algorithm>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <sys/stat.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sph/io/checkpoint.h>

#include "support/expect.h"
#include "support/run_sph.h"
#include "support/scenes.h"

namespace {

using sph::test::kDamBreak;

namespace fs = std::filesystem;
using sph::test::CommandResult;
using sph::test::slurp;
using sph::test::spit;
using sph::test::TempDir;

class RunDirectory : public testing::Test {
 protected:
  CommandResult sph(const std::vector<std::string>& args, const std::string& env = "") {
    return sph::test::run_sph(args, tmp_.path(), tmp_ / "stderr.txt", env);
  }
  fs::path at(const std::string& name) const { return tmp_ / name; }
  /// A run of the 2D dam break into DIR, `steps` steps, with `extra` flags; asserts exit 0.
  void run(const std::string& dir, int steps, std::vector<std::string> extra = {}) {
    std::vector<std::string> args{"run",           kDamBreak, "--steps", std::to_string(steps), "--every", "5",
                                  "--no-progress", "-o",      dir};
    args.insert(args.end(), extra.begin(), extra.end());
    const CommandResult r = sph(args);
    ASSERT_EQ(r.code, 0) << r.err;
  }
  /// Every file under DIR (relative name -> contents), to see that a refused command left it alone.
  static std::map<std::string, std::string> files(const fs::path& dir) {
    std::map<std::string, std::string> out;
    for (const auto& e : fs::recursive_directory_iterator(dir))
      if (e.is_regular_file()) out[fs::relative(e.path(), dir).string()] = slurp(e.path());
    return out;
  }
  static nlohmann::json summary(const fs::path& dir) { return nlohmann::json::parse(slurp(dir / "summary.json")); }
  /// Expects `r` refused: exit 2 and one error line containing each of `texts`.
  static void expect_refused(const CommandResult& r, const std::vector<std::string>& texts) {
    EXPECT_EQ(r.code, 2) << r.err;
    for (const auto& t : texts) EXPECT_CONTAINS(r.err, t);
  }

  TempDir tmp_;
};

// The issue's case: a run interrupted and resumed without --checkpoint-every used to keep the
// checkpoint of the interruption; `--resume DIR --steps N` with N below the steps done then
// removed the frames and stats rows past N, and a plain --resume recomputed the finished run.
// Here the checkpoint is put back behind the finished run's end by hand, as such a run left it.
TEST_F(RunDirectory, AFinishedRunIsNeverRecomputedOrCutShort) {
  run("d", 10, {"--checkpoint-every", "10"});
  fs::copy_file(at("d") / sph::kCheckpointFile, at("ck10"));
  CommandResult r = sph({"run", "--resume", "d", "--steps", "20", "--no-progress"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(sph::CheckpointReader(at("d") / sph::kCheckpointFile).header().step, 20)
      << "a resumed run checkpoints its last step: its checkpoint is never behind its end";
  fs::copy_file(at("ck10"), at("d") / sph::kCheckpointFile, fs::copy_options::overwrite_existing);
  const auto before = files(at("d"));

  expect_refused(sph({"run", "--resume", "d"}), {"already did all its 20 steps", "--steps N with N > 20"});
  expect_refused(sph({"run", "--resume", "d", "--steps", "15"}),
                 {"--steps 15 is not beyond the 20 steps the run already did", "give a total above 20"});
  expect_refused(sph({"run", "--resume", "d", "--steps", "20"}), {"not beyond the 20 steps"});
  EXPECT_EQ(files(at("d")), before) << "a refused resume changes nothing";

  // A larger total continues it; the steps after the old checkpoint are computed again, said so.
  r = sph({"run", "--resume", "d", "--steps", "25", "--no-progress"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_CONTAINS(r.err, "steps 11 to 20 are computed again");
  run("straight", 25);
  for (const auto& e : fs::directory_iterator(at("straight") / "frames")) {
    const fs::path name = e.path().filename();
    EXPECT_TRUE(slurp(e.path()) == slurp(at("d") / "frames" / name)) << name << " differs";
  }
  EXPECT_EQ(summary(at("d")).at("steps"), 25);
}

TEST_F(RunDirectory, StatsStepCountsTheStepsDoneLikeSummaryAndSteps) {
  run("d", 7);
  const std::string csv = slurp(at("d") / "stats.csv");
  std::vector<std::string> steps;
  std::size_t b = csv.find('\n') + 1;
  for (std::size_t e; (e = csv.find('\n', b)) != std::string::npos; b = e + 1)
    steps.push_back(csv.substr(b, csv.find(',', b) - b));
  EXPECT_EQ(steps, (std::vector<std::string>{"1", "2", "3", "4", "5", "6", "7"}));
  EXPECT_EQ(summary(at("d")).at("steps"), 7) << "the last row's step is summary.json's steps";
}

TEST_F(RunDirectory, TheRunIdAndSceneFingerprintAreInRunJsonSummaryAndCheckpoint) {
  run("a", 10, {"--checkpoint-every", "5"});
  run("b", 10, {"--checkpoint-every", "5"});
  const nlohmann::json id_a = nlohmann::json::parse(slurp(at("a") / "run.json"));
  const nlohmann::json id_b = nlohmann::json::parse(slurp(at("b") / "run.json"));
  const std::string run_a = id_a.at("run_id"), run_b = id_b.at("run_id");
  EXPECT_NE(run_a, run_b) << "each new run has its own id";
  EXPECT_EQ(id_a.at("scene_fingerprint"), id_b.at("scene_fingerprint")) << "the same scene";
  EXPECT_EQ(summary(at("a")).at("run_id"), run_a);
  EXPECT_EQ(summary(at("a")).at("scene_fingerprint"), id_a.at("scene_fingerprint"));
  const sph::CheckpointHeader h = sph::CheckpointReader(at("a") / sph::kCheckpointFile).header();
  EXPECT_EQ(h.identity.run_id, run_a);
  EXPECT_EQ(h.identity.scene_fingerprint, id_a.at("scene_fingerprint"));
  // scene.json stays a scene sph run reads.
  ASSERT_EQ(sph({"run", (at("a") / "scene.json").string(), "--steps", "2", "--no-progress", "-o", "again"}).code, 0);

  // A resumed run keeps its id; the total of steps does not change the fingerprint.
  ASSERT_EQ(sph({"run", "--resume", "a", "--steps", "15", "--no-progress"}).code, 0);
  EXPECT_EQ(summary(at("a")).at("run_id"), run_a);
  EXPECT_EQ(summary(at("a")).at("scene_fingerprint"), id_a.at("scene_fingerprint"));
}

TEST_F(RunDirectory, ACheckpointOfAnotherRunIsRefusedNamingBothIds) {
  run("a", 10, {"--checkpoint-every", "5"});
  run("b", 10, {"--checkpoint-every", "5"});
  const std::string run_a = summary(at("a")).at("run_id"), run_b = summary(at("b")).at("run_id");
  fs::copy_file(at("b") / sph::kCheckpointFile, at("a") / sph::kCheckpointFile, fs::copy_options::overwrite_existing);
  const auto before = files(at("a"));
  expect_refused(sph({"run", "--resume", "a", "--steps", "20"}), {"run.json: names run " + run_a, run_b});
  EXPECT_EQ(files(at("a")), before) << "a refused resume changes nothing";
  // With run.json copied too, summary.json still belongs to run a.
  fs::copy_file(at("b") / "run.json", at("a") / "run.json", fs::copy_options::overwrite_existing);
  expect_refused(sph({"run", "--resume", "a", "--steps", "20"}),
                 {"summary.json: is the summary of run " + run_a, run_b});
  fs::remove(at("a") / "run.json");
  expect_refused(sph({"run", "--resume", "a", "--steps", "20"}), {"run.json: missing", run_b});

  // A checkpoint and run.json of a run of another scene, in a killed run's directory (no summary).
  run("c", 10, {"--checkpoint-every", "5", "--set", "Fluid.viscosity=0.02"});
  for (const char* f : {sph::kCheckpointFile, "run.json"})
    fs::copy_file(at("c") / f, at("a") / f, fs::copy_options::overwrite_existing);
  fs::remove(at("a") / "summary.json");
  expect_refused(sph({"run", "--resume", "a", "--steps", "20"}),
                 {"scene.json: holds another scene, or a mesh file it names"});
  EXPECT_FALSE(fs::exists(at("a") / "summary.json"));
}

TEST_F(RunDirectory, ANewRunDoesNotDeleteAnUnfinishedRunsCheckpointWithoutOverwrite) {
  run("d", 10, {"--checkpoint-every", "5"});
  fs::remove(at("d") / "summary.json");  // as a kill -9 leaves it
  const auto before = files(at("d"));
  const CommandResult r = sph({"run", kDamBreak, "--steps", "3", "--no-progress", "-o", "d"});
  expect_refused(r, {"d: holds the checkpoint of a run that did not finish (no summary.json", "sph run --resume d",
                     "--overwrite"});
  EXPECT_EQ(files(at("d")), before);
  // An interrupted run's summary says so: still unfinished.
  spit(at("d") / "summary.json", R"({"status": "interrupted by SIGINT after step 10 of 30", "steps": 10})");
  expect_refused(sph({"run", kDamBreak, "--steps", "3", "--no-progress", "-o", "d"}),
                 {"summary.json: interrupted by SIGINT after step 10 of 30"});

  const CommandResult o = sph({"run", kDamBreak, "--steps", "3", "--no-progress", "-o", "d", "--overwrite"});
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_FALSE(fs::exists(at("d") / sph::kCheckpointFile));
  EXPECT_EQ(summary(at("d")).at("steps"), 3);
  expect_refused(sph({"run", "--resume", "d", "--overwrite"}), {"--overwrite cannot be given with it"});
  // A finished run's directory is reused as before, checkpoint and all.
  run("f", 10, {"--checkpoint-every", "5"});
  run("f", 3);
  EXPECT_FALSE(fs::exists(at("f") / sph::kCheckpointFile));
}

TEST_F(RunDirectory, ANewRunRemovesTheEarlierRunsPicturesAndKeepsOtherFiles) {
  run("d", 10);
  fs::create_directories(at("d") / "render");
  for (const char* f : {"render/frame_000000.png", "render/frame_000001.png", "render/movie.mp4", "view.html",
                        "render/notes.txt", "notes.txt"})
    spit(at("d") / f, "x");
  run("d", 5);
  for (const char* f : {"render/frame_000000.png", "render/frame_000001.png", "render/movie.mp4", "view.html"})
    EXPECT_FALSE(fs::exists(at("d") / f)) << f << " of the earlier run survived";
  EXPECT_TRUE(fs::exists(at("d") / "render" / "notes.txt"));
  EXPECT_TRUE(fs::exists(at("d") / "notes.txt"));
  // render/ holding only pictures goes entirely.
  fs::create_directories(at("d") / "render");
  spit(at("d") / "render" / "frame_000000.png", "x");
  run("d", 5);
  EXPECT_TRUE(fs::exists(at("d") / "render")) << "render/notes.txt is still there";
  fs::remove(at("d") / "render" / "notes.txt");
  spit(at("d") / "render" / "frame_000000.png", "x");
  // A killed render's hidden files (its process gone) go too; a running one's would stay.
  fs::create_directories(at("d") / "render" / ".sph-staging-999999999");
  spit(at("d") / "render" / ".sph-staging-999999999" / "frame_000003.png", "x");
  fs::create_directories(at("d") / "surface" / ".sph-staging-999999998");
  run("d", 5);
  EXPECT_FALSE(fs::exists(at("d") / "render"));
  EXPECT_FALSE(fs::exists(at("d") / "surface"));
}

TEST_F(RunDirectory, RenderRemovesOnlyTheFilesARenderMakes) {
  run("d", 5);
  fs::create_directories(at("pics"));
  for (const char* f : {"frame_000007.png", "movie.mp4", "frame_holiday.png", "notes.txt", "frame_12.png"})
    spit(at("pics") / f, "x");
  const CommandResult r = sph({"render", "d", "-o", "pics", "--frames", "0", "--size", "64x48", "--no-progress"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_FALSE(fs::exists(at("pics") / "frame_000007.png")) << "an earlier render's image";
  EXPECT_FALSE(fs::exists(at("pics") / "movie.mp4")) << "an earlier render's movie";
  EXPECT_TRUE(fs::exists(at("pics") / "frame_000000.png"));
  for (const char* f : {"frame_holiday.png", "notes.txt", "frame_12.png"})
    EXPECT_TRUE(fs::exists(at("pics") / f)) << f << " is a user's file";
}

// A render or surface that fails half-way (here a damaged frame, read after the first ones were
// drawn or meshed) leaves the earlier render's images and movie and the earlier surfaces as they
// were, and no half-written file or hidden directory beside them.
TEST_F(RunDirectory, ARenderOrSurfaceThatFailsHalfWayLeavesTheEarlierFilesWhole) {
  run("d", 20);  // frames 0 to 4
  const std::vector<std::string> render{"render", "d",       "-o",  "pics",         "--size",
                                        "64x48",  "--range", "0,2", "--no-progress"};
  const std::vector<std::string> surface{"surface", "d", "--format", "ply,obj", "--no-progress"};
  ASSERT_EQ(sph(render).code, 0);
  ASSERT_EQ(sph(surface).code, 0);
  spit(at("pics") / "notes.txt", "mine");
  const auto pics = files(at("pics")), meshes = files(at("d") / "surface");
  ASSERT_EQ(pics.size(), 6u);     // frame_000000.png ... frame_000004.png, notes.txt
  ASSERT_EQ(meshes.size(), 10u);  // surface_00000N.ply and .obj

  const fs::path frame = at("d") / "frames" / "frame_000003.vtu";
  spit(frame, slurp(frame).substr(0, 300));
  std::vector<std::string> again = render;
  again[5] = "80x60";  // other images, had they been written
  const CommandResult r = sph(again);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_CONTAINS(r.err, "frame_000003.vtu");
  EXPECT_EQ(files(at("pics")), pics) << "the earlier render changed";
  const CommandResult s = sph({"surface", "d", "--format", "ply", "--resolution", "3", "--no-progress"});
  EXPECT_EQ(s.code, 2) << s.err;
  EXPECT_CONTAINS(s.err, "frame_000003.vtu");
  EXPECT_EQ(files(at("d") / "surface"), meshes) << "the earlier surfaces changed";
  for (const fs::path& dir : {at("pics"), at("d") / "surface"})
    for (const auto& e : fs::directory_iterator(dir))
      EXPECT_EQ(e.path().filename().string().find(".sph-staging"), std::string::npos) << e.path() << " was left";

  // One that fails into a directory of its own leaves no directory; one that succeeds replaces
  // the whole earlier set (the frames 0 to 2 only: frame 3's images are removed, not kept) and
  // removes a hidden directory that a killed render left behind.
  EXPECT_EQ(sph({"render", "d", "-o", "new", "--range", "0,2", "--no-progress"}).code, 2);
  EXPECT_FALSE(fs::exists(at("new")));
  fs::create_directories(at("pics") / ".sph-staging-999999999");
  spit(at("pics") / ".sph-staging-999999999" / "frame_000001.png", "x");
  again.insert(again.end(), {"--frames", "0,1,2"});
  const CommandResult ok = sph(again);
  ASSERT_EQ(ok.code, 0) << ok.err;
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(at("pics"))) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"frame_000000.png", "frame_000001.png", "frame_000002.png", "notes.txt"}));
  EXPECT_NE(slurp(at("pics") / "frame_000000.png"), pics.at("frame_000000.png")) << "not the new image";
}

TEST_F(RunDirectory, RenderWithoutFfmpegIsRefusedBeforeAnyImage) {
  run("d", 5);
  const CommandResult r = sph({"render", "d", "--mp4", "-o", "pics", "--no-progress"}, "PATH=/nonexistent");
  expect_refused(r, {"--mp4: making an MP4 needs ffmpeg"});
  EXPECT_FALSE(fs::exists(at("pics"))) << "nothing written";
}

TEST_F(RunDirectory, AnEmptyOrRootOutputDirectoryIsRefused) {
  run("d", 5);
  expect_refused(sph({"run", kDamBreak, "--steps", "2", "-o", ""}), {"-o/--output: an empty directory name"});
  for (const char* root : {"/", "//", "/..", "/tmp/.."})
    expect_refused(sph({"run", kDamBreak, "--steps", "2", "-o", root}), {"is the root of the file system"});
  expect_refused(sph({"render", "d", "-o", ""}), {"-o/--output: an empty directory name"});
  expect_refused(sph({"render", "d", "-o", "/"}), {"is the root of the file system"});
  EXPECT_FALSE(fs::exists(at("d") / "render"));
  for (const char* command : {"bench", "validate", "compare"}) {
    std::vector<std::string> args{command};
    if (std::string(command) == "compare") args.push_back(kDamBreak);
    args.insert(args.end(), {"-o", ""});
    expect_refused(sph(args), {"-o/--output: an empty directory name"});
    args.back() = "/";
    expect_refused(sph(args), {"is the root of the file system"});
  }
}

// A directory that no run made (no run.json) but that holds files a run writes: the user's own
// scene.json beside which they ran `sph run scene.json -o .`, or a stats.csv of theirs. A run used
// to replace them without a word (the scene by the effective one, its "auto" and stopAt gone).
TEST_F(RunDirectory, AUsersOwnFilesThatARunWouldReplaceAreRefusedUnlessOverwrite) {
  fs::create_directories(at("mine"));
  fs::copy_file(kDamBreak, at("mine") / "scene.json");
  spit(at("mine") / "stats.csv", "my own table\n");
  fs::create_directories(at("mine") / "frames");
  spit(at("mine") / "frames" / "frame_000000.vtu", "my own frame");
  spit(at("mine") / "notes.txt", "mine");
  const auto before = files(at("mine"));
  CommandResult r = sph({"run", "mine/scene.json", "--steps", "2", "--no-progress", "-o", "mine"});
  expect_refused(r, {"mine: is not the directory of an earlier run (no run.json)",
                     "holds files a run writes (stats.csv, scene.json, frames/frame_000000.vtu)", "--overwrite"});
  EXPECT_EQ(files(at("mine")), before) << "nothing touched";
  // sph compare does not write among a run's files either.
  run("d", 5);
  const auto run_files = files(at("d"));
  expect_refused(sph({"compare", kDamBreak, "--steps", "2", "--no-progress", "-o", "d"}),
                 {"d: holds a run (run.json: sph run's output)"});
  EXPECT_EQ(files(at("d")), run_files);
  expect_refused(sph({"compare", kDamBreak, "--steps", "2", "-o", ""}), {"-o/--output: an empty directory name"});
  // An earlier run's directory is replaced as before; --overwrite allows the user's.
  run("d", 5);
  r = sph({"run", kDamBreak, "--steps", "2", "--no-progress", "-o", "mine", "--overwrite"});
  ASSERT_EQ(r.code, 0) << r.err;
  // It says which files it replaced: they are the user's, not an earlier run's.
  EXPECT_CONTAINS(r.err, "sph: replacing files a run writes in mine (stats.csv, scene.json, frames/frame_000000.vtu)");
  EXPECT_EQ(r.err.find("the earlier run's files"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(at("mine") / "notes.txt"), "mine") << "a file no run writes is kept";
  EXPECT_TRUE(fs::exists(at("mine") / "run.json"));
}

TEST_F(RunDirectory, SceneFilesThatAreNotScenesAreRefused) {
  expect_refused(sph({"run", "/dev/zero", "-o", "o"}), {"/dev/zero: is not a regular file"});
  ASSERT_EQ(::mkfifo(at("fifo.json").c_str(), 0600), 0);
  expect_refused(sph({"run", "fifo.json", "-o", "o"}), {"fifo.json: is not a regular file"});
  {
    std::ofstream big(at("big.json"));
    big << "{\"name\": \"big\"}";
  }
  fs::resize_file(at("big.json"), (std::uintmax_t{64} << 20) + 1);  // sparse: costs no disk
  expect_refused(sph({"run", "big.json", "-o", "o"}), {"big.json: the scene file is larger than 64 MiB"});
  EXPECT_FALSE(fs::exists(at("o")));
}

}  // namespace
