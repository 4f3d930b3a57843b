#include <sph/surface/solid_cut.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <fmt/format.h>

#include <sph/core/error.h>
#include <sph/solver/rigid_body.h>

namespace sph {

template <int D>
RigidPose<D> obstacle_pose_at(const SimulationParams<D>& sim, std::size_t k, double time,
                              std::span<const BodyPoseRow> bodies) {
  SPH_CHECK(k < sim.obstacles.size(), "no such obstacle");
  if (!obstacle_body(sim, k).dynamic) return pose_at(obstacle_motion(sim, k), time);
  if (bodies.empty()) return RigidPose<D>{};  // (no table: where it started)
  const BodyPoseRow* nearest = nullptr;
  for (const BodyPoseRow& r : bodies)
    if (r.obstacle == k && (!nearest || std::abs(r.time - time) < std::abs(nearest->time - time))) nearest = &r;
  // bodies.csv has a row for each body at each frame's time: none there means the table lost rows
  // (open_run_directory refuses a floating run's directory without one), and a neighbouring
  // frame's pose would put the body where it was not.
  if (!nearest || std::abs(nearest->time - time) > 1e-9 * std::max(1.0, std::abs(time)))
    throw Error(fmt::format("has no row of obstacle {} (a floating body) at t = {} s, the time of a frame; expected "
                            "the table sph run wrote with the frames (the run directory is incomplete)",
                            k, time),
                "bodies.csv");
  RigidBodyState<D> state;
  for (int a = 0; a < D; ++a) state.position[a] = nearest->position[static_cast<std::size_t>(a)];
  state.orientation = nearest->orientation;
  // (placed about its centre of mass at rest, as the simulation places it)
  return body_pose(state, obstacle_mass_properties(sim, k, 1.0).center);
}

template <int D>
SolidDistance obstacles_distance(const SimulationParams<D>& sim, std::vector<RigidPose<D>> poses) {
  if (sim.obstacles.empty()) return {};
  SPH_CHECK(poses.size() == sim.obstacles.size(), "one pose per obstacle");
  return [&sim, poses = std::move(poses)](const std::array<double, 3>& x, double reach) {
    Vec<D, double> p;
    for (int a = 0; a < D; ++a) p[a] = x[static_cast<std::size_t>(a)];
    double d = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < poses.size(); ++k)
      d = std::min(d, obstacle_distance(sim, k, poses[k].to_rest(p), reach).distance);
    return d;
  };
}

SolidDistance run_obstacles_distance(const RunDirectory& run, double time) {
  return run.scene.visit_body([&](const auto& body) {
    const auto& sim = body.sim;
    using Pose = std::decay_t<decltype(obstacle_pose_at(sim, 0, time, run.bodies))>;
    std::vector<Pose> poses;
    for (std::size_t k = 0; k < sim.obstacles.size(); ++k) poses.push_back(obstacle_pose_at(sim, k, time, run.bodies));
    return obstacles_distance(sim, std::move(poses));
  });
}

template RigidPose<2> obstacle_pose_at<2>(const SimulationParams<2>&, std::size_t, double,
                                          std::span<const BodyPoseRow>);
template RigidPose<3> obstacle_pose_at<3>(const SimulationParams<3>&, std::size_t, double,
                                          std::span<const BodyPoseRow>);
template SolidDistance obstacles_distance<2>(const SimulationParams<2>&, std::vector<RigidPose<2>>);
template SolidDistance obstacles_distance<3>(const SimulationParams<3>&, std::vector<RigidPose<3>>);

}  // namespace sph
