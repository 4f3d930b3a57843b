#pragma once
/// \file NeighborStrategy: the policy interface the solver calls once per step.

#include <memory>
#include <span>

#include <sph/core/particle_set.h>
#include <sph/neighbors/boundary_lists.h>
#include <sph/neighbors/cluster_pairs.h>
#include <sph/neighbors/list_builder.h>
#include <sph/neighbors/neighbor_lists.h>
#include <sph/neighbors/neighbor_mode.h>
#include <sph/neighbors/uniform_grid.h>

namespace sph {

class StateWriter;
class StateReader;

/// What one update() did.
struct NeighborCounters {
  std::uint64_t lists_rebuilt = 0;          ///< particles whose list was rebuilt this step
  std::uint64_t pairs_stored = 0;           ///< directed entries stored in all lists
  std::uint64_t boundary_pairs_stored = 0;  ///< entries stored in the boundary lists
  std::uint64_t entries_rebuilt = 0;        ///< entries written by this step's (re)builds and insertions
  std::uint64_t insertions = 0;             ///< tracked modes: a rebuilt particle entered another's list
  std::uint64_t removals = 0;               ///< tracked modes: a rebuilt particle left another's list
  std::uint64_t overflows = 0;              ///< tracked modes: lists that outgrew their room (chunk laid out again)
  double skin = 0;                          ///< lists hold pairs within h + skin (0: exactly h), m
  double grid_seconds = 0;                  ///< wall time spent building the grid
  double lists_seconds = 0;                 ///< wall time spent building lists
};

/// Options shared by the strategies (those a strategy does not use are ignored by it).
struct NeighborOptions {
  double radius = 0;              ///< kernel support h, m
  int full_rebuild_period = 200;  ///< adaptive: rebuild every list each this many steps
  double verlet_skin = 0;         ///< verlet: lists hold pairs closer than h + skin, m; 0: default
  /// tracked, adaptive_exact: lists hold pairs closer than h + skin, m; 0: chosen at each full
  /// rebuild by tracked_skin() from the time step and the speeds seen
  double tracked_skin = 0;
  double time_step = 0;  ///< the solver's step, s (the tracked modes' automatic skin)
};

/// Default verlet skin as a fraction of h (docs/paper-reproduction.md shows how it was chosen).
inline constexpr double kDefaultSkinFraction = 0.1;

/// A neighbor strategy keeps full neighbor lists of the particles current for the solver.
template <int D, std::floating_point R>
class NeighborStrategy {
 public:
  virtual ~NeighborStrategy() = default;
  virtual NeighborMode mode() const = 0;
  /// Called once per step, before density, with the current positions: afterwards lists()
  /// holds, for each particle, its neighbors for this step. Particles may have been appended
  /// since the last call (emitters); none are removed.
  virtual void update(const ParticleSet<D, R>& particles) = 0;
  virtual const NeighborLists& lists() const = 0;
  /// The same pairs as cluster pairs (verlet_clusters: every pair within h lies in a listed pair
  /// of clusters), which the WCSPH density and force passes then loop over instead of lists();
  /// null for the strategies that keep per-particle lists only.
  virtual const ClusterPairs<D, R>* cluster_pairs() const { return nullptr; }
  /// Asks that every update() from now on show each fluid list it builds, with its entries'
  /// squared distances, to `visitor` (null: none; list_builder.h, PairVisitor), in the thread that
  /// builds it. Returns whether the strategy will: true only where every update() builds every
  /// fluid list whole (standard); the others ignore the visitor.
  virtual bool visit_pairs_with(const PairVisitor<R>* visitor) {
    (void)visitor;
    return false;
  }
  /// The simulated time (s) of the state the next update() sees. The tracked modes follow each
  /// particle along a path in time; the others ignore it.
  virtual void set_time(double t) { (void)t; }

