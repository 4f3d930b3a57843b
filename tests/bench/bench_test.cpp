// The small neighbors and steps suites run through the library API: the files they write, the
// keys and counts in bench.json, and figures that follow from the workload's geometry (neighbors
// per particle). No timing is asserted, only that timings exist.

#include <cmath>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sph/bench/bench.h>
#include <sph/bench/workload.h>
#include <sph/core/error.h>

#include "bench_test_util.h"

namespace sph {
namespace {

using nlohmann::json;

/// Expected entries per particle of the side^3 jittered lattice with radius r (in units of
/// dx): the sum over lattice offsets o of P(|o + d| < r) times the fraction of points that have
/// the offset inside the lattice, where each component of d is the difference of two
/// independent uniform jitters in [-j, j]. Monte Carlo, independent samples per offset.
double expected_neighbors(int side, double r, double jitter) {
  SplitMix64 rng(12345);
  const int m = static_cast<int>(std::ceil(r + 1));
  double sum = 0;
  for (int x = -m; x <= m; ++x)
    for (int y = -m; y <= m; ++y)
      for (int z = -m; z <= m; ++z) {
        if (x == 0 && y == 0 && z == 0) continue;
        const double len = std::sqrt(double(x * x + y * y + z * z));
        const double reach = 2 * jitter * std::sqrt(3.0);  // the largest |d|
        double p;
        if (len + reach < r)
          p = 1;
        else if (len - reach >= r)
          p = 0;
        else {
          constexpr int kSamples = 40000;
          int in = 0;
          for (int k = 0; k < kSamples; ++k) {
            double d2 = 0;
            for (double o : {double(x), double(y), double(z)}) {
              const double t = o + rng.symmetric(jitter) - rng.symmetric(jitter);
              d2 += t * t;
            }
            in += d2 < r * r;
          }
          p = static_cast<double>(in) / kSamples;
        }
        const double w = double(side - std::abs(x)) * double(side - std::abs(y)) * double(side - std::abs(z)) /
                         (double(side) * side * side);
        sum += p * w;
      }
  return sum;
}

TEST(ExpectedNeighbors, MatchesTheLatticeCountsWithoutJitter) {
  // An unjittered lattice, boundaries negligible: 26 offsets with |o|^2 <= 3, 32 with
  // |o|^2 <= 4, 92 with |o|^2 <= 8.
  EXPECT_NEAR(expected_neighbors(100000, 2.0 - 1e-9, 0.0), 26.0, 0.01);
  EXPECT_NEAR(expected_neighbors(100000, 2.0 + 1e-9, 0.0), 32.0, 0.01);
  EXPECT_NEAR(expected_neighbors(100000, 3.0 - 1e-9, 0.0), 92.0, 0.02);
}

class SmallSuites : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new test::TempDir();
    BenchOptions o;
    o.suites = {"neighbors", "steps"};
    o.size = BenchSize::Small;
    o.threads = {1};
    o.repeats = 2;
    o.modes = {NeighborMode::Standard, NeighborMode::Verlet};
    o.warmup_steps = 2;
    o.timed_steps = 3;
    o.step_runs = 3;
    BenchOutput out;
    out.table = [](const std::string& line) { table_ += line + "\n"; };
    result_ = new BenchResult(run_benchmarks(o, dir_->path(), out));
    doc_ = new json(json::parse(test::slurp(dir_->path() / "bench.json")));
  }
  static void TearDownTestSuite() {
    delete doc_;
    delete result_;
    delete dir_;
  }
  static inline test::TempDir* dir_ = nullptr;
  static inline BenchResult* result_ = nullptr;
  static inline json* doc_ = nullptr;
  static inline std::string table_;
};

TEST_F(SmallSuites, WritesTheJsonAndOneCsvPerSuiteRun) {
  EXPECT_TRUE(std::filesystem::is_regular_file(dir_->path() / "bench.json"));
  EXPECT_TRUE(std::filesystem::is_regular_file(dir_->path() / "neighbors.csv"));
  EXPECT_TRUE(std::filesystem::is_regular_file(dir_->path() / "steps.csv"));
  EXPECT_FALSE(std::filesystem::exists(dir_->path() / "tank.csv"));
  // No temporary file left behind.
  for (const auto& e : std::filesystem::directory_iterator(dir_->path()))
    EXPECT_NE(e.path().filename().string().front(), '.') << e.path();
}

