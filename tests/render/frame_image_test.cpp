// Pictures of frames for sph render: panels, time label, legends.

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <sph/core/error.h>
#include <sph/render/frame_image.h>
#include <sph/surface/solid_cut.h>

#include "support/expect.h"

namespace {

using namespace sph;

RunDirectory run2d(const std::string& label) {
  RunDirectory run;
  run.dir = "/runs/" + label;
  run.label = label;
  run.dimension = 2;
  run.particle_radius = 0.05;
  run.particle_mass = 1;
  run.box_lo = {0, 0, 0};
  run.box_hi = {2, 1, 0};
  return run;
}

/// One particle at (x, y) moving at `speed` along x.
FrameData one_particle(double x, double y, double speed, double time) {
  FrameData f;
  f.time = time;
  f.size = 1;
  f.position = {x, y, 0};
  f.fields.push_back({"velocity", 3, {speed, 0, 0}});
  f.fields.push_back({"initial_position", 3, {2, 1, 0}});
  return f;
}

FrameStyle style(int w, int h, ColorBy by = ColorBy::Speed) {
  FrameStyle s;
  s.view = default_particle_view(2, w, h);
  s.view.shaded = false;
  s.color = {by, Colormap::Turbo, 0.0, 1.0};
  return s;
}

int count_color(const Image& img, Rgb c, int x0 = 0, int y0 = 0, int x1 = -1, int y1 = -1) {
  if (x1 < 0) x1 = img.width();
  if (y1 < 0) y1 = img.height();
  int n = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) n += img.at(x, y) == c;
  return n;
}

int count_dark(const Image& img, int x0, int y0, int x1, int y1) {
  int n = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      const Rgb c = img.at(x, y);
      n += c.r < 100 && c.g < 100 && c.b < 100;
    }
  return n;
}

TEST(FrameImage, TheParticleHasItsSpeedsColorWhereItIs) {
  const std::vector<RunDirectory> runs{run2d("a")};
  const std::vector<FrameData> frames{one_particle(1.5, 0.5, 1.0, 0.25)};
  const Image img = render_frame(runs, frames, style(400, 200));
  const Rgb top = colormap(Colormap::Turbo, 1.0);
  // The particle (radius 0.05 of a 2 x 1 box in a 400 x 200 view: about 8 px) in the right half.
  EXPECT_GT(count_color(img, top, 200, 0, 400, 200), 100);
  EXPECT_LT(count_color(img, top, 0, 40, 200, 200), 5);
  // The color bar widens the image and holds the map's ends.
  EXPECT_GT(img.width(), 400);
  EXPECT_GT(count_color(img, colormap(Colormap::Turbo, 0.0), 400, 0, img.width(), 200), 5);
  // The time in a caption row above the panel.
  EXPECT_GT(img.height(), 200);
  EXPECT_GT(count_dark(img, 150, 0, 250, img.height() - 200), 20);
}

TEST(FrameImage, InitialPositionHasAKeyInsteadOfAColorBar) {
  const std::vector<RunDirectory> runs{run2d("a")};
  const std::vector<FrameData> frames{one_particle(1.0, 0.5, 0.0, 0.0)};
  const Image img = render_frame(runs, frames, style(400, 200, ColorBy::InitialPosition));
  EXPECT_EQ(img.width(), 400);                                              // no color bar
  EXPECT_GT(count_color(img, Rgb{255, 255, 40}), 100);                      // x and y at their high ends, z flat
  EXPECT_GT(count_dark(img, 0, img.height() - 20, 400, img.height()), 20);  // the key along the bottom
}

TEST(FrameImage, SeveralRunsSideBySideWithCaptions) {
  const std::vector<RunDirectory> runs{run2d("standard"), run2d("adaptive")};
  const std::vector<FrameData> frames{one_particle(0.5, 0.5, 1.0, 0.1), one_particle(1.5, 0.5, 0.0, 0.1)};
  FrameStyle s = style(300, 150);
  s.legend = false;
  const Image img = render_frame(runs, frames, s);
  EXPECT_GT(img.width(), 600);
  EXPECT_GT(img.height(), 150);  // a caption row above the panels
  // The fast particle on the left panel, the still one on the right.
  const int half = img.width() / 2;
  EXPECT_GT(count_color(img, colormap(Colormap::Turbo, 1.0), 0, 0, half, img.height()), 20);
  EXPECT_EQ(count_color(img, colormap(Colormap::Turbo, 1.0), half, 0, img.width(), img.height()), 0);
  EXPECT_GT(count_color(img, colormap(Colormap::Turbo, 0.0), half, 0, img.width(), img.height()), 20);
}

