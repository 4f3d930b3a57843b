// Composition: panels side by side under captions; a color bar beside an image.

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <sph/render/compose.h>

#include "support/colors.h"

namespace sph {
namespace {

using test::kBlue;
using test::kRed;
using test::kWhite;

TEST(Hstack, PlacesPanelsSideBySideUnderTheirCaptions) {
  const std::vector<Image> panels = {Image(40, 30, kRed), Image(50, 20, kBlue)};
  const std::vector<std::string> captions = {"standard", "adaptive"};
  const Image out = hstack(panels, captions, kWhite);
  // Two panels, a gap between them; a caption row on top.
  const int band = out.height() - 30;
  EXPECT_GT(band, 9);
  EXPECT_GT(out.width(), 90);
  EXPECT_LT(out.width(), 120);
  const int gap = out.width() - 90;
  EXPECT_EQ(out.at(0, band), kRed);
  EXPECT_EQ(out.at(39, band + 29), kRed);
  EXPECT_EQ(out.at(40 + gap, band), kBlue);
  EXPECT_EQ(out.at(40 + gap + 49, band + 19), kBlue);
  EXPECT_EQ(out.at(40 + gap, band + 25), kWhite);  // below the shorter panel
  EXPECT_EQ(out.at(40, band), kWhite);             // the gap
  // Caption ink above each panel.
  auto ink_in = [&](int x0, int x1) {
    int n = 0;
    for (int y = 0; y < band; ++y)
      for (int x = x0; x < x1; ++x) n += out.at(x, y) != kWhite;
    return n;
  };
  EXPECT_GT(ink_in(0, 40), 20);
  EXPECT_GT(ink_in(40 + gap, out.width()), 20);
}

TEST(Hstack, NoCaptionsNoCaptionRowAndNoPanelsNoImage) {
  const std::vector<Image> panels = {Image(10, 10, kRed), Image(10, 10, kBlue)};
  const Image out = hstack(panels, {}, kWhite);
  EXPECT_EQ(out.height(), 10);
  EXPECT_EQ(out.at(0, 0), kRed);
  EXPECT_EQ(out.at(out.width() - 1, 0), kBlue);
  EXPECT_TRUE(hstack({}, {}, kWhite).empty());
}

TEST(Colorbar, KeepsTheImageAndAddsTheMapFromLowToHigh) {
  const Image base(300, 200, kRed);
  const Image out = add_colorbar(base, Colormap::Viridis, 0.0, 2.5, "speed [m/s]");
  EXPECT_EQ(out.height(), 200);
  ASSERT_GT(out.width(), 300);
  for (int y = 0; y < 200; y += 7)
    for (int x = 0; x < 300; x += 7) ASSERT_EQ(out.at(x, y), kRed);
  // Somewhere in the strip: the high end of the map near the top, the low end near the bottom.
  const Rgb hi = colormap(Colormap::Viridis, 1.0), lo = colormap(Colormap::Viridis, 0.0);
  int hi_row = -1, lo_row = -1;
  for (int y = 0; y < out.height(); ++y)
    for (int x = 300; x < out.width(); ++x) {
      if (out.at(x, y) == hi && hi_row < 0) hi_row = y;
      if (out.at(x, y) == lo) lo_row = y;
    }
  ASSERT_GE(hi_row, 0);
  ASSERT_GE(lo_row, 0);
  EXPECT_LT(hi_row, 100);
  EXPECT_GT(lo_row, 100);
  EXPECT_GT(lo_row - hi_row, 100);  // a tall bar
}

TEST(Colorbar, LabelsMakeTheStripWider) {
  const Image base(100, 100, kWhite);
  const int plain = add_colorbar(base, Colormap::Turbo, 0, 1, "").width();
  const int labelled = add_colorbar(base, Colormap::Turbo, 0, 1, "pressure").width();
  const int long_ticks = add_colorbar(base, Colormap::Turbo, -123456.0, 0.000123, "").width();
  EXPECT_GT(labelled, plain);
  EXPECT_GT(long_ticks, plain);
}

}  // namespace
}  // namespace sph
