#pragma once
// How deep a simulation's particles are inside its obstacles, where the obstacles are now (their
// poses: a prescribed motion's at the simulation's time, a floating body's from its state).

#include <algorithm>
#include <vector>

#include <sph/solver/simulation.h>

namespace sph::test {

/// The deepest any particle's centre is inside any obstacle, measured in the obstacle's own frame
/// (m; negative: all outside).
template <int D, std::floating_point R>
double deepest_inside(const Simulation<D, R>& sim) {
  const SimulationParams<D>& p = sim.params();
  const std::vector<RigidPose<D>> poses = sim.obstacle_poses();
  double deepest = -1e300;
  for (std::size_t k = 0; k < p.obstacles.size(); ++k)
    for (const auto& xr : sim.particles().position) {
      const Vec<D, double> X = poses[k].to_rest(vec_cast<double>(xr));
      double depth = 1e300;
      for (int d = 0; d < D; ++d) depth = std::min({depth, X[d] - p.obstacles[k].lo[d], p.obstacles[k].hi[d] - X[d]});
      deepest = std::max(deepest, depth);
    }
  return deepest;
}

}  // namespace sph::test