  /// Static boundary samples (boundary particles): from now on every update() also keeps
  /// boundary_lists(), each fluid particle's samples closer than h, by the strategy's own rule:
  /// standard rebuilds them every step; adaptive rebuilds a particle's boundary list with its
  /// fluid list, and the Eq. 7 test flags a particle for its fluid-boundary pairs too; verlet
  /// lists the samples within h + skin and rebuilds them with the fluid lists. Called before
  /// the first update; the samples never move.
  void set_boundary(std::span<const Vec<D, R>> samples) { boundary_.set_samples(samples, boundary_radius()); }
  /// The samples moved (moving obstacles; as many as were set): the next update() rebuilds
  /// every boundary list, whatever the strategy's rule, so that no fluid-boundary pair is missed.
  void move_boundary(std::span<const Vec<D, R>> samples) { boundary_.move_samples(samples); }
  /// Rebuilds the boundary lists if the samples moved and update() did not rebuild them
  /// (strategies that rebuild lists only on their own schedule, like verlet). Returns whether it did.
  bool refresh_moved_boundary(const ParticleSet<D, R>& particles) {
    if (!boundary_.moved()) return false;
    boundary_.build(particles.position);
    return true;
  }
  /// Each particle's boundary samples (indices into the samples); no lists without samples.
  virtual const NeighborLists& boundary_lists() const { return boundary_.lists(); }
  std::span<const Vec<D, R>> boundary_samples() const { return boundary_.samples(); }
  /// Counters of the last update().
  virtual const NeighborCounters& counters() const = 0;

  /// Flags, one per particle, that the solver's force pass sets for both particles of every
  /// listed pair whose predicted distance |x_i - x_j + dt (u_i - u_j)| exceeds h (paper
  /// Eq. 7). The strategy reads and clears them in its next update(). Empty for strategies
  /// that do not ask for the test (the solver then skips it).
  virtual std::span<std::uint8_t> pair_exit_flags() { return {}; }
  /// The radius of the Eq. 7 test: h for the paper's lists, the candidates' radius for
  /// adaptive_exact's (a pair is flagged when it is predicted to leave the lists' reach).
  R pair_exit_radius() const { return list_radius(); }

  /// The particles were reordered in memory: the lists refer to old indices, so the next
  /// update() rebuilds every list (and restarts whatever the strategy tracks per particle).
  virtual void invalidate() = 0;
  /// The grid of the fluid particles, whose memory a reorder may borrow as scratch
  /// (UniformGrid::lend_scratch) after invalidate(): its next update() builds it again before
  /// reading it. Null for a strategy without one.
  virtual UniformGrid<D, R>* fluid_grid() { return nullptr; }
  /// Memory the solver may use from now until the next update(): the fluid grid's
  /// (UniformGrid::lend_scratch), for a strategy that builds its grid again before it next reads
  /// it, at least 2 reals a particle; null otherwise (verlet_clusters: its per-particle lists are
  /// built from the grid when asked for, which may be later).
  virtual ScratchBuffer* scratch_until_update() { return nullptr; }

  /// Writes what the strategy carries from one update() to the next (checkpoints: lists,
  /// flags, reference positions), so that a resumed run makes exactly the choices the
  /// uninterrupted run would have made. Strategies that rebuild every list every step write
  /// nothing.
  virtual void save_state(StateWriter& out) const { (void)out; }
  /// Restores what save_state() wrote, for a set of `particles` particles. Throws sph::Error
  /// if the data does not fit.
  virtual void load_state(StateReader& in, std::size_t particles) {
    (void)in;
    (void)particles;
  }

 protected:
  /// The radius the lists hold pairs within (h; verlet: h + skin).
  virtual R list_radius() const = 0;
  /// The radius of the boundary lists (list_radius(); the tracked modes reach further).
  virtual R boundary_radius() const { return list_radius(); }
  BoundaryLists<D, R> boundary_;
};

/// Creates the strategy for `mode`. Throws sph::Error for a mode this build cannot run.
template <int D, std::floating_point R>
std::unique_ptr<NeighborStrategy<D, R>> make_neighbor_strategy(NeighborMode mode, const NeighborOptions& options);

}  // namespace sph
