#pragma once
/// \file Prescribed motion of obstacles (`Obstacles[].motion`, docs/scene-format.md and
/// docs/physics.md "Moving obstacles"): a wave paddle's oscillation, a stirrer's rotation, or
/// keyframes. A motion is a function of time only: an obstacle's pose at time t is the same
/// however the run got there (resumed, any thread count), so it needs no state of its own.
///
/// A pose places a point X of the obstacle at rest (the scene's `start` .. `end` box) at
///   x = c + t + R (X - c)
/// with c the motion's centre, t the translation and R the rotation; the velocity of the solid at
/// a placed point x is u + w x (x - c - t) (u = dt/dt, w the angular velocity).

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <sph/core/vec.h>

namespace sph {

/// What moves an obstacle.
enum class MotionType {
  None,  ///< at rest
  /// translation a(t) (sin(2 pi t / period + phase) - sin(phase)) along a direction (a piston wave
  /// paddle; at t = 0 at rest where the scene puts it)
  Oscillation,
  Rotation,   ///< rotation at a constant angular velocity about an axis through a centre (a stirrer)
  Keyframes,  ///< translation and rotation interpolated linearly between timed keys
};

/// One key of MotionType::Keyframes: at `time` the obstacle is translated by `translation` and
/// turned by `rotation` radians about the motion's axis through its centre.
template <int D>
struct MotionKey {
  double time = 0;               ///< s
  Vec<D, double> translation{};  ///< m
  double rotation = 0;           ///< rad, counter-clockwise about the axis (right-hand rule)

  friend bool operator==(const MotionKey&, const MotionKey&) = default;
};

/// An obstacle's prescribed motion.
template <int D>
struct ObstacleMotion {
  MotionType type = MotionType::None;
  // Oscillation: displacement amplitude r(t) (sin(2 pi t / period + phase) - sin(phase)) along
  // `direction` (unit), r the ramp below.
  Vec<D, double> direction{};
  double amplitude = 0;  ///< m
  double period = 0;     ///< s
  double phase = 0;      ///< rad
  // Rotation and keyframes: about `axis` (unit; 2D: the z axis) through `center` (m, at rest).
  Vec<3, double> axis{0, 0, 1};
  Vec<D, double> center{};
  double angular_velocity = 0;     ///< rad/s (rotation)
  std::vector<MotionKey<D>> keys;  ///< keyframes, times strictly increasing
  /// Oscillation and rotation: the amplitude (the angular velocity) grows linearly from 0 over
  /// the first ramp_time seconds, so that the motion starts without a jump in velocity; 0 starts
  /// at full amplitude.
  double ramp_time = 0;

  /// Whether the obstacle ever leaves its place at rest: not for MotionType::None, a rotation at
  /// no speed, or keyframes with one key (which the reader requires to be the rest pose).
  bool moves() const {
    return type == MotionType::Oscillation || (type == MotionType::Rotation && angular_velocity != 0) ||
           (type == MotionType::Keyframes && keys.size() > 1);
  }
  friend bool operator==(const ObstacleMotion&, const ObstacleMotion&) = default;
};

/// A rigid placement of an obstacle (see the file comment) and its velocity field.
template <int D>
struct RigidPose {
  std::array<double, 9> rotation{1, 0, 0, 0, 1, 0, 0, 0, 1};  ///< R, row-major 3 x 3 (2D: its upper-left 2 x 2)
  Vec<D, double> center{};                                    ///< c, m
  Vec<D, double> translation{};                               ///< t, m
  Vec<D, double> velocity{};                                  ///< u = dt/dt, m/s
  Vec<3, double> angular_velocity{};                          ///< w, rad/s (2D: z only)

