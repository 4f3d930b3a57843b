// The floating bodies' rigid dynamics (rigid_body.h): a box's mass and inertia, the pose a state
// gives, the integrator (free flight, a torque-free spin, the quaternion's length) and the
// container's contact.

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include <sph/solver/rigid_body.h>

namespace sph {
namespace {

/// A box's centre (a uniform box's centre of mass).
template <int D>
Vec<D, double> center_of(const Box<D>& b) {
  return (b.lo + b.hi) * 0.5;
}

TEST(RigidBody, ABoxsMassAndMomentsAreAUniformBoxs) {
  const MassProperties<3> m3 = box_mass_properties<3>(Box<3>{{{0, 0, 0}}, {{1, 2, 3}}}, 500);
  EXPECT_DOUBLE_EQ(m3.mass, 3000);
  EXPECT_DOUBLE_EQ(m3.inertia[0], 3000 * (4 + 9) / 12.0);
  EXPECT_DOUBLE_EQ(m3.inertia[1], 3000 * (1 + 9) / 12.0);
  EXPECT_DOUBLE_EQ(m3.inertia[2], 3000 * (1 + 4) / 12.0);
  EXPECT_EQ(m3.center, (Vec<3, double>{{0.5, 1, 1.5}}));
  const MassProperties<2> m2 = box_mass_properties<2>(Box<2>{{{0, 0}}, {{0.4, 0.2}}}, 500);
  EXPECT_DOUBLE_EQ(m2.mass, 40);
  EXPECT_DOUBLE_EQ(m2.inertia[2], 40 * (0.16 + 0.04) / 12.0);
}

TEST(RigidBody, ThePoseMovesTheCentreAndTurnsAboutIt) {
  RigidBodyState<3> s;
  s.position = {{1, 2, 3}};
  const double h = std::sqrt(0.5);
  s.orientation = {h, 0, 0, h};  // a quarter turn about z
  s.velocity = {{0.5, 0, 0}};
  s.angular_velocity = {{0, 0, 2}};
  const Vec<3, double> c{{0, 0, 0}};
  const RigidPose<3> p = body_pose(s, c);
  const Vec<3, double> centre = p.place(c), tip = p.place(Vec<3, double>{{1, 0, 0}});
  EXPECT_NEAR(centre[0], 1, 1e-15);
  EXPECT_NEAR(tip[0], 1, 1e-15);  // (1, 0, 0) from the centre turned to (0, 1, 0)
  EXPECT_NEAR(tip[1], 3, 1e-15);
  EXPECT_NEAR(tip[2], 3, 1e-15);
  // Its velocity: u + w x r = (0.5, 0, 0) + (0, 0, 2) x (0, 1, 0) = (-1.5, 0, 0).
  const Vec<3, double> v = p.velocity_at(tip);
  EXPECT_NEAR(v[0], -1.5, 1e-15);
  EXPECT_NEAR(v[1], 0, 1e-15);
}

TEST(RigidBody, FreeFlightFallsAsAStoneAndAPlanarSpinTurnsExactly) {
  const Box<2> box{{{0, 0}}, {{0.4, 0.2}}};
  const MassProperties<2> mp = box_mass_properties<2>(box, 500);
  RigidBodyState<2> s =
      initial_body_state(center_of(box), BodyParams<2>{true, 500, {{1, 0}}, {{0, 0, std::numbers::pi}}});
  const double dt = 1e-3;
  for (int k = 0; k < 1000; ++k) advance_body(s, mp, BodyLoad<2>{}, Vec<2, double>{{0, -10}}, dt);
  // Symplectic Euler: y = y0 - g dt^2 n (n + 1) / 2 after n steps; x at its constant speed.
  EXPECT_NEAR(s.position[1], 0.1 - 10 * dt * dt * 1000 * 1001 / 2, 1e-12);
  EXPECT_NEAR(s.position[0], 0.2 + 1.0, 1e-12);
  // Half a turn a second for a second: the quaternion of a half turn about z.
  EXPECT_NEAR(std::abs(s.orientation[3]), 1.0, 1e-12);
  EXPECT_NEAR(s.angular_velocity[2], std::numbers::pi, 1e-15);
}

TEST(RigidBody, ATorqueFreeTopKeepsItsAngularMomentumAndEnergy) {
  // An asymmetric box spinning about a tilted axis: no torque, so L = I_w w in the world frame
  // and the energy w . L / 2 stay (to the explicit gyroscopic term's first-order error).
  const Box<3> box{{{0, 0, 0}}, {{0.1, 0.2, 0.3}}};
  const MassProperties<3> mp = box_mass_properties<3>(box, 800);
  RigidBodyState<3> s = initial_body_state(center_of(box), BodyParams<3>{true, 800, {}, {{1.0, 2.0, 0.5}}});
  const auto momentum = [&](const RigidBodyState<3>& st) {
    const std::array<double, 9> r = quaternion_matrix(st.orientation);
    Vec<3, double> b{}, l{};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) b[i] += r[static_cast<std::size_t>(3 * j + i)] * st.angular_velocity[j];
    for (int i = 0; i < 3; ++i) b[i] *= mp.inertia[i];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) l[i] += r[static_cast<std::size_t>(3 * i + j)] * b[j];
    return l;
  };
  const Vec<3, double> l0 = momentum(s);
  const double e0 = dot(s.angular_velocity, l0) / 2;
  for (int k = 0; k < 2000; ++k) advance_body(s, mp, BodyLoad<3>{}, Vec<3, double>{}, 5e-4);
  const Vec<3, double> l1 = momentum(s);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(l1[i], l0[i], 0.01 * std::sqrt(norm2(l0))) << i;
  EXPECT_NEAR(dot(s.angular_velocity, l1) / 2, e0, 0.01 * e0);
  const auto& q = s.orientation;
  EXPECT_NEAR(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3], 1.0, 1e-14);
  // And it did turn (the state is not stuck).
  EXPECT_LT(std::abs(q[0]), 0.99);
}

