#pragma once
/// \file The benchmark suites behind `sph bench`. Workloads are fixed (workload.h), so figures
/// compare across versions of the code:
///   neighbors  grid + list building on a jittered 3D lattice: first build and rebuild after a
///              small move, lattice and shuffled particle order, checked for exactness;
///   steps      whole simulation steps of a 3D dam break per neighbor mode: ms per phase,
///              particle-steps per second, peak memory; `scaling` is time per particle-step
///              against N from the same runs;
///   tank       the paper's Fig. 4 scene run by each mode, repeats interleaved, and the speed
///              ratios of the modes.
/// The library runs and records; the app prints what it streams through BenchOutput.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <sph/bench/list_check.h>
#include <sph/bench/machine.h>
#include <sph/neighbors/strategy.h>
#include <sph/scene/scene_desc.h>
#include <sph/solver/simulation.h>

namespace sph {

/// How much to run: small = the 8k workloads with few steps (CI), medium adds 64k, large adds
/// 512k, full adds the 1M dam break to the steps suite.
enum class BenchSize { Small, Medium, Large, Full };

inline constexpr const char* kBenchSuites[] = {"neighbors", "steps", "tank"};

struct BenchOptions {
  std::vector<std::string> suites{"neighbors", "steps", "tank"};  ///< in this order
  BenchSize size = BenchSize::Small;
  std::vector<int> threads;           ///< thread counts; empty: 1 and the core count
  std::vector<Precision> precisions;  ///< empty: each suite's default (see the suites)
  int repeats = 5;                    ///< neighbors: timings per case; tank: runs per mode
  int step_runs = 3;                  ///< steps: runs per workload (the median run is reported)
  std::int64_t particles = 0;         ///< steps: one explicit particle count (rounded to a cube) instead of the size's
  std::int64_t warmup_steps = -1;     ///< steps: untimed steps before timing (-1: by size)
  std::int64_t timed_steps = -1;      ///< steps: timed steps (-1: by size)
  std::int64_t tank_steps = 0;        ///< tank: steps per run (0: the scene's, or 1000 at size small)
  std::vector<NeighborMode> modes = neighbor_modes(NeighborModeSet::Compared);
  std::filesystem::path scene_dir;  ///< tank: directory of tank_fill_3d.json (empty: default_scene_dir())
};

/// The paper scenes installed with sph: scene_dir("paper") (sph/core/data_dir.h).
std::filesystem::path default_scene_dir();

/// Median, minimum and maximum of some timings (seconds, in the order measured).
struct TimingStats {
  std::vector<double> seconds;
  double median = 0, min = 0, max = 0;
};
/// Summarizes `seconds` (the median of an even count is the mean of the middle two).
TimingStats summarize(std::vector<double> seconds);

/// One timed neighbors case.
struct NeighborsRow {
  std::size_t particles = 0;
  int side = 0;          ///< lattice points per axis
  double radius_dx = 0;  ///< search radius in lattice spacings
  Precision precision = Precision::Double;
  std::string order;  ///< "lattice" or "shuffled"
  int threads = 1;
  bool oversubscribed = false;  ///< more threads than logical cores
  std::string phase;            ///< "build" (fresh objects) or "rebuild" (objects reused, points moved)
  TimingStats time;
  double ns_per_particle = 0;         ///< median time per particle
  double neighbors_per_particle = 0;  ///< entries stored / particles
};

/// One correctness check of the neighbors suite (untimed).
struct NeighborsCheckRecord {
  std::size_t particles = 0;
  double radius_dx = 0;
  Precision precision = Precision::Double;
  std::string order, phase;
  int threads = 1;  ///< threads that built the checked lists
  ListCheck check;
};

/// One steps workload (a dam break run by one mode, precision and thread count).
struct StepsRow {
  std::size_t particles = 0;
  int side = 0;
  NeighborMode mode = NeighborMode::Standard;
  Precision precision = Precision::Double;
  int threads = 1;
  bool oversubscribed = false;
  std::int64_t warmup_steps = 0, timed_steps = 0;
  PhaseTimes ms_per_step;                   ///< milliseconds per timed step, by phase
  double wall_ms_per_step = 0;              ///< wall time of the timed loop per step (phases plus bookkeeping)
  int runs = 1;                             ///< runs of this workload; the row is the run of median wall time
  double wall_ms_min = 0, wall_ms_max = 0;  ///< fastest and slowest run's wall ms per step
  double particle_steps_per_second = 0;     ///< particles * steps / wall seconds
  double ns_per_particle_step = 0;          ///< the scaling figure: wall ns per particle and step
  double lists_rebuilt_per_step = 0;        ///< mean over the timed steps
  double neighbors_per_particle = 0;        ///< entries stored / particles after the last step
  /// Where the pair loops stand against the machine (docs/performance.md, "The pair loops against
  /// the machine"): the list entries (fluid and boundary) each of the two pair passes (density,
  /// forces) visits per particle and step, the share of the fluid entries closer than h (1 for
  /// lists of exactly the pairs within h; less with a skin), and the pair visits both passes
  /// achieve per second of their own time and per thread (the force pass's alone where the
  /// density sums are made in the list build: StepInfo::density_in_lists, the standard mode).
  double pair_visits_per_particle = 0;
  double within_h_fraction = 0;
  double pair_visits_per_core_second = 0;
  bool density_in_lists = false;         ///< the density sums were made in the list build (their time is the lists')
  std::int64_t baseline_rss_bytes = -1;  ///< VmRSS before the simulation was built
  std::int64_t peak_rss_bytes = -1;      ///< VmHWM after the run
  bool peak_reset = false;               ///< the peak counter was reset before the build
  double bytes_per_particle = 0;         ///< (peak - baseline) / particles
  double heap_bytes_per_particle =
      -1;  ///< malloc'd bytes held by the simulation after the run / particles (-1: unknown)
};

/// One mode's runs of the tank scene at one thread count and precision.
struct TankRow {
  int threads = 1;
  bool oversubscribed = false;
  NeighborMode mode = NeighborMode::Standard;
  Precision precision = Precision::Double;
  std::int64_t steps = 0;
  std::size_t particles_end = 0;
  TimingStats time;        ///< wall seconds of the stepping loop, one per repeat
  double ms_per_step = 0;  ///< median / steps
  double speedup = 0;      ///< median of standard / median of this mode (same threads and precision)
};

struct BenchResult {
  MachineInfo machine;
  BenchOptions options;
  std::vector<int> threads;  ///< thread counts used
  std::vector<std::string> suites_done;
  std::vector<std::string> notes;  ///< warnings worth keeping with the figures
  std::vector<NeighborsRow> neighbors;
  std::vector<NeighborsCheckRecord> neighbor_checks;
  std::vector<StepsRow> steps;
  std::vector<TankRow> tank;
  std::string tank_scene;  ///< path of the tank scene run
  std::string failure;     ///< the BenchFailure that stopped the run ("" if none)
};

/// Where the suites stream what they do. Either may be empty.
struct BenchOutput {
  std::function<void(const std::string&)> table;     ///< lines of the readable tables (stdout)
  std::function<void(const std::string&)> progress;  ///< what is running now, notes (stderr)
};

/// A benchmark found wrong results (neighbor lists that differ from the exact ones, a
/// simulation that blew up). The message names the case. Bad options are sph::Error instead.
class BenchFailure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Thread counts to run: options.threads, or 1 and the core count.
std::vector<int> bench_threads(const BenchOptions& options);
/// Lattice sides of the neighbors suite for a size: 20 (8,000 points), 40, 80.
std::vector<int> neighbors_sides(BenchSize size);
/// Block sides of the steps suite: 20, 40, 80, 100 by size, or the cube root of options.particles.
std::vector<int> steps_sides(const BenchOptions& options);
/// Untimed and timed steps of a steps workload with blocks of side^3 particles.
std::int64_t steps_warmup(const BenchOptions& options, int side);
std::int64_t steps_timed(const BenchOptions& options, int side);
/// Precisions of the steps suite at this block side: options.precisions, or float and double
/// (float alone from 1M particles on).
std::vector<Precision> steps_precisions(const BenchOptions& options, int side);

/// Runs one suite and appends to `result` (machine and options must be set). Throws
/// BenchFailure for wrong results, sph::Error for bad options (e.g. a missing tank scene).
void run_neighbors_suite(const BenchOptions& options, BenchResult& result, const BenchOutput& out);
void run_steps_suite(const BenchOptions& options, BenchResult& result, const BenchOutput& out);
void run_tank_suite(const BenchOptions& options, BenchResult& result, const BenchOutput& out);

/// Checks options (suite names, thread counts, repeats...); throws sph::Error naming the option.
void validate_bench_options(const BenchOptions& options);

/// Creates `dir` if needed and checks that files can be written there (throws sph::Error naming
/// the path otherwise). An earlier benchmark's files stay until write_bench_files replaces them.
void prepare_bench_directory(const std::filesystem::path& dir);

/// Runs every suite of options.suites in order, writing the files (write_bench_files) after each
/// suite, so that a later failure keeps the earlier figures. `dir` must be prepared.
BenchResult run_benchmarks(const BenchOptions& options, const std::filesystem::path& dir, const BenchOutput& out);

/// Writes DIR/bench.json (everything; its "status" is "completed" only once every suite ran,
/// "incomplete: ..." while they run or if the run was stopped) and one CSV per suite run
/// (neighbors.csv, steps.csv, tank.csv), each atomically, and removes the CSVs of the suites it
/// did not run (an earlier benchmark's).
void write_bench_files(const std::filesystem::path& dir, const BenchResult& result);
/// The JSON document of write_bench_files.
std::string bench_json(const BenchResult& result);

// Parsing of the command line's values; each throws sph::Error naming `where` and what is accepted.
std::vector<std::string> parse_bench_suites(std::string_view list, const std::string& where = "--suite");
BenchSize parse_bench_size(std::string_view name, const std::string& where = "--size");
std::vector<int> parse_thread_list(std::string_view list, const std::string& where = "--threads");
std::vector<Precision> parse_precisions(std::string_view list, const std::string& where = "--precision");
std::vector<NeighborMode> parse_bench_modes(std::string_view list, const std::string& where = "--modes");
const char* to_string(BenchSize size);

}  // namespace sph
