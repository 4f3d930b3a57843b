// The `sph` program as a user meets it: exit codes, messages on stderr, and what it does (and
// does not do) to the output directory. Each test runs the built binary from its own temporary
// directory.

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include <unistd.h>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/expect.h"
#include "support/run_sph.h"
#include "support/scenes.h"

namespace {

using sph::test::kDamBreak;

namespace fs = std::filesystem;

const std::string kBadScene = SPH_SOURCE_DIR "/tests/scene/bad/typo_optional_key_viscosity.json";  // Fluid.viscosty

std::string read_file(const fs::path& p) { return sph::test::slurp(p); }
void write_file(const fs::path& p, const std::string& text) { sph::test::spit(p, text); }

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto pos = text.find(what); pos != std::string::npos; pos = text.find(what, pos + what.size())) ++n;
  return n;
}

using Result = sph::test::CommandResult;

class Cli : public testing::Test {
 protected:
  void SetUp() override {
    const auto* info = testing::UnitTest::GetInstance()->current_test_info();
    root_ = fs::temp_directory_path() / ("sph_cli_test_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(root_);
    work_ = root_ / "work";
    fs::create_directories(work_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(root_, ec);
  }

  /// Runs `sph ARGS...` in work_ (the arguments are passed verbatim, not through word splitting),
  /// with `env_prefix` (e.g. "env -u VAR") in front of the binary.
  Result sph(const std::vector<std::string>& args, const std::string& env_prefix = "") {
    return sph::test::run_sph(args, work_, root_ / "stderr.txt", env_prefix);
  }

  /// A completed 5-step run of the 2D dam break into work_/DIR.
  void good_run(const std::string& dir) {
    const Result r = sph({"run", kDamBreak, "--steps", "5", "--threads", "2", "--no-progress", "-o", dir});
    ASSERT_EQ(r.code, 0) << r.err;
    ASSERT_TRUE(fs::is_regular_file(work_ / dir / "summary.json")) << r.err;
  }

  fs::path root_;
  fs::path work_;
};

// ---------------------------------------------------------------------------------------------
// Version and help

TEST_F(Cli, Version) {
  const Result r = sph({"--version"});
  EXPECT_EQ(r.code, 0);
  EXPECT_CONTAINS(r.out + r.err, "sph 0.1.0");
}

TEST_F(Cli, TopLevelHelp) {
  const Result r = sph({"--help"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_CONTAINS(r.out, "Usage: sph");
  EXPECT_CONTAINS(r.out, "run");
  EXPECT_CONTAINS(r.out, "--version");
  EXPECT_TRUE(r.err.empty()) << r.err;
}

TEST_F(Cli, RunHelp) {
  const Result r = sph({"run", "--help"});
  EXPECT_EQ(r.code, 0) << r.err;
  for (const char* opt : {"--neighbors", "--set", "--steps", "--threads", "--output", "--no-progress", "--format",
                          "--fields", "--every", "--fps"})
    EXPECT_CONTAINS(r.out, opt);
  EXPECT_CONTAINS(r.out, "Fluid.stiffness=2000");
}

// `sph --help` lists the subcommands only; a user looking for --neighbors or --set must know to
// ask `sph run --help`.
TEST_F(Cli, TopLevelHelpMentionsRunOptions) {
  const Result r = sph({"--help"});
  EXPECT_CONTAINS(r.out, "--neighbors");
  EXPECT_CONTAINS(r.out, "--set");
}

// ---------------------------------------------------------------------------------------------
// Flags

TEST_F(Cli, NoArgumentsFails) {
  const Result r = sph({});
  EXPECT_NE(r.code, 0);
  EXPECT_EQ(r.code, 2);
  EXPECT_CONTAINS(r.err, "sph: error:");
  EXPECT_CONTAINS(r.err, "sph --help");
}

TEST_F(Cli, RunWithoutSceneFails) {
  const Result r = sph({"run"});
  EXPECT_EQ(r.code, 2);
  EXPECT_CONTAINS(r.err, "scene");
}

TEST_F(Cli, UnknownFlagGivesOneMessage) {
  const std::vector<std::vector<std::string>> cases = {
      {"run", kDamBreak, "--bogus"}, {"--bogus", "run", kDamBreak}, {"run", kDamBreak, "-x"}};
  for (const auto& args : cases) {
    const Result r = sph(args);
    EXPECT_EQ(r.code, 2);
    EXPECT_EQ(count(r.err, "sph: error:"), 1u) << r.err;
    EXPECT_CONTAINS(r.err, args.back() == "-x" ? "-x" : "--bogus");
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
  EXPECT_FALSE(fs::exists(work_ / "out"));
}

// `sph --bogus` says only "A subcommand is required" and `sph run --bogus` only "scene is
// required": the unknown flag the user typed is not named.
TEST_F(Cli, UnknownFlagAloneIsNamed) {
  for (const std::vector<std::string>& args : {std::vector<std::string>{"--bogus"}, {"run", "--bogus"}}) {
    const Result r = sph(args);
    EXPECT_EQ(r.code, 2);
    EXPECT_CONTAINS(r.err, "--bogus");
  }
}

// A mistyped command, a value that is not a number, a file where a directory is expected: each
// named as what it is (CLI11 said "A subcommand is required", "Value abc not in range 0 to
// 1000000000000", and sph "no such directory" for an existing file).
TEST_F(Cli, MistypedCommandsAndValuesAreNamedAsWhatTheyAre) {
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases{
      {{"rnu", kDamBreak},
       "unknown command \"rnu\" (did you mean \"run\"?); expected one of: run, compare, bench, validate, render, "
       "view, surface"},
      {{}, "expected a command: run, compare, bench, validate, render, view, surface"},
      {{"run", "--neighbours", "adaptive", "x.json"}, "unknown option --neighbours (did you mean --neighbors?)"},
      {{"render", "r", "--colour-by", "speed"}, "unknown option --colour-by (did you mean --color-by?)"},
      {{"--verison"}, "unknown option --verison (did you mean --version?)"},
      {{"run", "x.json", "extra_arg"},
       "unexpected argument extra_arg; sph run takes only the arguments its help lists"},
      {{"run", kDamBreak, "--every", "abc"}, "--every: expected a whole number from 0 to"},
      {{"run", kDamBreak, "--threads", "two"}, "--threads: expected a whole number from 1 to 4096, got \"two\""},
      {{"run", kDamBreak, "--steps", "5.5"}, "--steps: expected a whole number from 1 to"},
      {{"run", kDamBreak, "--threads", "0"}, "--threads: expected a whole number from 1 to 4096, got 0"},
      {{"render", "afile"}, "afile: is a file, not a directory; expected a run directory"},
      {{"view", "afile"}, "afile: is a file, not a directory; expected a run directory"},
      {{"run", "--resume", "afile"},
       "afile: is a file, not a directory; expected the output directory of an earlier run"},
      {{"view", "nowhere", "-o", ""}, "-o/--output: an empty file name"},
      {{"run", kDamBreak, "--steps", "2", "-o", "afile/out/deeper"},
       "cannot create the output directory: afile is a file, not a directory; expected a directory path for the "
       "run's output"},
      {{"bench", "--suite", "neighbors", "-o", "afile/b"},
       "cannot create the output directory: afile is a file, not a directory; expected a directory path for the "
       "benchmark results"},
      // A missing argument or value, in words (CLI11 said "scene is required", "--output: 1
      // required TEXT missing" and "--neighbors: adaptiv not in {standard,adaptive,...}").
      {{"compare"}, "sph compare needs SCENE: scene file (JSON; see docs/scene-format.md)"},
      {{"render"}, "sph render needs DIR: a run's output directory (sph run -o DIR)"},
      {{"surface"}, "sph surface needs DIR: a run's output directory (sph run -o DIR)"},
      {{"run", kDamBreak, "-o"}, "--output needs a value: output directory (default: out/<scene name>)"},
      {{"run", kDamBreak, "--threads"}, "--threads needs a value: worker threads (default: all cores)"},
      {{"run", kDamBreak, "--neighbors", "adaptiv"},
       "--neighbors: unknown neighbor mode \"adaptiv\" (did you mean \"adaptive\"?); expected one of \"standard\""},
      {{"compare", kDamBreak, "--modes", "verlte"}, "unknown neighbor mode \"verlte\" (did you mean \"verlet\"?)"},
      {{"run", kDamBreak, "--fields", "none,id"},
       "--fields: \"none\" (positions only) cannot be combined with other names; give it alone, or list the ones "
       "wanted from velocity, density"},
      {{"run", kDamBreak, "--fields", "vel"}, ", or none alone (positions only)"},
      // Every vocabulary suggests the name a misspelling was probably meant to be.
      {{"validate", "--cases", "hydrostatc"}, "--cases: unknown case \"hydrostatc\" (did you mean \"hydrostatic\"?)"},
      {{"bench", "--suite", "stpes"}, "--suite: unknown suite \"stpes\" (did you mean \"steps\"?)"},
      {{"bench", "--size", "larg"}, "--size: unknown size \"larg\" (did you mean \"large\"?)"},
      {{"bench", "--precision", "flaot"}, "--precision: unknown precision \"flaot\" (did you mean \"float\"?)"},
      {{"render", ".", "--colormap", "virdis"}, "--colormap: unknown color map \"virdis\" (did you mean \"viridis\"?)"},
      {{"render", ".", "--color-by", "spede"}, "--color-by: unknown quantity \"spede\" (did you mean \"speed\"?)"},
      {{"view", ".", "--color-by", "densty"}, "--color-by: unknown quantity \"densty\" (did you mean \"density\"?)"},
  };
  std::ofstream(work_ / "afile") << "x";
  for (const auto& [args, message] : cases) {
    const Result r = sph(args);
    EXPECT_EQ(r.code, 2) << message;
    EXPECT_EQ(count(r.err, "sph: error:"), 1u) << r.err;
    EXPECT_CONTAINS(r.err, message);
  }
  EXPECT_FALSE(fs::exists(work_ / "out"));
}

// An option whose absence means a default, given an empty value (an unset shell variable), is
// refused like any other bad value: until 2026-12-07 these took "" as left out (and `run
// --resume ""` started a new run instead of continuing one).
TEST_F(Cli, AnEmptyValueIsRefusedNotTakenAsLeftOut) {
  good_run("r");
  const std::vector<std::vector<std::string>> cases{{"render", "r", "--color-by", ""},
                                                    {"render", "r", "--colormap", ""},
                                                    {"render", "r", "--range", ""},
                                                    {"render", "r", "--size", ""},
                                                    {"render", "r", "--format", ""},
                                                    {"surface", "r", "--frame-format", ""},
                                                    {"run", "--resume", ""},
                                                    {"bench", "--threads", ""},
                                                    {"bench", "--precision", ""},
                                                    {"bench", "--scene-dir", ""},
                                                    {"validate", "--scenes", "", "-o", "v"}};
  for (const auto& args : cases) {
    const Result r = sph(args);
    EXPECT_EQ(r.code, 2) << args[0] << " " << args[args.size() - 2];
    EXPECT_EQ(count(r.err, "sph: error:"), 1u) << r.err;
    EXPECT_CONTAINS(r.err, args[args[0] == "validate" ? 2 : args.size() - 2] + ": an empty value; expected ");
  }
  EXPECT_FALSE(fs::exists(work_ / "r" / "render"));
  EXPECT_FALSE(fs::exists(work_ / "r" / "surface"));
  EXPECT_FALSE(fs::exists(work_ / "v"));
  EXPECT_FALSE(fs::exists(work_ / "out"));
}

TEST_F(Cli, UnknownNeighborModeFlag) {
  const Result r = sph({"run", kDamBreak, "--neighbors", "bogus", "-o", "o"});
  EXPECT_EQ(r.code, 2);
  EXPECT_CONTAINS(r.err, "--neighbors");
  EXPECT_CONTAINS(r.err, "bogus");
  EXPECT_EQ(count(r.err, "sph: error:"), 1u) << r.err;
  EXPECT_FALSE(fs::exists(work_ / "o"));
}

// ---------------------------------------------------------------------------------------------
// Frame formats, fields and schedule

TEST_F(Cli, FormatFieldsAndFpsFlagsChooseTheFrames) {
  // dt = 1.5e-4 s, 1000 frames/s: frames at steps 0, 7, 14, 20, 27 and the last, 30.
  const Result r = sph({"run", kDamBreak, "--steps", "30", "--format", "vtk,ply", "--fields", "velocity,id", "--fps",
                        "1000", "--no-progress", "-o", "o"});
  ASSERT_EQ(r.code, 0) << r.err;
  std::vector<std::string> files;
  for (const auto& e : fs::directory_iterator(work_ / "o" / "frames")) files.push_back(e.path().filename().string());
  std::sort(files.begin(), files.end());
  std::vector<std::string> want;
  for (int k = 0; k < 6; ++k)
    for (const char* ext : {"ply", "vtk"}) want.push_back(fmt::format("frame_{:06d}.{}", k, ext));
  EXPECT_EQ(files, want);
  EXPECT_FALSE(fs::exists(work_ / "o" / "frames.pvd")) << "no .vtu frames, no ParaView collection";
  EXPECT_CONTAINS(r.err, "Blender: File > Import > Stanford PLY");
  EXPECT_EQ(r.err.find("frames.pvd"), std::string::npos) << r.err;
  const std::string ply = read_file(work_ / "o" / "frames" / "frame_000003.ply");
  EXPECT_CONTAINS(ply, fmt::format("comment time {}\n", 20 * 1.5e-4));  // step 20, as the run computes it
  EXPECT_CONTAINS(ply, "property float vz\nproperty uint id\nend_header\n");
  EXPECT_EQ(ply.find("density"), std::string::npos);
  // The flags are scene overrides: scene.json and summary.json record them.
  const auto scene = nlohmann::json::parse(read_file(work_ / "o" / "scene.json"));
  EXPECT_EQ(scene["Configuration"]["outputFormats"], nlohmann::json({"vtk", "ply"}));
  EXPECT_EQ(scene["Configuration"]["outputFields"], nlohmann::json({"velocity", "id"}));
  EXPECT_EQ(scene["Configuration"]["outputFps"], 1000);
  EXPECT_EQ(scene["Configuration"]["outputEveryNSteps"], 0) << "--fps replaces the scene's outputEveryNSteps";
  const auto summary = nlohmann::json::parse(read_file(work_ / "o" / "summary.json"));
  EXPECT_EQ(summary["frames"], 6);
  EXPECT_EQ(summary["frame_formats"], nlohmann::json({"vtk", "ply"}));

  // --every and --fields none: positions only, every 10 steps (0, 10, 20 and the last, 25).
  const Result e = sph({"run", kDamBreak, "--steps", "25", "--every", "10", "--fields", "none", "--format", "ply",
                        "--no-progress", "-o", "e"});
  ASSERT_EQ(e.code, 0) << e.err;
  EXPECT_TRUE(fs::exists(work_ / "e" / "frames" / "frame_000003.ply"));
  EXPECT_FALSE(fs::exists(work_ / "e" / "frames" / "frame_000004.ply"));
  const std::string pos = read_file(work_ / "e" / "frames" / "frame_000000.ply");
  EXPECT_CONTAINS(pos, "property float z\nend_header\n");
}

TEST_F(Cli, BadFrameFlagsAreOneErrorAndExitCode2) {
  struct Case {
    std::vector<std::string> flags;
    std::string expect;
  };
  const std::vector<Case> cases{
      {{"--format", "vtu,obj"}, "--format: \"obj\" is not one of vtu, vtk, ply"},
      {{"--format", "vtu,,ply"}, "--format: an empty name"},
      {{"--format", "ply,ply"}, "\"ply\" is given twice"},
      {{"--fields", "velocity,temperature"}, "--fields: \"temperature\" is not one of velocity"},
      {{"--fields", ""}, "--fields"},
      {{"--every", "5", "--fps", "30"}, "--every and --fps both choose"},
      {{"--fps", "0"}, "--fps"},
      {{"--fps", "-3"}, "--fps"},
      {{"--every", "-1"}, "--every"},
      {{"--set", "Configuration.outputFps=30"}, "outputEveryNSteps = 100 and outputFps = 30"},
  };
  for (const auto& c : cases) {
    std::vector<std::string> args{"run", kDamBreak, "--steps", "5", "--no-progress", "-o", "o"};
    args.insert(args.end(), c.flags.begin(), c.flags.end());
    const Result r = sph(args);
    EXPECT_EQ(r.code, 2) << c.flags[0] << "\n" << r.err;
    EXPECT_CONTAINS(r.err, c.expect);
    EXPECT_EQ(count(r.err, "sph: error:"), 1u) << r.err;
    EXPECT_FALSE(fs::exists(work_ / "o")) << c.flags[0];
    fs::remove_all(work_ / "o");
  }
}

TEST_F(Cli, EveryNeighborModeRunsAndAuditFillsTheAuditColumns) {
  for (const char* mode : {"standard", "adaptive", "verlet"}) {
    const Result r =
        sph({"run", kDamBreak, "--neighbors", mode, "--steps", "30", "--audit", "-o", "o", "--no-progress"});
    ASSERT_EQ(r.code, 0) << mode << ": " << r.err;
    const auto summary = nlohmann::json::parse(read_file(work_ / "o" / "summary.json"));
    EXPECT_EQ(summary["neighbors"], mode);
    ASSERT_TRUE(summary.contains("audit")) << mode;
    if (std::string(mode) != "adaptive") {
      EXPECT_EQ(summary["audit"]["missed_pairs"], 0) << mode;
    }
    std::istringstream stats(read_file(work_ / "o" / "stats.csv"));
    std::string header, row;
    std::getline(stats, header);
    std::getline(stats, row);
    // Column 10 (missed_pairs) holds a number when auditing.
    std::vector<std::string> cells;
    std::stringstream cs(row);
    for (std::string c; std::getline(cs, c, ',');) cells.push_back(c);
    ASSERT_GT(cells.size(), 11u);
    EXPECT_FALSE(cells[9].empty()) << mode << ": " << row;
  }
  // Without --audit the audit columns are empty and summary.json has no audit.
  const Result r = sph({"run", kDamBreak, "--steps", "3", "-o", "o", "--no-progress"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_FALSE(nlohmann::json::parse(read_file(work_ / "o" / "summary.json")).contains("audit"));
  EXPECT_CONTAINS(read_file(work_ / "o" / "stats.csv"), ",,,");
}

TEST_F(Cli, CompareWritesTheReportAndRefusesBadModes) {
  const Result ok = sph({"compare", kDamBreak, "--steps", "20", "--modes", "adaptive", "--frames", "1", "--set",
                         "FluidBlocks[0].end=[0.2,0.4]", "-o", "cmp", "--no-progress"});
  ASSERT_EQ(ok.code, 0) << ok.err;
  EXPECT_CONTAINS(ok.err, "report");
  // The results go to stdout (to stderr until 2026-12-07), one line per run, the status to stderr.
  EXPECT_CONTAINS(ok.out, "  standard ");
  EXPECT_CONTAINS(ok.out, "RMS divergence at end");
  EXPECT_EQ(ok.err.find("RMS divergence"), std::string::npos) << ok.err;
  EXPECT_TRUE(fs::is_regular_file(work_ / "cmp" / "report.md"));
  EXPECT_TRUE(fs::is_regular_file(work_ / "cmp" / "frame_000020.png"));
  EXPECT_CONTAINS(read_file(work_ / "cmp" / "phases.csv"), "standard (perturbed)");

  for (const char* modes : {"standard,bogus", "adaptive,adaptive", "brute_force", ","}) {
    const Result r = sph({"compare", kDamBreak, "--modes", modes, "-o", "bad"});
    EXPECT_EQ(r.code, 2) << modes;
    EXPECT_CONTAINS(r.err, "--modes");
    EXPECT_EQ(count(r.err, "sph: error:"), 1u) << r.err;
    EXPECT_FALSE(fs::exists(work_ / "bad")) << modes;
    // The modes it lists are those compare takes: not the brute-force oracle.
    if (std::string(modes) != "adaptive,adaptive") EXPECT_CONTAINS(r.err, "verlet_clusters");
    EXPECT_EQ(r.err.find("expected one of \"standard\", \"adaptive\", \"verlet\", \"tracked\", "
                         "\"adaptive_exact\", \"verlet_clusters\", \"brute_force\""),
              std::string::npos)
        << r.err;
  }
  const Result missing = sph({"compare", "no_such_scene.json", "-o", "bad"});
  EXPECT_EQ(missing.code, 2);
  EXPECT_CONTAINS(missing.err, "no_such_scene.json");
  EXPECT_FALSE(fs::exists(work_ / "bad"));
}

TEST_F(Cli, ZeroThreadsRefused) {
  const Result r = sph({"run", kDamBreak, "--threads", "0", "-o", "o"});
  EXPECT_EQ(r.code, 2);
  EXPECT_CONTAINS(r.err, "--threads");
  EXPECT_FALSE(fs::exists(work_ / "o"));
}

TEST_F(Cli, ZeroOrNonNumericStepsRefused) {
  for (const char* steps : {"0", "-5", "many"}) {
    const Result r = sph({"run", kDamBreak, "--steps", steps, "-o", "o"});
    EXPECT_EQ(r.code, 2) << steps;
    EXPECT_CONTAINS(r.err, "--steps");
  }
  EXPECT_FALSE(fs::exists(work_ / "o"));
}

// ---------------------------------------------------------------------------------------------
// Scene files

TEST_F(Cli, MissingSceneFileNamesThePath) {
  const Result r = sph({"run", "no/such/scene.json", "-o", "o"});
  EXPECT_EQ(r.code, 2);
  EXPECT_CONTAINS(r.err, "no/such/scene.json");
  EXPECT_CONTAINS(r.err, "cannot open");
  EXPECT_FALSE(fs::exists(work_ / "o"));
}

TEST_F(Cli, ValidateBoundariesNeedsTheBoundaryParticleDamBreakBeforeRunning) {
  // The boundaries case reads martin_moyce_2d_particles.json before it runs anything: missing,
  // or not a boundary-particle scene, it is refused with exit code 2 and no output directory.
  const fs::path scenes = work_ / "scenes";
  fs::create_directories(scenes);
  for (const auto& e : fs::directory_iterator(SPH_SOURCE_DIR "/scenes/validation"))
    if (e.path().extension() == ".json") fs::copy_file(e.path(), scenes / e.path().filename());
  const fs::path dam = scenes / "martin_moyce_2d_particles.json";
  const std::string text = read_file(dam);
  fs::remove(dam);
  Result r = sph({"validate", "--cases", "boundaries", "--scenes", "scenes", "--no-progress", "-o", "v"});
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_CONTAINS(r.err, "martin_moyce_2d_particles.json");
  EXPECT_EQ(count(r.err, "sph: error:"), 1u) << r.err;
  EXPECT_FALSE(fs::exists(work_ / "v"));

  const std::string key = "\"boundaryHandling\": \"particles\"";
  const std::size_t at = text.find(key);
  ASSERT_NE(at, std::string::npos) << "the scene says boundary particles as " << key;
  write_file(dam, std::string(text).replace(at, key.size(), "\"boundaryHandling\": \"penalty\""));
  r = sph({"validate", "--cases", "boundaries", "--scenes", "scenes", "--no-progress", "-o", "v"});
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_CONTAINS(r.err, "must say \"boundaryHandling\": \"particles\"");
  EXPECT_FALSE(fs::exists(work_ / "v"));
}

// sph validate's checks go to stdout, one line each, and its progress and status to stderr.
TEST_F(Cli, ValidateWritesItsChecksToStdout) {
  const Result r = sph({"validate", "--quick", "--cases", "conservation", "--no-progress", "-o", "v"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_CONTAINS(r.out, "  PASS  conservation: momentum drift");
  EXPECT_EQ(r.err.find("PASS"), std::string::npos) << r.err;
  EXPECT_CONTAINS(r.err, "sph: validated in");
}

TEST_F(Cli, SceneThatIsADirectory) {
  fs::create_directory(work_ / "scenes");
  const Result r = sph({"run", "scenes", "-o", "o"});
  EXPECT_EQ(r.code, 2);
  EXPECT_CONTAINS(r.err, "scenes: is a directory");
}

TEST_F(Cli, BadSceneNamesTheKeyAndCreatesNoOutput) {
  const Result r = sph({"run", kBadScene, "-o", "fresh/out"});
  EXPECT_EQ(r.code, 2);
  EXPECT_CONTAINS(r.err, "Fluid.viscosty");
  EXPECT_CONTAINS(r.err, "unknown key");
  EXPECT_CONTAINS(r.err, "typo_optional_key_viscosity.json");
  EXPECT_EQ(count(r.err, "sph: error:"), 1u) << r.err;
  EXPECT_FALSE(fs::exists(work_ / "fresh"));
}

TEST_F(Cli, SyntaxErrorNamesLineAndColumn) {
  write_file(work_ / "broken.json", "{\n  \"version\": 1,\n  \"name\": \"x\",,\n}\n");
  const Result r = sph({"run", "broken.json", "-o", "o"});
  EXPECT_EQ(r.code, 2);
  EXPECT_CONTAINS(r.err, "broken.json:3:15:");
  EXPECT_FALSE(fs::exists(work_ / "o"));
}

TEST_F(Cli, BadSetOverrideMentionsSet) {
  const Result r = sph({"run", kDamBreak, "--set", "Fluid.stifness=2000", "-o", "o"});
  EXPECT_EQ(r.code, 2);
  EXPECT_CONTAINS(r.err, "--set Fluid.stifness");
  EXPECT_FALSE(fs::exists(work_ / "o"));
  const Result idx = sph({"run", kDamBreak, "--set", "FluidBlocks[1].end=[0.5,0.7]", "-o", "o"});
  EXPECT_EQ(idx.code, 2);
  EXPECT_CONTAINS(idx.err, "--set FluidBlocks[1].end");
  EXPECT_FALSE(fs::exists(work_ / "o"));
}

// A number that overflows a double in the scene or in --set escapes as nlohmann's out_of_range
// exception: exit 70 (internal error) and a message with neither file nor key.
TEST_F(Cli, NumberOverflowIsBadInput) {
  const Result r = sph({"run", kDamBreak, "--set", "Fluid.stiffness=1e999", "-o", "o"});
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_CONTAINS(r.err, "Fluid.stiffness");
}

// ---------------------------------------------------------------------------------------------
// The output directory

TEST_F(Cli, OutputPathIsAnExistingFile) {
  const std::string content = "my notes, not a directory\n";
  write_file(work_ / "notes.txt", content);
  const Result r = sph({"run", kDamBreak, "--steps", "5", "-o", "notes.txt"});
  EXPECT_EQ(r.code, 2);
  EXPECT_CONTAINS(r.err, "notes.txt");
  EXPECT_CONTAINS(r.err, "not a directory");
  EXPECT_TRUE(fs::is_regular_file(work_ / "notes.txt"));
  EXPECT_EQ(read_file(work_ / "notes.txt"), content);
}

TEST_F(Cli, RunWritesSummaryStatsAndFrames) {
  const Result r = sph({"run", kDamBreak, "--steps", "5", "--threads", "2", "-o", "run1"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_CONTAINS(r.err, "sph: done: 5 steps, 3200 particles");
  const fs::path dir = work_ / "run1";

  ASSERT_TRUE(fs::is_regular_file(dir / "summary.json"));
  const auto summary = nlohmann::json::parse(read_file(dir / "summary.json"));
  EXPECT_EQ(summary["status"], "completed");
  EXPECT_EQ(summary["steps"], 5);
  EXPECT_EQ(summary["particles"], 3200);
  EXPECT_EQ(summary["dimension"], 2);
  EXPECT_EQ(summary["scene"], "dam_break_2d");

  ASSERT_TRUE(fs::is_regular_file(dir / "stats.csv"));
  std::istringstream stats(read_file(dir / "stats.csv"));
  std::vector<std::string> lines;
  for (std::string line; std::getline(stats, line);) lines.push_back(line);
  ASSERT_EQ(lines.size(), 6u) << "header + 5 rows expected";
  EXPECT_EQ(lines[0].rfind("step,time,particles,", 0), 0u) << lines[0];
  const auto columns = count(lines[0], ",");
  for (std::size_t i = 1; i < lines.size(); ++i) EXPECT_EQ(count(lines[i], ","), columns) << lines[i];

  ASSERT_TRUE(fs::is_regular_file(dir / "frames.pvd"));
  EXPECT_CONTAINS(read_file(dir / "frames.pvd"), "frames/frame_000000.vtu");
  EXPECT_TRUE(fs::is_regular_file(dir / "frames" / "frame_000000.vtu"));
  EXPECT_TRUE(fs::is_regular_file(dir / "scene.json"));
  // No temporary or probe files are left behind.
  for (const auto& e : fs::recursive_directory_iterator(dir))
    EXPECT_NE(e.path().filename().string().front(), '.') << e.path();
}

TEST_F(Cli, OpenMpThreadsSpinBrieflyByDefaultAndTheUsersChoiceIsKept) {
  // libgomp's long spin makes steps many times slower when another program competes for the
  // cores: sph restarts itself with a GOMP_SPINCOUNT of its own (a count of hundreds, calibrated
  // on the CPU to spin about kSpinMicroseconds) unless the user chose how threads wait.
  const std::vector<std::string> args{"run", kDamBreak, "--steps", "3", "--no-progress", "-o", "w"};
  Result r = sph(args, "env -u OMP_WAIT_POLICY -u GOMP_SPINCOUNT");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string chosen =
      nlohmann::json::parse(read_file(work_ / "w" / "summary.json"))["openmp_wait"].get<std::string>();
  const std::string prefix = "GOMP_SPINCOUNT=";
  ASSERT_EQ(chosen.rfind(prefix, 0), 0u) << chosen;
  const std::string digits = chosen.substr(prefix.size());
  ASSERT_TRUE(!digits.empty() && std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; }))
      << chosen;
  const long count = std::stol(digits);
  EXPECT_TRUE(count >= 100 && count <= 100000 && count % 100 == 0) << chosen;
  r = sph(args, "env -u GOMP_SPINCOUNT OMP_WAIT_POLICY=active");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_CONTAINS(read_file(work_ / "w" / "summary.json"), "\"openmp_wait\": \"OMP_WAIT_POLICY=active\"");
  r = sph(args, "env -u OMP_WAIT_POLICY GOMP_SPINCOUNT=50");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_CONTAINS(read_file(work_ / "w" / "summary.json"), "\"openmp_wait\": \"GOMP_SPINCOUNT=50\"");
}

TEST_F(Cli, UsageHintNamesTheSubcommandTyped) {
  Result r = sph({"bench", "--step-runs", "0"});
  EXPECT_EQ(r.code, 2);
  EXPECT_CONTAINS(r.err, "sph bench --help");
  r = sph({"compare", "--bogus"});
  EXPECT_EQ(r.code, 2);
  EXPECT_CONTAINS(r.err, "sph compare --help");
  r = sph({"run"});
  EXPECT_EQ(r.code, 2);
  EXPECT_CONTAINS(r.err, "sph run --help");
}

TEST_F(Cli, SetOverrideReachesTheEffectiveScene) {
  const Result r = sph({"run", kDamBreak, "--steps", "1", "--no-progress", "--set", "Fluid.stiffness=2000", "--set",
                        "FluidBlocks[0].end=[0.2,0.4]", "-o", "o"});
  ASSERT_EQ(r.code, 0) << r.err;
  const auto scene = nlohmann::json::parse(read_file(work_ / "o" / "scene.json"));
  EXPECT_EQ(scene["Fluid"]["stiffness"], 2000);
  EXPECT_EQ(nlohmann::json::parse(read_file(work_ / "o" / "summary.json"))["particles"], 800);
}

TEST_F(Cli, DefaultOutputDirectoryIsOutSceneName) {
  const Result r = sph({"run", kDamBreak, "--steps", "1", "--no-progress"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::is_regular_file(work_ / "out" / "dam_break_2d" / "summary.json"));
}

TEST_F(Cli, RunKeepsUnrelatedUserFiles) {
  fs::create_directories(work_ / "o" / "frames");
  write_file(work_ / "o" / "README.txt", "keep me\n");
  write_file(work_ / "o" / "frames" / "notes.txt", "keep me too\n");
  good_run("o");
  EXPECT_EQ(read_file(work_ / "o" / "README.txt"), "keep me\n");
  EXPECT_EQ(read_file(work_ / "o" / "frames" / "notes.txt"), "keep me too\n");
}

TEST_F(Cli, SecondRunReplacesTheFirstRunsFrames) {
  const Result first =
      sph({"run", kDamBreak, "--steps", "4", "--no-progress", "--set", "Configuration.outputEveryNSteps=1", "-o", "o"});
  ASSERT_EQ(first.code, 0) << first.err;
  EXPECT_TRUE(fs::is_regular_file(work_ / "o" / "frames" / "frame_000004.vtu"));
  good_run("o");  // 5 steps: two frames, the initial and the last state
  std::size_t frames = 0;
  for (const auto& e : fs::directory_iterator(work_ / "o" / "frames")) frames += e.path().extension() == ".vtu";
  EXPECT_EQ(frames, 2u);
  EXPECT_EQ(nlohmann::json::parse(read_file(work_ / "o" / "summary.json"))["steps"], 5);
}

TEST_F(Cli, FailedRunLeavesEarlierOutputUntouched) {
  good_run("o");
  const std::string summary = read_file(work_ / "o" / "summary.json");
  const std::string stats = read_file(work_ / "o" / "stats.csv");
  const std::string pvd = read_file(work_ / "o" / "frames.pvd");

  const Result bad = sph({"run", kBadScene, "--steps", "5", "-o", "o"});
  EXPECT_EQ(bad.code, 2);
  EXPECT_CONTAINS(bad.err, "Fluid.viscosty");
  const Result bad_skin = sph(
      {"run", kDamBreak, "--steps", "5", "--neighbors", "verlet", "--set", "Configuration.verletSkin=0", "-o", "o"});
  EXPECT_EQ(bad_skin.code, 2);
  EXPECT_CONTAINS(bad_skin.err, "verletSkin");
  const Result bad_set = sph({"run", kDamBreak, "--steps", "5", "--set", "Fluid.stiffness=-1", "-o", "o"});
  EXPECT_EQ(bad_set.code, 2);

  EXPECT_EQ(read_file(work_ / "o" / "summary.json"), summary);
  EXPECT_EQ(read_file(work_ / "o" / "stats.csv"), stats);
  EXPECT_EQ(read_file(work_ / "o" / "frames.pvd"), pvd);
}

}  // namespace
