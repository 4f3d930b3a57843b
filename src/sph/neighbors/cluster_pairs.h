#pragma once
/// \file ClusterPairs: the particles grouped in small spatial clusters, and for each cluster the
/// clusters whose bounding boxes come within a radius of its own (the cluster-pair lists of
/// molecular dynamics: Pall & Hess 2013, GROMACS's nbnxm). A pair loop then takes a neighbor
/// cluster's data with contiguous loads, not one gather per neighbor.

#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include <sph/core/vec.h>
#include <sph/neighbors/uniform_grid.h>

namespace sph {

/// Clusters of kSize particles and their cluster-pair lists.
///
/// Clusters: the box of the particles is cut into columns (along x in 2D, x and y in 3D) whose
/// side holds about kSize particles per cluster of cubic shape, at the particles' density; each
/// column's particles are sorted along the last axis (ties by index) and taken kSize at a time,
/// so a cluster is a compact group and a column's last cluster may have empty slots.
///
/// Lists: cluster c lists every cluster d (c itself included) whose bounding box is closer than
/// the radius to c's: two particles closer than the radius have boxes at least that close, so
/// their clusters are listed (the boxes' gaps are computed from the same coordinates with the same
/// roundings as a pair's offset, and are never larger). Lists are in a fixed order: columns in
/// order, and up each column. Everything depends on the positions only, never on the thread count.
template <int D, std::floating_point R>
class ClusterPairs {
 public:
  static constexpr int kSize = 4;                                                     ///< slots per cluster
  static constexpr std::uint32_t kEmpty = std::numeric_limits<std::uint32_t>::max();  ///< a slot without a particle

  /// Clusters `positions` and lists the cluster pairs within `radius`. `grid` is built on the same
  /// positions (its occupied cells give the particles' density, which sizes the columns).
  void build(const UniformGrid<D, R>& grid, std::span<const Vec<D, R>> positions, R radius);
  void clear();

  std::size_t particle_count() const { return particles_; }
  std::size_t cluster_count() const { return slots_.size() / kSize; }
  /// The particle in each slot: cluster c holds slots kSize c to kSize c + kSize - 1; kEmpty for
  /// the empty slots.
  std::span<const std::uint32_t> slots() const { return slots_; }
  /// The cluster of particle i.
  std::uint32_t cluster_of(std::size_t i) const { return cluster_of_[i]; }
  /// The clusters cluster c lists.
  std::span<const std::uint32_t> of(std::size_t c) const {
    return {chunks_[c / kChunkClusters].data() + begin_[c], end_[c] - begin_[c]};
  }
  /// Cluster pairs listed (directed, each cluster with itself included).
  std::size_t pair_count() const { return pairs_; }
  /// Bytes of memory held.
  std::size_t memory_bytes() const;

  /// Clusters per list chunk (chunks are built in parallel, each in its own buffer).
  static constexpr std::size_t kChunkClusters = 256;

 private:
  std::size_t particles_ = 0;
  std::size_t pairs_ = 0;
  std::vector<std::uint32_t> slots_;
  std::vector<std::uint32_t> cluster_of_;           // per particle: its cluster (during the build: its column)
  std::vector<std::uint32_t> column_start_;         // per column + 1: first particle in order_
  std::vector<std::uint32_t> column_cluster_;       // per column + 1: its first cluster
  std::vector<std::uint32_t> order_;                // particles by column, then along the last axis
  std::vector<Vec<D, R>> lo_, hi_;                  // per cluster: bounding box
  std::vector<std::vector<std::uint32_t>> chunks_;  // lists, per chunk of kChunkClusters clusters
  std::vector<std::uint32_t> begin_, end_;          // per cluster: its list in its chunk
  std::vector<std::size_t> chunk_pairs_;            // per chunk: pairs listed
  std::size_t longest_chunk_ = 0;                   // the most pairs a chunk has listed
};

extern template class ClusterPairs<2, float>;
extern template class ClusterPairs<2, double>;
extern template class ClusterPairs<3, float>;
extern template class ClusterPairs<3, double>;

}  // namespace sph
