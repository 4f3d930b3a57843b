// Messages that are true (issue 15, item 5), and scene values that a flag overrides still
// checked (item 3): each message is checked against what the program does, and each sentence
// of the docs that described it against the docs.

#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

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

class TrueMessages : public testing::Test {
 protected:
  CommandResult sph(const std::vector<std::string>& args) {
    return sph::test::run_sph(args, tmp_.path(), tmp_ / "stderr.txt");
  }
  fs::path at(const std::string& name) const { return tmp_ / name; }
  static std::string doc(const std::string& name) { return slurp(fs::path(SPH_SOURCE_DIR) / name); }
  /// The 2D dam break with `patch` merged into it, written to NAME.
  std::string scene_with(const std::string& name, const nlohmann::json& patch) {
    nlohmann::json j = nlohmann::json::parse(slurp(kDamBreak));
    j.merge_patch(patch);
    spit(at(name), j.dump(2));
    return name;
  }
  static void expect_refused(const CommandResult& r, const std::vector<std::string>& texts) {
    EXPECT_EQ(r.code, 2) << r.err;
    for (const auto& t : texts) EXPECT_CONTAINS(r.err, t);
  }

  TempDir tmp_;
};

TEST_F(TrueMessages, FrameRateRangeIsSaidInWordsNotWithTheLimitsOfADouble) {
  for (const char* fps : {"0", "-1", "abc", "inf"}) {
    SCOPED_TRACE(fps);
    const CommandResult r = sph({"run", kDamBreak, "--fps", fps, "-o", "o"});
    expect_refused(r, {"--fps", "expected a positive number (a frame rate in frames per simulated second), got"});
    EXPECT_LT(r.err.size(), 400u) << r.err;
    EXPECT_EQ(r.err.find("00000000"), std::string::npos) << r.err;
  }
  EXPECT_FALSE(fs::exists(at("o")));
}

