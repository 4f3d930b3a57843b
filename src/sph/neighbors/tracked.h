#pragma once
/// \file The tracked strategies: adaptive per-particle rebuilds that never miss a pair
/// (docs/neighbor-modes.md has the proof).

#include <sph/neighbors/list_builder.h>
#include <sph/neighbors/strategy.h>
#include <sph/neighbors/uniform_grid.h>

namespace sph {

/// The automatic skin of the tracked modes, m: s = sqrt(3 c v dt h / D), c = kTrackedRebuildCost,
/// v the mean particle speed, clamped to [0.02 h, 0.5 h]. It minimizes the linearized cost per
/// particle-step of pair loops that grow like (1 + s / h)^D and of list rebuilds that happen
/// every s / (3 v dt) steps (docs/neighbor-modes.md derives it).
double tracked_skin(double h, double mean_speed, double dt, int dimension);

/// The cost of rebuilding one list relative to one particle's density and force passes of a
/// step, as measured on this project's scenes (docs/neighbor-modes.md, "Choosing the skin").
inline constexpr double kTrackedRebuildCost = 0.5;

/// How far a tracked path runs, as a fraction of h: a particle built at t_i with velocity w_i is
/// rebuilt once |w_i| (t - t_i) exceeds this times h (docs/neighbor-modes.md, "The path rule").
inline constexpr double kTrackedReach = 0.1;

/// Tracked lists: symmetric lists of the pairs whose paths come closer than h + skin. Each
/// particle's list is built at a time t_i from its position b_i and velocity w_i there, and the
/// particle is followed along its path p_i(t) = b_i + w_i (t - t_i). A list is rebuilt when its
/// particle is more than a third of the skin off its path, when the path has run
/// kTrackedReach h (|w_i| (t - t_i) > kTrackedReach h; until then its window is open), or when
/// the particle was just emitted. A rebuild lists j when the two paths come within h + skin at
/// some time between now and the first of the two windows' ends (the closest approach of two
/// lines, in closed form), enters the particle in the lists of its new neighbors and takes it out
/// of the lists of those it left, so that j is in i's list exactly when i is in j's. A pair
/// listed by neither had paths farther apart than h + s over both windows at the later build of
/// the two, and each particle is at most s / 3 off its path, so the pair is farther than h + s / 3
/// while both windows are open; a window that closes rebuilds its list: no pair within h is
/// ever missed. Coherent motion (a falling block, a jet) follows its paths and is not rebuilt;
/// only what accelerates is. The candidates are those within h + s + s / 3 + 2 kTrackedReach h
/// of the particle (each path runs at most kTrackedReach h in its window); those closer than
/// h + s - s / 3 are listed without the path test, which they pass (sure_radius()). Without set_time()
/// every path stays at its build position: the rule is then the displacement rule (a particle
/// is rebuilt after moving s / 3). Every list is rebuilt each full_rebuild_period updates and
/// after invalidate(), which is also when an automatic skin is chosen again.
///
/// With the exit test on (the adaptive_exact mode) the solver's Eq. 7 test flags both particles
/// of a listed pair predicted to leave the candidates' radius, and flagged particles are rebuilt
/// too: the paper's rule, made exact by the path rule.
///
/// Lists keep room of their own for insertions; a list that outgrows it has its chunk laid out
/// again (counted as an overflow), which changes no list. Every step is deterministic for any
/// thread count: marks, rebuilds and the changes to other lists are computed per fixed chunk, and
/// the changes applied in chunk order; the path test is symmetric bit for bit.
template <int D, std::floating_point R>
class TrackedNeighbors final : public NeighborStrategy<D, R> {
 public:
  /// skin 0: automatic (tracked_skin at each full rebuild); time_step: the solver's dt.
  TrackedNeighbors(R radius, R skin, int full_rebuild_period, R time_step, bool exit_test);
  NeighborMode mode() const override { return exit_test_ ? NeighborMode::AdaptiveExact : NeighborMode::Tracked; }
  void update(const ParticleSet<D, R>& particles) override;
  const NeighborLists& lists() const override { return lists_; }
  const NeighborCounters& counters() const override { return counters_; }
  std::span<std::uint8_t> pair_exit_flags() override {
    return exit_test_ ? std::span<std::uint8_t>(flags_) : std::span<std::uint8_t>{};
  }
  void invalidate() override { invalid_ = true; }
  UniformGrid<D, R>* fluid_grid() override { return &grid_; }
  ScratchBuffer* scratch_until_update() override { return &grid_.lend_scratch(0); }  // (built before each read)
  void set_time(double t) override { time_ = t; }
  void save_state(StateWriter& out) const override;
  void load_state(StateReader& in, std::size_t particles) override;