  /// R v (directions and normals).
  Vec<D, double> rotate(const Vec<D, double>& v) const {
    Vec<D, double> r{};
    for (int a = 0; a < D; ++a)
      for (int b = 0; b < D; ++b) r[a] += rotation[static_cast<std::size_t>(3 * a + b)] * v[b];
    return r;
  }
  /// R^T v.
  Vec<D, double> unrotate(const Vec<D, double>& v) const {
    Vec<D, double> r{};
    for (int a = 0; a < D; ++a)
      for (int b = 0; b < D; ++b) r[a] += rotation[static_cast<std::size_t>(3 * b + a)] * v[b];
    return r;
  }
  /// x = c + t + R (X - c): where the point X of the obstacle at rest is.
  Vec<D, double> place(const Vec<D, double>& X) const { return center + translation + rotate(X - center); }
  /// X = c + R^T (x - c - t): the point at rest that is now at x.
  Vec<D, double> to_rest(const Vec<D, double>& x) const { return center + unrotate(x - center - translation); }
  /// The solid's velocity at the placed point x: u + w x (x - c - t).
  Vec<D, double> velocity_at(const Vec<D, double>& x) const {
    const Vec<D, double> r = x - center - translation;
    Vec<D, double> v = velocity;
    if constexpr (D == 2) {
      v[0] -= angular_velocity[2] * r[1];
      v[1] += angular_velocity[2] * r[0];
    } else {
      v[0] += angular_velocity[1] * r[2] - angular_velocity[2] * r[1];
      v[1] += angular_velocity[2] * r[0] - angular_velocity[0] * r[2];
      v[2] += angular_velocity[0] * r[1] - angular_velocity[1] * r[0];
    }
    return v;
  }
};

/// A floating rigid body (Obstacles[].dynamic, rigid_body.h): an obstacle moved by the fluid's
/// pressure and friction, gravity and contact with the container, instead of a prescribed motion.
template <int D>
struct BodyParams {
  bool dynamic = false;
  double density = 0;                 ///< kg/m^3 (2D: kg/m^2, as Fluid.density)
  Vec<D, double> velocity{};          ///< at t = 0, m/s
  Vec<3, double> angular_velocity{};  ///< at t = 0, rad/s (2D: z only)

  friend bool operator==(const BodyParams&, const BodyParams&) = default;
};

/// Corner c (0 .. 2^D - 1) of the box [lo, hi]: bit d of c chooses hi along axis d.
template <int D>
Vec<D, double> box_corner(const Vec<D, double>& lo, const Vec<D, double>& hi, int c) {
  Vec<D, double> x;
  for (int d = 0; d < D; ++d) x[d] = c >> d & 1 ? hi[d] : lo[d];
  return x;
}

/// The largest speed of the box [lo, hi] (at rest) placed by `pose`: the largest of its corners'
/// (a rigid motion's speed is convex in the point).
template <int D>
double pose_surface_speed(const RigidPose<D>& pose, const Vec<D, double>& lo, const Vec<D, double>& hi) {
  double most = 0;
  for (int c = 0; c < (1 << D); ++c) {
    const Vec<D, double> v = pose.velocity_at(pose.place(box_corner<D>(lo, hi, c)));
    most = std::max(most, std::sqrt(norm2(v)));
  }
  return most;
}

/// The pose of an obstacle moved by `m` at time t (s): the identity for MotionType::None;
/// keyframes hold their first key before it and their last after it.
template <int D>
RigidPose<D> pose_at(const ObstacleMotion<D>& m, double t);

/// The largest speed of the solid box [lo, hi] moved by `m` at time t: the largest of its
/// corners' (a rigid motion's speed is convex in the point).
template <int D>
double max_surface_speed(const ObstacleMotion<D>& m, const Vec<D, double>& lo, const Vec<D, double>& hi, double t);

extern template RigidPose<2> pose_at<2>(const ObstacleMotion<2>&, double);
extern template RigidPose<3> pose_at<3>(const ObstacleMotion<3>&, double);
extern template double max_surface_speed<2>(const ObstacleMotion<2>&, const Vec<2, double>&, const Vec<2, double>&,
                                            double);
extern template double max_surface_speed<3>(const ObstacleMotion<3>&, const Vec<3, double>&, const Vec<3, double>&,
                                            double);

}  // namespace sph
