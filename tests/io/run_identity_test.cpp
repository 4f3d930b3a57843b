// A run's identity (run id, scene fingerprint) and what a run directory says about its run:
// the functions of run_directory.h that `sph run` and `--resume` decide with.

#include <filesystem>
#include <set>
#include <string>

#include <unistd.h>

#include <gtest/gtest.h>

#include <sph/core/error.h>
#include <sph/io/checkpoint.h>
#include <sph/io/run_directory.h>

#include "support/expect.h"
#include "support/temp_dir.h"

namespace {

namespace fs = std::filesystem;
using sph::test::spit;
using sph::test::TempDir;

/// The message of the sph::Error that `f` throws ("" if none).
template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const sph::Error& e) {
    return e.what();
  }
  return "";
}

const std::string kScene =
    R"({"Configuration": {"numberOfSteps": 100, "timeStepSize": 0.0001}, "Fluid": {"stiffness": 1000}})";

TEST(RunIdentity, NewRunIdsAreDistinctAndSayWhenAndWhichProcess) {
  std::set<std::string> ids;
  for (int k = 0; k < 1000; ++k) ids.insert(sph::new_run_id());
  EXPECT_EQ(ids.size(), 1000u);
  const std::string id = *ids.begin();
  ASSERT_EQ(id.size(), 16u + 1 + std::to_string(::getpid()).size() + 1 + 8) << id;
  EXPECT_EQ(id[8], 'T');
  EXPECT_EQ(id[15], 'Z');
  EXPECT_EQ(id.substr(17, std::to_string(::getpid()).size()), std::to_string(::getpid()));
}

TEST(RunIdentity, TheFingerprintIgnoresTheNumberOfStepsAndKeyOrderButNothingElse) {
  const std::string fp = sph::scene_fingerprint(kScene);
  EXPECT_EQ(fp.size(), 16u);
  EXPECT_EQ(fp.find_first_not_of("0123456789abcdef"), std::string::npos) << fp;
  EXPECT_EQ(sph::scene_fingerprint(
                R"({"Fluid": {"stiffness": 1000}, "Configuration": {"timeStepSize": 0.0001, "numberOfSteps": 5}})"),
            fp);
  EXPECT_NE(sph::scene_fingerprint(
                R"({"Configuration": {"numberOfSteps": 100, "timeStepSize": 0.0002}, "Fluid": {"stiffness": 1000}})"),
            fp);
  EXPECT_NE(sph::scene_fingerprint(
                R"({"Configuration": {"numberOfSteps": 100, "timeStepSize": 0.0001}, "Fluid": {"stiffness": 1001}})"),
            fp);
}

// A resumed run reads its obstacles' meshes again: a mesh file changed since the run started would
// give it another obstacle, so the fingerprint covers the files' bytes.
TEST(RunIdentity, TheFingerprintCoversTheBytesOfTheMeshFilesTheSceneNames) {
  TempDir d;
  const fs::path mesh = d / "cube.obj";
  spit(mesh, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const std::string scene = R"({"Configuration": {"numberOfSteps": 100}, "Obstacles": [{"geometryFile": ")" +
                            mesh.string() + R"("}, {"start": [0, 0, 0], "end": [1, 1, 1]}]})";
  const std::string fp = sph::scene_fingerprint(scene);
  EXPECT_EQ(sph::scene_fingerprint(scene), fp);
  spit(mesh, "v 0 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\n");
  const std::string changed = sph::scene_fingerprint(scene);
  EXPECT_NE(changed, fp) << "a vertex moved";
  fs::remove(mesh);
  EXPECT_NE(sph::scene_fingerprint(scene), changed) << "the file is gone";
  EXPECT_NE(sph::scene_fingerprint(scene), fp);
}

TEST(RunIdentity, RenderOutputsAreOnlyNumberedPngFramesAndTheMovie) {
  for (const char* yes : {"frame_000000.png", "frame_123456789012.png", "movie.mp4"})
    EXPECT_TRUE(sph::is_render_output(yes)) << yes;
  for (const char* no : {"frame_12.png", "frame_holiday.png", "frame_000000.png.bak", "movie.mp4.txt",
                         "frame_000000.vtu", "notes.txt", "frame_0000000000000.png", "Movie.mp4"})
    EXPECT_FALSE(sph::is_render_output(no)) << no;
}

TEST(RunIdentity, CheckRunIdentityAcceptsItsOwnDirectoryAndNamesBothIdsOtherwise) {
  TempDir d;
  const sph::RunIdentity mine{"20260101T000000Z-1-00000001", sph::scene_fingerprint(kScene)};
  EXPECT_CONTAINS(error_of([&] { sph::check_run_identity(d.path(), mine); }), "run.json: missing");
  sph::write_run_identity(d.path(), mine);
  spit(d / "scene.json", kScene);
  EXPECT_NO_THROW(sph::check_run_identity(d.path(), mine));
  spit(d / "summary.json", R"({"run_id": "20260101T000000Z-1-00000001", "status": "completed", "steps": 3})");
  EXPECT_NO_THROW(sph::check_run_identity(d.path(), mine));

  const sph::RunIdentity other{"20260101T000000Z-2-00000002", mine.scene_fingerprint};
  EXPECT_CONTAINS(error_of([&] { sph::check_run_identity(d.path(), other); }),
                  "names run 20260101T000000Z-1-00000001; the checkpoint belongs to run 20260101T000000Z-2-00000002");
  sph::write_run_identity(d.path(), other);
  EXPECT_CONTAINS(error_of([&] { sph::check_run_identity(d.path(), other); }),
                  "summary.json: is the summary of run 20260101T000000Z-1-00000001");
  fs::remove(d / "summary.json");
  const sph::RunIdentity other_scene{other.run_id, "0123456789abcdef"};
  sph::write_run_identity(d.path(), other_scene);
  EXPECT_CONTAINS(
      error_of([&] { sph::check_run_identity(d.path(), other_scene); }),
      "scene.json: holds another scene, or a mesh file it names (geometryFile) changed since the run started "
      "(fingerprint " +
          mine.scene_fingerprint);
}

TEST(RunIdentity, AnUnfinishedRunIsACheckpointWithoutACompletedSummary) {
  TempDir d;
  EXPECT_FALSE(sph::unfinished_run(d.path()));
  EXPECT_FALSE(sph::read_run_end(d.path()));
  spit(d / sph::kCheckpointFile, "x");
  EXPECT_CONTAINS(sph::unfinished_run(d.path()).value_or(""), "no summary.json");
  spit(d / "summary.json", R"({"status": "failed: a blow-up", "steps": 7})");
  EXPECT_CONTAINS(sph::unfinished_run(d.path()).value_or(""), "failed: a blow-up");
  EXPECT_EQ(sph::read_run_end(d.path())->steps, 7);
  EXPECT_FALSE(sph::read_run_end(d.path())->finished());
  spit(d / "summary.json", R"({"status": "completed with warnings: Mach 0.4", "steps": 9})");
  EXPECT_FALSE(sph::unfinished_run(d.path()));
  EXPECT_TRUE(sph::read_run_end(d.path())->finished());
  spit(d / "summary.json", "not json");
  EXPECT_CONTAINS(error_of([&] { sph::read_run_end(d.path()); }), "cannot be read as a JSON object");
  EXPECT_CONTAINS(sph::unfinished_run(d.path()).value_or(""), "unreadable");
}

}  // namespace
