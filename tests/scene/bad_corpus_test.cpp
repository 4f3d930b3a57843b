// A corpus of realistic user mistakes: every tests/scene/bad/NAME.json holds one mistake and
// must be refused (by the reader, or when the simulation is built from it) with an sph::Error
// (never another exception, never accepted). NAME.expect lists what the message must say: one
// substring per non-empty line, all required (a sidecar file, because the strict reader
// refuses any extra key in the scene itself). tests/app/bad_input_test.cpp gives every file to
// `sph run` too.

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <string>
#include <typeinfo>
#include <vector>

#include <gtest/gtest.h>

#include <sph/core/error.h>
#include <sph/scene/builders.h>
#include <sph/scene/scene_reader.h>

namespace {

namespace fs = std::filesystem;

const fs::path kBadDir = fs::path(SPH_SOURCE_DIR) / "tests" / "scene" / "bad";

/// The stems of all bad/*.json files, sorted.
std::vector<std::string> bad_scene_names() {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(kBadDir, ec))
    if (e.path().extension() == ".json") names.push_back(e.path().stem().string());
  std::sort(names.begin(), names.end());
  return names;
}

std::vector<std::string> expected_substrings(const fs::path& file) {
  std::ifstream in(file);
  std::vector<std::string> out;
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (!line.empty()) out.push_back(line);
  }
  return out;
}

TEST(BadSceneCorpus, HasAtLeastThirtyFilesEachWithAnExpectation) {
  const auto names = bad_scene_names();
  EXPECT_GE(names.size(), 30u) << "in " << kBadDir;
  for (const auto& n : names) {
    const fs::path expect = kBadDir / (n + ".expect");
    EXPECT_TRUE(fs::is_regular_file(expect)) << "missing " << expect;
    EXPECT_FALSE(expected_substrings(expect).empty()) << expect << " lists no expected substring";
  }
  // And no orphan .expect file (a renamed scene would silently stop being tested).
  for (const auto& e : fs::directory_iterator(kBadDir)) {
    if (e.path().extension() == ".expect") {
      EXPECT_TRUE(fs::is_regular_file(kBadDir / (e.path().stem().string() + ".json"))) << "orphan " << e.path();
    }
  }
}

class BadScene : public testing::TestWithParam<std::string> {};

TEST_P(BadScene, IsRefusedWithTheExpectedMessage) {
  const fs::path scene = kBadDir / (GetParam() + ".json");
  const auto expected = expected_substrings(kBadDir / (GetParam() + ".expect"));
  ASSERT_FALSE(expected.empty());
  try {
    // Refused by the reader, or else when the particles are built (as `sph run` does).
    const sph::SceneDesc desc = sph::read_scene_file(scene.string());
    const bool f = desc.precision == sph::Precision::Float;
    if (desc.dimension == 2)
      f ? (void)sph::make_simulation<2, float>(desc) : (void)sph::make_simulation<2, double>(desc);
    else
      f ? (void)sph::make_simulation<3, float>(desc) : (void)sph::make_simulation<3, double>(desc);
    FAIL() << scene << " was accepted";
  } catch (const sph::Error& e) {
    const std::string what = e.what();
    for (const auto& s : expected)
      EXPECT_NE(what.find(s), std::string::npos) << "expected \"" << s << "\" in: " << what;
  } catch (const std::exception& e) {
    FAIL() << scene << " threw " << typeid(e).name() << " instead of sph::Error: " << e.what();
  }
}

INSTANTIATE_TEST_SUITE_P(Corpus, BadScene, testing::ValuesIn(bad_scene_names()),
                         [](const testing::TestParamInfo<std::string>& info) {
                           std::string n = info.param;
                           for (char& c : n)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return n;
                         });

}  // namespace
