#pragma once
/// \file Floating rigid bodies (Obstacles[].dynamic; docs/physics.md "Floating bodies"): an
/// obstacle (a box, a polygon or a mesh) whose motion the fluid, gravity and the container decide
/// (two-way coupling).
///
/// A body is its solid at rest (the scene's box or shape) and a state: the centre of mass (the
/// solid is uniform), a unit quaternion for its orientation, and its linear and angular
/// velocities. Its pose (motion.h) places the box at rest where the state puts it:
///   x = c + (position - c) + R(q) (X - c),  c the centre at rest,
/// so every mechanism of the moving obstacles (wall contact in the body's frame, boundary samples
/// placed with their velocities, the health checks) serves the bodies unchanged.
///
/// Each step the fluid's reaction is gathered as impulses (BodyLoad): what the body's boundary
/// samples or its penalty walls gave each fluid particle, times its mass and the step, with the
/// opposite sign (so fluid and body exchange momentum exactly), and its moment about the centre of
/// mass taken at the particle (the pair forces are central, along x_i - x_b, so the moment is the
/// same as at the sample). Gravity and the container's contact with the box's corners are added,
/// and advance_body() takes a symplectic Euler step, as the fluid's: velocities first, then the
/// position and the orientation with the new velocities.

#include <algorithm>
#include <array>
#include <span>
#include <vector>

#include <sph/solver/params.h>

namespace sph {

/// A body's state (part of a checkpoint).
template <int D>
struct RigidBodyState {
  Vec<D, double> position{};                      ///< centre of mass, m
  std::array<double, 4> orientation{1, 0, 0, 0};  ///< unit quaternion (w, x, y, z); 2D: about z only
  Vec<D, double> velocity{};                      ///< of the centre of mass, m/s
  Vec<3, double> angular_velocity{};              ///< rad/s, world frame (2D: z only)