  R skin() const { return skin_; }
  /// A list is rebuilt once its particle is farther than this off its path (a hair under a
  /// third of the skin, so that rounding can never let a pair within h slip).
  R trigger() const { return skin_ / R(3) * R(0.999); }

 private:
  /// A change to another particle's list: `source` enters (or, with kRemove set, leaves) the list of `target`.
  struct Change {
    std::uint32_t target, source;
  };
  static constexpr std::uint32_t kRemove = 0x80000000u;

  /// The lists' reach (and the exit test's radius): the candidates' radius.
  R list_radius() const override { return candidate_radius(); }
  /// The radius candidates are gathered within: every pair whose paths can come within h + s.
  R candidate_radius() const { return (radius_ + skin_ + trigger() + R(2 * kTrackedReach) * radius_) * R(1.0001); }
  /// Candidates closer than this are kept without the path test (ListBuilder::split_at): their
  /// paths are within h + s now, since the other particle is at most trigger() off its own path.
  R sure_radius() const { return (radius_ + skin_ - trigger()) * R(0.9999); }
  /// A particle's samples within h along its whole path: h + s + the path's reach.
  R boundary_radius() const override { return (radius_ + skin_ + R(kTrackedReach) * radius_) * R(1.0001); }
  /// How long a path at velocity v takes to run kTrackedReach h (infinite at rest).
  R window(const Vec<D, R>& v) const;
  /// Sizes the paths' arrays for n particles and points the builder at the path test.
  void size_paths(std::size_t n);
  /// Particle i's path starts now, where it is, at its velocity.
  void start_path(const ParticleSet<D, R>& ps, std::size_t i);
  /// The path test, as ListFilter: of the candidates of particle i (rebuilt now), keeps those
  /// whose paths come within h + s before the first of the two windows closes.
  struct PathFilter final : ListFilter {
    const TrackedNeighbors* self = nullptr;
    std::uint32_t keep(std::size_t i, std::uint32_t* list, std::uint32_t len) const override;
  };

  void full_build(const ParticleSet<D, R>& particles);
  void choose_skin(const ParticleSet<D, R>& particles);
  void set_skin(R skin);  // and indexes the boundary samples for the new radius
  void apply_changes();

  R radius_, fixed_skin_, skin_, dt_;
  int period_;
  bool exit_test_;
  std::int64_t updates_ = 0;
  bool invalid_ = false;
  double time_ = 0;                        // set_time()'s
  std::vector<Vec<D, R>> built_at_;        // each particle's position at its own last build
  std::vector<Vec<D, R>> built_velocity_;  // and its velocity there: the path's
  std::vector<double> built_time_;         // and the time of that build
  std::vector<double> window_end_;         // when its path has run kTrackedReach h
  std::vector<Vec<D, R>> path_now_;        // this update: where each path is now
  std::vector<R> left_;                    // and the time its window has left
  PathFilter filter_;
  std::vector<std::uint8_t> marks_;                 // this update rebuilds the list
  std::vector<std::uint8_t> flags_;                 // the solver's Eq. 7 flags (exit test only)
  std::vector<std::vector<Change>> changes_;        // per chunk: the changes its rebuilt lists make to others
  std::vector<std::vector<std::uint32_t>> stamps_;  // per thread: one stamp per particle
  std::vector<std::uint32_t> next_stamp_;           // per thread: the last stamp given
  std::vector<std::uint32_t> chunk_counts_;
  std::vector<R> chunk_speed_;
  std::vector<std::uint32_t> relayout_scratch_;
  std::vector<Vec<D, R>> samples_copy_;
  UniformGrid<D, R> grid_;
  ListBuilder<D, R> builder_;
  NeighborLists lists_;
  NeighborCounters counters_;
};

extern template class TrackedNeighbors<2, float>;
extern template class TrackedNeighbors<2, double>;
extern template class TrackedNeighbors<3, float>;
extern template class TrackedNeighbors<3, double>;

}  // namespace sph
