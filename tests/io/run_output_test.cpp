// prepare_output_directory and RunOutput: the output directory of a run.

#include <algorithm>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sph/core/error.h>
#include <sph/io/frames.h>
#include <sph/io/run_output.h>
#include <sph/scene/builders.h>
#include <sph/scene/scene_reader.h>

#include "support/temp_dir.h"

namespace sph {
namespace {

namespace fs = std::filesystem;
using test::entries;
using test::slurp;
using test::spit;
using test::TempDir;

std::vector<std::string> lines(const std::string& s) {
  std::vector<std::string> v;
  std::istringstream in(s);
  for (std::string l; std::getline(in, l);) v.push_back(l);
  return v;
}

TEST(OutputDirectory, CreatesNestedDirectories) {
  TempDir dir;
  const fs::path out = dir / "a/b/c";
  prepare_output_directory(out);
  EXPECT_TRUE(fs::is_directory(out));
  EXPECT_TRUE(fs::is_directory(out / "frames"));
  EXPECT_EQ(entries(out), std::vector<std::string>{"frames"}) << "no probe files left behind";
  EXPECT_TRUE(entries(out / "frames").empty()) << "no probe files left behind";
}

TEST(OutputDirectory, AcceptsAnExistingEmptyDirectoryTwice) {
  TempDir dir;
  prepare_output_directory(dir.path());
  prepare_output_directory(dir.path());
  EXPECT_EQ(entries(dir.path()), std::vector<std::string>{"frames"});
}

TEST(OutputDirectory, RefusesARegularFile) {
  TempDir dir;
  const fs::path file = dir / "out";
  spit(file, "not a directory");
  try {
    prepare_output_directory(file);
    FAIL() << "expected sph::Error";
  } catch (const Error& e) {
    EXPECT_EQ(e.where(), file.string());
  }
  EXPECT_EQ(slurp(file), "not a directory") << "the file must be left alone";
  EXPECT_THROW(prepare_output_directory(file / "sub"), Error) << "a path below a regular file";
}

TEST(OutputDirectory, RefusesAFramesEntryThatIsAFile) {
  TempDir dir;
  spit(dir / "frames", "x");
  EXPECT_THROW(prepare_output_directory(dir.path()), Error);
}

TEST(OutputDirectory, RemovesOldRunFilesButKeepsOthers) {
  TempDir dir;
  const fs::path out = dir.path();
  fs::create_directories(out / "frames");
  for (const char* f : {"frames.pvd", "stats.csv", "summary.json", "scene.json", "bodies.csv", "notes.txt",
                        "my_frame_000001.vtu", "stats.csv.bak"})
    spit(out / f, "old");
  for (const char* f : {"frame_000000.vtu", "frame_000001.vtu", "frame_123456.vtu", "keep.vtu", "frame_notes.txt",
                        "other_frame_000000.vtu"})
    spit(out / "frames" / f, "old");
  fs::create_directories(out / "results");
  spit(out / "results" / "frame_000000.vtu", "unrelated");

  prepare_output_directory(out);

  EXPECT_EQ(entries(out),
            (std::vector<std::string>{"frames", "my_frame_000001.vtu", "notes.txt", "results", "stats.csv.bak"}));
  EXPECT_EQ(entries(out / "frames"),
            (std::vector<std::string>{"frame_notes.txt", "keep.vtu", "other_frame_000000.vtu"}));
  EXPECT_EQ(entries(out / "results"), std::vector<std::string>{"frame_000000.vtu"});
  EXPECT_EQ(slurp(out / "notes.txt"), "old");
}

TEST(OutputDirectory, ReadOnlyDirectoryThrowsSphError) {
  if (::geteuid() == 0) GTEST_SKIP() << "running as root: permissions do not block writes";
  TempDir dir;
  const fs::path ro = dir / "ro";
  fs::create_directories(ro / "frames");
  spit(ro / "stats.csv", "old");
  fs::permissions(ro, fs::perms::owner_read | fs::perms::owner_exec);
  EXPECT_THROW(prepare_output_directory(ro), Error);
  fs::permissions(ro, fs::perms::owner_all);
  EXPECT_EQ(slurp(ro / "stats.csv"), "old") << "nothing is removed when the directory is not writable";
}

SceneDesc small_dam_break(int steps, int every) {
  return read_scene_file(SPH_SOURCE_DIR "/scenes/paper/dam_break_2d.json",
                         {"Configuration.numberOfSteps=" + std::to_string(steps),
                          "Configuration.outputEveryNSteps=" + std::to_string(every)});
}

TEST(RunOutput, WritesFramesStatsAndSummary) {
  TempDir dir;
  const SceneDesc desc = small_dam_break(5, 2);
  auto sim = make_simulation<2, double>(desc);
  prepare_output_directory(dir.path());
  RunOutput<2, double> out(dir.path(), desc, RunInfo{"standard", 1});
  out.begin(sim);
  for (std::int64_t s = 0; s < desc.steps; ++s) {
    const StepInfo& info = sim.step();
    out.after_step(sim, info, s + 1 == desc.steps);
  }
  out.finish(sim, "completed", 0.5);
  EXPECT_EQ(out.frames_written(), 4u) << "steps 0, 2, 4 and the last step 5";
  EXPECT_EQ(entries(dir / "frames"),
            (std::vector<std::string>{"frame_000000.vtu", "frame_000001.vtu", "frame_000002.vtu", "frame_000003.vtu"}));
  EXPECT_EQ(entries(dir.path()),
            (std::vector<std::string>{"frames", "frames.pvd", "run.json", "scene.json", "stats.csv", "summary.json"}));
  EXPECT_TRUE(parse_scene(slurp(dir / "scene.json"), desc.source) == desc) << "scene.json is the run's scene";
  const auto rows = lines(slurp(dir / "stats.csv"));
  ASSERT_EQ(rows.size(), 6u);
  // The header the readers of stats.csv know (tests/io/vtk_readback_test.py), from kStatsColumns.
  EXPECT_EQ(rows[0],
            "step,time,particles,kinetic_energy,max_speed,mean_neighbors,lists_rebuilt,pairs_stored,pairs_within_h,"
            "missed_pairs,particles_missing,max_missed_penetration,t_grid,t_lists,t_density,t_forces,t_integrate,"
            "t_output,outside,outside_depth,inside_solid,inside_depth,max_mach,rho_min,rho_max,energy,"
            "boundary_pairs_stored,boundary_missed_pairs,entries_rebuilt,list_insertions,list_removals,list_overflows,"
            "skin,dt,solver_iterations,density_error,divergence_iterations,divergence_error,t_solve,"
            "viscosity_iterations,viscosity_error");
  EXPECT_EQ(rows[0], stats_header());
  // step: the steps done after the row's step (1 to 5), as summary.json's steps counts them
  for (int i = 0; i < 5; ++i)
    EXPECT_EQ(rows[static_cast<std::size_t>(i) + 1].substr(0, 2), std::to_string(i + 1) + ",");
  const auto j = nlohmann::json::parse(slurp(dir / "summary.json"));
  EXPECT_EQ(j["status"], "completed");
  EXPECT_EQ(j["steps"], 5);
  EXPECT_EQ(j["particles"], 3200);
  EXPECT_EQ(j["frames"], 4);
  for (const char* k : {"grid", "lists", "density", "forces", "integrate", "output"})
    EXPECT_TRUE(j["phase_seconds"].contains(k)) << k;
}

TEST(RunOutput, UnfinishedRunStillLeavesItsStats) {
  TempDir dir;
  const SceneDesc desc = small_dam_break(10, 0);
  auto sim = make_simulation<2, double>(desc);
  prepare_output_directory(dir.path());
  {
    RunOutput<2, double> out(dir.path(), desc, RunInfo{"standard", 1});
    out.begin(sim);
    for (int s = 0; s < 3; ++s) out.after_step(sim, sim.step(), false);
    EXPECT_EQ(out.frames_written(), 0u) << "outputEveryNSteps = 0 writes no frames";
  }  // destroyed without finish(), e.g. by an exception
  const auto rows = lines(slurp(dir / "stats.csv"));
  EXPECT_EQ(rows.size(), 4u);
  EXPECT_FALSE(fs::exists(dir / "summary.json"));
  EXPECT_FALSE(fs::exists(dir / "frames.pvd"));
  EXPECT_EQ(entries(dir.path()), (std::vector<std::string>{"frames", "run.json", "scene.json", "stats.csv"}));
}

}  // namespace
}  // namespace sph

