// Particle images: placement in the fitted view, the box outline, depth order, solid obstacles
// (filled in 2D, shaded faces that hide what is behind them in 3D), and the edge cases (no
// particles, NaN positions, bad arguments).

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include <sph/core/error.h>
#include <sph/render/particles.h>

#include "support/colors.h"

namespace sph {
namespace {

using test::kBlue;
using test::kRed;
using test::kWhite;

using A3 = std::array<double, 3>;

ParticleView flat_view(int w = 400, int h = 300) {
  ParticleView v;
  v.width = w;
  v.height = h;
  v.shaded = false;
  return v;
}

bool is_gray(Rgb c) { return c.r == c.g && c.g == c.b; }

struct PixelBox {
  int x0 = 1 << 30, y0 = 1 << 30, x1 = -1, y1 = -1;
};

/// Bounding box of the pixels for which pred(pixel) holds.
template <typename Pred>
PixelBox bbox(const Image& img, Pred pred) {
  PixelBox b;
  for (int y = 0; y < img.height(); ++y)
    for (int x = 0; x < img.width(); ++x)
      if (pred(img.at(x, y))) {
        b.x0 = std::min(b.x0, x);
        b.y0 = std::min(b.y0, y);
        b.x1 = std::max(b.x1, x);
        b.y1 = std::max(b.y1, y);
      }
  return b;
}

TEST(Particles, ParticleAtTheBoxCenterColorsTheImageCenter2D) {
  const std::vector<double> xyz = {0.5, 0.5};
  const std::vector<Rgb> colors = {kRed};
  const Image img = render_particles(xyz, 2, colors, 0.05, A3{0, 0, 0}, A3{1, 1, 0}, flat_view());
  EXPECT_EQ(img.at(200, 150), kRed);
  EXPECT_EQ(img.at(199, 149), kRed);
  // Red only around the center: radius 0.05 of a ~0.92 * 300 px tall box is ~14 px.
  const PixelBox b = bbox(img, [](Rgb c) { return c == kRed; });
  EXPECT_GE(b.x0, 200 - 16);
  EXPECT_LE(b.x1, 200 + 16);
  EXPECT_GE(b.y0, 150 - 16);
  EXPECT_LE(b.y1, 150 + 16);
  EXPECT_GE(b.x1 - b.x0, 20);  // and it has the projected size, not one pixel
}

TEST(Particles, ParticleAtTheBoxCenterColorsTheImageCenter3D) {
  ParticleView view = flat_view();
  view.azimuth_deg = 30;
  view.elevation_deg = 20;
  const std::vector<double> xyz = {1, 2, 3};
  const std::vector<Rgb> colors = {kRed};
  const Image img = render_particles(xyz, 3, colors, 0.1, A3{0, 1, 2}, A3{2, 3, 4}, view);
  EXPECT_EQ(img.at(200, 150), kRed);
}

TEST(Particles, CornerParticleColorsThatCorner2D) {
  const std::vector<double> xyz = {0.05, 0.05};  // bottom left (y is up)
  const std::vector<Rgb> colors = {kRed};
  const Image img = render_particles(xyz, 2, colors, 0.05, A3{0, 0, 0}, A3{1, 1, 0}, flat_view());
  const PixelBox b = bbox(img, [](Rgb c) { return c == kRed; });
  ASSERT_GE(b.x1, 0);
  // The box spans ~276 px square centered at (200, 150): its bottom-left corner is near (62, 288).
  EXPECT_LT(b.x1, 200 - 100);
  EXPECT_GT(b.y0, 150 + 100);
  EXPECT_NEAR(0.5 * (b.x0 + b.x1), 200 - 0.45 / 1.1 * 276, 3);
  EXPECT_NEAR(0.5 * (b.y0 + b.y1), 150 + 0.45 / 1.1 * 276, 3);
}

TEST(Particles, NearestCornerOfA3DBoxAppearsUpperRightFromTheDefaultCamera) {
  // From azimuth 30, elevation 20 the camera sees the box from +x, +y, +z: the box_hi corner is
  // right of and above the center, and nearest to the camera.
  const std::vector<double> xyz = {0.95, 0.95, 0.95, 0.05, 0.05, 0.05};
  const std::vector<Rgb> colors = {kRed, kBlue};
  const Image img = render_particles(xyz, 3, colors, 0.05, A3{0, 0, 0}, A3{1, 1, 1}, [] {
    ParticleView v = default_particle_view(3, 400, 300);
    v.shaded = false;
    return v;
  }());
  const PixelBox red = bbox(img, [](Rgb c) { return c == kRed; });
  const PixelBox blue = bbox(img, [](Rgb c) { return c == kBlue; });
  ASSERT_GE(red.x1, 0);
  ASSERT_GE(blue.x1, 0);
  EXPECT_GT(red.x0, 200);
  EXPECT_LT(red.y1, 150);
  EXPECT_LT(blue.x1, 200);
  EXPECT_GT(blue.y0, 150);
}

TEST(Particles, NothingIsDrawnOutsideTheBoxProjection) {
  // A wide 2D box in a square image: particles fill it, up to one radius from its walls.
  const double r = 0.02;
  std::vector<double> xyz;
  for (double y = r; y <= 1 - r + 1e-12; y += 0.01)
    for (double x = r; x <= 2 - r + 1e-12; x += 0.01) {
      xyz.push_back(x);
      xyz.push_back(y);
    }
  const std::vector<Rgb> colors = {kRed};
  ParticleView view = flat_view(400, 400);
  view.shaded = true;
  const Image img = render_particles(xyz, 2, colors, r, A3{0, 0, 0}, A3{2, 1, 0}, view);
  const ParticleCamera cam(2, A3{0, 0, 0}, A3{2, 1, 0}, r, view);
  const A3 lo = cam.project(A3{0, 0, 0}), hi = cam.project(A3{2, 1, 0});
  const PixelBox ink = bbox(img, [](Rgb c) { return c != kWhite; });
  EXPECT_GE(ink.x0, std::floor(lo[0]) - 1);
  EXPECT_LE(ink.x1, std::ceil(hi[0]) + 1);
  EXPECT_GE(ink.y0, std::floor(hi[1]) - 1);  // y is up: the top of the box is hi
  EXPECT_LE(ink.y1, std::ceil(lo[1]) + 1);
  // Independent of the camera: the 2:1 box in a square image leaves the top and bottom quarters empty.
  EXPECT_GT(ink.y0, 400 / 4);
  EXPECT_LT(ink.y1, 400 * 3 / 4);
  EXPECT_GT(ink.x1 - ink.x0, 300);
}

TEST(Particles, NearParticleCoversFarOneWhateverTheIndexOrder) {
  ParticleView view = flat_view();  // azimuth 0, elevation 0: looking along -z
  const std::vector<Rgb> colors = {kRed, kBlue};
  const A3 lo{-1, -1, -1}, hi{1, 1, 1};
  const std::vector<double> red_near_first = {0, 0, 0.5, 0, 0, -0.5};
  const std::vector<double> red_far_first = {0, 0, -0.5, 0, 0, 0.5};
  EXPECT_EQ(render_particles(red_near_first, 3, colors, 0.2, lo, hi, view).at(200, 150), kRed);
  EXPECT_EQ(render_particles(red_far_first, 3, colors, 0.2, lo, hi, view).at(200, 150), kBlue);
  // Turned around (azimuth 180), the other one is in front.
  view.azimuth_deg = 180;
  EXPECT_EQ(render_particles(red_near_first, 3, colors, 0.2, lo, hi, view).at(200, 150), kBlue);
  // Looking down from above (elevation 90), the higher one is in front.
  view.azimuth_deg = 0;
  view.elevation_deg = 90;
  const std::vector<double> red_high = {0, 0.5, 0, 0, -0.5, 0};
  EXPECT_EQ(render_particles(red_high, 3, colors, 0.2, lo, hi, view).at(200, 150), kRed);
}

TEST(Particles, EqualDepthsDrawInIndexOrder) {
  const std::vector<double> xyz = {0, 0, 0, 0, 0, 0};
  const std::vector<Rgb> colors = {kRed, kBlue};
  const Image img = render_particles(xyz, 3, colors, 0.2, A3{-1, -1, -1}, A3{1, 1, 1}, flat_view());
  EXPECT_EQ(img.at(200, 150), kBlue);  // the later one on top
}

TEST(Particles, NoParticlesGiveBackgroundAndTheBoxOnly) {
  for (int dim : {2, 3}) {
    ParticleView view = default_particle_view(dim, 320, 240);
    view.background = Rgb{255, 255, 255};
    const Image img = render_particles({}, dim, {}, 0.1, A3{0, 0, 0}, A3{1, 1, 1}, view);
    int gray = 0;
    for (const Rgb& p : img.pixels()) {
      ASSERT_TRUE(is_gray(p)) << "dim " << dim;
      gray += p != kWhite;
    }
    EXPECT_GT(gray, 4 * 150) << "the box outline is missing, dim " << dim;
  }
}

TEST(Particles, BoxEdgesIn3DIncludeTheSilhouette) {
  // A cube seen from az 30, el 20: the outline spans its projected corners.
  ParticleView view = default_particle_view(3, 400, 300);
  const Image img = render_particles({}, 3, {}, 0.0, A3{0, 0, 0}, A3{1, 1, 1}, view);
  const ParticleCamera cam(3, A3{0, 0, 0}, A3{1, 1, 1}, 0.0, view);
  double xmin = 1e9, xmax = -1e9;
  for (int k = 0; k < 8; ++k) {
    const A3 p = cam.project(A3{double(k & 1), double((k >> 1) & 1), double((k >> 2) & 1)});
    xmin = std::min(xmin, p[0]);
    xmax = std::max(xmax, p[0]);
  }
  const PixelBox ink = bbox(img, [](Rgb c) { return c != kWhite; });
  EXPECT_NEAR(ink.x0, xmin, 2.0);
  EXPECT_NEAR(ink.x1, xmax, 2.0);
  // The view is fitted: here the projected cube is taller than wide for the 4:3 image, so it fills
  // the height but for the margins.
  EXPECT_GT(ink.y1 - ink.y0, 300 * 0.85);
  EXPECT_GT(xmax - xmin, 200);
}

TEST(Particles, NonFiniteAndFarAwayPositionsDrawNothing) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<Rgb> colors = {kRed, kBlue, kBlue, kBlue};  // far away: off the image
  const std::vector<double> with_bad = {0.3, 0.4, 0.6, nan, inf, 0.5, 1e300, -1e300};
  const std::vector<double> good = {0.3, 0.4};
  const std::vector<Rgb> one = {kRed};
  const A3 lo{0, 0, 0}, hi{1, 1, 0};
  EXPECT_EQ(render_particles(with_bad, 2, colors, 0.05, lo, hi, flat_view()),
            render_particles(good, 2, one, 0.05, lo, hi, flat_view()));
}

TEST(Particles, ShadingIsBrighterTowardsTheLightAndTinyParticlesStillShow) {
  ParticleView view = flat_view();
  view.shaded = true;
  const std::vector<double> xyz = {0.5, 0.5};
  const std::vector<Rgb> colors = {Rgb{200, 200, 200}};
  const Image img = render_particles(xyz, 2, colors, 0.2, A3{0, 0, 0}, A3{1, 1, 0}, view);
  const double r = 0.2 / 1.4 * 276;  // projected radius
  const Rgb upper_left = img.at(static_cast<int>(200 - 0.5 * r), static_cast<int>(150 - 0.5 * r));
  const Rgb lower_right = img.at(static_cast<int>(200 + 0.5 * r), static_cast<int>(150 + 0.5 * r));
  EXPECT_GT(upper_left.r, lower_right.r + 60);
  // A particle far smaller than a pixel still inks its pixel.
  view.shaded = false;
  const std::vector<Rgb> red = {kRed};
  const Image tiny = render_particles(xyz, 2, red, 1e-6, A3{0, 0, 0}, A3{1, 1, 0}, view);
  EXPECT_EQ(tiny.at(200, 150), kRed);
}

TEST(Particles, BadArgumentsThrow) {
  const std::vector<double> xyz = {0.5, 0.5};
  const A3 lo{0, 0, 0}, hi{1, 1, 0};
  EXPECT_THROW(render_particles(xyz, 2, {}, -1.0, lo, hi, flat_view()), Error);
  EXPECT_THROW(render_particles(xyz, 2, {}, std::nan(""), lo, hi, flat_view()), Error);
  EXPECT_THROW(render_particles(xyz, 2, {}, 0.1, hi, lo, flat_view()), Error);
  EXPECT_THROW(render_particles(xyz, 2, {}, 0.1, lo, hi, flat_view(0, 10)), Error);
  // Programming errors are checks, not user errors.
  EXPECT_THROW(render_particles(xyz, 3, {}, 0.1, lo, hi, flat_view()), std::logic_error);
  const std::vector<Rgb> three = {kRed, kRed, kRed};
  EXPECT_THROW(render_particles(xyz, 2, three, 0.1, lo, hi, flat_view()), std::logic_error);
}

/// The pixel under a world point.
std::array<int, 2> pixel_of(const ParticleCamera& cam, const A3& p) {
  const A3 s = cam.project(p);
  return {static_cast<int>(std::floor(s[0])), static_cast<int>(std::floor(s[1]))};
}

// A polygon that reaches past the container: the simulation drops the part past the walls, and
// the picture draws it cut at the wall (it was drawn over the outline and into the margin).
TEST(ParticlesSolids, A2DPolygonPastTheContainerIsCutAtTheWall) {
  const A3 lo{0, 0, 0}, hi{1, 1, 0};
  SolidBox tri;
  tri.lo = A3{0.6, 0, 0}, tri.hi = A3{1.4, 0.5, 0};
  tri.vertices = {A3{0.6, 0, 0}, A3{1.4, 0, 0}, A3{1.4, 0.5, 0}};
  const std::vector<SolidBox> solids = {tri};
  const ParticleView view = flat_view();
  const Image img = render_particles({}, 2, {}, 0.03, lo, hi, view, solids);
  const ParticleCamera cam(2, lo, hi, 0.03, view);
  const auto inside = pixel_of(cam, A3{0.9, 0.1, 0});
  EXPECT_EQ(img.at(inside[0], inside[1]), kSolidColor);
  const int wall = static_cast<int>(std::floor(cam.project(A3{1.0, 0.1, 0})[0]));
  const PixelBox solid = bbox(img, [](Rgb c) { return c == kSolidColor; });
  EXPECT_LE(solid.x1, wall) << "no fill past the right wall";
  const auto past = pixel_of(cam, A3{1.2, 0.1, 0});
  if (past[0] < img.width()) {
    EXPECT_NE(img.at(past[0], past[1]), kSolidColor);
  }
}

TEST(ParticlesSolids, A2DObstacleIsAFilledRectangleWithADarkerOutlineOverTheParticles) {
  const A3 lo{0, 0, 0}, hi{1, 1, 0};
  const std::vector<SolidBox> solids = {{A3{0.4, 0, 0}, A3{0.6, 0.3, 0}}};
  // A particle leaked into the obstacle's middle and one well outside it.
  const std::vector<double> xyz = {0.5, 0.15, 0.2, 0.5};
  const std::vector<Rgb> colors = {kRed};
  const ParticleView view = flat_view();
  const Image img = render_particles(xyz, 2, colors, 0.03, lo, hi, view, solids);
  const ParticleCamera cam(2, lo, hi, 0.03, view);
  const auto center = pixel_of(cam, A3{0.5, 0.15, 0});
  EXPECT_EQ(img.at(center[0], center[1]), kSolidColor);  // over the leaked particle
  const auto outside = pixel_of(cam, A3{0.5, 0.6, 0});   // above it: background
  EXPECT_EQ(img.at(outside[0], outside[1]), kWhite);
  const auto beside = pixel_of(cam, A3{0.7, 0.15, 0});
  EXPECT_EQ(img.at(beside[0], beside[1]), kWhite);
  const auto particle = pixel_of(cam, A3{0.2, 0.5, 0});
  EXPECT_EQ(img.at(particle[0], particle[1]), kRed);
  // Along the row through the center: background, then the outline, the fill, the outline.
  const int left = static_cast<int>(std::ceil(cam.project(A3{0.4, 0.15, 0})[0] - 0.5));
  const int right = static_cast<int>(std::floor(cam.project(A3{0.6, 0.15, 0})[0] - 0.5));
  EXPECT_EQ(img.at(left - 1, center[1]), kWhite);
  EXPECT_EQ(img.at(left, center[1]), kSolidEdgeColor);
  EXPECT_EQ(img.at(left + 3, center[1]), kSolidColor);
  EXPECT_EQ(img.at(right, center[1]), kSolidEdgeColor);
  EXPECT_EQ(img.at(right + 1, center[1]), kWhite);
  // Its pixels are exactly those whose centers lie in the projected rectangle (outline included).
  const PixelBox solid = bbox(img, [](Rgb c) { return c == kSolidColor || c == kSolidEdgeColor; });
  EXPECT_EQ(solid.x0, left);
  EXPECT_EQ(solid.x1, right);
  EXPECT_EQ(solid.y0, static_cast<int>(std::ceil(cam.project(A3{0.5, 0.3, 0})[1] - 0.5)));
  EXPECT_EQ(solid.y1, static_cast<int>(std::floor(cam.project(A3{0.5, 0.0, 0})[1] - 0.5)));
}

TEST(ParticlesSolids, A3DObstacleShowsItsThreeFacesTurnedToTheCameraInDistinctGrays) {
  const A3 lo{-1, -1, -1}, hi{1, 1, 1};
  const std::vector<SolidBox> solids = {{A3{-0.3, -0.3, -0.3}, A3{0.3, 0.3, 0.3}}};
  ParticleView view = default_particle_view(3, 400, 300);  // from +x, +y, +z
  view.shaded = false;
  const Image img = render_particles({}, 3, {}, 0.05, lo, hi, view, solids);
  const ParticleCamera cam(3, lo, hi, 0.05, view);
  const auto center = pixel_of(cam, A3{0, 0, 0});
  const Rgb c = img.at(center[0], center[1]);
  EXPECT_NE(c, kWhite);
  EXPECT_TRUE(is_gray(c));
  std::vector<Rgb> faces;
  for (const A3& p : {A3{0.3, 0, 0}, A3{0, 0.3, 0}, A3{0, 0, 0.3}}) {  // the face centers
    const auto px = pixel_of(cam, p);
    const Rgb f = img.at(px[0], px[1]);
    EXPECT_TRUE(is_gray(f));
    EXPECT_LE(f.r, kSolidColor.r);
    EXPECT_GT(f.r, kSolidEdgeColor.r);
    faces.push_back(f);
  }
  EXPECT_NE(faces[0], faces[1]);
  EXPECT_NE(faces[1], faces[2]);
  EXPECT_NE(faces[0], faces[2]);
  // Outside the obstacle's projection (left of its leftmost corner) is background.
  double xmin = 1e9;
  for (int k = 0; k < 8; ++k)
    xmin = std::min(xmin, cam.project(A3{k & 1 ? 0.3 : -0.3, k & 2 ? 0.3 : -0.3, k & 4 ? 0.3 : -0.3})[0]);
  EXPECT_EQ(img.at(static_cast<int>(xmin) - 3, center[1]), kWhite);
  // The outline: along the row through the center, the first pixel darker than the container's
  // outline (gray 150, lighter where anti-aliased) is the obstacle's edge, at its silhouette.
  int first = 0;
  while (first < center[0] && img.at(first, center[1]).r >= 150) ++first;
  EXPECT_EQ(img.at(first, center[1]), kSolidEdgeColor);
  EXPECT_NEAR(first, xmin, 2.0);
}

TEST(ParticlesSolids, A3DObstacleHidesTheParticlesBehindItAndNotThoseInFront) {
  const A3 lo{-1, -1, -1}, hi{1, 1, 1};
  const std::vector<SolidBox> solids = {{A3{-0.3, -0.3, -0.3}, A3{0.3, 0.3, 0.3}}};
  for (const double azimuth : {0.0, 30.0}) {
    ParticleView view = flat_view();  // azimuth 0: looking along -z
    view.azimuth_deg = azimuth;
    view.elevation_deg = azimuth > 0 ? 20.0 : 0.0;
    const ParticleCamera cam(3, lo, hi, 0.1, view);
    const A3& towards_viewer = cam.axes()[2];
    const auto along = [&](double t) {
      return A3{t * towards_viewer[0], t * towards_viewer[1], t * towards_viewer[2]};
    };
    const auto center = pixel_of(cam, A3{0, 0, 0});
    for (const double radius : {0.1, 1e-6}) {  // a disc, and a particle smaller than a pixel
      // Behind the obstacle (farther from the camera): hidden, whatever the index order.
      const A3 b = along(-0.8), f = along(0.8);
      const std::vector<double> behind = {b[0], b[1], b[2]};
      const std::vector<Rgb> red = {kRed};
      const Image hidden = render_particles(behind, 3, red, radius, lo, hi, view, solids);
      EXPECT_NE(hidden.at(center[0], center[1]), kRed) << azimuth << " " << radius;
      EXPECT_EQ(bbox(hidden, [](Rgb c) { return c == kRed; }).x1, -1) << azimuth << " " << radius;
      EXPECT_EQ(hidden, render_particles({}, 3, {}, radius, lo, hi, view, solids));
      // In front: seen.
      const std::vector<double> front = {f[0], f[1], f[2], b[0], b[1], b[2]};
      const std::vector<Rgb> colors = {kBlue, kRed};
      const Image seen = render_particles(front, 3, colors, radius, lo, hi, view, solids);
      EXPECT_EQ(seen.at(center[0], center[1]), kBlue) << azimuth << " " << radius;
    }
  }
  // Behind the obstacle but sticking out past its side: only the part outside its silhouette shows.
  const ParticleView view = flat_view();
  const ParticleCamera cam(3, lo, hi, 0.1, view);
  const std::vector<double> peeking = {0.35, 0, -0.7};
  const std::vector<Rgb> red = {kRed};
  const Image img = render_particles(peeking, 3, red, 0.1, lo, hi, view, solids);
  const PixelBox seen = bbox(img, [](Rgb c) { return c == kRed; });
  ASSERT_GE(seen.x1, 0);
  EXPECT_GE(seen.x0, cam.project(A3{0.3, 0, 0})[0] - 0.5);
  EXPECT_GT(seen.x1, cam.project(A3{0.4, 0, 0})[0]);
}

TEST(ParticlesSolids, ParticlesTouchingAFaceFromOutsideAreWhole) {
  // A particle resting on the obstacle's top and one against its front face, from the default
  // camera: nothing of them is hidden, as without the obstacle.
  const A3 lo{-1, -1, -1}, hi{1, 1, 1};
  const double r = 0.1;
  const std::vector<SolidBox> solids = {{A3{-0.3, -0.3, -0.3}, A3{0.3, 0.3, 0.3}}};
  ParticleView view = default_particle_view(3, 400, 300);
  view.shaded = false;
  for (const A3& p : {A3{0, 0.3 + r, 0}, A3{0, 0, 0.3 + r}, A3{0.3 + r, 0, 0}}) {
    const std::vector<double> xyz = {p[0], p[1], p[2]};
    const std::vector<Rgb> red = {kRed};
    const auto count = [&](std::span<const SolidBox> s) {
      const Image img = render_particles(xyz, 3, red, r, lo, hi, view, s);
      return static_cast<int>(std::count(img.pixels().begin(), img.pixels().end(), kRed));
    };
    const int alone = count({});
    EXPECT_GT(alone, 100);
    EXPECT_EQ(count(solids), alone) << p[0] << " " << p[1] << " " << p[2];
  }
}

TEST(ParticlesSolids, WithoutObstaclesTheImageIsUnchanged) {
  std::vector<double> xyz2, xyz3;
  for (int i = 0; i < 50; ++i) {
    const double t = i / 50.0;
    xyz2.insert(xyz2.end(), {t, 0.5 + 0.4 * std::sin(6 * t)});
    xyz3.insert(xyz3.end(), {t, 0.5 + 0.4 * std::sin(6 * t), 0.5 + 0.4 * std::cos(5 * t)});
  }
  const std::vector<Rgb> colors = {kRed};
  const A3 lo{0, 0, 0}, hi{1, 1, 1};
  const std::vector<SolidBox> none;
  // An obstacle far off the image goes through the solids' code and must change nothing either.
  const std::vector<SolidBox> off_image = {{A3{5, 5, 5}, A3{6, 6, 6}}};
  for (const bool shaded : {false, true}) {
    ParticleView v2 = default_particle_view(2, 320, 240), v3 = default_particle_view(3, 320, 240);
    v2.shaded = v3.shaded = shaded;
    const Image img2 = render_particles(xyz2, 2, colors, 0.03, lo, hi, v2);
    EXPECT_EQ(render_particles(xyz2, 2, colors, 0.03, lo, hi, v2, none), img2);
    EXPECT_EQ(render_particles(xyz2, 2, colors, 0.03, lo, hi, v2, off_image), img2);
    const Image img3 = render_particles(xyz3, 3, colors, 0.03, lo, hi, v3);
    EXPECT_EQ(render_particles(xyz3, 3, colors, 0.03, lo, hi, v3, none), img3);
    EXPECT_EQ(render_particles(xyz3, 3, colors, 0.03, lo, hi, v3, off_image), img3);
    EXPECT_NE(std::count(img3.pixels().begin(), img3.pixels().end(), kWhite), 320 * 240);
  }
}

/// A 2D box [lo, hi] turned by `angle` radians about its middle and shifted by `shift`.
SolidBox placed_2d(const A3& lo, const A3& hi, double angle, const A3& shift = {}) {
  SolidBox s{lo, hi};
  const double c = std::cos(angle), n = std::sin(angle);
  s.rotation = {c, -n, 0, n, c, 0, 0, 0, 1};
  s.center = {0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0};
  s.translation = shift;
  return s;
}

bool is_solid(Rgb c) { return c == kSolidColor || c == kSolidEdgeColor; }

TEST(ParticlesSolids, A2DObstacleTurnedByItsPoseIsDrawnTurned) {
  const A3 lo{0, 0, 0}, hi{1, 1, 0};
  const ParticleView view = flat_view(400, 400);
  const ParticleCamera cam(2, lo, hi, 0.02, view);
  const A3 blo{0.35, 0.35, 0}, bhi{0.65, 0.65, 0};  // a square of side 0.3 about (0.5, 0.5)
  const std::vector<SolidBox> upright = {{blo, bhi}};
  const std::vector<SolidBox> turned = {placed_2d(blo, bhi, std::numbers::pi / 4)};
  const Image a = render_particles({}, 2, {}, 0.02, lo, hi, view, upright);
  const Image b = render_particles({}, 2, {}, 0.02, lo, hi, view, turned);
  const auto at = [&](const Image& img, double x, double y) {
    const auto px = pixel_of(cam, A3{x, y, 0});
    return img.at(px[0], px[1]);
  };
  // Turned by 45 degrees the square is a diamond |x - 0.5| + |y - 0.5| <= 0.15 sqrt(2) = 0.212:
  // its corners point along the axes, past the upright square's sides, and the upright square's
  // corners are outside it.
  for (const auto& [x, y] : {std::pair{0.69, 0.5}, std::pair{0.31, 0.5}, std::pair{0.5, 0.69}, std::pair{0.5, 0.31}}) {
    EXPECT_TRUE(is_solid(at(b, x, y))) << x << " " << y;
    EXPECT_EQ(at(a, x, y), kWhite) << x << " " << y;
  }
  for (const auto& [x, y] :
       {std::pair{0.37, 0.37}, std::pair{0.63, 0.37}, std::pair{0.63, 0.63}, std::pair{0.37, 0.63}}) {
    EXPECT_EQ(at(b, x, y), kWhite) << x << " " << y;
    EXPECT_TRUE(is_solid(at(a, x, y))) << x << " " << y;
  }
  EXPECT_EQ(at(b, 0.5, 0.5), kSolidColor);
  // The outline runs along the diamond's sides: along the row through y = 0.55, the first pixel
  // that is not background is the outline's, where the side crosses the row (x = 0.5 - 0.212 + 0.05).
  const auto row = pixel_of(cam, A3{0.5, 0.55, 0});
  int first = pixel_of(cam, A3{0.1, 0.55, 0})[0];
  while (first < row[0] && b.at(first, row[1]) == kWhite) ++first;
  EXPECT_EQ(b.at(first, row[1]), kSolidEdgeColor);
  EXPECT_NEAR(first + 0.5, cam.project(A3{0.5 - 0.15 * std::sqrt(2.0) + 0.05, 0.55, 0})[0], 1.5);
  // Turning keeps the area: the same number of pixels to within the outline's rasterization.
  const auto count = [](const Image& img) {
    return static_cast<double>(std::count_if(img.pixels().begin(), img.pixels().end(), is_solid));
  };
  EXPECT_NEAR(count(b), count(a), 0.03 * count(a));
  EXPECT_GT(count(a), 1000);
}

TEST(ParticlesSolids, A2DObstacleTranslatedByItsPoseIsDrawnShifted) {
  const A3 lo{0, 0, 0}, hi{1, 1, 0};
  const ParticleView view = flat_view();
  const A3 blo{0.1, 0.1, 0}, bhi{0.3, 0.25, 0}, shift{0.5, 0.4, 0};
  SolidBox moved{blo, bhi};
  moved.translation = shift;
  const std::vector<SolidBox> solids = {moved};
  const Image img = render_particles({}, 2, {}, 0.02, lo, hi, view, solids);
  // The same picture as the box drawn at its shifted corners, and nothing at its place at rest.
  const std::vector<SolidBox> there = {
      {A3{blo[0] + shift[0], blo[1] + shift[1], 0}, A3{bhi[0] + shift[0], bhi[1] + shift[1], 0}}};
  EXPECT_EQ(img, render_particles({}, 2, {}, 0.02, lo, hi, view, there));
  const ParticleCamera cam(2, lo, hi, 0.02, view);
  const auto rest = pixel_of(cam, A3{0.2, 0.175, 0});
  const auto now = pixel_of(cam, A3{0.7, 0.575, 0});
  EXPECT_EQ(img.at(rest[0], rest[1]), kWhite);
  EXPECT_EQ(img.at(now[0], now[1]), kSolidColor);
  // A turn by a full circle, with a translation, is the same shifted box.
  const std::vector<SolidBox> full_turn = {placed_2d(blo, bhi, 2 * std::numbers::pi, shift)};
  const Image turned = render_particles({}, 2, {}, 0.02, lo, hi, view, full_turn);
  EXPECT_TRUE(is_solid(turned.at(now[0], now[1])));
  EXPECT_EQ(turned.at(rest[0], rest[1]), kWhite);
}

TEST(ParticlesSolids, A3DObstacleIsDrawnWithItsRotatedFaces) {
  const A3 lo{-1, -1, -1}, hi{1, 1, 1};
  ParticleView view = default_particle_view(3, 400, 300);  // from +x, +y, +z
  view.shaded = false;
  const ParticleCamera cam(3, lo, hi, 0.05, view);
  // A box 0.2 x 0.4 x 0.6 turned by +90 degrees about y (x -> -z, z -> x) is the box 0.6 x 0.4 x
  // 0.2: the same picture, which needs the faces turned to the camera chosen by their rotated
  // normals (the box's own +x, +y, +z faces are not the ones seen once it is turned).
  SolidBox turned{A3{-0.1, -0.2, -0.3}, A3{0.1, 0.2, 0.3}};
  turned.rotation = {0, 0, 1, 0, 1, 0, -1, 0, 0};
  const std::vector<SolidBox> a = {turned};
  const std::vector<SolidBox> b = {{A3{-0.3, -0.2, -0.1}, A3{0.3, 0.2, 0.1}}};
  const std::vector<SolidBox> unturned = {{turned.lo, turned.hi}};
  const Image img = render_particles({}, 3, {}, 0.05, lo, hi, view, a);
  const Image same = render_particles({}, 3, {}, 0.05, lo, hi, view, b);
  const Image other = render_particles({}, 3, {}, 0.05, lo, hi, view, unturned);
  const auto differing = [](const Image& x, const Image& y) {
    int n = 0;
    for (int yy = 0; yy < x.height(); ++yy)
      for (int xx = 0; xx < x.width(); ++xx) n += x.at(xx, yy) != y.at(xx, yy);
    return n;
  };
  EXPECT_LE(differing(img, same), 10);  // ties between faces along their shared edges at most
  EXPECT_GT(differing(img, other), 500);
  // Turned by 30 degrees about an oblique axis and shifted: drawn over its placed center, its
  // three faces turned to the camera (by their rotated normals) in three grays, and nothing at its
  // place at rest.
  SolidBox oblique{A3{-0.3, -0.2, -0.1}, A3{0.3, 0.2, 0.1}};
  const double s = std::sqrt(1.0 / 3.0), c = std::cos(std::numbers::pi / 6), n = std::sin(std::numbers::pi / 6),
               k = 1 - c;  // Rodrigues' formula about (1, 1, 1) / sqrt(3)
  oblique.rotation = {c + s * s * k,     s * s * k - s * n, s * s * k + s * n, s * s * k + s * n, c + s * s * k,
                      s * s * k - s * n, s * s * k - s * n, s * s * k + s * n, c + s * s * k};
  oblique.translation = {0.6, 0.5, 0};
  const std::vector<SolidBox> o = {oblique};
  const Image oi = render_particles({}, 3, {}, 0.05, lo, hi, view, o);
  const auto center = pixel_of(cam, A3{0.6, 0.5, 0});
  const Rgb mid = oi.at(center[0], center[1]);
  EXPECT_TRUE(is_gray(mid));
  EXPECT_LE(mid.r, kSolidColor.r);
  EXPECT_GT(mid.r, kSolidEdgeColor.r);
  const auto rest = pixel_of(cam, A3{0, 0, 0});
  EXPECT_EQ(oi.at(rest[0], rest[1]), kWhite);
  std::vector<Rgb> faces;
  for (int a = 0; a < 3; ++a) {
    const A3 axis{oblique.rotation[a], oblique.rotation[3 + a], oblique.rotation[6 + a]};
    const double toward = axis[0] * cam.axes()[2][0] + axis[1] * cam.axes()[2][1] + axis[2] * cam.axes()[2][2];
    ASSERT_GT(std::abs(toward), 0.05);
    const double half = toward > 0 ? oblique.hi[a] : oblique.lo[a];  // the face turned to the camera
    const A3 at{0.6 + half * axis[0], 0.5 + half * axis[1], half * axis[2]};
    const auto px = pixel_of(cam, at);
    const Rgb f = oi.at(px[0], px[1]);
    EXPECT_TRUE(is_gray(f)) << a;
    EXPECT_LE(f.r, kSolidColor.r) << a;
    EXPECT_GT(f.r, kSolidEdgeColor.r) << a;
    faces.push_back(f);
  }
  EXPECT_NE(faces[0], faces[1]);
  EXPECT_NE(faces[1], faces[2]);
  EXPECT_NE(faces[0], faces[2]);
}

TEST(ParticlesSolids, BadObstaclesThrow) {
  const A3 lo{0, 0, 0}, hi{1, 1, 1};
  const std::vector<SolidBox> flipped = {{A3{0.6, 0, 0}, A3{0.4, 1, 1}}};
  const std::vector<SolidBox> nan = {{A3{0, std::nan(""), 0}, A3{1, 1, 1}}};
  EXPECT_THROW(render_particles({}, 2, {}, 0.1, lo, hi, flat_view(), flipped), Error);
  EXPECT_THROW(render_particles({}, 3, {}, 0.1, lo, hi, flat_view(), nan), Error);
  // z does not matter in 2D.
  const std::vector<SolidBox> flat = {{A3{0.2, 0.2, 5}, A3{0.4, 0.4, -5}}};
  EXPECT_NO_THROW(render_particles({}, 2, {}, 0.1, lo, hi, flat_view(), flat));
  // A placement that is not finite.
  std::vector<SolidBox> placed = {{A3{0.2, 0.2, 0.2}, A3{0.4, 0.4, 0.4}}};
  placed[0].translation[1] = std::numeric_limits<double>::infinity();
  EXPECT_THROW(render_particles({}, 3, {}, 0.1, lo, hi, flat_view(), placed), Error);
  placed[0].translation[1] = 0;
  placed[0].rotation[4] = std::nan("");
  EXPECT_THROW(render_particles({}, 2, {}, 0.1, lo, hi, flat_view(), placed), Error);
}

}  // namespace
}  // namespace sph
