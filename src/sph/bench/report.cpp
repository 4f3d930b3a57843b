// What `sph bench` prints (tables) and writes (bench.json, one CSV per suite).

#include <algorithm>
#include <map>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <sph/bench/bench.h>
#include <sph/bench/tables.h>
#include <sph/bench/workload.h>
#include <sph/io/atomic_file.h>

namespace sph {

namespace detail {

namespace {
std::string threads_cell(int threads, bool oversubscribed) {
  return fmt::format("{}{}", threads, oversubscribed ? "*" : "");
}
double mib(std::int64_t bytes) { return static_cast<double>(bytes) / (1024.0 * 1024.0); }
}  // namespace

std::string neighbors_table_header() {
  return fmt::format("{:>8} {:>5} {:<6} {:<8} {:>4} {:<7} {:>10} {:>10} {:>10} {:>11} {:>13}", "N", "r", "prec",
                     "order", "thr", "phase", "median ms", "min ms", "max ms", "ns/particle", "nbrs/particle");
}

std::string neighbors_table_row(const NeighborsRow& r) {
  return fmt::format("{:>8} {:>5} {:<6} {:<8} {:>4} {:<7} {:>10.3f} {:>10.3f} {:>10.3f} {:>11.1f} {:>13.2f}",
                     r.particles, fmt::format("{:g}dx", r.radius_dx), precision_name(r.precision), r.order,
                     threads_cell(r.threads, r.oversubscribed), r.phase, 1e3 * r.time.median, 1e3 * r.time.min,
                     1e3 * r.time.max, r.ns_per_particle, r.neighbors_per_particle);
}

std::string steps_table_header() {
  return fmt::format(
      "{:>8} {:<9} {:<6} {:>4} {:>6} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>17} {:>10} {:>9} {:>9} {:>8} {:>7} "
      "{:>8} {:>6} {:>10}",
      "N", "mode", "prec", "thr", "steps", "grid", "lists", "density", "forces", "integr", "total", "wall",
      "[min .. max]", "Mpart-st/s", "ns/pt-st", "rebuilt/st", "peak MiB", "B/part", "visits/p", "<h", "Mvisit/c-s");
}

std::string steps_table_row(const StepsRow& r) {
  return fmt::format(
      "{:>8} {:<9} {:<6} {:>4} {:>6} {:>8.3f} {:>8.3f} {:>8.3f} {:>8.3f} {:>8.3f} {:>8.3f} {:>8.3f} {:>17} {:>10.3f} "
      "{:>9.1f} {:>9.0f} {:>8.1f} {:>7.0f} {:>8.1f} {:>6.3f} {:>10.1f}",
      r.particles, to_string(r.mode), precision_name(r.precision), threads_cell(r.threads, r.oversubscribed),
      r.timed_steps, r.ms_per_step.grid, r.ms_per_step.lists, r.ms_per_step.density, r.ms_per_step.forces,
      r.ms_per_step.integrate, r.ms_per_step.total(), r.wall_ms_per_step,
      fmt::format("[{:.3f} .. {:.3f}]", r.wall_ms_min, r.wall_ms_max), 1e-6 * r.particle_steps_per_second,
      r.ns_per_particle_step, r.lists_rebuilt_per_step, mib(r.peak_rss_bytes - r.baseline_rss_bytes),
      r.bytes_per_particle, r.pair_visits_per_particle, r.within_h_fraction, 1e-6 * r.pair_visits_per_core_second);
}

std::string scaling_table(const std::vector<StepsRow>& rows) {
  std::vector<std::size_t> sizes;
  for (const auto& r : rows)
    if (std::find(sizes.begin(), sizes.end(), r.particles) == sizes.end()) sizes.push_back(r.particles);
  std::sort(sizes.begin(), sizes.end());
  std::string s = fmt::format("{:<9} {:<6} {:>4}", "mode", "prec", "thr");
  for (std::size_t n : sizes) s += fmt::format(" {:>10}", n);
  // One line per (mode, precision, threads), in order of first appearance.
  std::vector<const StepsRow*> keys;
  for (const auto& r : rows) {
    const bool seen = std::any_of(keys.begin(), keys.end(), [&](const StepsRow* k) {
      return k->mode == r.mode && k->precision == r.precision && k->threads == r.threads;
    });
    if (!seen) keys.push_back(&r);
  }
  for (const StepsRow* k : keys) {
    s += fmt::format("\n{:<9} {:<6} {:>4}", to_string(k->mode), precision_name(k->precision),
                     threads_cell(k->threads, k->oversubscribed));
    for (std::size_t n : sizes) {
      const auto it = std::find_if(rows.begin(), rows.end(), [&](const StepsRow& r) {
        return r.mode == k->mode && r.precision == k->precision && r.threads == k->threads && r.particles == n;
      });
      s += it == rows.end() ? fmt::format(" {:>10}", "-") : fmt::format(" {:>10.1f}", it->ns_per_particle_step);
    }
  }
  return s;
}

std::string tank_table_header() {
  return fmt::format("{:>4} {:<6} {:<9} {:>6} {:>9} {:>9} {:>9} {:>9} {:>8} {:>8}", "thr", "prec", "mode", "steps",
                     "particles", "median s", "min s", "max s", "ms/step", "speedup");
}

std::string tank_table_row(const TankRow& r) {
  return fmt::format("{:>4} {:<6} {:<9} {:>6} {:>9} {:>9.3f} {:>9.3f} {:>9.3f} {:>8.3f} {:>7.2f}x",
                     threads_cell(r.threads, r.oversubscribed), precision_name(r.precision), to_string(r.mode), r.steps,
                     r.particles_end, r.time.median, r.time.min, r.time.max, r.ms_per_step, r.speedup);
}

}  // namespace detail

namespace {

using nlohmann::json;

json timing_json(const TimingStats& t, double scale) {
  json runs = json::array();
  for (double s : t.seconds) runs.push_back(s * scale);
  return {{"median", t.median * scale}, {"min", t.min * scale}, {"max", t.max * scale}, {"runs", runs}};
}

json machine_json(const MachineInfo& m) {
  return {{"cpu_model", m.cpu_model},
          {"logical_cores", m.logical_cores},
          {"default_threads", m.default_threads},
          {"memory_bytes", m.memory_bytes},
          {"os", m.os},
          {"compiler", m.compiler},
          {"build_type", m.build_type},
          {"build_flags", m.build_flags},
          {"git_commit", m.git_commit},
          {"sph_version", m.version},
          {"date", m.date},
          {"load_average", m.load_average},
          {"openmp_env", m.openmp_env}};
}

json options_json(const BenchResult& r) {
  const BenchOptions& o = r.options;
  json precisions = json::array(), modes = json::array();
  for (Precision p : o.precisions) precisions.push_back(precision_name(p));
  for (NeighborMode m : o.modes) modes.push_back(std::string(to_string(m)));
  return {{"suites", o.suites},
          {"size", to_string(o.size)},
          {"threads", r.threads},
          {"precisions", precisions},
          {"repeats", o.repeats},
          {"particles", o.particles},
          {"warmup_steps", o.warmup_steps},
          {"timed_steps", o.timed_steps},
          {"tank_steps", o.tank_steps},
          {"modes", modes}};
}

json neighbors_json(const BenchResult& r) {
  json results = json::array(), checks = json::array();
  for (const NeighborsRow& x : r.neighbors)
    results.push_back({{"particles", x.particles},
                       {"side", x.side},
                       {"radius_dx", x.radius_dx},
                       {"precision", precision_name(x.precision)},
                       {"order", x.order},
                       {"threads", x.threads},
                       {"oversubscribed", x.oversubscribed},
                       {"phase", x.phase},
                       {"ms", timing_json(x.time, 1e3)},
                       {"ns_per_particle", x.ns_per_particle},
                       {"neighbors_per_particle", x.neighbors_per_particle}});
  for (const NeighborsCheckRecord& c : r.neighbor_checks)
    checks.push_back({{"particles", c.particles},
                      {"radius_dx", c.radius_dx},
                      {"precision", precision_name(c.precision)},
                      {"order", c.order},
                      {"phase", c.phase},
                      {"threads", c.threads},
                      {"ok", c.check.ok},
                      {"method", c.check.method},
                      {"lists_compared", c.check.lists_compared},
                      {"entries", c.check.entries},
                      {"problem", c.check.problem}});
  LatticeSpec spec;
  return {{"workload",
           {{"geometry", "cubic lattice, side^3 points, each coordinate jittered uniformly"},
            {"spacing", spec.spacing},
            {"jitter_dx", spec.jitter},
            {"move_dx", 0.05},
            {"radii_dx", {2.0, 3.0}},
            {"seeds", {{"lattice", kLatticeSeed}, {"move", kMoveSeed}, {"shuffle", kShuffleSeed}}},
            {"build", "fresh UniformGrid + ListBuilder + NeighborLists (allocations included)"},
            {"rebuild", "same objects, every point moved by up to +-0.05 dx per coordinate"},
            {"shuffled",
             "Fisher-Yates shuffled input; timed work includes MortonOrder::compute (cell = r) and the "
             "gather of the positions"}}},
          {"results", results},
          {"checks", checks}};
}

json steps_json(const BenchResult& r) {
  json results = json::array();
  for (const StepsRow& x : r.steps)
    results.push_back({{"particles", x.particles},
                       {"side", x.side},
                       {"mode", std::string(to_string(x.mode))},
                       {"precision", precision_name(x.precision)},
                       {"threads", x.threads},
                       {"oversubscribed", x.oversubscribed},
                       {"warmup_steps", x.warmup_steps},
                       {"timed_steps", x.timed_steps},
                       {"ms_per_step",
                        {{"grid", x.ms_per_step.grid},
                         {"lists", x.ms_per_step.lists},
                         {"density", x.ms_per_step.density},
                         {"forces", x.ms_per_step.forces},
                         {"integrate", x.ms_per_step.integrate},
                         {"total", x.ms_per_step.total()},
                         {"wall", x.wall_ms_per_step}}},
                       {"runs", x.runs},
                       {"wall_ms_per_step_min", x.wall_ms_min},
                       {"wall_ms_per_step_max", x.wall_ms_max},
                       {"particle_steps_per_second", x.particle_steps_per_second},
                       {"ns_per_particle_step", x.ns_per_particle_step},
                       {"lists_rebuilt_per_step", x.lists_rebuilt_per_step},
                       {"neighbors_per_particle", x.neighbors_per_particle},
                       {"pair_visits_per_particle", x.pair_visits_per_particle},
                       {"within_h_fraction", x.within_h_fraction},
                       {"pair_visits_per_core_second", x.pair_visits_per_core_second},
                       {"density_in_lists", x.density_in_lists},
                       {"memory",
                        {{"baseline_rss_bytes", x.baseline_rss_bytes},
                         {"peak_rss_bytes", x.peak_rss_bytes},
                         {"peak_reset", x.peak_reset},
                         {"bytes_per_particle", x.bytes_per_particle},
                         {"heap_bytes_per_particle", x.heap_bytes_per_particle}}}});
  return {{"workload",
           {{"scene",
             "3D dam break: a side^3 block (spacing 0.02 m) against the left wall of a 2.5 x 1.5 x 1 block-width box"},
            {"particle_radius", 0.01},
            {"kernel_radius", 0.04},
            {"time_step", 4e-4},
            {"memory",
             "peak_rss_bytes = VmHWM after the run, reset (clear_refs 5) before the build; "
             "bytes_per_particle = (peak - baseline VmRSS) / particles; heap_bytes_per_particle = malloc'd "
             "bytes the simulation holds after the run / particles"}}},
          {"results", results}};
}

json scaling_json(const BenchResult& r) {
  json out = json::array();
  for (const StepsRow& x : r.steps)
    out.push_back({{"particles", x.particles},
                   {"mode", std::string(to_string(x.mode))},
                   {"precision", precision_name(x.precision)},
                   {"threads", x.threads},
                   {"ns_per_particle_step", x.ns_per_particle_step}});
  return out;
}

json tank_json(const BenchResult& r) {
  json results = json::array(), ratios = json::array();
  for (const TankRow& x : r.tank) {
    results.push_back({{"threads", x.threads},
                       {"oversubscribed", x.oversubscribed},
                       {"precision", precision_name(x.precision)},
                       {"mode", std::string(to_string(x.mode))},
                       {"steps", x.steps},
                       {"particles_end", x.particles_end},
                       {"seconds", timing_json(x.time, 1.0)},
                       {"ms_per_step", x.ms_per_step},
                       {"speedup_vs_standard", x.speedup}});
    if (x.mode != NeighborMode::Standard)
      ratios.push_back({{"threads", x.threads},
                        {"precision", precision_name(x.precision)},
                        {"ratio", fmt::format("standard/{}", to_string(x.mode))},
                        {"value", x.speedup}});
  }
  return {{"scene", r.tank_scene},
          {"method",
           "each mode runs the scene from the start; repeats interleaved (standard, adaptive, verlet, "
           "standard, ...); wall seconds of the stepping loop; ratios of medians"},
          {"results", results},
          {"ratios", ratios}};
}

template <class Rows>
bool ran(const BenchResult& r, const char* suite, const Rows& rows) {
  return !rows.empty() || std::find(r.suites_done.begin(), r.suites_done.end(), suite) != r.suites_done.end();
}

std::string neighbors_csv(const BenchResult& r) {
  std::string s =
      "particles,side,radius_dx,precision,order,threads,oversubscribed,phase,repeats,median_ms,min_ms,max_ms,"
      "ns_per_particle,neighbors_per_particle\n";
  for (const NeighborsRow& x : r.neighbors)
    s += fmt::format("{},{},{},{},{},{},{},{},{},{:.6f},{:.6f},{:.6f},{:.3f},{:.4f}\n", x.particles, x.side,
                     x.radius_dx, precision_name(x.precision), x.order, x.threads, x.oversubscribed ? 1 : 0, x.phase,
                     x.time.seconds.size(), 1e3 * x.time.median, 1e3 * x.time.min, 1e3 * x.time.max, x.ns_per_particle,
                     x.neighbors_per_particle);
  return s;
}

std::string steps_csv(const BenchResult& r) {
  std::string s =
      "particles,side,mode,precision,threads,oversubscribed,warmup_steps,timed_steps,ms_grid,ms_lists,ms_density,"
      "ms_forces,ms_integrate,ms_total,ms_wall,particle_steps_per_s,ns_per_particle_step,lists_rebuilt_per_step,"
      "neighbors_per_particle,baseline_rss_bytes,peak_rss_bytes,bytes_per_particle,heap_bytes_per_particle,runs,"
      "ms_wall_min,ms_wall_max,pair_visits_per_particle,within_h_fraction,pair_visits_per_core_second\n";
  for (const StepsRow& x : r.steps)
    s += fmt::format(
        "{},{},{},{},{},{},{},{},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.1f},{:.3f},{:.1f},"
        "{:.4f},{},{},{:.1f},{:.1f},{},{:.6f},{:.6f},{:.4f},{:.6f},{:.6g}\n",
        x.particles, x.side, to_string(x.mode), precision_name(x.precision), x.threads, x.oversubscribed ? 1 : 0,
        x.warmup_steps, x.timed_steps, x.ms_per_step.grid, x.ms_per_step.lists, x.ms_per_step.density,
        x.ms_per_step.forces, x.ms_per_step.integrate, x.ms_per_step.total(), x.wall_ms_per_step,
        x.particle_steps_per_second, x.ns_per_particle_step, x.lists_rebuilt_per_step, x.neighbors_per_particle,
        x.baseline_rss_bytes, x.peak_rss_bytes, x.bytes_per_particle, x.heap_bytes_per_particle, x.runs, x.wall_ms_min,
        x.wall_ms_max, x.pair_visits_per_particle, x.within_h_fraction, x.pair_visits_per_core_second);
  return s;
}

std::string tank_csv(const BenchResult& r) {
  std::string s =
      "threads,oversubscribed,precision,mode,steps,particles_end,repeats,median_s,min_s,max_s,ms_per_step,"
      "speedup_vs_standard\n";
  for (const TankRow& x : r.tank)
    s += fmt::format("{},{},{},{},{},{},{},{:.6f},{:.6f},{:.6f},{:.6f},{:.4f}\n", x.threads, x.oversubscribed ? 1 : 0,
                     precision_name(x.precision), to_string(x.mode), x.steps, x.particles_end, x.time.seconds.size(),
                     x.time.median, x.time.min, x.time.max, x.ms_per_step, x.speedup);
  return s;
}

}  // namespace

std::string bench_json(const BenchResult& r) {
  json doc = {{"schema", "sph-bench/1"},
              {"machine", machine_json(r.machine)},
              {"options", options_json(r)},
              {"suites_done", r.suites_done},
              {"status", !r.failure.empty() ? "failed: " + r.failure
                         : r.suites_done.size() == r.options.suites.size()
                             ? std::string("completed")
                             : fmt::format("incomplete: {} of {} suites done (stopped, or still running)",
                                           r.suites_done.size(), r.options.suites.size())},
              {"notes", r.notes}};
  if (ran(r, "neighbors", r.neighbors)) doc["neighbors"] = neighbors_json(r);
  if (ran(r, "steps", r.steps)) {
    doc["steps"] = steps_json(r);
    doc["scaling"] = scaling_json(r);
  }
  if (ran(r, "tank", r.tank)) doc["tank"] = tank_json(r);
  return doc.dump(2) + "\n";
}

void write_bench_files(const std::filesystem::path& dir, const BenchResult& r) {
  std::error_code ec;
  // Each suite's table, or none: an earlier run's would sit next to this run's as if it belonged to it.
  const auto table = [&](const char* suite, const auto& rows, const char* file, auto&& csv) {
    if (ran(r, suite, rows))
      write_file_atomic(dir / file, csv(r));
    else
      std::filesystem::remove(dir / file, ec);
  };
  table("neighbors", r.neighbors, "neighbors.csv", neighbors_csv);
  table("steps", r.steps, "steps.csv", steps_csv);
  table("tank", r.tank, "tank.csv", tank_csv);
  write_file_atomic(dir / "bench.json", bench_json(r));
}

}  // namespace sph