TEST_F(SmallSuites, JsonHasTheMachineBuildAndOptions) {
  const json& d = *doc_;
  EXPECT_EQ(d["schema"], "sph-bench/1");
  EXPECT_EQ(d["status"], "completed");
  for (const char* key : {"cpu_model", "logical_cores", "compiler", "build_flags", "build_type", "git_commit", "date",
                          "sph_version", "memory_bytes"})
    EXPECT_TRUE(d["machine"].contains(key)) << key;
  EXPECT_GE(d["machine"]["logical_cores"].get<int>(), 1);
  EXPECT_FALSE(d["machine"]["compiler"].get<std::string>().empty());
  EXPECT_EQ(d["options"]["size"], "small");
  EXPECT_EQ(d["options"]["threads"], json::array({1}));
  EXPECT_EQ(d["suites_done"], json::array({"neighbors", "steps"}));
  EXPECT_FALSE(d.contains("tank"));
}

TEST_F(SmallSuites, NeighborsResultsCoverEveryCase) {
  const json& res = (*doc_)["neighbors"]["results"];
  // 2 radii x 2 precisions x 2 orders x 1 thread count x 2 phases, all 8,000 points.
  ASSERT_EQ(res.size(), 16u);
  for (const json& r : res) {
    EXPECT_EQ(r["particles"], 8000);
    EXPECT_GT(r["ms"]["median"].get<double>(), 0);
    EXPECT_LE(r["ms"]["min"].get<double>(), r["ms"]["median"].get<double>());
    EXPECT_LE(r["ms"]["median"].get<double>(), r["ms"]["max"].get<double>());
    EXPECT_EQ(r["ms"]["runs"].size(), 2u);
    EXPECT_GT(r["ns_per_particle"].get<double>(), 0);
  }
  const json& checks = (*doc_)["neighbors"]["checks"];
  ASSERT_EQ(checks.size(), 8u * 2u);  // per case: the build's and the rebuild's lists
  for (const json& c : checks) {
    EXPECT_TRUE(c["ok"].get<bool>()) << c.dump();
    EXPECT_EQ(c["lists_compared"], 8000);  // at 8,000 points every list against brute force
  }
}

TEST_F(SmallSuites, NeighborsPerParticleFollowTheLatticeGeometry) {
  const double expected2 = expected_neighbors(20, 2.0, 0.1);
  const double expected3 = expected_neighbors(20, 3.0, 0.1);
  // About 26 and 90 at 20^3 (the boundary layers have fewer); 28.9 and 107 in the interior.
  EXPECT_NEAR(expected2, 26.0, 0.5);
  EXPECT_NEAR(expected3, 90.2, 1.0);
  for (const json& r : (*doc_)["neighbors"]["results"]) {
    if (r["phase"] != "build") continue;
    const double got = r["neighbors_per_particle"].get<double>();
    // The spread of one random realization is about 0.02 (r = 2 dx) and 0.07 (3 dx).
    if (r["radius_dx"].get<double>() == 2.0)
      EXPECT_NEAR(got, expected2, 0.15) << r.dump();
    else
      EXPECT_NEAR(got, expected3, 0.4) << r.dump();
  }
  // Both orders and both precisions see the same points, hence the same counts.
  for (const NeighborsRow& a : result_->neighbors)
    for (const NeighborsRow& b : result_->neighbors)
      if (a.radius_dx == b.radius_dx && a.phase == b.phase) {
        EXPECT_NEAR(a.neighbors_per_particle, b.neighbors_per_particle, 0.01);
      }
}

