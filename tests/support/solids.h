#pragma once
// How deep a simulation's particles are inside its obstacles, where the obstacles are now (their
// poses: a prescribed motion's at the simulation's time, a floating body's from its state).

#include <algorithm>
#include <vector>

#include <sph/solver/simulation.h>

namespace sph::test {

/// The deepest any particle's centre is inside any obstacle (a box or a shape), measured in the
/// obstacle's own frame (m; negative: all outside, by at least that much).
template <int D, std::floating_point R>
double deepest_inside(const Simulation<D, R>& sim) {
  const SimulationParams<D>& p = sim.params();
  const std::vector<RigidPose<D>> poses = sim.obstacle_poses();
  double deepest = -1e300;
  for (std::size_t k = 0; k < p.obstacles.size(); ++k)
    for (const auto& xr : sim.particles().position) {
      const Vec<D, double> X = poses[k].to_rest(vec_cast<double>(xr));
      // (a box's or a shape's signed distance, exact inside the solid)
      deepest = std::max(deepest, -obstacle_distance(p, k, X, 0.0).distance);
    }
  return deepest;
}

}  // namespace sph::test
