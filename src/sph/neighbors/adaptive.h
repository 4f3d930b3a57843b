#pragma once
/// \file The adaptive strategy: the paper's Algorithm 2 (Pelfrey & House, Section 5).

#include <sph/neighbors/list_builder.h>
#include <sph/neighbors/strategy.h>
#include <sph/neighbors/uniform_grid.h>

namespace sph {

/// Adaptive neighbor pairing. One flag per particle, set at the start and for every particle
/// added later. Each update() rebuilds the lists of the flagged particles (all of them every
/// `full_rebuild_period` steps) from a fresh grid and clears their flags; the solver's force
/// pass then sets the flags of both particles of any listed pair whose predicted distance
/// after the step, |x_i - x_j + dt (u_i - u_j)| (Eq. 7, with the solver's step size dt),
/// exceeds h (pair_exit_flags()).
///
/// The test only watches pairs that are listed: a particle coming into range of a particle
/// whose list is not rebuilt is missed until the next rebuild of that list. Lists can also be
/// asymmetric (i lists j, j does not list i). Both are what the paper does; the audit
/// (ListAuditor) measures them.
///
/// When no particle is flagged the grid is not rebuilt either (it is only used to build lists),
/// which changes no result. With full_rebuild_period 1 every update rebuilds everything, exactly
/// as StandardNeighbors does, with bitwise-identical lists.
template <int D, std::floating_point R>
class AdaptiveNeighbors final : public NeighborStrategy<D, R> {
 public:
  AdaptiveNeighbors(R radius, int full_rebuild_period);
  NeighborMode mode() const override { return NeighborMode::Adaptive; }
  void update(const ParticleSet<D, R>& particles) override;
  const NeighborLists& lists() const override { return lists_; }
  const NeighborCounters& counters() const override { return counters_; }
  std::span<std::uint8_t> pair_exit_flags() override { return flags_; }
  /// The next update is a full rebuild (Simulation reorders on full-rebuild steps by default,
  /// so that this costs nothing extra).
  void invalidate() override { invalid_ = true; }
  UniformGrid<D, R>* fluid_grid() override { return &grid_; }
  ScratchBuffer* scratch_until_update() override { return &grid_.lend_scratch(0); }  // (built before each read)
  void save_state(StateWriter& out) const override;
  void load_state(StateReader& in, std::size_t particles) override;

 private:
  R list_radius() const override { return radius_; }
  R radius_;
  int period_;
  std::int64_t updates_ = 0;
  bool invalid_ = false;
  std::vector<std::uint8_t> flags_;
  UniformGrid<D, R> grid_;
  ListBuilder<D, R> builder_;
  NeighborLists lists_;
  NeighborCounters counters_;
};

extern template class AdaptiveNeighbors<2, float>;
extern template class AdaptiveNeighbors<2, double>;
extern template class AdaptiveNeighbors<3, float>;
extern template class AdaptiveNeighbors<3, double>;

}  // namespace sph
