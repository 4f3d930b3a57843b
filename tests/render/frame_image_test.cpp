// Pictures of frames for sph render: panels, time label, legends.

#include <vector>

#include <gtest/gtest.h>

#include <sph/core/error.h>
#include <sph/render/frame_image.h>

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

}  // namespace
