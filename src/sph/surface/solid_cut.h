#pragma once
/// \file The obstacles a surface is cut by (SurfaceSettings::solids): a run's obstacles placed
/// where they are at a frame's time, as a signed distance.

#include <cstddef>
#include <span>
#include <vector>

#include <sph/io/run_directory.h>
#include <sph/solver/motion.h>
#include <sph/solver/params.h>
#include <sph/surface/surface.h>

namespace sph {

/// Obstacle k of `sim` at `time`: a prescribed motion's pose then, a floating body's where
/// `bodies` (a run's bodies.csv) has it at `time` (a frame's), where it started if `bodies` is
/// empty. Throws sph::Error naming bodies.csv if it has no row of a floating body at `time`.
template <int D>
RigidPose<D> obstacle_pose_at(const SimulationParams<D>& sim, std::size_t k, double time,
                              std::span<const BodyPoseRow> bodies);

/// The signed distance to the obstacles of `sim` placed by `poses` (one per obstacle), for
/// SurfaceSettings::solids: the least of obstacle_distance() over them, each at its pose. Empty
/// (no cut) for a scene without obstacles. The function refers to `sim`, which must outlive it.
template <int D>
SolidDistance obstacles_distance(const SimulationParams<D>& sim, std::vector<RigidPose<D>> poses);

/// obstacles_distance() of a run's obstacles at `time` (a frame's): where obstacle_pose_at()
/// puts them. The function refers to `run`, which must outlive it.
SolidDistance run_obstacles_distance(const RunDirectory& run, double time);

}  // namespace sph
