// The health monitor through the run driver: a warning is given once through the callback and
// recorded in the status, summary.json and stats.csv; RunSettings::strict makes it a failure in
// the step that raised it; a resumed run remembers the warnings given before its checkpoint;
// stepping with RunDriver::step gives the same warnings through new_warnings.

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sph/run/driver.h>
#include <sph/run/resume.h>
#include <sph/scene/scene_reader.h>

#include "support/temp_dir.h"

namespace sph {
namespace {

namespace fs = std::filesystem;
using test::slurp;
using test::TempDir;

/// The 2D dam break with its column thrown at the right wall at 13 m/s: Mach 0.33 (c0 = 40 m/s).
SceneDesc thrown_dam_break(std::int64_t steps = 40) {
  return read_scene_file(SPH_SOURCE_DIR "/scenes/paper/dam_break_2d.json",
                         {"Configuration.numberOfSteps=" + std::to_string(steps), "Configuration.outputEveryNSteps=10",
                          "FluidBlocks[0].velocity=[13,0]"});
}

TEST(HealthRun, AWarningIsGivenOnceAndRecordedInTheStatusSummaryAndStats) {
  TempDir tmp;
  std::vector<std::string> heard;
  RunCallbacks callbacks;
  callbacks.warning = [&](const std::string& w) { heard.push_back(w); };
  RunDriver<2, double> run(thrown_dam_break(), RunSettings{tmp / "o", 0});
  const RunResult r = run.run(callbacks);
  ASSERT_EQ(r.status, RunStatus::Completed) << r.message;
  ASSERT_EQ(heard.size(), 1u);
  EXPECT_NE(heard[0].find("Mach 0.3"), std::string::npos) << heard[0];
  EXPECT_EQ(r.warnings, heard);
  EXPECT_EQ(r.message, "completed with warnings: " + heard[0]);
  const auto summary = nlohmann::json::parse(slurp(tmp / "o" / "summary.json"));
  EXPECT_EQ(summary.at("status"), r.message);
  EXPECT_EQ(summary.at("warnings").size(), 1u);
  EXPECT_GE(summary.at("warning_counts").at("mach").get<int>(), 1);
  EXPECT_EQ(summary.at("warning_counts").at("outside").get<int>(), 0);
  EXPECT_GT(summary.at("health").at("max_mach").get<double>(), 0.3);
  const std::string stats = slurp(tmp / "o" / "stats.csv");
  EXPECT_NE(stats.find(",outside,outside_depth,inside_solid,inside_depth,max_mach,rho_min,rho_max,energy,"),
            std::string::npos);
}

TEST(HealthRun, StepByStepGivesTheWarningsOfRunOnceAtTheirStep) {
  TempDir tmp;
  std::vector<std::pair<std::int64_t, std::string>> heard;  // (steps done, warning) of run()
  RunCallbacks callbacks;
  RunDriver<2, double> ran(thrown_dam_break(), RunSettings{tmp / "o", 0});
  callbacks.warning = [&](const std::string& w) { heard.emplace_back(ran.simulation().steps_done(), w); };
  ran.run(callbacks);
  ASSERT_EQ(heard.size(), 1u);
  RunDriver<2, double> stepped(thrown_dam_break(), RunSettings{});
  std::vector<std::pair<std::int64_t, std::string>> given;
  for (int k = 0; k < 40; ++k)
    for (const std::string& w : stepped.new_warnings(stepped.step())) given.emplace_back(k + 1, w);
  EXPECT_EQ(given, heard);
  EXPECT_EQ(stepped.simulation().health().warnings(), ran.simulation().health().warnings());
}

// A message's "at step N (t = T s)" is stats.csv's row N, whose time is T: the steps counted
// from 1, as stats.csv, summary.json and steps_done() count them (messages counted from 0 until
// 2026-12-07, one below the row of their own time).
TEST(HealthRun, AWarningsStepAndTimeAreThoseOfItsStatsRow) {
  TempDir tmp;
  std::string warning;
  RunCallbacks callbacks;
  callbacks.warning = [&](const std::string& w) { warning = w; };
  RunDriver<2, double> run(thrown_dam_break(), RunSettings{tmp / "o", 0});
  ASSERT_EQ(run.run(callbacks).status, RunStatus::Completed);
  const std::size_t at = warning.find("at step ");
  ASSERT_NE(at, std::string::npos) << warning;
  long long step = 0;
  double time = 0;
  ASSERT_EQ(std::sscanf(warning.c_str() + at, "at step %lld (t = %lf s)", &step, &time), 2) << warning;
  std::ifstream stats(tmp / "o" / "stats.csv");
  std::string line;
  std::getline(stats, line);
  ASSERT_EQ(line.rfind("step,time,", 0), 0u) << line;
  bool found = false;
  while (std::getline(stats, line))
    if (std::stoll(line.substr(0, line.find(','))) == step) {
      found = true;
      const double row_time = std::stod(line.substr(line.find(',') + 1));
      EXPECT_NEAR(row_time, time, 1e-6 * time) << line << "\n" << warning;
    }
  EXPECT_TRUE(found) << "no stats.csv row of step " << step;
}

TEST(HealthRun, StrictMakesTheFirstWarningAFailureInItsStep) {
  TempDir tmp;
  RunSettings settings{tmp / "o", 0};
  settings.strict = true;
  RunDriver<2, double> run(thrown_dam_break(), settings);
  RunCallbacks callbacks;
  int warned = 0;  // the warning is the failure's message: it is not told as a warning too
  callbacks.warning = [&](const std::string&) { ++warned; };
  const RunResult r = run.run(callbacks);
  ASSERT_EQ(r.status, RunStatus::Failed) << r.message;
  EXPECT_EQ(warned, 0);
  EXPECT_EQ(r.steps_done, 1) << "the warning of step 0 stops the run there";
  EXPECT_NE(r.error.find("Mach 0.3"), std::string::npos) << r.error;
  EXPECT_EQ(r.message, "failed: " + r.error);
  EXPECT_EQ(r.error.substr(r.error.size() - 11), " (--strict)");
  EXPECT_EQ(nlohmann::json::parse(slurp(tmp / "o" / "summary.json")).at("status"), r.message);
}

/// stats.csv's last row: its step and the value of `column`.
std::pair<long long, double> last_row(const fs::path& stats_csv, const std::string& column) {
  std::ifstream stats(stats_csv);
  std::string header, line, last;
  std::getline(stats, header);
  while (std::getline(stats, line)) last = line;
  std::vector<std::string> names, cells;
  for (auto* v : {&names, &cells}) {
    std::string text = v == &names ? header : last, cell;
    std::istringstream in(text);
    while (std::getline(in, cell, ',')) v->push_back(cell);
  }
  std::size_t k = 0;
  while (k < names.size() && names[k] != column) ++k;
  if (k >= cells.size() || cells.empty()) return {-1, 0};
  return {std::stoll(cells[0]), std::stod(cells[k])};
}

// A step that fails, by a --strict warning or by a health check's failure level, has its stats.csv
// row like every other step: the failure's "at step N" is the last row, and the row shows what
// failed (here its Mach number). (Until 2026-12-07 the table ended one step before the failure.)
TEST(HealthRun, AFailingStepHasItsStatsRow) {
  for (const double speed : {13.0, 45.0}) {  // Mach 0.33 (a warning, --strict) and 1.1 (supersonic: fails)
    SCOPED_TRACE(speed);
    TempDir tmp;
    RunSettings settings{tmp / "o", 0};
    settings.strict = speed < 20;
    RunDriver<2, double> run(read_scene_file(SPH_SOURCE_DIR "/scenes/paper/dam_break_2d.json",
                                             {"Configuration.numberOfSteps=40", "Configuration.outputEveryNSteps=10",
                                              "FluidBlocks[0].velocity=[" + std::to_string(speed) + ",0]"}),
                             settings);
    const RunResult r = run.run();
    ASSERT_EQ(r.status, RunStatus::Failed) << r.message;
    EXPECT_NE(r.error.find(speed < 20 ? "Mach 0.3" : "supersonic"), std::string::npos) << r.error;
    const std::size_t at = r.error.find("at step ");
    ASSERT_NE(at, std::string::npos) << r.error;
    const long long step = std::stoll(r.error.substr(at + 8));
    const auto [row, mach] = last_row(tmp / "o" / "stats.csv", "max_mach");
    EXPECT_EQ(row, step) << r.error;
    EXPECT_EQ(row, r.steps_done);
    EXPECT_GT(mach, speed < 20 ? 0.3 : 1.0);
  }
}

TEST(HealthRun, AResumedRunRemembersTheWarningsGivenBeforeItsCheckpoint) {
  TempDir tmp;
  RunCallbacks stop;
  int heard = 0;
  stop.warning = [&](const std::string&) { ++heard; };
  stop.stop_requested = [](std::int64_t done) { return done == 20 ? std::string("test") : std::string(); };
  {
    RunDriver<2, double> run(thrown_dam_break(), RunSettings{tmp / "o", 0});
    ASSERT_EQ(run.run(stop).status, RunStatus::Interrupted);
  }
  EXPECT_EQ(heard, 1);
  RunToResume again = open_run_to_resume(tmp / "o");
  RunDriver<2, double> run(again.desc, *again.checkpoint, RunSettings{tmp / "o", 0});
  RunCallbacks rest;
  rest.warning = [&](const std::string&) { ++heard; };
  const RunResult r = run.run(rest);
  ASSERT_EQ(r.status, RunStatus::Completed) << r.message;
  EXPECT_EQ(heard, 1) << "the warning is not given again after the resume";
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_EQ(r.message, "completed with warnings: " + r.warnings[0]);
}

/// A light box 2 cm off the floor of a 1 m tank, with a dam break released at its left that
/// carries it into the right wall (DFSPH, boundary particles, CFL steps of at most 5 ms).
std::string box_in_a_dam_break() {
  return R"({"version": 1, "name": "box_in_a_dam_break", "units": "SI", "dimension": 2,
  "Configuration": {"timeStepSize": 0.001, "stopAt": 0.5, "particleRadius": 0.005,
    "boundaryHandling": "particles", "kernel": "cubic", "simulationMethod": "dfsph", "outputFps": 25},
  "Container": {"start": [0, 0], "end": [1.0, 0.6]},
  "FluidBlocks": [{"start": [0, 0], "end": [0.3, 0.4]}],
  "Obstacles": [{"start": [0.6, 0.02], "end": [0.7, 0.07], "dynamic": true, "density": 400}]})";
}

