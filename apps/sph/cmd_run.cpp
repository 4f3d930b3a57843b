// `sph run SCENE.json`: runs a scene and writes frames, stats and a summary.

#include <algorithm>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <unistd.h>

#include <fmt/format.h>

#include <sph/core/error.h>
#include <sph/core/parallel.h>
#include <sph/core/timer.h>
#include <sph/io/run_output.h>
#include <sph/scene/builders.h>
#include <sph/scene/scene_reader.h>

#include "commands.h"
#include "progress.h"

namespace sph::app {

namespace {

struct RunOptions {
  std::string scene;
  std::string output;
  std::string neighbors;
  std::int64_t steps = 0;
  int threads = 0;
  std::vector<std::string> sets;
  bool no_progress = false;
  bool audit = false;
};

template <int D, std::floating_point R>
int run_scene(const SceneDesc& desc, const RunOptions& opt) {
  // Everything that can be refused is checked before the output directory is touched.
  Simulation<D, R> sim = make_simulation<D, R>(desc);
  const std::filesystem::path dir =
      opt.output.empty() ? std::filesystem::path("out") / desc.name : std::filesystem::path(opt.output);
  prepare_output_directory(dir);

  RunInfo info{std::string(to_string(sim.params().neighbors)), num_threads()};
  RunOutput<D, R> out(dir, desc, info);
  fmt::print(stderr, "sph: {} ({}D, {}, {} neighbors, {} thread{}): {} particles{}, {} steps of {:.4g} s -> {}\n",
             desc.name, D, std::is_same_v<R, float> ? "float" : "double", info.mode, info.threads,
             info.threads == 1 ? "" : "s", sim.particles().size(),
             sim.params().emitters.empty() ? "" : " (emitters add more)", desc.steps, sim.params().time_step,
             dir.string());
  Stopwatch wall;
  out.begin(sim);
  Progress progress(
      desc.steps,
      opt.no_progress ? Progress::Mode::Off : (::isatty(STDERR_FILENO) ? Progress::Mode::Bar : Progress::Mode::Lines),
      stderr);
  try {
    for (std::int64_t s = 0; s < desc.steps; ++s) {
      const StepInfo& step = sim.step();
      out.after_step(sim, step, s + 1 == desc.steps);
      progress.update(s + 1, step.particles);
    }
  } catch (const Error& e) {
    progress.finish();
    out.finish(sim, std::string("failed: ") + e.what(), wall.elapsed());
    fmt::print(stderr, "sph: error: {}\nsph: the frames written before the failure are kept in {}\n", e.what(),
               dir.string());
    return kRunFailed;
  }
  progress.finish();
  const double seconds = wall.elapsed();
  out.finish(sim, "completed", seconds);
  fmt::print(stderr,
             "sph: done: {} steps, {} particles, {:.2f} s ({:.3f} ms/step). Wrote {} frames.\n"
             "  {}/frames.pvd   open in ParaView (Filters > Point Gaussian to see particles)\n"
             "  {}/stats.csv    per-step energy, neighbors and phase timings\n"
             "  {}/summary.json totals\n",
             desc.steps, sim.particles().size(), seconds, 1e3 * seconds / static_cast<double>(desc.steps),
             out.frames_written(), dir.string(), dir.string(), dir.string());
  if (opt.audit)
    fmt::print(stderr,
               "sph: audit: {} pairs within h were missing from the lists, in {} of {} steps; the deepest miss "
               "was (h - r) / h = {:.3g}\n",
               out.audit_totals().missed_pairs, out.audit_steps_with_misses(), desc.steps,
               out.audit_totals().max_penetration);
  return kOk;
}

int run(const RunOptions& opt) {
  std::vector<std::string> sets = opt.sets;
  if (!opt.neighbors.empty()) sets.push_back("Configuration.neighbors=\"" + opt.neighbors + "\"");
  if (opt.steps > 0) sets.push_back("Configuration.numberOfSteps=" + std::to_string(opt.steps));
  if (opt.threads > 0) set_num_threads(opt.threads);

  SceneDesc desc = read_scene_file(opt.scene, sets);
  desc.body2.sim.audit = desc.body3.sim.audit = opt.audit;
  for (const auto& w : desc.warnings) fmt::print(stderr, "sph: warning: {}\n", w);
  const bool f = desc.precision == Precision::Float;
  if (desc.dimension == 2) return f ? run_scene<2, float>(desc, opt) : run_scene<2, double>(desc, opt);
  return f ? run_scene<3, float>(desc, opt) : run_scene<3, double>(desc, opt);
}

}  // namespace

std::function<int()> add_run_command(CLI::App& app) {
  auto opt = std::make_shared<RunOptions>();
  CLI::App* cmd = app.add_subcommand("run", "Run a scene file and write frames (VTK), stats.csv and summary.json");
  cmd->add_option("scene", opt->scene, "Scene file (JSON; see docs/scene-format.md)")->required();
  cmd->add_option("-o,--output", opt->output, "Output directory (default: out/<scene name>)");
  cmd->add_option("--neighbors", opt->neighbors, "Neighbor strategy, overriding the scene's Configuration.neighbors")
      ->check(CLI::IsMember({"standard", "adaptive", "verlet", "brute_force"}));
  cmd->add_option("--steps", opt->steps, "Number of steps, overriding Configuration.numberOfSteps")
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{1'000'000'000'000}));
  cmd->add_option("--threads", opt->threads, "Worker threads (default: all cores)")->check(CLI::Range(1, 4096));
  cmd->add_option("--set", opt->sets,
                  "Override a scene value by its key path, e.g. --set Fluid.stiffness=2000 "
                  "--set FluidBlocks[0].end=[0.5,1.0] (repeatable; VALUE is JSON or a plain string)")
      ->type_name("KEY=VALUE");
  cmd->add_flag("--audit", opt->audit,
                "Check the lists every step against exact lists and record the pairs within h they miss "
                "(stats.csv columns missed_pairs, particles_missing, max_missed_penetration; costs about one "
                "extra standard list build per step)");
  cmd->add_flag("--no-progress", opt->no_progress,
                "No progress output (default: a bar with ETA on a terminal, a line every 10 % otherwise)");
  return [opt, cmd]() -> int {
    if (!cmd->parsed()) return kBadInput;
    return run(*opt);
  };
}

}  // namespace sph::app
