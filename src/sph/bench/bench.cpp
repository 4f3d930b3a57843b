#include <sph/bench/bench.h>

#include <algorithm>
#include <cmath>
#include <thread>

#include <fmt/format.h>

#include <sph/core/data_dir.h>
#include <sph/core/error.h>
#include <sph/core/spelling.h>
#include <sph/io/atomic_file.h>
#include <sph/neighbors/neighbor_mode.h>
#include <sph/scene/scene_reader.h>

namespace sph {

namespace {

std::vector<std::string_view> split(std::string_view list) {
  std::vector<std::string_view> items;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = list.find(',', start);
    std::string_view item =
        list.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start);
    while (!item.empty() && item.front() == ' ') item.remove_prefix(1);
    while (!item.empty() && item.back() == ' ') item.remove_suffix(1);
    items.push_back(item);
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return items;
}

int logical_cores() { return std::max(1, static_cast<int>(std::thread::hardware_concurrency())); }

}  // namespace

std::filesystem::path default_scene_dir() { return scene_dir("paper"); }

const char* to_string(BenchSize size) {
  switch (size) {
    case BenchSize::Small:
      return "small";
    case BenchSize::Medium:
      return "medium";
    case BenchSize::Large:
      return "large";
    case BenchSize::Full:
      return "full";
  }
  return "?";
}

TimingStats summarize(std::vector<double> seconds) {
  TimingStats s;
  s.seconds = seconds;
  if (seconds.empty()) return s;
  std::sort(seconds.begin(), seconds.end());
  const std::size_t n = seconds.size();
  s.min = seconds.front();
  s.max = seconds.back();
  s.median = n % 2 ? seconds[n / 2] : 0.5 * (seconds[n / 2 - 1] + seconds[n / 2]);
  return s;
}

namespace {

/// The one message for a suite that is none of kBenchSuites.
[[noreturn]] void unknown_suite(std::string_view name, const std::string& where) {
  throw Error(fmt::format("unknown suite \"{}\"{}; expected a comma-separated list of neighbors, steps, tank, or all",
                          name, did_you_mean(name, kBenchSuites)),
              where);
}

}  // namespace

std::vector<std::string> parse_bench_suites(std::string_view list, const std::string& where) {
  constexpr const char* kExpected = "expected a comma-separated list of neighbors, steps, tank, or all";
  std::vector<std::string> suites;
  for (std::string_view item : split(list)) {
    if (item.empty()) throw Error(fmt::format("empty suite name in \"{}\"; {}", list, kExpected), where);
    if (item == "all") {
      for (const char* s : kBenchSuites)
        if (std::find(suites.begin(), suites.end(), s) == suites.end()) suites.emplace_back(s);
      continue;
    }
    const auto known =
        std::find_if(std::begin(kBenchSuites), std::end(kBenchSuites), [&](const char* s) { return item == s; });
    if (known == std::end(kBenchSuites)) unknown_suite(item, where);
    if (std::find(suites.begin(), suites.end(), item) == suites.end()) suites.emplace_back(item);
  }
  // Always run in the documented order, whatever the order given.
  std::vector<std::string> ordered;
  for (const char* s : kBenchSuites)
    if (std::find(suites.begin(), suites.end(), s) != suites.end()) ordered.emplace_back(s);
  return ordered;
}

BenchSize parse_bench_size(std::string_view name, const std::string& where) {
  for (BenchSize s : {BenchSize::Small, BenchSize::Medium, BenchSize::Large, BenchSize::Full})
    if (name == to_string(s)) return s;
  throw Error(fmt::format("unknown size \"{}\"{}; expected small, medium, large or full", name,
                          did_you_mean(name, std::array{"small", "medium", "large", "full"})),
              where);
}

std::vector<int> parse_thread_list(std::string_view list, const std::string& where) {
  constexpr const char* kExpected = "expected a comma-separated list of thread counts from 1 to 4096, e.g. 1,2";
  std::vector<int> threads;
  for (std::string_view item : split(list)) {
    int v = 0;
    bool ok = !item.empty() && item.size() <= 4;
    for (char c : item) {
      ok = ok && c >= '0' && c <= '9';
      v = v * 10 + (c - '0');
    }
    if (!ok || v < 1 || v > 4096) throw Error(fmt::format("bad thread count \"{}\"; {}", item, kExpected), where);
    if (std::find(threads.begin(), threads.end(), v) == threads.end()) threads.push_back(v);
  }
  return threads;
}

std::vector<Precision> parse_precisions(std::string_view list, const std::string& where) {
  std::vector<Precision> out;
  for (std::string_view item : split(list)) {
    Precision p;
    if (item == "float")
      p = Precision::Float;
    else if (item == "double")
      p = Precision::Double;
    else
      throw Error(fmt::format("unknown precision \"{}\"{}; expected float, double or float,double", item,
                              did_you_mean(item, std::array{"float", "double"})),
                  where);
    if (std::find(out.begin(), out.end(), p) == out.end()) out.push_back(p);
  }
  return out;
}

std::vector<NeighborMode> parse_bench_modes(std::string_view list, const std::string& where) {
  std::vector<NeighborMode> out;
  for (std::string_view item : split(list)) {
    const NeighborMode m = parse_neighbor_mode(item, where, NeighborModeSet::Compared);
    if (std::find(out.begin(), out.end(), m) == out.end()) out.push_back(m);
  }
  return out;
}

