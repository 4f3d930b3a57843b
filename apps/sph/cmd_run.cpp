// `sph run SCENE.json`: runs a scene and writes frames, stats and a summary.

#include <algorithm>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <unistd.h>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <sph/core/error.h>
#include <sph/core/parallel.h>
#include <sph/io/checkpoint.h>
#include <sph/io/run_directory.h>
#include <sph/io/run_output.h>
#include <sph/neighbors/neighbor_mode.h>
#include <sph/run/driver.h>
#include <sph/run/resume.h>
#include <sph/scene/builders.h>
#include <sph/scene/dispatch.h>
#include <sph/scene/scene_reader.h>
#include <sph/surface/mesh_files.h>

#include "cli_checks.h"
#include "commands.h"
#include "progress.h"

namespace sph::app {

namespace {

struct RunOptions {
  std::string scene;
  std::optional<std::string> output;  // -o DIR (given empty: refused)
  std::string neighbors;
  std::int64_t steps = 0;
  int threads = 0;
  std::vector<std::string> sets;
  bool no_progress = false;
  bool audit = false;
  bool overwrite = false;
  bool strict = false;
  std::int64_t checkpoint_every = 0;
  bool surface = false;  // --surface: DIR/surface/ per frame
  std::string surface_format = "all";
  double surface_resolution = 2, surface_smoothing = 2;
  std::string resume;
  std::optional<std::string> formats;  // --format vtu,ply
  std::optional<std::string> fields;   // --fields velocity,density or none
  std::optional<std::int64_t> every;   // --every N
  std::optional<double> fps;           // --fps F
};

/// The comma-separated names of `list` as a JSON array of strings, each checked against
/// `choices`; `none` (if given), alone, stands for the empty list, which `none_means` says in
/// words. Throws sph::Error naming `flag`.
std::string name_list_json(const std::string& list, const std::vector<std::string>& choices, const std::string& flag,
                           const char* none = nullptr, const char* none_means = nullptr) {
  std::string expected;
  for (const auto& c : choices) expected += (expected.empty() ? "" : ", ") + c;
  if (none && list == none) return "[]";
  std::vector<std::string> names;
  std::size_t begin = 0;
  while (true) {
    const std::size_t comma = list.find(',', begin);
    const std::string name = list.substr(begin, comma == std::string::npos ? std::string::npos : comma - begin);
    if (none && name == none)
      throw Error(fmt::format("\"{}\" ({}) cannot be combined with other names; give it alone, or list the ones "
                              "wanted from {}",
                              none, none_means, expected),
                  flag);
    if (std::find(choices.begin(), choices.end(), name) == choices.end())
      throw Error(fmt::format("{}\"{}\" is not one of {}; expected a comma-separated list such as {},{}{}",
                              name.empty() ? "an empty name in the list: " : "", name, expected, choices[0], choices[1],
                              none ? fmt::format(", or {} alone ({})", none, none_means) : std::string()),
                  flag);
    if (std::find(names.begin(), names.end(), name) != names.end())
      throw Error("\"" + name + "\" is given twice; expected each name at most once", flag);
    names.push_back(name);
    if (comma == std::string::npos) break;
    begin = comma + 1;
  }
  std::string json = "[";
  for (const auto& n : names) json += (json.size() > 1 ? ",\"" : "\"") + n + "\"";
  return json + "]";
}

/// The --set overrides that --format, --fields, --every and --fps stand for (so that they land
/// in scene.json and in checkpoints like any scene value).
std::vector<std::string> output_overrides(const RunOptions& opt) {
  std::vector<std::string> sets;
  if (opt.every && opt.fps)
    throw Error("--every and --fps both choose when frames are written; give one of them", "--every/--fps");
  // Each replaces the other schedule, whatever the scene chose.
  if (opt.every)
    sets.push_back("Configuration.outputFps=0"),
        sets.push_back(fmt::format("Configuration.outputEveryNSteps={}", *opt.every));
  if (opt.fps)
    sets.push_back("Configuration.outputEveryNSteps=0"),
        sets.push_back(fmt::format("Configuration.outputFps={}", *opt.fps));
  if (opt.formats)
    sets.push_back("Configuration.outputFormats=" + name_list_json(*opt.formats, frame_format_names(), "--format"));
  if (opt.fields)
    sets.push_back("Configuration.outputFields=" +
                   name_list_json(*opt.fields, {std::begin(kFrameFieldNames), std::end(kFrameFieldNames)}, "--fields",
                                  "none", "positions only"));
  return sets;
}

/// `word` as one shell word: unchanged if it is plain, else in single quotes.
std::string shell_word(const std::string& word) {
  if (!word.empty() && word.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789/._-+") ==
                           std::string::npos)
    return word;
  std::string q = "'";
  for (char c : word) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

/// The signal that asked the run to stop (SIGINT or SIGTERM), 0 if none. The handler only
/// records it; the step loop finishes its step, writes a checkpoint and exits.
volatile std::sig_atomic_t g_stop_signal = 0;

extern "C" void record_stop_signal(int sig) { g_stop_signal = sig; }

/// Installs the handler for SIGINT and SIGTERM for the life of the step loop. SA_RESETHAND:
/// a second signal kills the program at once (files stay whole: every file is written under a
/// temporary name and renamed into place).
class StopSignals {
 public:
  StopSignals() {
    struct sigaction sa = {};
    sa.sa_handler = record_stop_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESETHAND;
    sigaction(SIGINT, &sa, &old_int_);
    sigaction(SIGTERM, &sa, &old_term_);
  }
  ~StopSignals() {
    sigaction(SIGINT, &old_int_, nullptr);
    sigaction(SIGTERM, &old_term_, nullptr);
  }
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

 private:
  struct sigaction old_int_ = {}, old_term_ = {};
};

/// The lines of the closing message that say where the frames are (none if none were written).
std::string frames_hint(const OutputDesc& output, const std::filesystem::path& dir, std::size_t frames, bool obstacles,
                        bool bodies) {
  std::string s;
  if (frames == 0) return s;
  for (FrameFormat f : output.formats) {
    const FrameFormatDesc& d = frame_format_desc(f);
    s += fmt::format("  {}/{} {}\n", dir.string(), d.look_at, d.hint);
  }
  if (obstacles)
    s +=
        fmt::format("  {}/solids.pvd   the obstacles at each frame's time (ParaView, with the frames)\n", dir.string());
  if (bodies)
    s += fmt::format(
        "  {}/bodies.csv   the floating bodies at each frame: position, orientation, velocities, the "
        "fluid's force\n",
        dir.string());
  return s;
}

/// The closing lines of a completed run.
template <int D, std::floating_point R>
void print_done(const RunDriver<D, R>& run, const RunResult& result, bool audit) {
  const RunOutput<D, R>& out = *run.output();
  const std::filesystem::path& dir = run.settings().dir;
  const std::int64_t ran = result.steps_done - result.first_step;
  fmt::print(
      stderr,
      "sph: done: {} steps, {} particles, {:.2f} s ({:.3f} ms/step). {} {} frames.\n"
      "{}{}"
      "  {}/stats.csv    per-step energy, neighbors and phase timings\n"
      "  {}/summary.json totals\n"
      "{}",
      ran, run.simulation().particles().size(), result.wall_seconds,
      1e3 * result.wall_seconds / static_cast<double>(std::max<std::int64_t>(ran, 1)),
      result.first_step > 0 ? "The run now has" : "Wrote", out.frames_written(),
      frames_hint(run.scene().output, dir, out.frames_written(), !run.simulation().params().obstacles.empty(),
                  !run.simulation().bodies().empty()),
      run.settings().surface && out.frames_written() > 0
          ? fmt::format("  {}/surface/      the free surface of each frame (sph surface's files)\n", dir.string())
          : std::string(),
      dir.string(), dir.string(),
      out.frames_written() > 0
          ? fmt::format("  look at it: sph render {0} --mp4 (PNG frames, a movie); sph view {0} (a web page)\n",
                        shell_word(dir.string()))
          : std::string());
  if (audit)
    fmt::print(stderr,
               "sph: audit: {} pairs within h were missing from the lists, in {} of {} steps; the deepest miss "
               "was (h - r) / h = {:.3g}; {} fluid-boundary pairs were missing from the boundary lists\n",
               out.audit_totals().missed_pairs, out.audit_steps_with_misses(), result.steps_done,
               out.audit_totals().max_penetration, out.boundary_missed_pairs());
}

/// Runs `desc` into `dir`: a new run, or (with `checkpoint`) the continuation of the run that
/// wrote it. Returns the exit code.
template <int D, std::floating_point R>
int run_scene(const SceneDesc& desc, const RunOptions& opt, const std::filesystem::path& dir,
              CheckpointReader* checkpoint) {
  RunSettings settings{dir, opt.checkpoint_every, opt.strict, {}};
  if (opt.surface) {
    SurfaceOutput surface;
    surface.formats = parse_surface_formats(opt.surface_format, "--surface-format");
    if (D == 2 && surface.formats.vdb && opt.surface_format != "all")  // ("all": those that apply)
      throw Error("a 2D run's surfaces are polylines, which have no level set: vdb is for 3D runs; choose ply or obj",
                  "--surface-format");
    surface.settings.resolution = opt.surface_resolution;
    surface.settings.smoothing = opt.surface_smoothing;
    settings.surface = surface;
  }
  std::optional<RunDriver<D, R>> run;
  if (checkpoint)
    run.emplace(desc, *checkpoint, settings);
  else
    run.emplace(desc, settings);
  if (!run->resume_warning().empty()) fmt::print(stderr, "sph: warning: {}\n", run->resume_warning());
  const Simulation<D, R>& sim = run->simulation();
  const RunInfo& info = run->info();
  const std::int64_t first = run->first_step();
  // A run of CFL steps that ends at a time counts its progress in milliseconds of simulated time.
  const bool by_time = desc.end_time > 0;
  const auto sim_ms = [&] { return static_cast<std::int64_t>(std::llround(sim.time() * 1e3)); };
  const std::int64_t first_ms = sim_ms();
  const std::string length =
      by_time
          ? fmt::format("to t = {:.6g} s in CFL steps of {:.4g} to {:.4g} s", desc.end_time, sim.params().cfl.min_dt,
                        sim.params().cfl.max_dt)
          : fmt::format(
                "{} {}steps of {}{:.4g} s", desc.steps, sim.params().time_stepping == TimeStepping::Cfl ? "CFL " : "",
                sim.params().time_stepping == TimeStepping::Cfl ? "at most " : "",
                sim.params().time_stepping == TimeStepping::Cfl ? sim.params().cfl.max_dt : sim.params().time_step);
  fmt::print(stderr, "sph: {} ({}D, {}, {}{} neighbors, {} thread{}): {} particles{}, {}{} -> {}\n", desc.name, D,
             std::is_same_v<R, float> ? "float" : "double",
             sim.params().method == SimulationMethod::Dfsph ? "DFSPH, " : "", info.mode, info.threads,
             info.threads == 1 ? "" : "s", sim.particles().size(),
             sim.params().emitters.empty() ? "" : " (emitters add more)", length,
             checkpoint ? fmt::format(", resumed at step {}", first) : std::string(), dir.string());
  const Progress::Mode mode =
      opt.no_progress ? Progress::Mode::Off : (::isatty(STDERR_FILENO) ? Progress::Mode::Bar : Progress::Mode::Lines);
  Progress progress(
      by_time ? static_cast<std::int64_t>(std::llround(desc.end_time * 1e3)) - first_ms : desc.steps - first, mode,
      stderr, by_time ? "ms of simulated time" : "step");
  RunCallbacks callbacks;
  callbacks.progress = [&](std::int64_t done, std::size_t particles) {
    progress.update(by_time ? sim_ms() - first_ms : done - first, particles);
  };
  callbacks.warning = [&](const std::string& w) {
    fmt::print(stderr, "{}sph: warning: {}\n", mode == Progress::Mode::Bar ? "\n" : "", w);
  };
  callbacks.stop_requested = [](std::int64_t) -> std::string {
    const int sig = g_stop_signal;
    return sig == 0 ? "" : sig == SIGINT ? "SIGINT" : "SIGTERM";
  };
  RunResult result;
  {
    const StopSignals signals;
    result = run->run(callbacks);
  }
  progress.finish();
  switch (result.status) {
    case RunStatus::Interrupted:
      fmt::print(stderr,
                 "sph: interrupted by {} after step {} of {}: wrote a checkpoint. Continue the run with:\n"
                 "  sph run --resume {}\n",
                 result.stop_cause, result.steps_done, desc.steps, shell_word(dir.string()));
      return 128 + g_stop_signal;
    case RunStatus::Failed:
      fmt::print(stderr, "sph: error: {}\nsph: the frames written before the failure are kept in {}\n", result.error,
                 dir.string());
      return kRunFailed;
    case RunStatus::Completed:
      break;
  }
  print_done(*run, result, opt.audit);
  if (!result.warnings.empty())
    fmt::print(stderr,
               "sph: completed with {} health warning{} (above, and in {}/summary.json); the results may not be "
               "trustworthy (--strict makes warnings failures)\n",
               result.warnings.size(), result.warnings.size() == 1 ? "" : "s", dir.string());
  return kOk;
}

/// `sph run --resume DIR`: continues the run whose checkpoint is in DIR.
int resume(RunOptions opt) {
  const char* conflict = !opt.scene.empty()       ? "a SCENE file"
                         : opt.output             ? "-o/--output"
                         : opt.overwrite          ? "--overwrite"
                         : !opt.sets.empty()      ? "--set"
                         : !opt.neighbors.empty() ? "--neighbors"
                         : opt.audit              ? "--audit"
                         : opt.formats            ? "--format"
                         : opt.fields             ? "--fields"
                         : opt.every              ? "--every"
                         : opt.fps                ? "--fps"
                         : opt.surface            ? "--surface"
                                                  : nullptr;
  if (conflict)
    throw Error(
        fmt::format("--resume continues a run with the scene and settings it started with; {} cannot be "
                    "given with it (allowed: --steps, --threads, --checkpoint-every, --strict, --no-progress)",
                    conflict));
  if (opt.threads > 0) set_num_threads(opt.threads);
  RunToResume resumed = open_run_to_resume(opt.resume, opt.steps);
  for (const auto& w : resumed.warnings) fmt::print(stderr, "sph: warning: {}\n", w);
  // The checkpoint does not hold the --surface settings: the frames go on, the surfaces do not.
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(resumed.dir / "surface", ec))
    if (is_surface_output(e.path().filename().string())) {
      fmt::print(stderr,
                 "sph: warning: the run made surfaces of its frames (--surface); the resumed run writes frames only: "
                 "make the rest with sph surface {} once it ends\n",
                 shell_word(resumed.dir.string()));
      break;
    }
  if (opt.checkpoint_every == 0) opt.checkpoint_every = resumed.checkpoint_every;  // go on as the run did
  return dispatch(resumed.desc, [&]<int D, class R>() {
    return run_scene<D, R>(resumed.desc, opt, resumed.dir, resumed.checkpoint.get());
  });
}

int run(const RunOptions& opt) {
  if (!opt.resume.empty()) return resume(opt);
  if (opt.output) check_output_path(*opt.output, "-o/--output");
  if (opt.scene.empty())
    throw Error(
        "sph run needs a scene file: sph run SCENE.json (or --resume DIR to continue a run); see sph run --help");
  check_set_flag_conflicts(opt.sets,
                           {{"Configuration.numberOfSteps", opt.steps > 0 ? "--steps" : nullptr},
                            {"Configuration.neighbors", opt.neighbors.empty() ? nullptr : "--neighbors"},
                            {"Configuration.outputEveryNSteps", opt.every || opt.fps ? "--every/--fps" : nullptr},
                            {"Configuration.outputFps", opt.every || opt.fps ? "--every/--fps" : nullptr},
                            {"Configuration.outputFormats", opt.formats ? "--format" : nullptr},
                            {"Configuration.outputFields", opt.fields ? "--fields" : nullptr}});
  std::vector<std::string> sets = opt.sets;
  for (std::string& o : output_overrides(opt)) sets.push_back(std::move(o));
  if (!opt.neighbors.empty()) sets.push_back("Configuration.neighbors=\"" + opt.neighbors + "\"");
  if (opt.steps > 0) sets.push_back("Configuration.numberOfSteps=" + std::to_string(opt.steps));
  if (opt.threads > 0) set_num_threads(opt.threads);

  SceneDesc desc = read_scene_file(opt.scene, sets);
  desc.set_audit(opt.audit);
  for (const auto& w : desc.warnings) fmt::print(stderr, "sph: warning: {}\n", w);
  const std::filesystem::path dir =
      opt.output ? std::filesystem::path(*opt.output) : std::filesystem::path("out") / desc.name;
  check_new_run_directory(dir, opt.overwrite, "-o/--output", "--overwrite",
                          "continue it with sph run --resume " + shell_word(dir.string()));
  if (const std::vector<std::filesystem::path> replaced = files_a_run_replaces(dir); !replaced.empty()) {
    std::error_code ec;
    if (std::filesystem::exists(dir / kRunIdentityFile, ec)) {
      fmt::print(stderr, "sph: replacing the earlier run's files in {} (its frames, stats, summary and pictures)\n",
                 dir.string());
    } else {  // (--overwrite of files no run of this directory wrote: name them)
      std::vector<std::string> names;
      for (std::size_t k = 0; k < replaced.size() && k < 3; ++k)
        names.push_back(replaced[k].lexically_relative(dir).string());
      if (replaced.size() > 3) names.push_back(fmt::format("{} more", replaced.size() - 3));
      fmt::print(stderr, "sph: replacing files a run writes in {} ({}): --overwrite was given\n", dir.string(),
                 fmt::join(names, ", "));
    }
  }
  return dispatch(desc, [&]<int D, class R>() { return run_scene<D, R>(desc, opt, dir, nullptr); });
}

}  // namespace

std::function<int()> add_run_command(CLI::App& app) {
  auto opt = std::make_shared<RunOptions>();
  CLI::App* cmd = app.add_subcommand("run", "Run a scene file and write frames (VTK, PLY), stats.csv and summary.json");
  cmd->add_option("scene", opt->scene, "Scene file (JSON; see docs/scene-format.md); required unless --resume");
  cmd->add_option("-o,--output", opt->output, "Output directory (default: out/<scene name>)");
  cmd->add_option("--neighbors", opt->neighbors, "Neighbor strategy, overriding the scene's Configuration.neighbors")
      ->check(neighbor_mode_check());
  cmd->add_option("--steps", opt->steps, "Number of steps, overriding Configuration.numberOfSteps")
      ->check(in_range(std::int64_t{1}, std::int64_t{1'000'000'000'000}));
  cmd->add_option("--threads", opt->threads, "Worker threads (default: all cores)")->check(in_range(1, 4096));
  cmd->add_option("--set", opt->sets,
                  "Override a scene value by its key path, e.g. --set Fluid.stiffness=2000 "
                  "--set FluidBlocks[0].end=[0.5,1.0] (repeatable; VALUE is JSON or a plain string)")
      ->type_name("KEY=VALUE");
  cmd->add_option("--format", opt->formats,
                  "Frame formats, a comma-separated list of " + frame_format_list("", " and ", true) +
                      ", overriding Configuration.outputFormats (default: vtu)")
      ->type_name("LIST");
  cmd->add_option("--fields", opt->fields,
                  "Point fields of each frame besides the positions, a comma-separated list of " + frame_field_list() +
                      ", or none; overrides Configuration.outputFields (default: all)")
      ->type_name("LIST");
  cmd->add_option("--every", opt->every,
                  "A frame every N steps (0: no frames), overriding Configuration.outputEveryNSteps and outputFps")
      ->check(in_range(std::int64_t{0}, std::int64_t{1'000'000'000'000}))
      ->type_name("N");
  cmd->add_option("--fps", opt->fps,
                  "F frames per simulated second (frame k at the first step whose time reaches k / F), overriding "
                  "Configuration.outputFps and outputEveryNSteps")
      ->check(positive_number("a frame rate in frames per simulated second"))
      ->type_name("F");
  cmd->add_flag("--audit", opt->audit,
                "Check the lists every step against exact lists and record the pairs within h they miss "
                "(stats.csv columns missed_pairs, particles_missing, max_missed_penetration; costs about one "
                "extra standard list build per step)");
  cmd->add_flag("--strict", opt->strict,
                "Health warnings (particles outside the container, Mach above 0.3, density 30 % above rest, energy "
                "growing; docs/reliability.md) fail the run: exit 1, status \"failed: ... (--strict)\"");
  cmd->add_flag("--surface", opt->surface,
                "Also mesh the free surface of every frame: DIR/surface/surface_NNNNNN.ply, .obj and (3D) .vdb, as "
                "sph surface does (docs/visualization.md)");
  cmd->add_option("--surface-format", opt->surface_format, "With --surface: all, or a comma list of ply, obj and vdb")
      ->default_str("all");
  cmd->add_option("--surface-resolution", opt->surface_resolution,
                  "With --surface: voxels per particle spacing, 0.5 to 8")
      ->default_str("2")
      ->check(in_range(0.5, 8.0));
  cmd->add_option("--surface-smoothing", opt->surface_smoothing,
                  "With --surface: kernel radius in particle spacings, 1 to 4")
      ->default_str("2")
      ->check(in_range(1.0, 4.0));
  cmd->add_option("--checkpoint-every", opt->checkpoint_every,
                  "Write DIR/checkpoint.sphc every N steps and at the last step (the latest replaces the "
                  "previous, atomically). Ctrl-C or SIGTERM always writes one: the run finishes its step, "
                  "writes the checkpoint and stops")
      ->check(in_range(std::int64_t{1}, std::int64_t{1'000'000'000'000}))
      ->type_name("N");
  cmd->add_option("--resume", opt->resume,
                  "Continue the run in DIR from its checkpoint, bitwise identically to a run never interrupted; "
                  "only --steps (a new total), --threads, --checkpoint-every, --strict and --no-progress may be given "
                  "with it (the frame settings are the run's)")
      ->check(not_empty("the output directory of the run to continue"))
      ->type_name("DIR");
  cmd->add_flag("--overwrite", opt->overwrite,
                "Start the run even if the output directory holds an unfinished run's checkpoint (interrupted, "
                "killed or failed), deleting it with that run's frames, stats.csv, summary.json, scene.json and "
                "run.json (without it such a directory is refused; a finished run's files are always replaced)");
  cmd->add_flag("--no-progress", opt->no_progress,
                "No progress output (default: a bar with ETA on a terminal, a line every 10 % otherwise)");
  return [opt, cmd]() -> int {
    if (!cmd->parsed()) return kBadInput;
    if (!opt->surface)  // (they would be ignored without a word)
      for (const char* o : {"--surface-format", "--surface-resolution", "--surface-smoothing"})
        if (cmd->count(o) > 0) throw Error("applies to the surfaces of --surface; give --surface too", o);
    return run(*opt);
  };
}

}  // namespace sph::app
