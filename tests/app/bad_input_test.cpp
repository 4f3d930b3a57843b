// Bad input through the program, as a user meets it: every scene of the bad-scene corpus
// (tests/scene/bad) given to `sph run` gives exit code 2, one error line naming what is wrong,
// no crash, and no output directory. Also: output paths nobody can write (even root), and a
// run that blows up (exit code 1, the step, the particle id and the quantity named, frames
// kept).

#include <algorithm>
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
using sph::test::TempDir;

const fs::path kBadDir = fs::path(SPH_SOURCE_DIR) / "tests" / "scene" / "bad";

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::size_t b = 0;
  for (std::size_t e; (e = text.find('\n', b)) != std::string::npos; b = e + 1) out.push_back(text.substr(b, e - b));
  if (b < text.size()) out.push_back(text.substr(b));
  return out;
}

TEST(BadInputThroughTheProgram, EveryCorpusSceneExits2WithOneErrorLineAndWritesNothing) {
  std::vector<fs::path> scenes;
  for (const auto& e : fs::directory_iterator(kBadDir))
    if (e.path().extension() == ".json") scenes.push_back(e.path());
  std::sort(scenes.begin(), scenes.end());
  ASSERT_GE(scenes.size(), 30u);
  TempDir tmp;
  for (const fs::path& scene : scenes) {
    SCOPED_TRACE(scene.filename().string());
    const CommandResult r =
        sph::test::run_sph({"run", scene.string(), "--no-progress", "-o", "out"}, tmp.path(), tmp / "err.txt");
    EXPECT_EQ(r.code, 2) << r.err;
    std::vector<std::string> errors;
    for (const auto& l : lines(r.err))
      if (l.rfind("sph: error:", 0) == 0) errors.push_back(l);
    EXPECT_EQ(errors.size(), 1u) << r.err;
    // The sidecar .expect file's first line is a substring the message must contain.
    const std::string expect = lines(slurp(fs::path(scene).replace_extension(".expect"))).at(0);
    EXPECT_CONTAINS(r.err, expect);
    EXPECT_EQ(r.err.find("terminate"), std::string::npos);
    EXPECT_FALSE(fs::exists(tmp / "out")) << "a refused scene creates no output directory";
  }
}

TEST(BadInputThroughTheProgram, OutputPathsNobodyCanWriteAreRefusedBeforeRunning) {
  // Paths where even root cannot create a directory (the tests may run as root, for whom
  // permission bits do not apply): inside /proc, and below a regular file.
  TempDir tmp;
  sph::test::spit(tmp / "a_file", "x");
  for (const std::string& out : {std::string("/proc/sph-cannot-write-here"), (tmp / "a_file" / "sub").string()}) {
    SCOPED_TRACE(out);
    const CommandResult r =
        sph::test::run_sph({"run", kDamBreak, "--steps", "2", "--no-progress", "-o", out}, tmp.path(), tmp / "e.txt");
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_CONTAINS(r.err, out);
    EXPECT_CONTAINS(r.err, "cannot create the output directory");
    EXPECT_EQ(r.err.find("done"), std::string::npos) << "nothing ran";
  }
}

TEST(BadInputThroughTheProgram, AParticleCountBeyondTheMachinesMemoryIsRefusedBeforeAllocating) {
  // 1.18e9 particles (below the reader's 2e9 cap): about 360 GB, more than any test machine has.
  TempDir tmp;
  for (const std::string cmd : {"run", "compare"}) {
    SCOPED_TRACE(cmd);
    const CommandResult r = sph::test::run_sph(
        {cmd, SPH_SOURCE_DIR "/scenes/paper/block_3d.json", "--set", "Configuration.particleRadius=0.00015", "--set",
         "Configuration.kernelRadius=0.0006", "--set", "Configuration.timeStepSize=1e-6", "--no-progress", "-o", "o"},
        tmp.path(), tmp / "e.txt");
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_CONTAINS(r.err, "the scene holds up to 1183408074 particles");
    EXPECT_CONTAINS(r.err, "GB of memory");
    EXPECT_FALSE(fs::exists(tmp / "o"));
  }
}

TEST(BlowUp, StopsInTheStepNamingStepParticleAndQuantityAndKeepsTheFrames) {
  // 30 km/s: 750 times the sound speed sqrt(1600) = 40 m/s. The health monitor fails a supersonic
  // step (Mach above 1), which replaced the old blow-up limit of 20 sound speeds plus free fall.
  TempDir tmp;
  const CommandResult r = sph::test::run_sph(
      {"run", kDamBreak, "--set", "FluidBlocks[0].velocity=[30000,0]", "--steps", "50", "--no-progress", "-o", "o"},
      tmp.path(), tmp / "e.txt");
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_CONTAINS(r.err, "went supersonic at step 1");
  EXPECT_CONTAINS(r.err, "particle id ");
  EXPECT_CONTAINS(r.err, "Mach 750");
  EXPECT_CONTAINS(r.err, "Fluid.stiffness >= (10 v)^2");
  EXPECT_CONTAINS(r.err, "frames written before the failure are kept");
  EXPECT_TRUE(fs::is_regular_file(tmp / "o" / "frames" / "frame_000000.vtu"));
  EXPECT_TRUE(fs::is_regular_file(tmp / "o" / "stats.csv"));
  const auto summary = nlohmann::json::parse(slurp(tmp / "o" / "summary.json"));
  EXPECT_CONTAINS(summary.at("status").get<std::string>(), "failed: simulation went supersonic at step 1");
}

}  // namespace
