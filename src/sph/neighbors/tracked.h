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

/// Tracked lists: symmetric lists of every pair closer than h + skin at the later of the two
/// particles' own builds. A particle's list is rebuilt when it has moved more than a third of
/// the skin since its own build (or was just emitted); the rebuild then enters the particle in
/// the lists of its new neighbors and takes it out of the lists of those it left, so that j is
/// in i's list exactly when i is in j's. A pair listed by neither was farther than h + s at the
/// later build of the two; since then one particle moved at most s / 3 and the other at most
/// 2 s / 3 (s / 3 from its own build to each of the two moments), so it is still farther than
/// h: no pair within h is ever missed. Every list is rebuilt each full_rebuild_period updates
/// and after invalidate(), which is also when an automatic skin is chosen again.
///
/// With the exit test on (the adaptive_exact mode) the solver's Eq. 7 test flags both particles
/// of a listed pair predicted to leave h + skin, and flagged particles are rebuilt too: the
/// paper's rule, made exact by the displacement rule.
///
/// Lists keep room of their own for insertions; a list that outgrows it has its chunk laid out
/// again (counted as an overflow), which changes no list. Every step is deterministic for any
/// thread count: marks, rebuilds and the changes to other lists are computed per fixed chunk, and
/// the changes applied in chunk order.
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
  void save_state(StateWriter& out) const override;
  void load_state(StateReader& in, std::size_t particles) override;

  R skin() const { return skin_; }
  /// A list is rebuilt once its particle moved farther than this since its own build (a hair
  /// under a third of the skin, so that rounding can never let a pair within h slip).
  R trigger() const { return skin_ / R(3) * R(0.999); }

 private:
  /// A change to another particle's list: `source` enters (or, with kRemove set, leaves) the list of `target`.
  struct Change {
    std::uint32_t target, source;
  };
  static constexpr std::uint32_t kRemove = 0x80000000u;

  R list_radius() const override { return radius_ + skin_; }
  void full_build(const ParticleSet<D, R>& particles);
  void choose_skin(const ParticleSet<D, R>& particles);
  void set_skin(R skin);  // and indexes the boundary samples for the new radius
  void apply_changes();

  R radius_, fixed_skin_, skin_, dt_;
  int period_;
  bool exit_test_;
  std::int64_t updates_ = 0;
  bool invalid_ = false;
  std::vector<Vec<D, R>> built_at_;                 // each particle's position at its own last build
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