TEST(FrameImage, AFrameWithoutTheFieldIsRefused) {
  const std::vector<RunDirectory> runs{run2d("a")};
  FrameData f = one_particle(1.0, 0.5, 0.0, 0.0);
  f.fields.clear();
  const std::vector<FrameData> frames{f};
  EXPECT_THROW(render_frame(runs, frames, style(100, 100)), Error);
}

/// run2d with two obstacles: [0.2, 0.4] x [0, 0.3] oscillating along x (amplitude 1.2 m, period
/// 2 s: at 1.4 .. 1.6 at t = 0.5 s) and [0.9, 1.1] x [0.6, 0.7] turning at pi/2 rad/s about its
/// middle (upright at t = 0); without `rotate` the second has no entry in `motions`.
RunDirectory run_with_moving_obstacles(bool rotate = true) {
  RunDirectory run = run2d("moving");
  SceneBody<2> body;
  body.sim.obstacles = {Box<2>{{{0.2, 0}}, {{0.4, 0.3}}}, Box<2>{{{0.9, 0.6}}, {{1.1, 0.7}}}};
  ObstacleMotion<2> paddle;
  paddle.type = MotionType::Oscillation;
  paddle.direction = {{1, 0}};
  paddle.amplitude = 1.2;
  paddle.period = 2;
  body.sim.motions = {paddle};
  if (rotate) {
    ObstacleMotion<2> stirrer;
    stirrer.type = MotionType::Rotation;
    stirrer.center = {{1.0, 0.65}};
    stirrer.angular_velocity = std::numbers::pi / 2;
    body.sim.motions.push_back(stirrer);
  }
  run.scene.set_body(body);
  return run;
}

TEST(FrameImage, RunObstaclesArePlacedAtTheFramesTime) {
  const RunDirectory run = run_with_moving_obstacles();
  for (const double t : {0.0, 0.5, 1.0, 1.5}) {
    const std::vector<SolidBox> s = run_obstacles(run, t);
    ASSERT_EQ(s.size(), 2u);
    // Always the boxes at rest, each with its placement.
    EXPECT_EQ(s[0].lo, (std::array<double, 3>{0.2, 0, 0}));
    EXPECT_EQ(s[0].hi, (std::array<double, 3>{0.4, 0.3, 0}));
    EXPECT_EQ(s[1].lo, (std::array<double, 3>{0.9, 0.6, 0}));
    EXPECT_EQ(s[1].hi, (std::array<double, 3>{1.1, 0.7, 0}));
    // The paddle: translated by 1.2 sin(pi t) along x, not turned.
    EXPECT_NEAR(s[0].translation[0], 1.2 * std::sin(std::numbers::pi * t), 1e-12) << t;
    EXPECT_EQ(s[0].translation[1], 0.0);
    EXPECT_TRUE(s[0].axis_aligned()) << t;
    EXPECT_NEAR(s[0].place({0.2, 0, 0}, 2)[0], 0.2 + 1.2 * std::sin(std::numbers::pi * t), 1e-12) << t;
    // The stirrer: turned by pi t / 2 about (1, 0.65), not translated; its right side's middle goes round.
    const double angle = std::numbers::pi * t / 2;
    EXPECT_NEAR(s[1].rotation[0], std::cos(angle), 1e-12) << t;
    EXPECT_NEAR(s[1].rotation[1], -std::sin(angle), 1e-12) << t;
    EXPECT_NEAR(s[1].rotation[3], std::sin(angle), 1e-12) << t;
    EXPECT_EQ(s[1].rotation[8], 1.0);
    EXPECT_EQ(s[1].center, (std::array<double, 3>{1.0, 0.65, 0}));
    const auto p = s[1].place({1.1, 0.65, 0}, 2);
    EXPECT_NEAR(p[0], 1.0 + 0.1 * std::cos(angle), 1e-12) << t;
    EXPECT_NEAR(p[1], 0.65 + 0.1 * std::sin(angle), 1e-12) << t;
    EXPECT_EQ(p[2], 0.0);
  }
  // An obstacle without a motion is at rest.
  const std::vector<SolidBox> at_rest = run_obstacles(run_with_moving_obstacles(false), 1.0);
  EXPECT_TRUE(at_rest[1].axis_aligned());
  EXPECT_EQ(at_rest[1].translation, (std::array<double, 3>{0, 0, 0}));
}