namespace sph {
namespace {

// With boundary particles and Configuration.outputBoundary, the run directory holds boundary.vtu
// (every sample once, its id and psi), summary.json counts the samples and stats.csv the
// entries of their lists; with penalty walls there is no boundary.vtu.
TEST(RunOutput, WritesTheBoundaryParticlesOnce) {
  for (const char* handling : {"particles", "penalty"}) {
    TempDir dir;
    const SceneDesc desc = read_scene_file(
        SPH_SOURCE_DIR "/scenes/paper/dam_break_2d.json",
        {"Configuration.numberOfSteps=3", "Configuration.outputEveryNSteps=0", "Configuration.outputBoundary=true",
         std::string("Configuration.boundaryHandling=") + handling});
    auto sim = make_simulation<2, double>(desc);
    prepare_output_directory(dir.path());
    RunOutput<2, double> out(dir.path(), desc, RunInfo{"standard", 1});
    out.begin(sim);
    for (int s = 0; s < 3; ++s) out.after_step(sim, sim.step(), s == 2);
    out.finish(sim, "completed", 0.1);
    const auto j = nlohmann::json::parse(slurp(dir / "summary.json"));
    EXPECT_EQ(j["boundary_samples"], sim.boundary().size());
    const auto rows = lines(slurp(dir / "stats.csv"));
    if (std::string(handling) == "penalty") {
      EXPECT_FALSE(fs::exists(dir / "boundary.vtu"));
      EXPECT_EQ(sim.boundary().size(), 0u);
      continue;
    }
    ASSERT_GT(sim.boundary().size(), 1000u);
    const FieldSpec psi{"psi", FieldKind::Real, "kg/m", "kg", ""};
    const FrameData b = read_frame(dir / "boundary.vtu", std::span<const FieldSpec>(&psi, 1));
    ASSERT_EQ(b.size, sim.boundary().size());
    ASSERT_NE(b.field("psi"), nullptr);
    ASSERT_NE(b.field("id"), nullptr);
    for (std::size_t k = 0; k < b.size; k += 97) {
      EXPECT_EQ(b.position[3 * k], sim.boundary().position[k][0]);
      EXPECT_EQ(b.position[3 * k + 1], sim.boundary().position[k][1]);
      EXPECT_EQ(b.field("psi")->values[k], sim.boundary().psi[k]);
    }
    // The step's boundary list entries (before the empty audit column).
    const auto cells = [](const std::string& row) {
      std::vector<std::string> c;
      std::stringstream in(row);
      for (std::string x; std::getline(in, x, ',');) c.push_back(x);
      return c;
    };
    const auto head = cells(rows[0]);
    const auto values = cells(rows.back());
    const auto at = std::find(head.begin(), head.end(), "boundary_pairs_stored") - head.begin();
    EXPECT_EQ(std::stoull(values[static_cast<std::size_t>(at)]), sim.last_step().neighbors.boundary_pairs_stored);
    EXPECT_GT(sim.last_step().neighbors.boundary_pairs_stored, 0u);
  }
}

}  // namespace
}  // namespace sph
