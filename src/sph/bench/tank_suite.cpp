// The tank suite: the paper's Fig. 4 scene (scenes/paper/tank_fill_3d.json) run by every mode,
// repeats interleaved (standard, adaptive, verlet, standard, ...) so that the machine's drift
// hits every mode alike, and the speed ratios of the medians.

#include <algorithm>
#include <map>

#include <fmt/format.h>

#include <sph/bench/bench.h>
#include <sph/bench/tables.h>
#include <sph/bench/workload.h>
#include <sph/core/error.h>
#include <sph/core/parallel.h>
#include <sph/core/timer.h>
#include <sph/run/driver.h>
#include <sph/scene/builders.h>
#include <sph/scene/dispatch.h>
#include <sph/scene/scene_reader.h>

namespace sph {

namespace {

constexpr const char* kTankScene = "tank_fill_3d.json";
constexpr std::int64_t kSmallTankSteps = 1000;
constexpr std::int64_t kWarmupSteps = 50;

struct TankRunResult {
  double seconds = 0;
  std::size_t particles_end = 0;
};

/// `steps` steps of `desc` in precision R, timed from the first step to the last. No output
/// directory: the driver adds nothing to the timed steps. Throws the failed step's sph::Error.
template <std::floating_point R>
TankRunResult run_tank(SceneDesc desc, std::int64_t steps) {
  desc.steps = steps;
  RunDriver<3, R> run(std::move(desc), RunSettings{});
  Stopwatch watch;
  const RunResult result = run.run();
  const double seconds = watch.elapsed();
  if (result.status == RunStatus::Failed) throw Error(result.error);
  return {seconds, run.simulation().particles().size()};
}

TankRunResult run_tank(const SceneDesc& desc, std::int64_t steps) {
  return dispatch(desc, [&]<int D, class R>() -> TankRunResult {
    if constexpr (D != 3)
      throw Error("expected a 3D scene for the tank suite", desc.source);
    else
      return run_tank<R>(desc, steps);
  });
}

}  // namespace

void run_tank_suite(const BenchOptions& options, BenchResult& result, const BenchOutput& out) {
  const std::filesystem::path dir = options.scene_dir.empty() ? default_scene_dir() : options.scene_dir;
  const std::string path = (dir / kTankScene).string();
  result.tank_scene = path;
  // The scene as the paper runs it; only the step count, the precision and the mode change.
  const SceneDesc base = read_scene_file(path, {"Configuration.outputEveryNSteps=0"});
  if (base.dimension != 3) throw Error("expected a 3D scene for the tank suite", path);
  for (const auto& w : base.warnings) {
    result.notes.push_back(fmt::format("{}: {}", path, w));
    if (out.progress) out.progress("note: " + result.notes.back());
  }
  const std::int64_t steps = options.tank_steps > 0             ? options.tank_steps
                             : options.size == BenchSize::Small ? std::min(kSmallTankSteps, base.steps)
                                                                : base.steps;
  const std::vector<Precision> precisions =
      options.precisions.empty() ? std::vector<Precision>{base.precision} : options.precisions;
  std::vector<NeighborMode> modes = options.modes;
  // Standard is the reference of every ratio: always run it, first.
  modes.erase(std::remove(modes.begin(), modes.end(), NeighborMode::Standard), modes.end());
  modes.insert(modes.begin(), NeighborMode::Standard);
  const int cores = result.machine.logical_cores;

  if (out.table) {
    out.table(fmt::format(
        "\ntank: {} ({} steps per run), wall seconds per run, median of {} interleaved repeats [min .. max]; "
        "speedup = standard median / mode median",
        path, steps, options.repeats));
    out.table(detail::tank_table_header());
  }
  for (int t : bench_threads(options))
    for (Precision p : precisions) {
      set_num_threads(t);
      std::vector<SceneDesc> descs;
      for (NeighborMode m : modes) {
        SceneDesc d = base;
        d.precision = p;
        d.steps = steps;
        d.body<3>().sim.neighbors = m;
        descs.push_back(std::move(d));
      }
      // Warm-up, not recorded: caches, page faults and thread start-up would otherwise be
      // charged to the first run.
      if (out.progress)
        out.progress(fmt::format("tank: {} {} thread{}: warm-up", precision_name(p), t, t == 1 ? "" : "s"));
      try {
        run_tank(descs[0], std::min(steps, kWarmupSteps));
      } catch (const Error&) {
        // The recorded standard run meets the same failure and reports it.
      }
      std::vector<std::vector<double>> seconds(modes.size());
      std::vector<std::size_t> particles_end(modes.size(), 0);
      for (int rep = 0; rep < options.repeats; ++rep)
        for (std::size_t m = 0; m < modes.size(); ++m) {
          if (out.progress)
            out.progress(fmt::format("tank: {} {} {} thread{}: run {} of {}", to_string(modes[m]), precision_name(p), t,
                                     t == 1 ? "" : "s", rep + 1, options.repeats));
          TankRunResult r;
          try {
            r = run_tank(descs[m], steps);
          } catch (const Error& e) {
            throw BenchFailure(fmt::format("the tank run {} {} with {} thread{} failed: {}", to_string(modes[m]),
                                           precision_name(p), t, t == 1 ? "" : "s", e.what()));
          }
          seconds[m].push_back(r.seconds);
          particles_end[m] = r.particles_end;
        }
      const std::size_t first = result.tank.size();
      for (std::size_t m = 0; m < modes.size(); ++m) {
        TankRow row;
        row.threads = t;
        row.oversubscribed = t > cores;
        row.mode = modes[m];
        row.precision = p;
        row.steps = steps;
        row.particles_end = particles_end[m];
        row.time = summarize(seconds[m]);
        row.ms_per_step = 1e3 * row.time.median / static_cast<double>(steps);
        result.tank.push_back(row);
      }
      const double reference = result.tank[first].time.median;
      for (std::size_t k = first; k < result.tank.size(); ++k) {
        TankRow& row = result.tank[k];
        row.speedup = row.time.median > 0 ? reference / row.time.median : 0;
        if (out.table) out.table(detail::tank_table_row(row));
      }
    }
}

}  // namespace sph
