// The neighbors suite: grid + list building on a jittered 3D lattice (workload.h), timed as a
// first build with fresh objects and as a rebuild after every point moved, in lattice order
// and in shuffled order (then with the Morton reordering and gather that the project uses),
// and checked once per case against an independent exact search.

#include <algorithm>

#include <fmt/format.h>

#include <sph/bench/bench.h>
#include <sph/bench/tables.h>
#include <sph/bench/workload.h>
#include <sph/core/parallel.h>
#include <sph/core/timer.h>
#include <sph/neighbors/list_builder.h>
#include <sph/neighbors/reorder.h>
#include <sph/neighbors/uniform_grid.h>

namespace sph {

namespace {

constexpr double kRadiiDx[] = {2.0, 3.0};
constexpr double kMoveFraction = 0.05;  // of dx, per coordinate, for the rebuild

/// Everything one build needs. Lattice order: grid and lists on the points as given. Shuffled
/// order: Morton permutation (cell = radius), a gathered copy of the points in that order
/// (buffer reused), then grid and lists on the copy; list k then belongs to point perm[k].
template <std::floating_point R>
struct NeighborPipeline {
  using V = Vec<3, R>;
  explicit NeighborPipeline(bool reorder) : reorder(reorder) {}

  void build(std::span<const V> points, R radius) {
    std::span<const V> x = points;
    if (reorder) {
      perm = morton.compute(points, radius);
      gather<V>(points, perm, gathered);
      x = gathered;
    }
    grid.build(x, radius);
    builder.build(grid, x, radius, lists);
  }

  bool reorder;
  MortonOrder<3, R> morton;
  std::span<const std::uint32_t> perm;  // (in morton's memory)
  std::vector<V> gathered;
  UniformGrid<3, R> grid;
  ListBuilder<3, R> builder;
  NeighborLists lists;
};

std::string case_name(std::size_t n, double radius_dx, Precision p, const std::string& order,
                      const std::string& phase) {
  return fmt::format("N={} r={}dx {} {} ({})", n, radius_dx, precision_name(p), order, phase);
}

template <std::floating_point R>
void run_lattice(int side, const BenchOptions& options, const std::vector<int>& threads, BenchResult& result,
                 const BenchOutput& out) {
  using V = Vec<3, R>;
  const Precision precision = std::is_same_v<R, float> ? Precision::Float : Precision::Double;
  LatticeSpec spec;
  spec.side = side;
  const std::size_t n = spec.count();
  const std::vector<V> lattice = lattice_points<R>(spec);
  const std::vector<V> lattice_moved = moved_points<R>(lattice, kMoveFraction * spec.spacing, kMoveSeed);
  const std::vector<std::uint32_t> shuffle = shuffle_permutation(n, kShuffleSeed);
  const int cores = result.machine.logical_cores;
  const int check_threads = *std::max_element(threads.begin(), threads.end());

  for (double radius_dx : kRadiiDx) {
    const R radius = static_cast<R>(radius_dx * spec.spacing);
    for (const std::string order : {"lattice", "shuffled"}) {
      const bool shuffled = order == "shuffled";
      std::vector<V> points, moved;
      if (shuffled) {
        gather<V>(lattice, shuffle, points);
        gather<V>(lattice_moved, shuffle, moved);
      } else {
        points = lattice;
        moved = lattice_moved;
      }

      // Correctness, once per case and untimed: the lists of a build and of a rebuild.
      set_num_threads(check_threads);
      {
        if (out.progress)
          out.progress(
              fmt::format("neighbors: checking {}", case_name(n, radius_dx, precision, order, "build and rebuild")));
        NeighborPipeline<R> p(shuffled);
        for (const std::string phase : {"build", "rebuild"}) {
          const std::vector<V>& x = phase == "build" ? points : moved;
          p.build(x, radius);
          NeighborsCheckRecord rec;
          rec.particles = n;
          rec.radius_dx = radius_dx;
          rec.precision = precision;
          rec.order = order;
          rec.phase = phase;
          rec.threads = check_threads;
          rec.check = check_neighbor_lists<3, R>(x, radius, view_of(p.lists),
                                                 shuffled ? p.perm : std::span<const std::uint32_t>());
          result.neighbor_checks.push_back(rec);
          if (!rec.check.ok)
            throw BenchFailure(fmt::format("neighbor lists are wrong for {}, built with {} thread{}: {}",
                                           case_name(n, radius_dx, precision, order, phase), check_threads,
                                           check_threads == 1 ? "" : "s", rec.check.problem));
        }
      }

      for (int t : threads) {
        set_num_threads(t);
        std::vector<double> build_s, rebuild_s;
        std::size_t build_entries = 0, rebuild_entries = 0;
        for (int rep = 0; rep < options.repeats; ++rep) {
          release_free_heap();  // so that every first build pays for its memory, as a first build does
          NeighborPipeline<R> p(shuffled);
          Stopwatch watch;
          p.build(points, radius);
          build_s.push_back(watch.lap());
          build_entries = p.lists.entry_count();
          watch.lap();
          p.build(moved, radius);
          rebuild_s.push_back(watch.lap());
          rebuild_entries = p.lists.entry_count();
        }
        for (const std::string phase : {"build", "rebuild"}) {
          NeighborsRow row;
          row.particles = n;
          row.side = side;
          row.radius_dx = radius_dx;
          row.precision = precision;
          row.order = order;
          row.threads = t;
          row.oversubscribed = t > cores;
          row.phase = phase;
          row.time = summarize(phase == "build" ? build_s : rebuild_s);
          row.ns_per_particle = 1e9 * row.time.median / static_cast<double>(n);
          row.neighbors_per_particle =
              static_cast<double>(phase == "build" ? build_entries : rebuild_entries) / static_cast<double>(n);
          result.neighbors.push_back(row);
          if (out.table) out.table(detail::neighbors_table_row(row));
        }
      }
    }
  }
}

}  // namespace

void run_neighbors_suite(const BenchOptions& options, BenchResult& result, const BenchOutput& out) {
  const std::vector<int> threads = bench_threads(options);
  const std::vector<Precision> precisions =
      options.precisions.empty() ? std::vector<Precision>{Precision::Float, Precision::Double} : options.precisions;
  if (out.table) {
    out.table(fmt::format(
        "\nneighbors: jittered 3D lattice (dx = 0.025, +-0.1 dx), grid + lists; build = fresh objects, rebuild = "
        "after a +-0.05 dx move; shuffled includes the Morton reorder + gather; median of {} [min .. max]",
        options.repeats));
    out.table(detail::neighbors_table_header());
  }
  for (int side : neighbors_sides(options.size))
    for (Precision p : precisions) {
      if (p == Precision::Float)
        run_lattice<float>(side, options, threads, result, out);
      else
        run_lattice<double>(side, options, threads, result, out);
    }
}

}  // namespace sph