TEST(RigidBody, TheWorldInverseInertiaTurnsAnImpulseAsTheStepDoes) {
  // An asymmetric box turned to a general orientation: the step's change of w under an angular
  // impulse L (no spin, so no gyroscopic term) is world_inverse_inertia L, and I_w times it, with
  // I_w = R diag(I) R^T from the quaternion, gives L back.
  const Box<3> box{{{0, 0, 0}}, {{0.1, 0.2, 0.3}}};
  const MassProperties<3> mp = box_mass_properties<3>(box, 800);
  RigidBodyState<3> s = initial_body_state(center_of(box), BodyParams<3>{true, 800, {}, {{1.0, 2.0, 0.5}}});
  for (int k = 0; k < 700; ++k) advance_body(s, mp, BodyLoad<3>{}, Vec<3, double>{}, 1e-3);
  ASSERT_LT(std::abs(s.orientation[0]), 0.9);
  s.angular_velocity = {};
  BodyLoad<3> load;
  load.angular_impulse = {{0.3, -0.2, 0.5}};
  RigidBodyState<3> after = s;
  advance_velocities(after, mp, load, Vec<3, double>{}, 1e-3);
  const std::array<double, 9> inv = world_inverse_inertia(s, mp);
  const std::array<double, 9> r = quaternion_matrix(s.orientation);
  for (int a = 0; a < 3; ++a) {
    double w = 0, l = 0;
    for (int b = 0; b < 3; ++b) {
      w += inv[static_cast<std::size_t>(3 * a + b)] * load.angular_impulse[b];
      for (int k = 0; k < 3; ++k)  // (I_w dw)_a
        l += r[static_cast<std::size_t>(3 * a + k)] * mp.inertia[k] * r[static_cast<std::size_t>(3 * b + k)] *
             after.angular_velocity[b];
    }
    EXPECT_NEAR(after.angular_velocity[a], w, 1e-12 * std::sqrt(norm2(after.angular_velocity))) << a;
    EXPECT_NEAR(l, load.angular_impulse[a], 1e-12) << a;
  }
  // 2D: about z only.
  const MassProperties<2> flat = box_mass_properties<2>(Box<2>{{{0, 0}}, {{0.4, 0.2}}}, 500);
  const std::array<double, 9> inv2 = world_inverse_inertia(RigidBodyState<2>{}, flat);
  EXPECT_DOUBLE_EQ(inv2[8], 1 / flat.inertia[2]);
  for (int k = 0; k < 8; ++k) EXPECT_EQ(inv2[static_cast<std::size_t>(k)], 0) << k;
}