TEST_F(TrueMessages, TheClosingHintsPointOnlyAtFilesThatWereWritten) {
  CommandResult r = sph({"run", kDamBreak, "--steps", "3", "--every", "0", "--no-progress", "-o", "none"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_FALSE(fs::exists(at("none") / "frames.pvd"));
  EXPECT_EQ(r.err.find("frames.pvd"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("sph render"), std::string::npos) << r.err;
  r = sph({"run", kDamBreak, "--steps", "3", "--no-progress", "-o", "some"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_CONTAINS(r.err, "some/frames.pvd");
  EXPECT_TRUE(fs::exists(at("some") / "frames.pvd"));
}

// In ParaView, Point Gaussian is a representation (the Representation menu), not a filter.
TEST_F(TrueMessages, PointGaussianIsARepresentation) {
  const CommandResult r = sph({"run", kDamBreak, "--steps", "2", "--no-progress", "-o", "o"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_CONTAINS(r.err, "Representation: Point Gaussian");
  for (const char* f : {"README.md", "docs/visualization.md"}) {
    EXPECT_EQ(doc(f).find("Filters > Point Gaussian"), std::string::npos) << f;
    EXPECT_EQ(doc(f).find("apply *Point Gaussian*"), std::string::npos) << f;
    EXPECT_CONTAINS(doc(f), "*Point Gaussian* representation");
  }
  EXPECT_EQ(r.err.find("Filters"), std::string::npos) << r.err;
}

// Off a terminal (as here: stderr is a file) the progress is a line every 10 %, as README says.
TEST_F(TrueMessages, ProgressOffATerminalIsALineEveryTenPercentAsTheReadmeSays) {
  const CommandResult r = sph({"run", kDamBreak, "--steps", "20", "-o", "o"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_CONTAINS(r.err, "progress:  10%");
  EXPECT_CONTAINS(r.err, "progress: 100%");
  EXPECT_EQ(r.err.find('\r'), std::string::npos) << "no bar redrawn in place";
  const CommandResult quiet = sph({"run", kDamBreak, "--steps", "20", "--no-progress", "-o", "o"});
  EXPECT_EQ(quiet.err.find("progress:"), std::string::npos) << quiet.err;
  EXPECT_CONTAINS(doc("README.md"),
                  "| `--no-progress` | no progress output (by default a bar with ETA on a terminal, "
                  "a line every 10 % otherwise) |");
}

TEST_F(TrueMessages, AUtf16OrNonUtf8SceneIsNamedAsSuch) {
  spit(at("le.json"), std::string("\xFF\xFE{\0}\0", 6));
  expect_refused(sph({"run", "le.json", "-o", "o"}), {"le.json: the scene file is UTF-16", "save it as UTF-8"});
  spit(at("be.json"), std::string("\xFE\xFF\0{\0}", 6));
  expect_refused(sph({"run", "be.json", "-o", "o"}), {"be.json: the scene file is UTF-16", "save it as UTF-8"});
  spit(at("nobom.json"), std::string("{\0\n\0}\0", 6));
  expect_refused(sph({"run", "nobom.json", "-o", "o"}), {"holds NUL bytes", "UTF-16", "save it as UTF-8"});
  spit(at("latin1.json"), "{\n  \"name\": \"caf\xE9\"\n}\n");
  expect_refused(sph({"run", "latin1.json", "-o", "o"}),
                 {"latin1.json: the scene file is not UTF-8 text: byte 0xE9 at line 2:15", "save it as UTF-8"});
  EXPECT_FALSE(fs::exists(at("o")));
  // A UTF-8 byte-order mark is UTF-8: still read.
  spit(at("bom8.json"), "\xEF\xBB\xBF" + slurp(kDamBreak));
  EXPECT_EQ(sph({"run", "bom8.json", "--steps", "1", "--no-progress", "-o", "o"}).code, 0);
}

TEST_F(TrueMessages, ValuesAFlagOverridesAreStillChecked) {
  const std::string steps = scene_with("steps.json", {{"Configuration", {{"numberOfSteps", "abc"}}}});
  expect_refused(sph({"run", steps, "--steps", "10", "-o", "o"}),
                 {"Configuration.numberOfSteps: expected a number of steps", "string \"abc\"",
                  "the value in the scene file, which a flag overrides"});
  expect_refused(sph({"run", steps, "--set", "Configuration.numberOfSteps=10", "-o", "o"}),
                 {"Configuration.numberOfSteps", "string \"abc\""});
  const std::string mode = scene_with("mode.json", {{"Configuration", {{"neighbors", "adaptve"}}}});
  expect_refused(sph({"run", mode, "--neighbors", "standard", "-o", "o"}),
                 {"Configuration.neighbors: unknown value \"adaptve\"", "the value in the scene file"});
  const std::string every = scene_with("every.json", {{"Configuration", {{"outputEveryNSteps", -3}}}});
  expect_refused(sph({"run", every, "--every", "5", "-o", "o"}), {"Configuration.outputEveryNSteps", "got -3"});
  EXPECT_FALSE(fs::exists(at("o")));
  // A valid value in the file is overridden as before.
  const CommandResult ok = sph({"run", kDamBreak, "--steps", "2", "--no-progress", "-o", "o"});
  ASSERT_EQ(ok.code, 0) << ok.err;
  EXPECT_EQ(nlohmann::json::parse(slurp(at("o") / "summary.json")).at("steps"), 2);
  // A key the file does not have can be given by a flag.
  ASSERT_EQ(
      sph({"run", kDamBreak, "--steps", "2", "--set", "Configuration.verletSkin=0.001", "--no-progress", "-o", "o"})
          .code,
      0);
}

TEST_F(TrueMessages, TheVerletSkinMessageSaysTheRangeItChecksAndOnlyInVerletMode) {
  // The dam break's h is 0.02 m: a skin of 0.1 m is over 2 h.
  const CommandResult r =
      sph({"run", kDamBreak, "--neighbors", "verlet", "--set", "Configuration.verletSkin=0.1", "-o", "o"});
  expect_refused(r, {"Configuration.verletSkin", "more than twice h", "at most 2 h"});
  EXPECT_EQ(r.err.find("between 0.05 h and 0.5 h"), std::string::npos) << r.err;
  EXPECT_CONTAINS(doc("docs/scene-format.md"), "> 0 and at most 2 h");
  // In the other modes the skin is not used: no message about lists it does not make.
  const CommandResult standard = sph({"run", kDamBreak, "--neighbors", "standard", "--set",
                                      "Configuration.verletSkin=0.1", "--steps", "2", "--no-progress", "-o", "o"});
  EXPECT_EQ(standard.code, 0) << standard.err;
  EXPECT_EQ(standard.err.find("verletSkin"), std::string::npos) << standard.err;
}

TEST_F(TrueMessages, AnEmitterHeightIsRefusedIn2DAsTheDocsSay) {
  const CommandResult r = sph({"run", kDamBreak, "--set",
                               "Emitters=[{\"translation\":[0.5,0.5],\"direction\":[1,0],\"velocity\":1,\"width\":4,"
                               "\"height\":4,\"maxParticles\":10}]",
                               "-o", "o"});
  expect_refused(r, {"Emitters[0].height: not a key of a 2D emitter", "a line of `width` particles"});
  EXPECT_EQ(doc("docs/physics.md").find("ignored in 2D"), std::string::npos);
  EXPECT_CONTAINS(doc("docs/scene-format.md"), "| `height` | particles | required in 3D, refused in 2D |");
}

TEST_F(TrueMessages, TheCompareReportCallsTheStandardRunTheReference) {
  const CommandResult r = sph({"compare", kDamBreak, "--steps", "20", "--modes", "adaptive", "--frames", "1", "--set",
                               "FluidBlocks[0].end=[0.2,0.4]", "-o", "cmp", "--no-progress"});
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string report = slurp(at("cmp") / "report.md");
  std::size_t references = 0;
  for (std::size_t p = report.find("\n| standard |"); p != std::string::npos;
       p = report.find("\n| standard |", p + 1)) {
    const std::string row = report.substr(p + 1, report.find('\n', p + 1) - p - 1);
    EXPECT_EQ(row.find("| 1.00x |"), std::string::npos) << row;
    EXPECT_EQ(row.find("| 1.00 |"), std::string::npos) << row;
    references += row.find("| reference |") != std::string::npos ? 1 : 0;
  }
  EXPECT_EQ(references, 2u) << "the speed and the kinetic energy tables\n" << report;
  EXPECT_CONTAINS(report, "x |");  // the other runs keep their ratio
  // The summary on the screen says the same: the first line (standard) is the reference, not a
  // ratio of its own against the standard runs' mean.
  const std::string first = r.out.substr(0, r.out.find('\n'));
  EXPECT_CONTAINS(first, "standard");
  EXPECT_CONTAINS(first, "s  reference");
  EXPECT_EQ(first.find("x  "), std::string::npos) << first;
  EXPECT_CONTAINS(r.out, "x  RMS divergence");  // (adaptive's line keeps its ratio)
}

}  // namespace
