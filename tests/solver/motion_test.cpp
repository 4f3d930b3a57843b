// Prescribed motion of obstacles (motion.h): each motion's pose and velocity at a time, against
// finite differences of the pose and against the values written out by hand; the penalty walls
// of a moving obstacle push where the obstacle is and damp the velocity relative to it.

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include <sph/solver/motion.h>
#include <sph/solver/wcsph.h>

namespace sph {
namespace {

constexpr double kPi = std::numbers::pi;

/// The velocity of the solid point that is at x at time t, by central differences of place().
template <int D>
Vec<D, double> finite_difference_velocity(const ObstacleMotion<D>& m, const Vec<D, double>& x, double t) {
  const double e = 1e-6;
  const Vec<D, double> X = pose_at(m, t).to_rest(x);
  return (pose_at(m, t + e).place(X) - pose_at(m, t - e).place(X)) * (1 / (2 * e));
}

template <int D>
void expect_near(const Vec<D, double>& a, const Vec<D, double>& b, double tol) {
  for (int d = 0; d < D; ++d) EXPECT_NEAR(a[d], b[d], tol) << "component " << d;
}

TEST(Motion, OscillationStartsAtRestAndMovesAlongItsDirection) {
  ObstacleMotion<2> m;
  m.type = MotionType::Oscillation;
  m.direction = {{0.6, 0.8}};
  m.amplitude = 0.05;
  m.period = 2.0;
  m.phase = 0.3;
  // At t = 0 the box is where the scene puts it, whatever the phase.
  expect_near<2>(pose_at(m, 0.0).translation, {}, 1e-15);
  const double t = 0.7;
  const double s = 0.05 * (std::sin(kPi * t + 0.3) - std::sin(0.3));
  expect_near<2>(pose_at(m, t).translation, {{0.6 * s, 0.8 * s}}, 1e-15);
  // The velocity field is the pose's derivative, everywhere on the body.
  for (const Vec<2, double> x : {Vec<2, double>{{0.1, 0.2}}, Vec<2, double>{{-3, 5}}})
    for (const double tt : {0.1, 0.7, 1.9})
      expect_near<2>(pose_at(m, tt).velocity_at(x), finite_difference_velocity(m, x, tt), 1e-8);
}

TEST(Motion, TheRampStartsTheMotionWithoutAJumpInVelocity) {
  ObstacleMotion<2> m;
  m.type = MotionType::Oscillation;
  m.direction = {{1, 0}};
  m.amplitude = 0.1;
  m.period = 1.0;
  m.ramp_time = 2.0;
  EXPECT_EQ(norm2(pose_at(m, 0.0).velocity), 0.0);
  // At 1.25 s of a 2 s ramp: 0.625 of the amplitude.
  EXPECT_NEAR(pose_at(m, 1.25).translation[0], 0.625 * 0.1 * std::sin(2 * kPi * 1.25), 1e-15);
  for (const double t : {0.3, 1.0, 1.999, 2.5}) {
    const Vec<2, double> x{{0.2, 0.1}};
    expect_near<2>(pose_at(m, t).velocity_at(x), finite_difference_velocity(m, x, t), 1e-7);
  }
  // Rotation: the angular velocity ramps, the angle is its integral.
  ObstacleMotion<2> r;
  r.type = MotionType::Rotation;
  r.center = {{1, 1}};
  r.angular_velocity = 4.0;
  r.ramp_time = 0.5;
  EXPECT_NEAR(pose_at(r, 0.25).angular_velocity[2], 2.0, 1e-15);
  const Vec<2, double> X{{2, 1}};           // one metre from the centre along x
  const double angle = 4.0 * (1.0 - 0.25);  // after the ramp: w (t - ramp / 2)
  expect_near<2>(pose_at(r, 1.0).place(X), {{1 + std::cos(angle), 1 + std::sin(angle)}}, 1e-14);
  for (const double t : {0.1, 0.45, 1.0}) {  // (not at 0.5: the differences straddle the ramp's kink)
    const Vec<2, double> x = pose_at(r, t).place(X);
    expect_near<2>(pose_at(r, t).velocity_at(x), finite_difference_velocity(r, x, t), 1e-7);
  }
}

TEST(Motion, ARotationIn3DTurnsAboutItsAxisThroughItsCentre) {
  ObstacleMotion<3> m;
  m.type = MotionType::Rotation;
  m.axis = {{0, 1, 0}};
  m.center = {{0.3, 0.2, 0.3}};
  m.angular_velocity = kPi / 2;  // a quarter turn per second
  const RigidPose<3> p = pose_at(m, 1.0);
  // About +y, a quarter turn takes +x to -z (right-hand rule); points on the axis stay.
  expect_near<3>(p.place({{0.4, 0.2, 0.3}}), {{0.3, 0.2, 0.2}}, 1e-15);
  expect_near<3>(p.place({{0.3, 0.9, 0.3}}), {{0.3, 0.9, 0.3}}, 1e-15);
  const Vec<3, double> x{{0.35, 0.1, 0.45}};
  expect_near<3>(p.to_rest(p.place(x)), x, 1e-15);
  expect_near<3>(p.velocity_at(x), finite_difference_velocity(m, x, 1.0), 1e-8);
  // The fastest point of a box is a corner, at w times its distance from the axis.
  EXPECT_NEAR(max_surface_speed<3>(m, {{0.2, 0.1, 0.2}}, {{0.4, 0.3, 0.4}}, 1.0), kPi / 2 * std::sqrt(0.02), 1e-12);
  // An oblique axis: the rotation matrix stays orthonormal.
  m.axis = {{0.48, 0.6, 0.64}};
  const RigidPose<3> q = pose_at(m, 0.37);
  const Vec<3, double> a{{1, -2, 0.5}};
  EXPECT_NEAR(norm2(q.rotate(a)), norm2(a), 1e-13);
  expect_near<3>(q.rotate(m.axis), m.axis, 1e-15);
  expect_near<3>(q.velocity_at(x), finite_difference_velocity(m, x, 0.37), 1e-8);
}

TEST(Motion, KeyframesInterpolateLinearlyAndHoldTheirEnds) {
  ObstacleMotion<2> m;
  m.type = MotionType::Keyframes;
  m.center = {{0, 0}};
  m.keys = {{0.5, {}, 0.0}, {1.5, {{0.2, 0.1}}, kPi / 2}, {2.0, {{0.2, -0.1}}, kPi / 2}};
  expect_near<2>(pose_at(m, 0.2).translation, {}, 0);  // before the first key: at rest
  EXPECT_EQ(norm2(pose_at(m, 0.2).velocity), 0.0);
  // The first key's own time starts the first segment (a step that starts there sees the speed).
  expect_near<2>(pose_at(m, 0.5).velocity, {{0.2, 0.1}}, 1e-15);
  const RigidPose<2> p = pose_at(m, 1.0);  // halfway between the first two keys
  expect_near<2>(p.translation, {{0.1, 0.05}}, 1e-15);
  expect_near<2>(p.velocity, {{0.2, 0.1}}, 1e-15);
  EXPECT_NEAR(p.angular_velocity[2], kPi / 2, 1e-15);
  expect_near<2>(p.place({{1, 0}}), {{0.1 + std::cos(kPi / 4), 0.05 + std::sin(kPi / 4)}}, 1e-15);
  // A key's own time starts its segment; after the last key the pose holds, at rest.
  expect_near<2>(pose_at(m, 1.5).velocity, {{0, -0.4}}, 1e-15);
  expect_near<2>(pose_at(m, 3.0).translation, {{0.2, -0.1}}, 0);
  EXPECT_EQ(norm2(pose_at(m, 3.0).velocity), 0.0);
  EXPECT_EQ(pose_at(m, 3.0).angular_velocity[2], 0.0);
}

TEST(Motion, OnlyAMotionThatLeavesTheRestPoseMoves) {
  ObstacleMotion<3> m;
  EXPECT_FALSE(m.moves());
  m.type = MotionType::Rotation;
  EXPECT_FALSE(m.moves());  // no angular velocity
  m.angular_velocity = 1e-3;
  EXPECT_TRUE(m.moves());
  m.type = MotionType::Keyframes;
  m.keys = {{0.5, {}, 0.0}};
  EXPECT_FALSE(m.moves());  // one key: the rest pose throughout
  m.keys.push_back({1.0, {{0, 0, 0.1}}, 0.0});
  EXPECT_TRUE(m.moves());
  m.type = MotionType::Oscillation;
  EXPECT_TRUE(m.moves());
}

TEST(Motion, PenaltyWallsOfAMovingBoxPushWhereItIsAndDampRelativeToIt) {
  const Box<2> container{{{0, 0}}, {{1, 1}}};
  const std::vector<Box<2>> obstacles{{{{0.4, 0.4}}, {{0.6, 0.6}}}};
  WallParams walls;
  walls.stiffness = 1e4;
  walls.damping = 10;
  const double r = 0.01;
  ObstacleMotion<2> m;
  m.type = MotionType::Keyframes;
  m.keys = {{0, {}, 0}, {1, {{0.1, 0}}, 0}};
  const std::vector<RigidPose<2>> poses{pose_at(m, 0.5)};  // moved 0.05 along +x, at 0.1 m/s
  const std::vector<std::uint8_t> moving{1};
  const WallContact<2, double> moved(container, obstacles, r, walls, true, poses, moving);
  const WallContact<2, double> still(container, obstacles, r, walls);
  // Just right of where the box's right face now is (0.65): pushed out along +x by the spring,
  // less the damping of its velocity relative to the face's.
  const Vec<2, double> x{{0.65 + 0.5 * r, 0.5}};
  const Vec<2, double> v{{0.05, 0.0}};
  const Vec<2, double> a = moved(x, v);
  EXPECT_NEAR(a[0], 1e4 * 0.5 * r - 10 * (0.05 - 0.1), 1e-9);
  EXPECT_EQ(a[1], 0.0);
  EXPECT_EQ(norm2(still(x, v)), 0.0);  // (the box at rest is 0.05 m away)
  // Where the box was, nothing pushes any more.
  EXPECT_EQ(norm2(moved({{0.4 - 0.5 * r, 0.5}}, v)), 0.0);
}

}  // namespace
}  // namespace sph