void validate_bench_options(const BenchOptions& o) {
  if (o.suites.empty()) throw Error("no suite selected; expected neighbors, steps, tank or all", "--suite");
  for (const auto& s : o.suites)
    if (std::find_if(std::begin(kBenchSuites), std::end(kBenchSuites), [&](const char* k) { return s == k; }) ==
        std::end(kBenchSuites))
      unknown_suite(s, "--suite");
  for (int t : o.threads)
    if (t < 1 || t > 4096) throw Error(fmt::format("bad thread count {}; expected 1 to 4096", t), "--threads");
  if (o.repeats < 1 || o.repeats > 1000)
    throw Error(fmt::format("{} repeats; expected 1 to 1000", o.repeats), "--repeats");
  if (o.particles < 0 || o.particles > 2'000'000'000)
    throw Error(fmt::format("{} particles; expected 1 to 2e9", o.particles), "--particles");
  if (o.warmup_steps < -1) throw Error("expected 0 or more warm-up steps", "--warmup-steps");
  if (o.timed_steps == 0 || o.timed_steps < -1) throw Error("expected 1 or more timed steps", "--timed-steps");
  if (o.tank_steps < 0) throw Error("expected 1 or more steps", "--steps");
  if (o.modes.empty())
    throw Error("no neighbor mode; expected " + join_neighbor_mode_names(NeighborModeSet::Compared, ", ", " and/or "),
                "--modes");
  for (NeighborMode m : o.modes)  // (the parser's refusal of a mode outside the compared ones)
    (void)parse_neighbor_mode(to_string(m), "--modes", NeighborModeSet::Compared);
  if (std::find(o.suites.begin(), o.suites.end(), "tank") != o.suites.end()) {
    // Refuse a missing or broken tank scene before anything runs or is written.
    const std::filesystem::path dir = o.scene_dir.empty() ? default_scene_dir() : o.scene_dir;
    read_scene_file((dir / "tank_fill_3d.json").string());
  }
}

std::vector<int> bench_threads(const BenchOptions& options) {
  if (!options.threads.empty()) return options.threads;
  const int cores = logical_cores();
  return cores > 1 ? std::vector<int>{1, cores} : std::vector<int>{1};
}

std::vector<int> neighbors_sides(BenchSize size) {
  switch (size) {
    case BenchSize::Small:
      return {20};
    case BenchSize::Medium:
      return {20, 40};
    case BenchSize::Large:
    case BenchSize::Full:
      return {20, 40, 80};
  }
  return {20};
}

std::vector<int> steps_sides(const BenchOptions& options) {
  if (options.particles > 0)
    return {std::max(1, static_cast<int>(std::lround(std::cbrt(static_cast<double>(options.particles)))))};
  switch (options.size) {
    case BenchSize::Small:
      return {20};
    case BenchSize::Medium:
      return {20, 40};
    case BenchSize::Large:
      return {20, 40, 80};
    case BenchSize::Full:
      return {20, 40, 80, 100};
  }
  return {20};
}

std::int64_t steps_warmup(const BenchOptions& options, int side) {
  if (options.warmup_steps >= 0) return options.warmup_steps;
  if (options.size == BenchSize::Small && options.particles == 0) return 10;
  return side <= 20 ? 20 : side <= 40 ? 10 : side <= 80 ? 5 : 3;
}

std::int64_t steps_timed(const BenchOptions& options, int side) {
  if (options.timed_steps > 0) return options.timed_steps;
  if (options.size == BenchSize::Small && options.particles == 0) return 40;
  return side <= 20 ? 50 : side <= 40 ? 20 : side <= 80 ? 10 : 5;
}

std::vector<Precision> steps_precisions(const BenchOptions& options, int side) {
  if (!options.precisions.empty()) return options.precisions;
  const std::int64_t n = static_cast<std::int64_t>(side) * side * side;
  if (n >= 1'000'000) return {Precision::Float};
  return {Precision::Float, Precision::Double};
}

void prepare_bench_directory(const std::filesystem::path& dir) {
  make_writable_directory(dir, "the benchmark results");  // throws sph::Error naming the path
  // An earlier run's files stay until this run has results to put in their place
  // (write_bench_files removes those of suites it did not run): a run stopped before its first
  // suite ends leaves them as they were.
}

BenchResult run_benchmarks(const BenchOptions& options, const std::filesystem::path& dir, const BenchOutput& out) {
  validate_bench_options(options);
  BenchResult result;
  result.machine = machine_info();
  result.options = options;
  result.threads = bench_threads(options);
  for (int t : result.threads)
    if (t > result.machine.logical_cores)
      result.notes.push_back(
          fmt::format("{} threads is more than the {} logical cores of this machine (oversubscribed)", t,
                      result.machine.logical_cores));
  if (result.machine.load_average > result.machine.logical_cores)
    result.notes.push_back(
        fmt::format("the machine was busy when the run started (load average {:.2f} on {} logical "
                    "cores): timings may be disturbed",
                    result.machine.load_average, result.machine.logical_cores));
  for (const auto& note : result.notes)
    if (out.progress) out.progress("note: " + note);
  for (const std::string& suite : options.suites) {
    try {
      if (suite == "neighbors") run_neighbors_suite(options, result, out);
      if (suite == "steps") run_steps_suite(options, result, out);
      if (suite == "tank") run_tank_suite(options, result, out);
    } catch (const BenchFailure& e) {
      // Keep what was measured, with the failure, then let the caller report it.
      result.failure = e.what();
      write_bench_files(dir, result);
      throw;
    }
    result.suites_done.push_back(suite);
    write_bench_files(dir, result);
  }
  return result;
}

}  // namespace sph
