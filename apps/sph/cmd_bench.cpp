// `sph bench`: the benchmark suites (neighbor search, whole steps, the paper's tank), printed
// as tables while they run and written to DIR/bench.json plus one CSV per suite.

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <sph/bench/bench.h>
#include <sph/core/error.h>
#include <sph/core/timer.h>
#include <sph/neighbors/neighbor_mode.h>

#include "cli_checks.h"
#include "commands.h"

namespace sph::app {

namespace {

struct BenchCliOptions {
  std::string suites = "all";
  std::string size = "small";
  std::string threads;
  std::string precisions;
  std::string modes = join_neighbor_mode_names(NeighborModeSet::Compared, ",", ",");
  int repeats = 5;
  int step_runs = 3;
  std::string output = "out/bench";
  std::int64_t particles = 0;
  std::int64_t warmup_steps = -1;
  std::int64_t timed_steps = -1;
  std::int64_t tank_steps = 0;
  std::string scene_dir;
  bool no_progress = false;
};

/// The options that only some suites read, and those suites: one given for none of the suites
/// chosen is ignored, and the user is told (`--suite neighbors --particles 1000000` times the
/// size's own lattices). A warning, not an error: scripts/bench.sh hands the same extra options
/// to runs of different suites.
struct SuiteOption {
  const char* flag;
  std::vector<std::string> suites;
};
const std::vector<SuiteOption>& suite_options() {
  static const std::vector<SuiteOption> kOptions{{"--precision", {"neighbors", "steps"}},
                                                 {"--repeats", {"neighbors", "tank"}},
                                                 {"--step-runs", {"steps"}},
                                                 {"--particles", {"steps"}},
                                                 {"--modes", {"steps", "tank"}},
                                                 {"--warmup-steps", {"steps"}},
                                                 {"--timed-steps", {"steps"}},
                                                 {"--steps", {"tank"}},
                                                 {"--scene-dir", {"tank"}}};
  return kOptions;
}

void warn_unread_options(const CLI::App& cmd, const std::vector<std::string>& suites) {
  for (const SuiteOption& o : suite_options()) {
    if (cmd.count(o.flag) == 0) continue;
    if (std::any_of(o.suites.begin(), o.suites.end(),
                    [&](const std::string& s) { return std::find(suites.begin(), suites.end(), s) != suites.end(); }))
      continue;
    const bool one = o.suites.size() == 1;
    fmt::print(stderr, "sph: warning: {}: only the {} suite{} read{} it, and --suite {} {}: it is ignored\n", o.flag,
               fmt::join(o.suites, " and "), one ? "" : "s", one ? "s" : "", fmt::join(suites, ","),
               one ? "does not run it" : "runs neither");
  }
}

int bench(const BenchCliOptions& cli, const CLI::App& cmd) {
  // Everything that can be refused is checked before the output directory is touched.
  check_output_path(cli.output, "-o/--output");
  BenchOptions opt;
  opt.suites = parse_bench_suites(cli.suites, "--suite");
  opt.size = parse_bench_size(cli.size, "--size");
  if (!cli.threads.empty()) opt.threads = parse_thread_list(cli.threads, "--threads");
  if (!cli.precisions.empty()) opt.precisions = parse_precisions(cli.precisions, "--precision");
  opt.modes = parse_bench_modes(cli.modes, "--modes");
  opt.repeats = cli.repeats;
  opt.step_runs = cli.step_runs;
  opt.particles = cli.particles;
  opt.warmup_steps = cli.warmup_steps;
  opt.timed_steps = cli.timed_steps;
  opt.tank_steps = cli.tank_steps;
  opt.scene_dir = cli.scene_dir;
  validate_bench_options(opt);
  warn_unread_options(cmd, opt.suites);
  const std::filesystem::path dir(cli.output);
  prepare_bench_directory(dir);

  BenchOutput out;
  out.table = [](const std::string& text) {
    fmt::print(stdout, "{}\n", text);
    std::fflush(stdout);
  };
  if (!cli.no_progress) out.progress = [](const std::string& text) { fmt::print(stderr, "sph: {}\n", text); };

  const std::vector<int> threads = bench_threads(opt);
  const bool steps = std::find(opt.suites.begin(), opt.suites.end(), "steps") != opt.suites.end();
  const std::string size = opt.particles > 0 && steps
                               ? fmt::format("size {}, steps suite {} particles", to_string(opt.size), opt.particles)
                               : fmt::format("size {}", to_string(opt.size));
  fmt::print(stderr, "sph: bench {} ({}, threads {}, repeats {}) -> {}\n", fmt::join(opt.suites, ","), size,
             fmt::join(threads, ","), opt.repeats, dir.string());
  Stopwatch wall;
  try {
    run_benchmarks(opt, dir, out);
  } catch (const BenchFailure& e) {
    fmt::print(stderr, "sph: error: {}\nsph: the figures measured before the failure are in {}\n", e.what(),
               (dir / "bench.json").string());
    return kRunFailed;
  }
  fmt::print(stderr, "sph: bench done in {:.1f} s: {}", wall.elapsed(), (dir / "bench.json").string());
  for (const std::string& suite : opt.suites) fmt::print(stderr, ", {}", (dir / (suite + ".csv")).string());
  fmt::print(stderr, "\n");
  return kOk;
}

}  // namespace

std::function<int()> add_bench_command(CLI::App& app) {
  auto opt = std::make_shared<BenchCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "bench", "Benchmark suites: neighbor search, simulation steps per mode, the paper's tank; tables and CSV/JSON");
  // A flag given twice takes its last value, so scripts can append overrides to their defaults.
  cmd->option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  cmd->add_option("--suite", opt->suites, "Comma-separated suites: neighbors, steps, tank, or all")->default_str("all");
  cmd->add_option("--size", opt->size,
                  "small (8k particles, few steps: CI), medium (adds 64k), large (adds 512k), full (adds the 1M "
                  "dam break to steps)")
      ->default_str("small");
  cmd->add_option("--threads", opt->threads,
                  "Comma-separated thread counts to run, e.g. 1,2 (default: 1 and the core count; more threads "
                  "than cores are allowed and marked with *)")
      ->check(not_empty("comma-separated thread counts, e.g. 1,2"));
  cmd->add_option("--precision", opt->precisions,
                  "float, double or float,double (default: both; float only from 1M particles on; the tank runs "
                  "the scene's own precision)")
      ->check(not_empty("float, double or float,double"));
  cmd->add_option("--repeats", opt->repeats, "Timings per neighbors case and runs per tank mode (medians reported)")
      ->check(in_range(1, 1000))
      ->default_str("5");
  cmd->add_option("--step-runs", opt->step_runs,
                  "Steps suite: runs per workload; the run of median wall time is reported, with the fastest and "
                  "slowest")
      ->check(in_range(1, 100))
      ->default_str("3");
  cmd->add_option("-o,--output", opt->output,
                  "Output directory for bench.json and the CSVs (an earlier benchmark's files there, those of other "
                  "suites too, are replaced once this one has its first results)")
      ->default_str("out/bench");
  cmd->add_option("--particles", opt->particles,
                  "Steps suite: run one dam break of about this many particles (rounded to a cube) instead of the "
                  "size's, e.g. 10000000")
      ->check(in_range(std::int64_t{1}, std::int64_t{2'000'000'000}));
  cmd->add_option("--modes", opt->modes, "Neighbor modes of the steps and tank suites")
      ->default_str(join_neighbor_mode_names(NeighborModeSet::Compared, ",", ","));
  cmd->add_option("--warmup-steps", opt->warmup_steps,
                  "Steps suite: untimed steps before timing (default: 10 at size small, else 20 to 3 by size)")
      ->check(in_range(std::int64_t{0}, std::int64_t{1'000'000}));
  cmd->add_option("--timed-steps", opt->timed_steps,
                  "Steps suite: timed steps (default: 40 at size small, else 50 to 5 by size)")
      ->check(in_range(std::int64_t{1}, std::int64_t{1'000'000}));
  cmd->add_option("--steps", opt->tank_steps,
                  "Tank suite: steps per run (default: the whole scene, 1000 at size small)")
      ->check(in_range(std::int64_t{1}, std::int64_t{1'000'000'000}));
  cmd->add_option("--scene-dir", opt->scene_dir,
                  "Directory holding tank_fill_3d.json (default: the paper scenes installed with sph)")
      ->check(not_empty("the directory holding tank_fill_3d.json"));
  cmd->add_flag("--no-progress", opt->no_progress, "No progress lines on stderr (the tables still go to stdout)");
  return [opt, cmd]() -> int {
    if (!cmd->parsed()) return kBadInput;
    return bench(*opt, *cmd);
  };
}

}  // namespace sph::app
