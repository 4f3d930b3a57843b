#pragma once
/// \file The standard strategy: rebuild the grid and every list every step (paper Section 4).

#include <sph/neighbors/list_builder.h>
#include <sph/neighbors/strategy.h>
#include <sph/neighbors/uniform_grid.h>

namespace sph {

template <int D, std::floating_point R>
class StandardNeighbors final : public NeighborStrategy<D, R> {
 public:
  explicit StandardNeighbors(R radius);
  NeighborMode mode() const override { return NeighborMode::Standard; }
  void update(const ParticleSet<D, R>& particles) override;
  const NeighborLists& lists() const override { return lists_; }
  const NeighborCounters& counters() const override { return counters_; }
  void invalidate() override {}  // every update rebuilds everything anyway
  UniformGrid<D, R>* fluid_grid() override { return &grid_; }
  ScratchBuffer* scratch_until_update() override { return &grid_.lend_scratch(0); }  // (built before each read)
  bool visit_pairs_with(const PairVisitor<R>* visitor) override {
    builder_.set_pair_visitor(visitor);
    return true;
  }

 private:
  R list_radius() const override { return radius_; }
  R radius_;
  UniformGrid<D, R> grid_;
  ListBuilder<D, R> builder_;
  NeighborLists lists_;
  NeighborCounters counters_;
};

/// The test oracle: every pair checked, O(N^2). Lists are sorted by index.
template <int D, std::floating_point R>
class BruteForceNeighbors final : public NeighborStrategy<D, R> {
 public:
  explicit BruteForceNeighbors(R radius);
  NeighborMode mode() const override { return NeighborMode::BruteForce; }
  void update(const ParticleSet<D, R>& particles) override;
  const NeighborLists& lists() const override { return lists_; }
  const NeighborLists& boundary_lists() const override { return boundary_lists_; }
  const NeighborCounters& counters() const override { return counters_; }
  void invalidate() override {}  // every update rebuilds everything anyway

 private:
  R list_radius() const override { return radius_; }
  R radius_;
  NeighborLists lists_, boundary_lists_;
  NeighborCounters counters_;
};

/// Brute-force lists of `positions` within `radius` (strictly closer), sorted by index.
template <int D, std::floating_point R>
NeighborLists brute_force_lists(std::span<const Vec<D, R>> positions, R radius);
/// Every sample closer than `radius` to each query point, by testing every pair (brute-force
/// boundary lists: the reference the grid's are tested against).
template <int D, std::floating_point R>
NeighborLists brute_force_query_lists(std::span<const Vec<D, R>> queries, std::span<const Vec<D, R>> samples, R radius);

}  // namespace sph