TEST(HealthRun, AFloatingBodySunkIntoAWallIsToldOfAndTheAdviceHolds) {
  // Carried into the wall at about 0.4 s, the box sank 13.5 mm (2.7 spacings) into it with springs
  // made for 5 ms steps, and nothing said so; with steps of at most 1.25 ms, 1.8 mm at 1 ms.
  TempDir tmp;
  { std::ofstream(tmp / "box.json") << box_in_a_dam_break(); }
  RunDriver<2, double> run(read_scene_file((tmp / "box.json").string()), RunSettings{tmp / "a", 0});
  const RunResult r = run.run();
  ASSERT_EQ(r.status, RunStatus::Completed) << r.message;
  ASSERT_EQ(r.warnings.size(), 1u);
  const std::string& w = r.warnings[0];
  EXPECT_NE(w.find("floating body Obstacles[0] is 0.005"), std::string::npos) << w;
  EXPECT_NE(w.find("into the container's +x wall"), std::string::npos) << w;
  EXPECT_NE(w.find("lower Configuration.cflMaxTimeStepSize (now 0.005 s), e.g. to 0.0013 s"), std::string::npos) << w;
  const auto summary = nlohmann::json::parse(slurp(tmp / "a" / "summary.json"));
  EXPECT_GE(summary.at("warning_counts").at("body_in_wall").get<int>(), 1);
  // The advice, taken: no warning.
  RunDriver<2, double> advised(
      read_scene_file((tmp / "box.json").string(), {"Configuration.cflMaxTimeStepSize=0.00125"}),
      RunSettings{tmp / "b", 0});
  const RunResult b = advised.run();
  ASSERT_EQ(b.status, RunStatus::Completed) << b.message;
  EXPECT_TRUE(b.warnings.empty()) << b.message;
}

}  // namespace
}  // namespace sph
