// Shapes (shape.h): a mesh's and a polygon's signed distance against exact answers (a cube's
// against the box's own, a circle's and a sphere's against their radius), the coarse grid's
// bound, inverted shapes, and the checks of make_shape and polygon_shape on broken surfaces.

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <sph/core/error.h>
#include <sph/solver/params.h>
#include <sph/solver/rigid_body.h>
#include <sph/solver/shape.h>

namespace sph {
namespace {

using V2 = Vec<2, double>;
using V3 = Vec<3, double>;

/// The unit cube [0, 1]^3 as 12 triangles; `inward` turns every face the wrong way.
ObstacleShape<3> cube(bool inward = false, bool inverted = false) {
  std::vector<V3> v;
  for (int i = 0; i < 8; ++i) v.push_back(V3{{double(i & 1), double(i >> 1 & 1), double(i >> 2 & 1)}});
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  std::vector<std::array<std::uint32_t, 3>> t;
  for (const auto& q : quads) {
    t.push_back({std::uint32_t(q[0]), std::uint32_t(q[1]), std::uint32_t(q[2])});
    t.push_back({std::uint32_t(q[0]), std::uint32_t(q[2]), std::uint32_t(q[3])});
  }
  if (inward)
    for (auto& f : t) std::swap(f[1], f[2]);
  return make_shape<3>(v, t, inverted);
}

/// The same cube as a box obstacle (obstacle_distance's exact box distance).
SimulationParams<3> cube_box() {
  SimulationParams<3> p;
  p.obstacles.push_back(Box<3>{V3{}, V3::filled(1)});
  return p;
}

/// An icosphere of radius 1: 20 faces, each split in 4 `levels` times, vertices on the sphere.
ObstacleShape<3> sphere(int levels) {
  const double t = (1 + std::sqrt(5.0)) / 2;
  std::vector<V3> v = {V3{{-1, t, 0}}, V3{{1, t, 0}}, V3{{-1, -t, 0}}, V3{{1, -t, 0}},
                       V3{{0, -1, t}}, V3{{0, 1, t}}, V3{{0, -1, -t}}, V3{{0, 1, -t}},
                       V3{{t, 0, -1}}, V3{{t, 0, 1}}, V3{{-t, 0, -1}}, V3{{-t, 0, 1}}};
  for (V3& x : v) x = x * (1 / std::sqrt(norm2(x)));
  std::vector<std::array<std::uint32_t, 3>> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                                 {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                                 {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                                 {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> mid;
    const auto middle = [&](std::uint32_t a, std::uint32_t b) {
      const auto key = std::make_pair(std::min(a, b), std::max(a, b));
      if (auto it = mid.find(key); it != mid.end()) return it->second;
      V3 m = (v[a] + v[b]) * 0.5;
      v.push_back(m * (1 / std::sqrt(norm2(m))));
      return mid[key] = static_cast<std::uint32_t>(v.size() - 1);
    };
    std::vector<std::array<std::uint32_t, 3>> g;
    for (const auto& [a, b, c] : f) {
      const std::uint32_t ab = middle(a, b), bc = middle(b, c), ca = middle(c, a);
      g.push_back({a, ab, ca});
      g.push_back({b, bc, ab});
      g.push_back({c, ca, bc});
      g.push_back({ab, bc, ca});
    }
    f = g;
  }
  return make_shape<3>(v, f, false);
}

std::vector<V3> random_points(int n, double lo, double hi, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(lo, hi);
  std::vector<V3> out;
  for (int i = 0; i < n; ++i) out.push_back(V3{{u(rng), u(rng), u(rng)}});
  return out;
}

TEST(Shape, ACubeMeshHasTheBoxsSignedDistanceAndNormal) {
  const ObstacleShape<3> mesh = cube();
  const SimulationParams<3> box = cube_box();
  EXPECT_NEAR(mesh.field->volume(), 1.0, 1e-12);
  for (const V3& x : random_points(4000, -0.6, 1.6, 1)) {
    const SurfaceDistance<3> m = mesh.field->distance(x);
    const SurfaceDistance<3> b = obstacle_distance(box, 0, x, 10.0);
    ASSERT_NEAR(m.distance, b.distance, 1e-12) << x[0] << " " << x[1] << " " << x[2];
    // Outside, the normal points from the nearest point to x; inside, out through the nearest face
    // (where two faces are equally near, either is right).
    if (b.distance > 1e-9 || std::abs(norm2(m.normal - b.normal)) < 1e-18) continue;
    double ties = 0;
    for (int d = 0; d < 3; ++d) ties += std::abs(std::min(x[d], 1 - x[d]) + b.distance) < 1e-12;
    EXPECT_GT(ties, 1) << "inside normal differs without a tie";
  }
}

TEST(Shape, FacesTurnedInwardsAreTurnedOutwards) {
  const ObstacleShape<3> in = cube(true), out = cube();
  EXPECT_NEAR(in.field->volume(), 1.0, 1e-12);
  for (const V3& x : random_points(500, -0.5, 1.5, 2))
    EXPECT_EQ(in.field->distance(x).distance, out.field->distance(x).distance);
}

TEST(Shape, AnIcosphereIsWithinItsChordErrorOfTheSphere) {
  const ObstacleShape<3> s = sphere(4);  // 5120 faces: the flat faces sag at most ~1e-3 inside the sphere
  for (const V3& x : random_points(3000, -2, 2, 3)) {
    const double r = std::sqrt(norm2(x));
    if (r < 0.05) continue;
    const SurfaceDistance<3> d = s.field->distance(x);
    EXPECT_NEAR(d.distance, r - 1, 2e-3) << r;
    EXPECT_GT(dot(d.normal, x * (1 / r)), 0.95);  // about radial
  }
}

TEST(Shape, TheGridsShortcutIsALowerBoundOnTheFarSideOnly) {
  const ObstacleShape<3> s = sphere(2);
  for (const double reach : {0.01, 0.1, 0.4})
    for (const V3& x : random_points(3000, -3, 3, 4)) {
      const double exact = s.field->distance(x).distance;
      const SurfaceDistance<3> q = s.field->distance_within(x, reach);
      if (q.distance == exact) continue;
      // Short-cut: only outside, farther than reach, and never more than the truth.
      EXPECT_GT(exact, reach);
      EXPECT_GT(q.distance, reach);
      EXPECT_LE(q.distance, exact);
      // With the solid outside (inverted), the far side is the inside.
      const SurfaceDistance<3> inv = s.field->distance_within(x, reach, false);
      EXPECT_EQ(inv.distance, exact);
    }
}

TEST(Shape, AnInvertedShapeIsTheSolidOutsideItsSurface) {
  const ObstacleShape<3> in = cube(false, true);
  SimulationParams<3> p;
  p.obstacles.push_back(shape_bounds(in));
  p.shapes.push_back(in);
  for (const V3& x : random_points(2000, -1, 2, 5)) {
    const double exact = in.field->distance(x).distance;
    const SurfaceDistance<3> d = obstacle_distance(p, 0, x, 0.05);
    if (exact < -0.05) {
      EXPECT_GE(d.distance, 0.05);  // deep in the fluid's room: a bound is enough
      EXPECT_LE(d.distance, -exact);
    } else {
      EXPECT_EQ(d.distance, -exact);
    }
  }
  EXPECT_LT(obstacle_distance(p, 0, V3::filled(2), 0.0).distance, -0.9);  // outside the cube: in the solid
}

TEST(Shape, APolygonHasItsExactSignedDistanceEitherWayRound) {
  // An L: concave, its vertices clockwise (turned counter-clockwise by polygon_shape).
  const std::vector<V2> l = {V2{{0, 0}}, V2{{0, 2}}, V2{{1, 2}}, V2{{1, 1}}, V2{{2, 1}}, V2{{2, 0}}};
  const ObstacleShape<2> s = polygon_shape(l, false);
  EXPECT_NEAR(s.field->volume(), 3.0, 1e-12);
  const auto check = [&](V2 x, double expect) { EXPECT_NEAR(s.field->distance(x).distance, expect, 1e-12); };
  check(V2{{0.5, 0.5}}, -0.5);
  check(V2{{1.5, 1.5}}, 0.5);  // in the notch, as near the two edges that meet at (1, 1)
  check(V2{{1.2, 1.5}}, 0.2);
  check(V2{{3, 0.5}}, 1.0);
  check(V2{{-1, -1}}, std::sqrt(2.0));
  check(V2{{1.9, 0.5}}, -0.1);
  // A circle as a 256-gon: within its chord error of the radius.
  std::vector<V2> circle;
  for (int k = 0; k < 256; ++k) {
    const double a = 2 * std::numbers::pi * k / 256;
    circle.push_back(V2{{std::cos(a), std::sin(a)}});
  }
  const ObstacleShape<2> c = polygon_shape(circle, false);
  std::mt19937_64 rng(6);
  std::uniform_real_distribution<double> u(-2, 2);
  for (int i = 0; i < 2000; ++i) {
    const V2 x{{u(rng), u(rng)}};
    EXPECT_NEAR(c.field->distance(x).distance, std::sqrt(norm2(x)) - 1, 1e-4);
  }
}

/// The cube's mesh turned by R (row-major), scaled to a x b x c first: its vertices R (s * X).
ObstacleShape<3> turned_box(double a, double b, double c, const std::array<double, 9>& r) {
  const ObstacleShape<3> unit = cube();
  std::vector<V3> v;
  for (const V3& x : unit.vertices) {
    const V3 y{{x[0] * a, x[1] * b, x[2] * c}};
    v.push_back(V3{{r[0] * y[0] + r[1] * y[1] + r[2] * y[2], r[3] * y[0] + r[4] * y[1] + r[5] * y[2],
                    r[6] * y[0] + r[7] * y[1] + r[8] * y[2]}});
  }
  return make_shape<3>(v, unit.faces, false);
}

TEST(ShapeMass, AMeshOfABoxHasTheBoxsMassCentreAndInertia) {
  const MassProperties<3> mesh = shape_mass_properties(turned_box(1, 2, 3, {1, 0, 0, 0, 1, 0, 0, 0, 1}), 500);
  const MassProperties<3> box = box_mass_properties<3>(Box<3>{V3{}, V3{{1, 2, 3}}}, 500);
  EXPECT_NEAR(mesh.mass, box.mass, 1e-9);
  for (int d = 0; d < 3; ++d) EXPECT_NEAR(mesh.center[d], box.center[d], 1e-12);
  // The same principal moments, in some order, along the box's own axes.
  std::vector<double> a(mesh.inertia.c.begin(), mesh.inertia.c.end()), b(box.inertia.c.begin(), box.inertia.c.end());
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(a[k], b[k], 1e-9 * b[2]);
  for (int k = 0; k < 3; ++k) {
    const V3 axis{{mesh.axes[k], mesh.axes[3 + k], mesh.axes[6 + k]}};
    EXPECT_NEAR(std::max({std::abs(axis[0]), std::abs(axis[1]), std::abs(axis[2])}), 1.0, 1e-9);
  }
}

TEST(ShapeMass, ATurnedBoxsPrincipalAxesAreItsTurnedEdges) {
  // Turned 30 degrees about z, then 40 about x.
  const double c1 = std::cos(0.5236), s1 = std::sin(0.5236), c2 = std::cos(0.6981), s2 = std::sin(0.6981);
  const std::array<double, 9> rz{c1, -s1, 0, s1, c1, 0, 0, 0, 1}, rx{1, 0, 0, 0, c2, -s2, 0, s2, c2};
  std::array<double, 9> r{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) r[3 * i + j] += rx[3 * i + k] * rz[3 * k + j];
  const MassProperties<3> mp = shape_mass_properties(turned_box(1, 2, 3, r), 800);
  const MassProperties<3> box = box_mass_properties<3>(Box<3>{V3{}, V3{{1, 2, 3}}}, 800);
  for (int k = 0; k < 3; ++k) {
    // Each principal axis is one of the turned edges (R e_d, up to sign), with that edge's moment.
    const V3 axis{{mp.axes[k], mp.axes[3 + k], mp.axes[6 + k]}};
    int matched = 0;
    for (int d = 0; d < 3; ++d) {
      const V3 edge{{r[d], r[3 + d], r[6 + d]}};
      if (std::abs(std::abs(dot(axis, edge)) - 1) < 1e-9) {
        EXPECT_NEAR(mp.inertia[k], box.inertia[d], 1e-9 * box.inertia[d]);
        ++matched;
      }
    }
    EXPECT_EQ(matched, 1) << "axis " << k;
  }
  // A rotation: orthonormal, determinant +1.
  const V3 e0{{mp.axes[0], mp.axes[3], mp.axes[6]}}, e1{{mp.axes[1], mp.axes[4], mp.axes[7]}},
      e2{{mp.axes[2], mp.axes[5], mp.axes[8]}};
  EXPECT_NEAR(dot(e0, e1), 0, 1e-12);
  EXPECT_NEAR(e0[0] * (e1[1] * e2[2] - e1[2] * e2[1]) - e0[1] * (e1[0] * e2[2] - e1[2] * e2[0]) +
                  e0[2] * (e1[0] * e2[1] - e1[1] * e2[0]),
              1, 1e-12);
}

TEST(ShapeMass, AnIcosphereIsASolidBallAndAPolygonAPlate) {
  const MassProperties<3> ball = shape_mass_properties(sphere(4), 1000);
  const double m = 1000 * 4 * std::numbers::pi / 3;
  EXPECT_NEAR(ball.mass, m, 0.01 * m);  // (the faces sag inside the sphere)
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(ball.center[k], 0, 1e-12);
    EXPECT_NEAR(ball.inertia[k], 0.4 * m, 0.02 * 0.4 * m);
  }
  // 2D: a rectangle polygon is the box; a right triangle's centroid is a third of the way in.
  const MassProperties<2> rect = shape_mass_properties(
      polygon_shape({V2{{0.2, 0.1}}, V2{{0.6, 0.1}}, V2{{0.6, 0.3}}, V2{{0.2, 0.3}}}, false), 500);
  const MassProperties<2> box = box_mass_properties<2>(Box<2>{V2{{0.2, 0.1}}, V2{{0.6, 0.3}}}, 500);
  EXPECT_NEAR(rect.mass, box.mass, 1e-12);
  EXPECT_NEAR(rect.center[0], box.center[0], 1e-12);
  EXPECT_NEAR(rect.center[1], box.center[1], 1e-12);
  EXPECT_NEAR(rect.inertia[2], box.inertia[2], 1e-12);
  const MassProperties<2> tri = shape_mass_properties(polygon_shape({V2{{0, 0}}, V2{{3, 0}}, V2{{0, 3}}}, false), 2);
  EXPECT_NEAR(tri.mass, 9, 1e-12);
  EXPECT_NEAR(tri.center[0], 1, 1e-12);
  EXPECT_NEAR(tri.center[1], 1, 1e-12);
  EXPECT_NEAR(tri.inertia[2], 2 * 4.5 * (9 + 9) / 18, 1e-9);  // rho A (a^2 + b^2) / 18 for legs a, b
}

/// The message make_shape or polygon_shape throws for a broken surface ("" if it accepts it).
template <class F>
std::string refusal(F&& make) {
  try {
    make();
  } catch (const Error& e) {
    return e.message();
  }
  return "";
}

TEST(Shape, BrokenSurfacesAreRefusedWithWhatIsWrong) {
  const ObstacleShape<3> c = cube();
  auto v = c.vertices;
  auto f = c.faces;
  // Open: two triangles (a face) missing.
  auto open = f;
  open.resize(open.size() - 2);
  EXPECT_NE(refusal([&] { make_shape<3>(v, open, false); }).find("is not closed: 4 edges"), std::string::npos);
  // One triangle turned the wrong way.
  auto flipped = f;
  std::swap(flipped[0][1], flipped[0][2]);
  EXPECT_NE(refusal([&] { make_shape<3>(v, flipped, false); }).find("same direction"), std::string::npos);
  // A triangle of zero area.
  auto degenerate = f;
  degenerate.push_back({0, 1, 1});
  EXPECT_NE(refusal([&] { make_shape<3>(v, degenerate, false); }).find("1 degenerate triangles"), std::string::npos);
  // An index past the vertices.
  auto bad_index = f;
  bad_index[3][2] = 99;
  EXPECT_NE(refusal([&] { make_shape<3>(v, bad_index, false); }).find("uses vertex 99"), std::string::npos);
  // A vertex that is not a number.
  auto nan_vertex = v;
  nan_vertex[2][1] = std::nan("");
  EXPECT_NE(refusal([&] { make_shape<3>(nan_vertex, f, false); }).find("not a finite number"), std::string::npos);
  // Polygons: too few vertices, a repeated vertex, a bow tie.
  EXPECT_NE(refusal([] { polygon_shape({V2{{0, 0}}, V2{{1, 0}}}, false); }).find("at least 3"), std::string::npos);
  EXPECT_NE(refusal([] {
              polygon_shape({V2{{0, 0}}, V2{{1, 0}}, V2{{1, 0}}, V2{{0, 1}}}, false);
            }).find("same point"),
            std::string::npos);
  EXPECT_NE(refusal([] {
              polygon_shape({V2{{0, 0}}, V2{{1, 1}}, V2{{1, 0}}, V2{{0, 1}}}, false);
            }).find("cross"),
            std::string::npos);
  EXPECT_NE(refusal([] {
              polygon_shape({V2{{0, 0}}, V2{{1, 0}}, V2{{2, 0}}}, false);
            }).find("cross"),
            std::string::npos);
  EXPECT_EQ(refusal([&] { make_shape<3>(v, f, false); }), "");
}

}  // namespace
}  // namespace sph