  friend bool operator==(const RigidBodyState&, const RigidBodyState&) = default;
};

/// A uniform body's mass, kg (2D: kg/m), its centre of mass at rest, and its principal moments of
/// inertia about it, kg m^2 (2D: only z counts), along its principal axes: the columns of `axes`
/// (a rotation, row-major, in the frame at rest; a box's own axes, the identity).
template <int D>
struct MassProperties {
  double mass = 0;
  Vec<3, double> inertia{};
  Vec<D, double> center{};  ///< the centre of mass at rest, m
  std::array<double, 9> axes{1, 0, 0, 0, 1, 0, 0, 0, 1};
};

template <int D>
MassProperties<D> box_mass_properties(const Box<D>& box, double density);

/// A uniform solid bounded by a shape's closed surface (shape.h; not inverted): its volume's
/// mass, centre and inertia, summed exactly over the tetrahedra (3D; triangles in 2D) that its faces
/// make with the origin (Mirtich 1996's divergence-theorem integrals, in the covariance form), and
/// the inertia tensor's principal axes (Jacobi rotations).
template <int D>
MassProperties<D> shape_mass_properties(const ObstacleShape<D>& shape, double density);

/// Obstacle k's mass properties at `density`: its shape's, or its box's.
template <int D>
MassProperties<D> obstacle_mass_properties(const SimulationParams<D>& p, std::size_t k, double density) {
  const ObstacleShape<D>* shape = obstacle_shape(p, k);
  return shape ? shape_mass_properties(*shape, density) : box_mass_properties(p.obstacles[k], density);
}

/// The rotation from a body's principal axes to the world's: R(q) times `mp.axes`.
template <int D>
std::array<double, 9> principal_frame(const RigidBodyState<D>& s, const MassProperties<D>& mp);

/// The inverse of the body's inertia tensor in the world's frame, R I^-1 R^T (row-major 3 x 3; R
/// its principal_frame). 2D: only the z row and column are set (a 2D body turns about z only).
template <int D>
std::array<double, 9> world_inverse_inertia(const RigidBodyState<D>& s, const MassProperties<D>& mp);

/// The state at t = 0: the body where the scene puts it (its centre of mass at `center`), at its
/// initial velocities.
template <int D>
RigidBodyState<D> initial_body_state(const Vec<D, double>& center, const BodyParams<D>& params);

/// The pose (motion.h) the state gives the box whose centre at rest is `center`.
template <int D>
RigidPose<D> body_pose(const RigidBodyState<D>& s, const Vec<D, double>& center);

/// What acts on a body over one step: an impulse, N s (2D: N s / m), and an angular impulse about
/// its centre of mass, N m s (2D: z only).
template <int D>
struct BodyLoad {
  Vec<D, double> impulse{};
  Vec<3, double> angular_impulse{};
};

/// Calls f(x) for each point of a body that meets the container, placed by `pose`: its box's
/// corners, or its shape's vertices.
template <int D, class F>
void for_each_contact_point(const Box<D>& box, const ObstacleShape<D>* shape, const RigidPose<D>& pose, F&& f) {
  if (shape) {
    for (const Vec<D, double>& v : shape->vertices) f(pose.place(v));
    return;
  }
  for (int c = 0; c < (1 << D); ++c) f(pose.place(box_corner<D>(box.lo, box.hi, c)));
}

/// The container's contact with a body: each corner of the box (each vertex of its shape) past a
/// wall is pushed back by a damped spring, k pen - c v_n along the wall's normal (never pulling),
/// with k = m w^2 and c = m w (a damping ratio of 1/2 for one corner, so that four corners at once
/// stay stable): `omega` (w) is body_contact_rate(). Adds the impulses of a step of dt to `load`.
template <int D>
void add_container_contact(const Box<D>& container, const Box<D>& box, const RigidBodyState<D>& s,
                           const MassProperties<D>& mp, double omega, double dt, BodyLoad<D>& load,
                           const ObstacleShape<D>* shape = nullptr);

/// How far the body's deepest corner (its shape's deepest vertex) is past the container's walls,
/// m (0: none), with the index of the wall's axis (-1: none) and whether it is the high wall.
struct WallDepth {
  double depth = 0;
  int axis = -1;
  bool high = false;
};
template <int D>
WallDepth container_depth(const Box<D>& container, const Box<D>& box, const RigidBodyState<D>& s,
                          const MassProperties<D>& mp, const ObstacleShape<D>* shape = nullptr);

/// The energy of those springs, J (2D: J/m): 1/2 k pen^2 summed over the points and walls.
template <int D>
double container_contact_energy(const Box<D>& container, const Box<D>& box, const RigidBodyState<D>& s,
                                const MassProperties<D>& mp, double omega, const ObstacleShape<D>* shape = nullptr);

/// A box another body's corners can meet (add_body_contact): the box at rest, its pose now, and
/// its mass, kg (0: it does not give way: a resting or prescribed-motion obstacle).
template <int D>
struct ContactBox {
  Box<D> box;
  RigidPose<D> pose;
  double mass = 0;
  /// An obstacle's shape when it is not its box (shape.h): its vertices meet the other's faces,
  /// and the other's corners meet its surface.
  const ObstacleShape<D>* shape = nullptr;
};

/// The contact of two boxes, a floating body `a` and a box `b` (another body, or an obstacle that
/// does not give way): each corner of either inside the other is pushed out through the nearest
/// face of the other (in its frame), by a damped spring k pen - c v_n along that face's normal
/// (never pulling), v_n the corner's velocity relative to the other box's surface there, k = m
/// w^2 and c = m w with m the pair's reduced mass (a's own against an obstacle). A shape takes part
/// with its vertices for corners and its surface (signed distance and normal) for faces. The impulses over
/// dt and their moments about each body's centre of mass (the pose's c + t) are added to `load_a`
/// and, opposite, to `load_b` (null: `b` takes nothing). Corners against faces only: in 3D two
/// boxes meeting edge to edge with no corner inside the other pass through each other there.
template <int D>
void add_body_contact(const ContactBox<D>& a, const ContactBox<D>& b, double omega, double dt, BodyLoad<D>& load_a,
                      BodyLoad<D>* load_b);

/// The contact's angular rate w, 1/s, for steps of at most `max_dt`: a contact oscillation takes 20
/// of the longest steps (w dt <= pi / 10, stable for symplectic Euler with room to spare), so a
/// body resting on the floor sinks g / w^2 into it (about a millimetre for 5 ms steps).
double body_contact_rate(double max_dt);
/// The step body_contact_rate() is given for a scene: its longest, cflMaxTimeStepSize with CFL
/// steps (timeStepSize if that is longer), else timeStepSize, s.
template <int D>
double body_contact_step(const SimulationParams<D>& p) {
  return p.time_stepping == TimeStepping::Cfl ? std::max(p.time_step, p.cfl.max_dt) : p.time_step;
}

/// One symplectic Euler step of dt: v += impulse / m + g dt; w += I^-1 (angular impulse - dt w x I
/// w) (I in the world's frame); then x += dt v and q += dt / 2 (0, w) q, normalized.
template <int D>
void advance_body(RigidBodyState<D>& s, const MassProperties<D>& mp, const BodyLoad<D>& load,
                  const Vec<D, double>& gravity, double dt);
/// The velocities' half of advance_body: v and w as it changes them, x and q left.
template <int D>
void advance_velocities(RigidBodyState<D>& s, const MassProperties<D>& mp, const BodyLoad<D>& load,
                        const Vec<D, double>& gravity, double dt);

/// The rotation matrix of a unit quaternion (row-major 3 x 3).
std::array<double, 9> quaternion_matrix(const std::array<double, 4>& q);

/// Adds m (x - c) x f to `moment` (2D: its z component), the moment about c of f at x.
template <int D, class T>
void add_moment(Vec<3, T>& moment, const Vec<D, T>& x, const Vec<D, T>& c, const Vec<D, T>& f) {
  const Vec<D, T> r = x - c;
  if constexpr (D == 2) {
    moment[2] += r[0] * f[1] - r[1] * f[0];
  } else {
    moment[0] += r[1] * f[2] - r[2] * f[1];
    moment[1] += r[2] * f[0] - r[0] * f[2];
    moment[2] += r[0] * f[1] - r[1] * f[0];
  }
}

extern template MassProperties<2> box_mass_properties<2>(const Box<2>&, double);
extern template MassProperties<3> box_mass_properties<3>(const Box<3>&, double);
extern template RigidBodyState<2> initial_body_state<2>(const Vec<2, double>&, const BodyParams<2>&);
extern template RigidBodyState<3> initial_body_state<3>(const Vec<3, double>&, const BodyParams<3>&);
extern template MassProperties<2> shape_mass_properties<2>(const ObstacleShape<2>&, double);
extern template MassProperties<3> shape_mass_properties<3>(const ObstacleShape<3>&, double);
extern template std::array<double, 9> principal_frame<2>(const RigidBodyState<2>&, const MassProperties<2>&);
extern template std::array<double, 9> principal_frame<3>(const RigidBodyState<3>&, const MassProperties<3>&);
extern template std::array<double, 9> world_inverse_inertia<2>(const RigidBodyState<2>&, const MassProperties<2>&);
extern template std::array<double, 9> world_inverse_inertia<3>(const RigidBodyState<3>&, const MassProperties<3>&);
extern template double container_contact_energy<2>(const Box<2>&, const Box<2>&, const RigidBodyState<2>&,
                                                   const MassProperties<2>&, double, const ObstacleShape<2>*);
extern template double container_contact_energy<3>(const Box<3>&, const Box<3>&, const RigidBodyState<3>&,
                                                   const MassProperties<3>&, double, const ObstacleShape<3>*);
extern template RigidPose<2> body_pose<2>(const RigidBodyState<2>&, const Vec<2, double>&);
extern template RigidPose<3> body_pose<3>(const RigidBodyState<3>&, const Vec<3, double>&);
extern template void add_container_contact<2>(const Box<2>&, const Box<2>&, const RigidBodyState<2>&,
                                              const MassProperties<2>&, double, double, BodyLoad<2>&,
                                              const ObstacleShape<2>*);
extern template void add_container_contact<3>(const Box<3>&, const Box<3>&, const RigidBodyState<3>&,
                                              const MassProperties<3>&, double, double, BodyLoad<3>&,
                                              const ObstacleShape<3>*);
extern template void add_body_contact<2>(const ContactBox<2>&, const ContactBox<2>&, double, double, BodyLoad<2>&,
                                         BodyLoad<2>*);
extern template void add_body_contact<3>(const ContactBox<3>&, const ContactBox<3>&, double, double, BodyLoad<3>&,
                                         BodyLoad<3>*);
extern template void advance_body<2>(RigidBodyState<2>&, const MassProperties<2>&, const BodyLoad<2>&,
                                     const Vec<2, double>&, double);
extern template void advance_body<3>(RigidBodyState<3>&, const MassProperties<3>&, const BodyLoad<3>&,
                                     const Vec<3, double>&, double);
extern template void advance_velocities<2>(RigidBodyState<2>&, const MassProperties<2>&, const BodyLoad<2>&,
                                           const Vec<2, double>&, double);
extern template void advance_velocities<3>(RigidBodyState<3>&, const MassProperties<3>&, const BodyLoad<3>&,
                                           const Vec<3, double>&, double);

}  // namespace sph
