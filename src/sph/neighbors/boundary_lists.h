#pragma once
/// \file BoundaryLists: each fluid particle's list of static boundary samples (boundary
/// particles), kept by the neighbor strategies beside their fluid lists.

#include <span>
#include <vector>

#include <sph/neighbors/list_builder.h>
#include <sph/neighbors/neighbor_lists.h>
#include <sph/neighbors/uniform_grid.h>

namespace sph {

class StateWriter;
class StateReader;

/// The samples are indexed in their own grid when set (and again when moving obstacles move
/// them); each build then queries that grid at every fluid particle's position
/// (ListBuilder::build_queries), so a step costs one lookup per fluid particle and no grid build. Lists hold sample
/// indices; with no samples there are no lists (particle_count() 0), and the solver skips the boundary terms.
/// Deterministic for any thread count, as the fluid lists are.
template <int D, std::floating_point R>
class BoundaryLists {
 public:
  /// Takes the samples and indexes them for lists of pairs closer than `radius` (the
  /// strategy's list radius: h, or h + skin for verlet).
  void set_samples(std::span<const Vec<D, R>> samples, R radius);
  /// The samples moved (moving obstacles): takes their new positions (as many as before) and
  /// indexes them again; the next build or rebuild_some() then rebuilds every list.
  void move_samples(std::span<const Vec<D, R>> samples);
  /// Whether the samples moved since the lists were last built.
  bool moved() const { return moved_; }
  bool empty() const { return samples_.empty(); }
  std::span<const Vec<D, R>> samples() const { return samples_; }
  R radius() const { return radius_; }

  /// Rebuilds every fluid particle's list. Nothing (and no lists) without samples.
  void build(std::span<const Vec<D, R>> fluid);
  /// Rebuilds the lists of the particles with rebuild[i] != 0 and of any particle appended since
  /// the last build; keeps the others (all of them after move_samples()).
  void rebuild_some(std::span<const Vec<D, R>> fluid, std::span<const std::uint8_t> rebuild);
  const NeighborLists& lists() const { return lists_; }

  /// The lists, for a checkpoint (the samples come from the scene).
  void save(StateWriter& out) const;
  /// Restores what save() wrote, for `particles` fluid particles; throws sph::Error if it does not fit.
  void load(StateReader& in, std::size_t particles);

 private:
  std::vector<Vec<D, R>> samples_;
  R radius_ = 0;
  UniformGrid<D, R> grid_;
  ListBuilder<D, R> builder_;
  NeighborLists lists_;
  bool moved_ = false;
};

extern template class BoundaryLists<2, float>;
extern template class BoundaryLists<2, double>;
extern template class BoundaryLists<3, float>;
extern template class BoundaryLists<3, double>;

}  // namespace sph
