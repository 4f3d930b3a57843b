// data_dir(): an installed program finds <prefix>/share/sph from its own location, a program in
// the build tree the source tree named next to it (sph-data-dir.txt), $SPH_DATA_DIR overrides
// both, and a program that has neither gets one error naming where it looked.

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include <sph/core/data_dir.h>
#include <sph/core/error.h>

#include "support/temp_dir.h"

namespace sph {
namespace {

namespace fs = std::filesystem;

void write_text(const fs::path& file, const std::string& text) {
  fs::create_directories(file.parent_path());
  std::ofstream(file) << text;
}

TEST(DataDir, AnInstalledProgramFindsTheShareDirectoryOfItsPrefix) {
  test::TempDir prefix;
  fs::create_directories(prefix / "share/sph/scenes/paper");
  write_text(prefix / "bin/sph", "");
  EXPECT_EQ(detail::find_data_dir(prefix / "bin/sph", nullptr), prefix / "share/sph");
}

TEST(DataDir, TheInstalledLayoutComesBeforeTheBuildTreeFile) {
  test::TempDir prefix;
  test::TempDir source;
  fs::create_directories(prefix / "share/sph/scenes");
  fs::create_directories(source / "scenes");
  write_text(prefix / "bin/sph-data-dir.txt", source.path().string() + "\n");
  EXPECT_EQ(detail::find_data_dir(prefix / "bin/sph", nullptr), prefix / "share/sph");
}

TEST(DataDir, AProgramInTheBuildTreeFindsTheSourceTreeNamedNextToIt) {
  test::TempDir build;
  test::TempDir source;
  fs::create_directories(source / "scenes/validation");
  write_text(build / "tests/sph-data-dir.txt", source.path().string() + "\n");
  EXPECT_EQ(detail::find_data_dir(build / "tests/test_core", nullptr), source.path());
}

TEST(DataDir, TheEnvironmentVariableOverridesBothAndMustHoldScenes) {
  test::TempDir prefix;
  test::TempDir mine;
  fs::create_directories(prefix / "share/sph/scenes");
  fs::create_directories(mine / "scenes");
  EXPECT_EQ(detail::find_data_dir(prefix / "bin/sph", mine.path().c_str()), mine.path());
  // An empty value counts as unset.
  EXPECT_EQ(detail::find_data_dir(prefix / "bin/sph", ""), prefix / "share/sph");
  try {
    detail::find_data_dir(prefix / "bin/sph", prefix.path().c_str());  // no scenes/ directly in it
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.where(), "SPH_DATA_DIR");
    EXPECT_NE(e.message().find(prefix.path().string()), std::string::npos) << e.what();
  }
}

TEST(DataDir, NoDataIsOneErrorNamingEveryPlaceLookedAt) {
  test::TempDir elsewhere;
  write_text(elsewhere / "bin/sph-data-dir.txt", (elsewhere / "gone").string() + "\n");
  try {
    detail::find_data_dir(elsewhere / "bin/sph", nullptr);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find((elsewhere / "share/sph").string()), std::string::npos) << m;
    EXPECT_NE(m.find((elsewhere / "gone").string()), std::string::npos) << m;
    EXPECT_NE(m.find("SPH_DATA_DIR"), std::string::npos) << m;
  }
}

TEST(DataDir, ThisTestProgramFindsTheRepositoryScenes) {
  // build/tests/test_core reads build/tests/sph-data-dir.txt, which names the source tree.
  if (std::getenv("SPH_DATA_DIR") != nullptr) GTEST_SKIP() << "SPH_DATA_DIR is set";
  EXPECT_EQ(fs::canonical(data_dir()), fs::canonical(SPH_SOURCE_DIR));
  EXPECT_TRUE(fs::is_regular_file(scene_dir("paper") / "tank_fill_3d.json"));
  EXPECT_TRUE(fs::is_directory(scene_dir("validation")));
  EXPECT_THROW(scene_dir("no_such_set"), Error);
}

}  // namespace
}  // namespace sph