/// run2d with a floating box [0.2, 0.4] x [0, 0.2] (centre 0.3, 0.1) whose bodies.csv rows put it
/// at (1, 0.5) turned by 90 degrees at t = 1 s, and at rest at t = 0.
RunDirectory run_with_floating_box() {
  RunDirectory run = run2d("floating");
  SceneBody<2> body;
  body.sim.obstacles = {Box<2>{{{0.2, 0}}, {{0.4, 0.2}}}};
  BodyParams<2> b;
  b.dynamic = true;
  b.density = 500;
  body.sim.bodies = {b};
  run.scene.set_body(body);
  const double h = std::sqrt(0.5);
  run.bodies = {BodyPoseRow{0.0, 0, {0.3, 0.1, 0}, {1, 0, 0, 0}}, BodyPoseRow{1.0, 0, {1.0, 0.5, 0}, {h, 0, 0, h}}};
  return run;
}

TEST(FrameImage, FloatingBodiesAreDrawnWhereTheRunsTableHasThem) {
  RunDirectory run = run_with_floating_box();
  // Each frame's row: t = 0 at rest, t = 1 moved and turned.
  EXPECT_TRUE(run_obstacles(run, 0.0)[0].axis_aligned());
  EXPECT_NEAR(run_obstacles(run, 0.0)[0].translation[0], 0.0, 1e-12);
  const SolidBox s = run_obstacles(run, 1.0)[0];
  const auto centre = s.place({0.3, 0.1, 0}, 2);
  EXPECT_NEAR(centre[0], 1.0, 1e-12);
  EXPECT_NEAR(centre[1], 0.5, 1e-12);
  const auto corner = s.place({0.4, 0.0, 0}, 2);  // (0.1, -0.1) from the centre, turned a quarter
  EXPECT_NEAR(corner[0], 1.1, 1e-12);
  EXPECT_NEAR(corner[1], 0.6, 1e-12);
  // A time the table has no row at (it lost rows): refused, not drawn at the nearest row's pose.
  try {
    (void)run_obstacles(run, 0.9);
    ADD_FAILURE() << "no row at t = 0.9 s";
  } catch (const sph::Error& e) {
    EXPECT_CONTAINS(std::string(e.what()), "has no row of obstacle 0 (a floating body) at t = 0.9 s");
  }
  // Without a table, where it started.
  run.bodies.clear();
  EXPECT_EQ(run_obstacles(run, 0.9)[0].translation, (std::array<double, 3>{0, 0, 0}));
}

TEST(FrameImage, TheSurfacesCutIsTheObstaclesWhereTheFrameHasThem) {
  // run_obstacles_distance (the solids a frame's surface is cut by) puts each obstacle where
  // run_obstacles draws it: the paddle of run_with_moving_obstacles at 1.4 .. 1.6 at t = 0.5 s.
  const RunDirectory moving = run_with_moving_obstacles();
  const SolidDistance at_half = run_obstacles_distance(moving, 0.5);
  ASSERT_TRUE(at_half);
  EXPECT_NEAR(at_half({1.5, 0.15, 0}, 1), -0.1, 1e-12);  // inside, 0.1 from its sides
  EXPECT_NEAR(at_half({1.7, 0.15, 0}, 1), 0.1, 1e-12);
  EXPECT_GT(at_half({0.3, 0.15, 0}, 1), 0.7);  // where it is at rest: fluid's space (the stirrer 0.75 away)
  EXPECT_NEAR(run_obstacles_distance(moving, 0.0)({0.3, 0.15, 0}, 1), -0.1, 1e-12);
  // The floating box at t = 1 s, from bodies.csv: [0.9, 1.1] x [0.4, 0.6] (a square turned by 90 degrees).
  const RunDirectory floating = run_with_floating_box();
  EXPECT_NEAR(run_obstacles_distance(floating, 1.0)({1.0, 0.5, 0}, 1), -0.1, 1e-12);
  EXPECT_NEAR(run_obstacles_distance(floating, 1.0)({1.25, 0.5, 0}, 1), 0.15, 1e-12);
  // No obstacles: no cut.
  EXPECT_FALSE(run_obstacles_distance(run2d("empty"), 0.0));
}