TEST_F(SmallSuites, StepsResultsHaveTimingsThroughputAndMemory) {
  const json& res = (*doc_)["steps"]["results"];
  ASSERT_EQ(res.size(), 2u * 2u);  // 2 modes x float and double
  for (const json& r : res) {
    EXPECT_EQ(r["particles"], 8000);
    EXPECT_EQ(r["timed_steps"], 3);
    for (const char* phase : {"grid", "lists", "density", "forces", "integrate", "total", "wall"})
      EXPECT_GE(r["ms_per_step"][phase].get<double>(), 0) << phase;
    EXPECT_GT(r["ms_per_step"]["total"].get<double>(), 0);
    EXPECT_GE(r["ms_per_step"]["wall"].get<double>(), r["ms_per_step"]["total"].get<double>() * 0.99);
    // The reported run is the median of three: between the fastest and the slowest.
    EXPECT_EQ(r["runs"], 3);
    EXPECT_LE(r["wall_ms_per_step_min"].get<double>(), r["ms_per_step"]["wall"].get<double>());
    EXPECT_GE(r["wall_ms_per_step_max"].get<double>(), r["ms_per_step"]["wall"].get<double>());
    EXPECT_GT(r["particle_steps_per_second"].get<double>(), 0);
    EXPECT_GT(r["ns_per_particle_step"].get<double>(), 0);
    // A lattice block: the first lists hold the ~30 neighbors within h = 2 dx (verlet more).
    EXPECT_GT(r["neighbors_per_particle"].get<double>(), 15);
    // The pair loops' figures: standard's lists hold exactly the pairs within h when the passes
    // run; verlet's skin (0.1 h) adds the lattice's shell at 2 dx = h (26 of 32 entries within h
    // in the interior, more at the block's faces, 0.90 measured); both passes' visits per
    // core-second follow from the visits and the two phases' times, the force pass's alone from
    // its time where the density sums are made in the list build (standard's, and only there).
    const double visits = r["pair_visits_per_particle"].get<double>();
    const double within = r["within_h_fraction"].get<double>();
    if (r["mode"] == "standard") {
      EXPECT_EQ(within, 1.0);
      EXPECT_NEAR(visits, r["neighbors_per_particle"].get<double>(), 0.5);
    } else {
      EXPECT_GT(within, 0.7);
      EXPECT_LT(within, 0.95);
    }
    const bool in_lists = r["density_in_lists"].get<bool>();
    EXPECT_EQ(in_lists, r["mode"] == "standard");
    const double pass_s =
        1e-3 * ((in_lists ? 0 : r["ms_per_step"]["density"].get<double>()) + r["ms_per_step"]["forces"].get<double>());
    EXPECT_NEAR(r["pair_visits_per_core_second"].get<double>() * pass_s / r["threads"].get<double>(),
                (in_lists ? 1 : 2) * visits * r["particles"].get<double>(),
                1e-6 * visits * r["particles"].get<double>());
    const json& mem = r["memory"];
    EXPECT_GT(mem["peak_rss_bytes"].get<std::int64_t>(), 0);
    EXPECT_GT(mem["baseline_rss_bytes"].get<std::int64_t>(), 0);
    // Positions, velocities, densities and lists alone take over 100 bytes per particle.
    EXPECT_GT(mem["bytes_per_particle"].get<double>(), 0);
    if (mem["peak_reset"].get<bool>()) {
      EXPECT_GT(mem["bytes_per_particle"].get<double>(), 100);
    }
  }
  const json& scaling = (*doc_)["scaling"];
  ASSERT_EQ(scaling.size(), res.size());
  for (const json& s : scaling) EXPECT_GT(s["ns_per_particle_step"].get<double>(), 0);
}

TEST_F(SmallSuites, CsvRowsMatchTheResults) {
  const auto neighbors = test::lines_of(test::slurp(dir_->path() / "neighbors.csv"));
  ASSERT_EQ(neighbors.size(), 1u + 16u);
  EXPECT_EQ(neighbors[0].rfind("particles,side,radius_dx,precision,order,threads", 0), 0u) << neighbors[0];
  const auto steps = test::lines_of(test::slurp(dir_->path() / "steps.csv"));
  ASSERT_EQ(steps.size(), 1u + 4u);
  EXPECT_NE(steps[0].find("ns_per_particle_step"), std::string::npos);
  EXPECT_NE(steps[0].find("bytes_per_particle"), std::string::npos);
}

TEST_F(SmallSuites, PrintsATableLinePerResult) {
  std::size_t rows = 0;
  for (const auto& line : test::lines_of(table_)) rows += line.rfind("    8000 ", 0) == 0;
  EXPECT_EQ(rows, 16u + 4u);
  EXPECT_NE(table_.find("scaling"), std::string::npos);
}

