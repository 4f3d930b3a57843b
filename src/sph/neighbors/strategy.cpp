#include <sph/neighbors/strategy.h>

#include <sph/core/error.h>
#include <sph/neighbors/adaptive.h>
#include <sph/neighbors/standard.h>
#include <sph/neighbors/tracked.h>
#include <sph/neighbors/verlet.h>

namespace sph {

template <int D, std::floating_point R>
std::unique_ptr<NeighborStrategy<D, R>> make_neighbor_strategy(NeighborMode mode, const NeighborOptions& options) {
  const R radius = static_cast<R>(options.radius);
  switch (mode) {
    case NeighborMode::Standard:
      return std::make_unique<StandardNeighbors<D, R>>(radius);
    case NeighborMode::BruteForce:
      return std::make_unique<BruteForceNeighbors<D, R>>(radius);
    case NeighborMode::Adaptive:
      return std::make_unique<AdaptiveNeighbors<D, R>>(radius, options.full_rebuild_period);
    case NeighborMode::Verlet:
    case NeighborMode::VerletClusters: {
      const R skin =
          static_cast<R>(options.verlet_skin > 0 ? options.verlet_skin : kDefaultSkinFraction * options.radius);
      return std::make_unique<VerletNeighbors<D, R>>(radius, skin, mode == NeighborMode::VerletClusters);
    }
    case NeighborMode::Tracked:
    case NeighborMode::AdaptiveExact:
      return std::make_unique<TrackedNeighbors<D, R>>(radius, static_cast<R>(options.tracked_skin),
                                                      options.full_rebuild_period, static_cast<R>(options.time_step),
                                                      mode == NeighborMode::AdaptiveExact);
  }
  throw Error("unknown neighbor mode");
}

template std::unique_ptr<NeighborStrategy<2, float>> make_neighbor_strategy<2, float>(NeighborMode,
                                                                                      const NeighborOptions&);
template std::unique_ptr<NeighborStrategy<2, double>> make_neighbor_strategy<2, double>(NeighborMode,
                                                                                        const NeighborOptions&);
template std::unique_ptr<NeighborStrategy<3, float>> make_neighbor_strategy<3, float>(NeighborMode,
                                                                                      const NeighborOptions&);
template std::unique_ptr<NeighborStrategy<3, double>> make_neighbor_strategy<3, double>(NeighborMode,
                                                                                        const NeighborOptions&);

}  // namespace sph