TEST(RigidBody, TheContainerHoldsARestingBoxAtItsSpringsSag) {
  // A box on the floor of a container, stepped at the contact's own longest step: it comes to
  // rest sunk by g / (n w^2), n = 2 corners on the floor in 2D.
  const Box<2> container{{{0, 0}}, {{1, 1}}};
  const Box<2> box{{{0.3, 0.0}}, {{0.7, 0.2}}};
  const MassProperties<2> mp = box_mass_properties<2>(box, 500);
  RigidBodyState<2> s = initial_body_state(center_of(box), BodyParams<2>{true, 500, {}, {}});
  const double dt = 0.005, w = body_contact_rate(dt);
  for (int k = 0; k < 400; ++k) {
    BodyLoad<2> load;
    add_container_contact(container, box, s, mp, w, dt, load);
    advance_body(s, mp, load, Vec<2, double>{{0, -9.81}}, dt);
  }
  EXPECT_NEAR(s.position[1] - 0.1, -9.81 / (2 * w * w), 1e-6);
  EXPECT_NEAR(s.velocity[1], 0, 1e-6);
  EXPECT_NEAR(s.orientation[3], 0, 1e-12);  // pushed evenly: it does not tip
  // container_depth (the health monitor's) reads the sag at the deepest corner, past the floor.
  const WallDepth sunk = container_depth(container, box, s, mp);
  EXPECT_NEAR(sunk.depth, 9.81 / (2 * w * w), 1e-6);
  EXPECT_EQ(sunk.axis, 1);
  EXPECT_FALSE(sunk.high);
  // Tilted by 0.1 rad about its centre and pushed 2 cm into the right wall (x = 1): its corner
  // there is deepest, by the tilt's share of the half-diagonal.
  RigidBodyState<2> tilted = initial_body_state(Vec<2, double>{{0.82, 0.5}}, BodyParams<2>{true, 500, {}, {}});
  tilted.orientation = {std::cos(0.05), 0, 0, std::sin(0.05)};
  const WallDepth right = container_depth(container, box, tilted, mp);
  const double reach = std::max(0.2 * std::cos(0.1) + 0.1 * std::sin(0.1), 0.2 * std::cos(0.1) - 0.1 * std::sin(0.1));
  EXPECT_NEAR(right.depth, 0.82 + reach - 1.0, 1e-12);
  EXPECT_EQ(right.axis, 0);
  EXPECT_TRUE(right.high);
  EXPECT_EQ(
      container_depth(container, box, initial_body_state(center_of(box), BodyParams<2>{true, 500, {}, {}}), mp).depth,
      0.0);
  // And a wall never pulls: a box just off the wall, moving away, gets nothing.
  s = initial_body_state(center_of(Box<2>{{{0.3, 0.01}}, {{0.7, 0.21}}}), BodyParams<2>{true, 500, {{0, 1}}, {}});
  BodyLoad<2> load;
  add_container_contact(container, box, s, mp, w, dt, load);
  EXPECT_EQ(load.impulse, (Vec<2, double>{}));
}

TEST(RigidBody, TwoBoxesInContactArePushedApartEquallyAndOppositely) {
  // a's right side overlaps b's left side by 1 cm, b turned a little: each is pushed out of the
  // other, the impulses are opposite, and so are the moments about a common point.
  const Box<2> box_a{{{0, 0}}, {{0.2, 0.1}}}, box_b{{{0.19, 0.02}}, {{0.39, 0.12}}};
  RigidBodyState<2> sa = initial_body_state(center_of(box_a), BodyParams<2>{true, 500, {{0.3, 0}}, {}});
  RigidBodyState<2> sb = initial_body_state(center_of(box_b), BodyParams<2>{true, 800, {{-0.1, 0}}, {}});
  const double turn = 0.05;
  sb.orientation = {std::cos(turn / 2), 0, 0, std::sin(turn / 2)};
  const MassProperties<2> ma = box_mass_properties<2>(box_a, 500), mb = box_mass_properties<2>(box_b, 800);
  const ContactBox<2> a{box_a, body_pose(sa, ma.center), ma.mass}, b{box_b, body_pose(sb, mb.center), mb.mass};
  BodyLoad<2> la, lb;
  add_body_contact(a, b, 50.0, 1e-3, la, &lb);
  EXPECT_LT(la.impulse[0], 0);  // a pushed back to the left, b to the right
  EXPECT_GT(lb.impulse[0], 0);
  EXPECT_NEAR(la.impulse[0] + lb.impulse[0], 0, 1e-15);
  EXPECT_NEAR(la.impulse[1] + lb.impulse[1], 0, 1e-15);
  // Moments about the origin: each body's about its centre plus its centre x its impulse.
  const double about_origin = la.angular_impulse[2] + sa.position[0] * la.impulse[1] - sa.position[1] * la.impulse[0] +
                              lb.angular_impulse[2] + sb.position[0] * lb.impulse[1] - sb.position[1] * lb.impulse[0];
  EXPECT_NEAR(about_origin, 0, 1e-15);
  // Against an obstacle that does not give way, only a is pushed, by the same law.
  BodyLoad<2> alone;
  add_body_contact<2>(a, ContactBox<2>{box_b, b.pose, 0.0}, 50.0, 1e-3, alone, nullptr);
  EXPECT_LT(alone.impulse[0], 0);
  // Apart, nothing.
  BodyLoad<2> none;
  add_body_contact<2>(a, ContactBox<2>{Box<2>{{{0.5, 0}}, {{0.6, 0.1}}}, RigidPose<2>{}, 1.0}, 50.0, 1e-3, none,
                      nullptr);
  EXPECT_EQ(none.impulse, (Vec<2, double>{}));
}

}  // namespace
}  // namespace sph