TEST(BenchOptionsParsing, AcceptsTheDocumentedValuesAndNamesTheFlagOtherwise) {
  EXPECT_EQ(parse_bench_suites("all"), (std::vector<std::string>{"neighbors", "steps", "tank"}));
  EXPECT_EQ(parse_bench_suites("tank,neighbors"), (std::vector<std::string>{"neighbors", "tank"}));
  EXPECT_EQ(parse_thread_list("1,2,2,8"), (std::vector<int>{1, 2, 8}));
  EXPECT_EQ(parse_precisions("double"), std::vector<Precision>{Precision::Double});
  EXPECT_EQ(parse_bench_size("full"), BenchSize::Full);
  for (const char* bad : {"foo", "neighbors,", "", "scaling"}) {
    try {
      parse_bench_suites(bad);
      ADD_FAILURE() << bad;
    } catch (const Error& e) {
      EXPECT_EQ(e.where(), "--suite");
      EXPECT_NE(e.message().find("neighbors, steps, tank, or all"), std::string::npos) << e.what();
    }
  }
  for (const char* bad : {"0", "-1", "a", "1,,2", "99999", "1.5"}) EXPECT_THROW(parse_thread_list(bad), Error) << bad;
  EXPECT_THROW(parse_precisions("half"), Error);
  EXPECT_THROW(parse_bench_size("huge"), Error);
  EXPECT_THROW(parse_bench_modes("brute_force"), Error);
}

TEST(BenchSizes, GrowWithTheSize) {
  BenchOptions o;
  o.size = BenchSize::Small;
  EXPECT_EQ(steps_sides(o), std::vector<int>{20});
  EXPECT_EQ(neighbors_sides(BenchSize::Small), std::vector<int>{20});
  o.size = BenchSize::Large;
  EXPECT_EQ(steps_sides(o), (std::vector<int>{20, 40, 80}));
  EXPECT_EQ(neighbors_sides(BenchSize::Large), (std::vector<int>{20, 40, 80}));
  o.size = BenchSize::Full;
  EXPECT_EQ(steps_sides(o), (std::vector<int>{20, 40, 80, 100}));
  // The 1M target is float unless asked otherwise.
  EXPECT_EQ(steps_precisions(o, 100), std::vector<Precision>{Precision::Float});
  EXPECT_EQ(steps_precisions(o, 80).size(), 2u);
  o.particles = 10'000'000;
  EXPECT_EQ(steps_sides(o), std::vector<int>{215});
}

}  // namespace
}  // namespace sph

namespace sph {
namespace {

// A benchmark stopped (or read) before its last suite ends says so, and an earlier benchmark's
// files stay until this one has results to put in their place.
TEST(BenchFiles, AnUnfinishedRunIsIncompleteAndEarlierFilesStayUntilReplaced) {
  test::TempDir dir;
  test::spit(dir / "bench.json", "earlier\n");
  test::spit(dir / "steps.csv", "earlier\n");
  test::spit(dir / "tank.csv", "earlier\n");
  prepare_bench_directory(dir.path());
  EXPECT_EQ(test::slurp(dir / "bench.json"), "earlier\n") << "kept until this run writes";
  BenchResult r;
  r.options.suites = {"neighbors", "steps"};
  r.suites_done = {"neighbors"};
  EXPECT_EQ(json::parse(bench_json(r))["status"], "incomplete: 1 of 2 suites done (stopped, or still running)");
  write_bench_files(dir.path(), r);
  EXPECT_TRUE(std::filesystem::exists(dir / "neighbors.csv"));
  EXPECT_FALSE(std::filesystem::exists(dir / "steps.csv")) << "the earlier run's, not this one's";
  EXPECT_FALSE(std::filesystem::exists(dir / "tank.csv"));
  r.suites_done.push_back("steps");
  EXPECT_EQ(json::parse(bench_json(r))["status"], "completed");
  r.failure = "boom";
  EXPECT_EQ(json::parse(bench_json(r))["status"], "failed: boom");
}

}  // namespace
}  // namespace sph