TEST(FrameImage, RunObstaclesOfA3DSceneTurnAboutTheirAxis) {
  RunDirectory run = run2d("3d");
  run.dimension = 3;
  run.box_hi = {2, 1, 1};
  SceneBody<3> body;
  body.sim.obstacles = {Box<3>{{{0.5, 0.2, 0.2}}, {{0.7, 0.4, 0.6}}}};
  ObstacleMotion<3> m;
  m.type = MotionType::Rotation;
  m.axis = {{1, 0, 0}};
  m.center = {{0.6, 0.3, 0.4}};
  m.angular_velocity = std::numbers::pi;  // half a turn at t = 1 s
  body.sim.motions = {m};
  run.scene.set_body(body);
  const std::vector<SolidBox> s = run_obstacles(run, 1.0);
  ASSERT_EQ(s.size(), 1u);
  // Half a turn about x through the middle: the corner (0.5, 0.2, 0.2) goes to (0.5, 0.4, 0.6).
  const auto p = s[0].place({0.5, 0.2, 0.2}, 3);
  EXPECT_NEAR(p[0], 0.5, 1e-12);
  EXPECT_NEAR(p[1], 0.4, 1e-12);
  EXPECT_NEAR(p[2], 0.6, 1e-12);
  // A quarter turn at t = 0.5 s: +y goes to +z.
  const auto q = run_obstacles(run, 0.5)[0].axis(1, 3);
  EXPECT_NEAR(q[0], 0.0, 1e-12);
  EXPECT_NEAR(q[1], 0.0, 1e-12);
  EXPECT_NEAR(q[2], 1.0, 1e-12);
  // Drawn where it is: a 3D frame renders with it.
  FrameData f = one_particle(1.5, 0.5, 0.0, 0.5);
  f.position = {1.5, 0.5, 0.5};
  FrameStyle st = style(200, 100);
  st.view = default_particle_view(3, 200, 100);
  EXPECT_NO_THROW(render_frame(std::vector<RunDirectory>{run}, std::vector<FrameData>{f}, st));
}

TEST(FrameImage, MovingObstaclesAreDrawnWhereTheyAreAtTheFramesTime) {
  const std::vector<RunDirectory> runs{run_with_moving_obstacles(false)};
  FrameStyle s = style(400, 200);
  s.legend = false;
  // The particle, still (colormap's low end), away from the obstacles.
  const auto render_at = [&](double t) {
    return render_frame(runs, std::vector<FrameData>{one_particle(1.0, 0.9, 0.0, t)}, s);
  };
  // The paddle [0.2, 0.4] x [0, 0.3] at rest left of the middle at t = 0 (pixels ~66 .. 100),
  // right of it (1.4 .. 1.6, pixels ~267 .. 300) at t = 0.5 s; the still obstacle [0.9, 1.1] x
  // [0.6, 0.7] is in the middle (pixels ~183 .. 217), counted in neither part.
  const Image at0 = render_at(0.0), at05 = render_at(0.5);
  ASSERT_EQ(at0.width(), 400);
  const int h = at0.height();
  const int left = count_color(at0, kSolidColor, 0, 0, 160, h);
  EXPECT_GT(left, 200);
  EXPECT_EQ(count_color(at0, kSolidColor, 240, 0, 400, h), 0);
  EXPECT_EQ(count_color(at05, kSolidColor, 0, 0, 160, h), 0);
  const int right = count_color(at05, kSolidColor, 240, 0, 400, h);
  EXPECT_NEAR(right, left, 0.08 * left);  // shifted, not changed
  // The still obstacle stays where it is.
  EXPECT_EQ(count_color(at0, kSolidColor, 160, 0, 240, h), count_color(at05, kSolidColor, 160, 0, 240, h));
  EXPECT_GT(count_color(at0, kSolidColor, 160, 0, 240, h), 100);
}

}  // namespace
