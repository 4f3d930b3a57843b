// The steps suite: whole simulation steps of a 3D dam break (workload.h) per neighbor mode,
// precision and thread count, with the peak memory of each workload.

#include <algorithm>

#include <fmt/format.h>

#include <sph/bench/bench.h>
#include <sph/bench/tables.h>
#include <sph/bench/workload.h>
#include <sph/core/error.h>
#include <sph/core/parallel.h>
#include <sph/core/timer.h>
#include <sph/run/driver.h>
#include <sph/scene/builders.h>
#include <sph/scene/scene_reader.h>

namespace sph {

namespace {

template <std::floating_point R>
StepsRow run_workload(const SceneDesc& desc, int side, NeighborMode mode, int threads, std::int64_t warmup,
                      std::int64_t timed) {
  StepsRow row;
  row.side = side;
  row.particles = static_cast<std::size_t>(side) * side * side;
  row.mode = mode;
  row.precision = std::is_same_v<R, float> ? Precision::Float : Precision::Double;
  row.threads = threads;
  row.warmup_steps = warmup;
  row.timed_steps = timed;

  // Memory: the peak RSS over the build and the run, above the RSS before it. The previous
  // workload's memory is gone (its simulation is destroyed and the heap trimmed).
  release_free_heap();
  row.peak_reset = reset_peak_rss();
  row.baseline_rss_bytes = current_rss_bytes();
  const std::int64_t heap_before = heap_bytes_in_use();
  {
    // No output directory: the driver adds nothing to the timed steps but the observer's sums.
    RunDriver<3, R> run(desc, RunSettings{});
    const Simulation<3, R>& sim = run.simulation();
    SPH_CHECK(sim.particles().size() == row.particles, "the dam break block does not hold side^3 particles");
    SPH_CHECK(desc.steps == warmup + timed, "the workload's scene runs the warm-up and the timed steps");
    PhaseTimes sum;
    std::uint64_t rebuilt = 0, entries = 0, fluid_entries = 0, within = 0;
    bool density_in_lists = false;
    double wall = 0;
    run.advance(warmup);
    Stopwatch watch;
    const RunResult result = run.run({}, [&](Simulation<3, R>&, const StepInfo& info) {
      sum += info.seconds;
      rebuilt += info.neighbors.lists_rebuilt;
      fluid_entries += info.neighbors.pairs_stored;
      entries += info.neighbors.pairs_stored + info.neighbors.boundary_pairs_stored;
      within += info.pairs_within_h;
      density_in_lists = density_in_lists || info.density_in_lists;
    });
    wall = watch.elapsed();
    if (result.status == RunStatus::Failed) throw Error(result.error);
    const double k = 1e3 / static_cast<double>(timed);
    row.ms_per_step = PhaseTimes{sum.grid * k, sum.lists * k, sum.density * k, sum.forces * k, sum.integrate * k};
    row.wall_ms_per_step = wall * k;
    const double particle_steps = static_cast<double>(row.particles) * static_cast<double>(timed);
    row.particle_steps_per_second = wall > 0 ? particle_steps / wall : 0;
    row.ns_per_particle_step = 1e9 * wall / particle_steps;
    row.lists_rebuilt_per_step = static_cast<double>(rebuilt) / static_cast<double>(timed);
    row.neighbors_per_particle =
        static_cast<double>(sim.last_step().neighbors.pairs_stored) / static_cast<double>(row.particles);
    // Each of the density and force passes visits every list entry once per step.
    row.pair_visits_per_particle = static_cast<double>(entries) / particle_steps;
    row.within_h_fraction = fluid_entries > 0 ? static_cast<double>(within) / static_cast<double>(fluid_entries) : 0;
    // (where the density sums are made in the list build, standard's, only the force pass's
    // visits have a time of their own)
    row.density_in_lists = density_in_lists;
    const double passes = density_in_lists ? 1.0 : 2.0;
    const double pair_seconds =
        (density_in_lists ? sum.forces : sum.density + sum.forces) * static_cast<double>(threads);
    row.pair_visits_per_core_second = pair_seconds > 0 ? passes * static_cast<double>(entries) / pair_seconds : 0;
    const std::int64_t heap_after = heap_bytes_in_use();
    if (heap_before >= 0 && heap_after >= 0)
      row.heap_bytes_per_particle = static_cast<double>(heap_after - heap_before) / static_cast<double>(row.particles);
    row.peak_rss_bytes = peak_rss_bytes();
  }
  if (row.peak_rss_bytes >= 0 && row.baseline_rss_bytes >= 0)
    row.bytes_per_particle =
        static_cast<double>(row.peak_rss_bytes - row.baseline_rss_bytes) / static_cast<double>(row.particles);
  release_free_heap();
  return row;
}

}  // namespace

void run_steps_suite(const BenchOptions& options, BenchResult& result, const BenchOutput& out) {
  const std::vector<int> threads = bench_threads(options);
  const int cores = result.machine.logical_cores;
  const std::vector<int> sides = steps_sides(options);
  if (options.particles > 0) {
    const std::int64_t n = static_cast<std::int64_t>(sides[0]) * sides[0] * sides[0];
    if (n != options.particles) {
      result.notes.push_back(
          fmt::format("--particles {} rounded to a {}^3 = {} particle block", options.particles, sides[0], n));
      if (out.progress) out.progress("note: " + result.notes.back());
    }
  }
  if (out.table) {
    out.table(
        "\nsteps: 3D dam break (side^3 particles, spacing 0.02 m, h = 0.04 m, dt = 4e-4 s), ms per step by phase "
        "of the run of median wall time (of --step-runs runs), "
        "after warm-up steps");
    out.table(detail::steps_table_header());
  }
  std::size_t first_row = result.steps.size();
  bool peak_warned = false;
  for (int side : sides)
    for (int t : threads)
      for (Precision p : steps_precisions(options, side))
        for (NeighborMode mode : options.modes) {
          const std::int64_t warmup = steps_warmup(options, side), timed = steps_timed(options, side);
          const std::string name = fmt::format("N={} {} {} {} thread{}", static_cast<std::int64_t>(side) * side * side,
                                               to_string(mode), precision_name(p), t, t == 1 ? "" : "s");
          if (out.progress) out.progress(fmt::format("steps: {}: {} + {} steps", name, warmup, timed));
          const SceneDesc desc = parse_scene(dam_break_scene_json(side, p, mode, warmup + timed),
                                             fmt::format("<bench dam break {}>", side));
          for (const auto& w : desc.warnings) {
            const std::string note = fmt::format("dam break {}^3: {}", side, w);
            if (std::find(result.notes.begin(), result.notes.end(), note) == result.notes.end()) {
              result.notes.push_back(note);
              if (out.progress) out.progress("note: " + note);
            }
          }
          set_num_threads(t);
          // Several runs; the row is the run of median wall time, with the spread beside it.
          std::vector<StepsRow> runs;
          for (int r = 0; r < options.step_runs; ++r) {
            try {
              runs.push_back(p == Precision::Float ? run_workload<float>(desc, side, mode, t, warmup, timed)
                                                   : run_workload<double>(desc, side, mode, t, warmup, timed));
            } catch (const Error& e) {
              throw BenchFailure(fmt::format("the steps workload {} failed: {}", name, e.what()));
            }
          }
          std::sort(runs.begin(), runs.end(),
                    [](const StepsRow& a, const StepsRow& b) { return a.wall_ms_per_step < b.wall_ms_per_step; });
          StepsRow row = runs[runs.size() / 2];
          row.runs = static_cast<int>(runs.size());
          row.wall_ms_min = runs.front().wall_ms_per_step;
          row.wall_ms_max = runs.back().wall_ms_per_step;
          row.oversubscribed = t > cores;
          if (!row.peak_reset && !peak_warned) {
            peak_warned = true;
            result.notes.push_back(
                "the kernel refused to reset the peak RSS (/proc/self/clear_refs): peak memory figures cover the "
                "whole process so far, not each workload alone");
            if (out.progress) out.progress("note: " + result.notes.back());
          }
          result.steps.push_back(row);
          if (out.table) out.table(detail::steps_table_row(row));
        }
  if (out.table) {
    const std::vector<StepsRow> rows(result.steps.begin() + static_cast<std::ptrdiff_t>(first_row), result.steps.end());
    out.table("\nscaling: wall ns per particle-step against N (from the steps suite)");
    out.table(detail::scaling_table(rows));
  }
}

}  // namespace sph
