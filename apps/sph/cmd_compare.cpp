// `sph compare SCENE.json -o DIR`: runs the neighbor modes on one scene and reports speed,
// accuracy against the standard run and the chaos floor, missed pairs, and images.

#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include <sph/analysis/compare.h>
#include <sph/core/error.h>
#include <sph/core/parallel.h>
#include <sph/core/timer.h>
#include <sph/io/atomic_file.h>
#include <sph/io/frames.h>
#include <sph/io/run_directory.h>
#include <sph/neighbors/neighbor_mode.h>
#include <sph/run/memory.h>
#include <sph/scene/scene_reader.h>

#include "cli_checks.h"
#include "commands.h"

namespace sph::app {

namespace {

namespace fs = std::filesystem;

struct CompareCliOptions {
  std::string scene;
  std::optional<std::string> output;
  std::string modes = join_neighbor_mode_names(NeighborModeSet::Compared, ",", ",");
  std::int64_t steps = 0;
  int threads = 0;
  int frames = 3;
  double perturbation = 1e-9;
  std::vector<std::string> sets;
  bool no_audit = false;
  bool no_progress = false;
  bool no_run_frames = false;
};

std::vector<NeighborMode> parse_modes(const std::string& list) {
  std::vector<NeighborMode> modes;
  std::stringstream ss(list);
  for (std::string item; std::getline(ss, item, ',');) {
    if (item.empty())
      throw Error("empty mode name in \"" + list + "\"; expected e.g. " +
                      join_neighbor_mode_names(NeighborModeSet::Compared, ",", ","),
                  "--modes");
    const NeighborMode m = parse_neighbor_mode(item, "--modes", NeighborModeSet::Compared);
    if (std::find(modes.begin(), modes.end(), m) != modes.end())
      throw Error("mode \"" + item + "\" is listed twice", "--modes");
    modes.push_back(m);
  }
  if (modes.empty())
    throw Error("no mode given; expected e.g. " + join_neighbor_mode_names(NeighborModeSet::Compared, ",", ","),
                "--modes");
  return modes;
}

int compare(const CompareCliOptions& opt) {
  CompareOptions co;
  co.modes = parse_modes(opt.modes);
  co.steps = opt.steps;
  co.frames = opt.frames;
  co.perturbation = opt.perturbation;
  co.audit = !opt.no_audit;
  if (opt.threads > 0) set_num_threads(opt.threads);

  check_set_flag_conflicts(opt.sets, {{"Configuration.numberOfSteps", opt.steps > 0 ? "--steps" : nullptr}});
  std::vector<std::string> sets = opt.sets;
  if (opt.steps > 0) sets.push_back("Configuration.numberOfSteps=" + std::to_string(opt.steps));
  if (opt.output) check_output_path(*opt.output, "-o/--output");
  const SceneDesc desc = read_scene_file(opt.scene, sets);
  check_fits_in_memory(desc);  // each mode's run holds one simulation at a time
  check_comparable(desc);
  for (const auto& w : desc.warnings) fmt::print(stderr, "sph: warning: {}\n", w);
  const fs::path dir = opt.output ? fs::path(*opt.output) : fs::path("out") / (desc.name + "_compare");
  prepare_comparison_directory(dir);
  if (!opt.no_run_frames) co.runs_dir = dir;

  fmt::print(stderr, "sph: compare {} ({}D, {} steps, {} thread{}) -> {}\n", desc.name, desc.dimension, desc.steps,
             num_threads(), num_threads() == 1 ? "" : "s", dir.string());
  Stopwatch wall;
  // A line per quarter of each run.
  int run_shown = -1;
  std::int64_t quarters_shown = 0;
  const CompareProgress progress = [&](const std::string& label, int index, int count, std::int64_t done,
                                       std::int64_t total) {
    if (opt.no_progress) return;
    if (index != run_shown) run_shown = index, quarters_shown = 0;
    const std::int64_t quarters = 4 * done / total;
    if (quarters <= quarters_shown) return;
    quarters_shown = quarters;
    if (done == total)
      fmt::print(stderr, "sph: [{}/{}] {}: done\n", index + 1, count, label);
    else
      fmt::print(stderr, "sph: [{}/{}] {}: {} %\n", index + 1, count, label, 25 * quarters);
  };
  const CompareResult result = run_comparison(desc, co, progress);
  write_comparison(dir, result);

  // A one-screen summary: speed ratios and the final divergence.
  fmt::print(stderr, "sph: compared in {:.1f} s:\n", wall.elapsed());
  const double ref = standard_seconds(result);
  for (std::size_t k = 0; k < result.runs.size(); ++k) {
    const RunRecord& r = result.runs[k];
    const double t = r.totals.total();
    // (the first run is the reference, as in report.md: its ratio against the standard runs' mean
    // would read as a speed of its own)
    std::string line = k == 0 ? fmt::format("  {:<22} {:8.3f} s  reference", r.label, t)
                              : fmt::format("  {:<22} {:8.3f} s  {:5.2f}x", r.label, t, t > 0 ? ref / t : 0.0);
    if (k > 0 && !result.divergence[k].empty())
      line += fmt::format("  RMS divergence at end {:.3g} h", result.divergence[k].back().rms);
    if (co.audit) line += fmt::format("  missed pairs {}", r.missed_pairs());
    if (co.audit && result.has_boundary_particles)
      line += fmt::format(" (fluid-boundary {})", r.boundary_missed_pairs());
    if (!r.failure.empty()) line += "  FAILED: " + r.failure;
    fmt::print(stdout, "{}\n", line);  // (the results to stdout, as bench's tables)
  }
  std::fflush(stdout);
  fmt::print(stderr, "  report: {}\n", (dir / "report.md").string());
  for (const RunRecord& r : result.runs)
    if (!r.failure.empty()) return kRunFailed;
  return kOk;
}

}  // namespace

std::function<int()> add_compare_command(CLI::App& app) {
  auto opt = std::make_shared<CompareCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "compare", "Run the neighbor modes on one scene and write a report: speed, divergence, missed pairs, images");
  cmd->add_option("scene", opt->scene, "Scene file (JSON; see docs/scene-format.md)")->required();
  cmd->add_option("-o,--output", opt->output, "Output directory (default: out/<scene name>_compare)");
  cmd->add_option("--modes", opt->modes, "Comma-separated modes to run (standard is always run: it is the reference)")
      ->default_str(join_neighbor_mode_names(NeighborModeSet::Compared, ",", ","));
  cmd->add_option("--steps", opt->steps, "Number of steps, overriding Configuration.numberOfSteps")
      ->check(in_range(std::int64_t{1}, std::int64_t{1'000'000'000}));
  cmd->add_option("--threads", opt->threads, "Worker threads (default: all cores)")->check(in_range(1, 4096));
  cmd->add_option("--frames", opt->frames, "Side-by-side images at this many evenly spaced steps")
      ->check(in_range(1, 100))
      ->default_str("3");
  cmd->add_option("--perturbation", opt->perturbation,
                  "Chaos floor: a second standard run with particles displaced by this fraction of h (0: none)")
      ->check(in_range(0.0, 0.1))
      ->default_str("1e-9");
  cmd->add_option("--set", opt->sets, "Override a scene value by its key path (repeatable), as in sph run")
      ->type_name("KEY=VALUE");
  cmd->add_flag("--no-audit", opt->no_audit, "Do not audit the lists for missed pairs (the audit is never timed)");
  cmd->add_flag("--no-run-frames", opt->no_run_frames,
                "Do not write each mode's frames to DIR/<mode>/ (by default they are written on the scene's "
                "output schedule, for sph render and sph view)");
  cmd->add_flag("--no-progress", opt->no_progress, "No progress lines");
  return [opt, cmd]() -> int {
    if (!cmd->parsed()) return kBadInput;
    return compare(*opt);
  };
}

}  // namespace sph::app
