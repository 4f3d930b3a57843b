// The physics corpus (tests/app/trust/, format in tests/app/trust/README.md): physically bad or
// fragile scenes run through `sph run`, each with the verdict it must get (NAME.expect):
//   refused    exit 2, one `sph: error:` line holding every `message:`, no output directory;
//   failed     exit 1, summary.json status "failed: ..." holding every message;
//   warned     exit 0, status "completed with warnings: ..." holding every message;
//   completed  exit 0, status "completed".
// Independently of the health monitor, the frames the run wrote are read back and checked: if any
// holds a particle outside the container (by more than the monitor's documented tolerance,
// kOutsideTolerance spacings: half a spacing) or faster than the sound speed sqrt(Fluid.stiffness), the status
// must not be plain "completed".

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sph/io/frames.h>
#include <sph/solver/health.h>

#include "support/expect.h"
#include "support/run_sph.h"

namespace {

namespace fs = std::filesystem;
using sph::test::CommandResult;
using sph::test::error_lines;
using sph::test::slurp;
using sph::test::TempDir;

const fs::path kTrustDir = fs::path(SPH_SOURCE_DIR) / "tests" / "app" / "trust";

struct Expectation {
  std::string verdict;
  std::vector<std::string> messages;
  std::vector<std::string> args;
  std::string why;
};

std::string trim(const std::string& s) {
  const std::size_t b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return {};
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

/// Reads NAME.expect; a line it does not know fails the test (a typo must not pass silently).
Expectation read_expect(const fs::path& file) {
  Expectation e;
  std::istringstream in(slurp(file));
  for (std::string line; std::getline(in, line);) {
    if (trim(line).empty()) continue;
    const std::size_t colon = line.find(':');
    EXPECT_NE(colon, std::string::npos) << file << ": " << line;
    if (colon == std::string::npos) continue;
    const std::string key = trim(line.substr(0, colon)), value = trim(line.substr(colon + 1));
    if (key == "verdict")
      e.verdict = value;
    else if (key == "message")
      e.messages.push_back(value);
    else if (key == "why")
      e.why = value;
    else if (key == "args") {
      std::istringstream words(value);
      for (std::string w; words >> w;) e.args.push_back(w);
    } else
      ADD_FAILURE() << file << ": unknown key \"" << key << "\"";
  }
  return e;
}

/// What the frames of a run show, checked against the effective scene (scene.json).
struct FrameCheck {
  std::size_t frames = 0;
  std::size_t outside = 0;  // particles outside the container (beyond the tolerance), over all frames
  double max_mach = 0;
};

FrameCheck check_frames(const fs::path& dir) {
  FrameCheck check;
  const auto scene = nlohmann::json::parse(slurp(dir / "scene.json"));
  const auto lo = scene.at("Container").at("start").get<std::vector<double>>();
  const auto hi = scene.at("Container").at("end").get<std::vector<double>>();
  const double c0 = std::sqrt(scene.at("Fluid").at("stiffness").get<double>());
  const double tol = sph::kOutsideTolerance * 2.0 * scene.at("Configuration").at("particleRadius").get<double>();
  std::vector<fs::path> files;  // one format's files: the first of vtu, vtk, ply the run wrote
  for (const char* ext : {".vtu", ".vtk", ".ply"}) {
    for (const auto& e : fs::directory_iterator(dir / "frames"))
      if (e.path().extension() == ext) files.push_back(e.path());
    if (!files.empty()) break;
  }
  std::sort(files.begin(), files.end());
  for (const fs::path& f : files) {
    const sph::FrameData frame = sph::read_frame(f);
    ++check.frames;
    for (std::size_t i = 0; i < frame.size; ++i)
      for (std::size_t d = 0; d < lo.size(); ++d) {
        const double x = frame.position[3 * i + d];
        if (x < lo[d] - tol || x > hi[d] + tol) {
          ++check.outside;
          break;
        }
      }
    const sph::FrameField* v = frame.field("velocity");
    EXPECT_NE(v, nullptr) << f << " holds no velocity";
    if (!v) continue;
    for (std::size_t i = 0; i < frame.size; ++i) {
      double v2 = 0;
      for (int d = 0; d < v->components; ++d) v2 += v->values[i * v->components + d] * v->values[i * v->components + d];
      check.max_mach = std::max(check.max_mach, std::sqrt(v2) / c0);
    }
  }
  return check;
}

std::vector<fs::path> corpus() {
  std::vector<fs::path> scenes;
  for (const auto& e : fs::directory_iterator(kTrustDir))
    if (e.path().extension() == ".json") scenes.push_back(e.path());
  std::sort(scenes.begin(), scenes.end());
  return scenes;
}

void run_one(const fs::path& scene, const fs::path& work, std::map<std::string, int>& verdicts) {
  const std::string name = scene.stem().string();
  SCOPED_TRACE(name);
  const fs::path expect_file = fs::path(scene).replace_extension(".expect");
  ASSERT_TRUE(fs::is_regular_file(expect_file)) << "every corpus scene has its NAME.expect";
  const Expectation e = read_expect(expect_file);
  EXPECT_FALSE(e.why.empty()) << "a corpus scene says why it is there (why: ...)";
  ++verdicts[e.verdict];
  std::vector<std::string> args = {"run", scene.string(), "--no-progress", "--threads", "1", "-o", name};
  args.insert(args.end(), e.args.begin(), e.args.end());
  const CommandResult r = sph::test::run_sph(args, work, work / (name + ".err"));
  EXPECT_EQ(r.err.find("terminate"), std::string::npos) << r.err;
  const fs::path dir = work / name;
  if (e.verdict == "refused") {
    EXPECT_EQ(r.code, 2) << r.err;
    const std::vector<std::string> errors = error_lines(r.err);
    EXPECT_EQ(errors.size(), 1u) << r.err;
    for (const std::string& m : e.messages) EXPECT_CONTAINS(errors.empty() ? r.err : errors[0], m);
    EXPECT_FALSE(fs::exists(dir)) << "a refused scene creates no output directory";
    return;
  }
  ASSERT_TRUE(e.verdict == "failed" || e.verdict == "warned" || e.verdict == "completed")
      << "verdict \"" << e.verdict << "\" is not one of refused, failed, warned, completed";
  EXPECT_EQ(r.code, e.verdict == "failed" ? 1 : 0) << r.err;
  ASSERT_TRUE(fs::is_regular_file(dir / "summary.json")) << r.err;
  const std::string status = nlohmann::json::parse(slurp(dir / "summary.json")).at("status").get<std::string>();
  if (e.verdict == "failed") {
    EXPECT_EQ(status.rfind("failed:", 0), 0u) << status;
    EXPECT_EQ(error_lines(r.err).size(), 1u) << r.err;
  } else if (e.verdict == "warned") {
    EXPECT_EQ(status.rfind("completed with warnings", 0), 0u) << status;
    EXPECT_CONTAINS(r.err, "sph: warning:");
  } else {
    EXPECT_EQ(status, "completed");
  }
  for (const std::string& m : e.messages) EXPECT_CONTAINS(status, m);
  // The independent check: what the frames show.
  const FrameCheck frames = check_frames(dir);
  EXPECT_GE(frames.frames, 1u);
  if (frames.outside > 0 || frames.max_mach > 1.0) {
    EXPECT_NE(status, "completed") << frames.outside << " particles outside the container in the frames, max Mach "
                                   << frames.max_mach;
  }
}

TEST(TrustCorpus, EverySceneGetsItsVerdictAndNoneEndsCompletedOutsideOrSupersonic) {
  const std::vector<fs::path> scenes = corpus();
  ASSERT_GE(scenes.size(), 20u);
  TempDir tmp;
  std::map<std::string, int> verdicts;
  for (const fs::path& scene : scenes) run_one(scene, tmp.path(), verdicts);
  // The corpus holds scenes of each kind that runs (refused ones come from the preflight).
  EXPECT_GE(verdicts["failed"], 5);
  EXPECT_GE(verdicts["warned"], 3);
  EXPECT_GE(verdicts["completed"], 3);
}

TEST(TrustCorpus, EveryExpectFileHasItsScene) {
  for (const auto& e : fs::directory_iterator(kTrustDir))
    if (e.path().extension() == ".expect") {
      EXPECT_TRUE(fs::is_regular_file(fs::path(e.path()).replace_extension(".json"))) << e.path();
    }
}

}  // namespace
