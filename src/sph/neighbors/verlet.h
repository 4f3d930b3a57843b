#pragma once
/// \file The verlet strategy: exact lists with a skin, the molecular-dynamics standard.

#include <sph/neighbors/list_builder.h>
#include <sph/neighbors/strategy.h>
#include <sph/neighbors/uniform_grid.h>

namespace sph {

/// Verlet (skin) lists. Lists hold every pair closer than h + skin at the last build and are
/// reused until some particle has moved more than skin / 2 since then, or particles were
/// added; then everything is rebuilt. Two particles closer than h now were closer than
/// h + skin at the last build (each moved at most skin / 2), so no pair within h is ever
/// missed. The solver ignores listed pairs beyond h (the kernels vanish there).
///
/// With `clusters` (the verlet_clusters mode) each build groups the particles in clusters and
/// lists the cluster pairs within h + skin instead (cluster_pairs.h): the same guarantee, since
/// two particles closer than h + skin at the build are in a listed cluster pair. The per-particle
/// lists, the same as verlet's, are then built only when something asks for them (lists(): DFSPH,
/// the gradient correction, the implicit viscosity, the audit), from the build's grid and positions.
template <int D, std::floating_point R>
class VerletNeighbors final : public NeighborStrategy<D, R> {
 public:
  VerletNeighbors(R radius, R skin, bool clusters = false);
  NeighborMode mode() const override { return clusters_ ? NeighborMode::VerletClusters : NeighborMode::Verlet; }
  void update(const ParticleSet<D, R>& particles) override;
  const NeighborLists& lists() const override;
  const ClusterPairs<D, R>* cluster_pairs() const override { return clusters_ ? &pairs_ : nullptr; }
  const NeighborCounters& counters() const override { return counters_; }
  void invalidate() override { built_at_.clear(); }  // the next update rebuilds
  UniformGrid<D, R>* fluid_grid() override { return &grid_; }
  // (verlet builds its grid again at each rebuild, before reading it; with clusters its lists are
  // built from the grid when they are first asked for)
  ScratchBuffer* scratch_until_update() override { return clusters_ ? nullptr : &grid_.lend_scratch(0); }
  void save_state(StateWriter& out) const override;
  void load_state(StateReader& in, std::size_t particles) override;

  R skin() const { return skin_; }
  /// Largest displacement of a particle since the last build, as measured by the last update().
  R max_displacement() const { return max_disp_; }

 private:
  R list_radius() const override { return radius_ + skin_; }
  /// The lists of the last build (from grid_ and built_at_), as requested.
  void build_lists() const;
  /// Pair lanes the cluster pairs hold (ClusterPairs::kSize squared each): the pair visits of a pass.
  std::uint64_t cluster_lanes() const {
    return static_cast<std::uint64_t>(pairs_.pair_count()) * ClusterPairs<D, R>::kSize * ClusterPairs<D, R>::kSize;
  }
  R radius_, skin_;
  bool clusters_;
  R max_disp_ = 0;
  std::vector<Vec<D, R>> built_at_;  // positions at the last build
  std::vector<R> chunk_max_;
  UniformGrid<D, R> grid_;
  mutable ListBuilder<D, R> builder_;
  mutable NeighborLists lists_;
  mutable bool lists_built_ = false;  // clusters: lists_ holds the last build's lists
  ClusterPairs<D, R> pairs_;
  NeighborCounters counters_;
};

extern template class VerletNeighbors<2, float>;
extern template class VerletNeighbors<2, double>;
extern template class VerletNeighbors<3, float>;
extern template class VerletNeighbors<3, double>;

}  // namespace sph
