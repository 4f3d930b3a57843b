// `sph bench` as a user meets it: a small run writes its files; bad flags exit 2 with one
// message naming the flag and what is accepted, and write nothing.

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "bench_test_util.h"

namespace sph {
namespace {

namespace fs = std::filesystem;

class BenchCli : public ::testing::Test {
 protected:
  test::CommandResult sph(const std::vector<std::string>& args) {
    return test::run_sph(args, tmp_.path(), tmp_ / "stderr.txt");
  }
  static std::size_t count(const std::string& text, const std::string& what) {
    std::size_t n = 0;
    for (auto pos = text.find(what); pos != std::string::npos; pos = text.find(what, pos + what.size())) ++n;
    return n;
  }
  test::TempDir tmp_;
};

TEST_F(BenchCli, SmallNeighborsRunWritesItsFiles) {
  const fs::path out = tmp_ / "bench";
  // An earlier run's files for other suites must not pass for this run's.
  fs::create_directories(out);
  std::ofstream(out / "steps.csv") << "old\n";
  std::ofstream(out / "tank.csv") << "old\n";
  // Options of suites that do not run are ignored, and the user is told (they were ignored
  // without a word until 2026-12-07); --threads, read by every suite, is not named.
  const auto r = sph({"bench", "--size", "small", "--suite", "neighbors", "--threads", "1", "--particles", "1000000",
                      "--steps", "5", "-o", out.string()});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("sph: warning: --particles: only the steps suite reads it, and --suite neighbors does not "
                       "run it: it is ignored"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("sph: warning: --steps: only the tank suite reads it"), std::string::npos) << r.err;
  EXPECT_EQ(count(r.err, "sph: warning:"), 2u) << r.err;
  EXPECT_EQ(r.err.find("1000000 particles"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::is_regular_file(out / "bench.json"));
  EXPECT_TRUE(fs::is_regular_file(out / "neighbors.csv"));
  EXPECT_FALSE(fs::exists(out / "steps.csv"));
  EXPECT_FALSE(fs::exists(out / "tank.csv"));
  const auto doc = nlohmann::json::parse(test::slurp(out / "bench.json"));
  EXPECT_EQ(doc["neighbors"]["results"].size(), 16u);
  EXPECT_EQ(doc["options"]["repeats"], 5);
  // The table goes to stdout as it runs, one line per result.
  EXPECT_NE(r.out.find("nbrs/particle"), std::string::npos) << r.out;
  EXPECT_EQ(count(r.out, "    8000 "), 16u) << r.out;
  EXPECT_NE(r.err.find("bench.json"), std::string::npos) << r.err;
}

TEST_F(BenchCli, UnknownSuiteExits2NamingTheAcceptedValues) {
  const auto r = sph({"bench", "--suite", "foo", "-o", "o"});
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(count(r.err, "sph: error:"), 1u) << r.err;
  EXPECT_NE(r.err.find("--suite"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("\"foo\""), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("neighbors, steps, tank, or all"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_FALSE(fs::exists(tmp_ / "o"));
}

TEST_F(BenchCli, BadValuesExit2NamingTheFlagAndWriteNothing) {
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"--threads", "0"}, "--threads"},
      {{"--threads", "two"}, "--threads"},
      {{"--threads", "1,,2"}, "--threads"},
      {{"--size", "huge"}, "--size"},
      {{"--precision", "half"}, "--precision"},
      {{"--modes", "brute_force"}, "--modes"},
      {{"--repeats", "0"}, "--repeats"},
      {{"--suite", "tank", "--scene-dir", "no_such_dir"}, "tank_fill_3d.json"},
  };
  for (const auto& [flags, named] : cases) {
    std::vector<std::string> args{"bench", "-o", "o"};
    args.insert(args.end(), flags.begin(), flags.end());
    const auto r = sph(args);
    EXPECT_EQ(r.code, 2) << flags[0] << " " << flags[1] << ": " << r.err;
    EXPECT_EQ(count(r.err, "sph: error:"), 1u) << r.err;
    EXPECT_NE(r.err.find(named), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(tmp_ / "o")) << flags[0];
  }
}

TEST_F(BenchCli, UnwritableOutputExits2NamingThePath) {
  { std::ofstream(tmp_ / "a_file") << "x"; }
  for (const fs::path& out : {tmp_ / "a_file", tmp_ / "a_file" / "sub"}) {
    const auto r = sph({"bench", "--suite", "neighbors", "--threads", "1", "--repeats", "1", "-o", out.string()});
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find(out.string()), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
}

TEST_F(BenchCli, HelpListsTheOptionsAndTopLevelHelpTheCommand) {
  auto r = sph({"bench", "--help"});
  EXPECT_EQ(r.code, 0);
  for (const char* opt : {"--suite", "--size", "--threads", "--precision", "--repeats", "--output", "--no-progress",
                          "--particles", "--scene-dir"})
    EXPECT_NE(r.out.find(opt), std::string::npos) << opt;
  r = sph({"--help"});
  EXPECT_NE(r.out.find("sph bench"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace sph
