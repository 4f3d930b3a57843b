// Image: pixel access, blending, clipping and the drawing primitives the other render code uses.

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include <sph/render/image.h>

#include "support/colors.h"

namespace sph {
namespace {

using test::kBlue;
using test::kRed;
using test::kWhite;

int count_color(const Image& img, Rgb c) {
  int n = 0;
  for (const Rgb& p : img.pixels()) n += p == c;
  return n;
}

TEST(Image, FilledWithTheBackgroundAndRowMajor) {
  Image img(4, 3, Rgb{1, 2, 3});
  EXPECT_EQ(img.width(), 4);
  EXPECT_EQ(img.height(), 3);
  EXPECT_EQ(img.pixels().size(), 12u);
  EXPECT_EQ(img.bytes().size(), 36u);
  EXPECT_EQ(count_color(img, Rgb{1, 2, 3}), 12);
  img.set(3, 1, kRed);
  EXPECT_EQ(img.at(3, 1), kRed);
  EXPECT_EQ(img.pixels()[1 * 4 + 3], kRed);
  EXPECT_EQ(img.bytes()[(1 * 4 + 3) * 3 + 0], 255);
  EXPECT_EQ(img.bytes()[(1 * 4 + 3) * 3 + 1], 0);
}

TEST(Image, AtOutsideIsABugSetOutsideIsIgnored) {
  Image img(2, 2, kWhite);
  EXPECT_THROW((void)img.at(2, 0), std::logic_error);
  EXPECT_THROW((void)img.at(0, -1), std::logic_error);
  img.set(-1, 0, kRed);
  img.set(0, 2, kRed);
  img.blend(5, 5, kRed, 1.0);
  EXPECT_EQ(count_color(img, kWhite), 4);
}

TEST(Image, BlendMixesByAlphaAndClampsIt) {
  Image img(3, 1, Rgb{0, 0, 0});
  img.blend(0, 0, Rgb{200, 100, 50}, 0.5);
  EXPECT_EQ(img.at(0, 0), (Rgb{100, 50, 25}));
  img.blend(1, 0, kRed, 7.0);
  EXPECT_EQ(img.at(1, 0), kRed);
  img.blend(2, 0, kRed, -1.0);
  EXPECT_EQ(img.at(2, 0), (Rgb{0, 0, 0}));
}

TEST(Image, FillRectIsClipped) {
  Image img(5, 5, kWhite);
  img.fill_rect(3, -2, 10, 4, kRed);  // covers x 3..4, y 0..1
  EXPECT_EQ(count_color(img, kRed), 4);
  EXPECT_EQ(img.at(3, 0), kRed);
  EXPECT_EQ(img.at(4, 1), kRed);
  EXPECT_EQ(img.at(2, 0), kWhite);
  EXPECT_EQ(img.at(3, 2), kWhite);
}

TEST(Image, HorizontalLineCoversItsPixelsAndNothingFar) {
  Image img(20, 9, kWhite);
  img.draw_line(2.5, 4.5, 16.5, 4.5, kRed, 1.0);
  for (int x = 3; x <= 16; ++x) EXPECT_EQ(img.at(x, 4), kRed) << x;
  for (int x = 0; x < 20; ++x) {
    EXPECT_EQ(img.at(x, 2), kWhite);
    EXPECT_EQ(img.at(x, 6), kWhite);
  }
  EXPECT_EQ(img.at(0, 4), kWhite);
  EXPECT_EQ(img.at(19, 4), kWhite);
}

TEST(Image, ThickDiagonalLineStaysNearTheSegment) {
  Image img(40, 40, kWhite);
  img.draw_line(5, 5, 35, 35, kBlue, 3.0);
  int inked = 0;
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 40; ++x) {
      if (img.at(x, y) == kWhite) continue;
      ++inked;
      // Distance of the pixel center to the line y = x is |x - y| / sqrt(2).
      EXPECT_LE(std::abs(x - y) / std::sqrt(2.0), 2.0 + 1e-9) << x << "," << y;
    }
  EXPECT_GT(inked, 30 * 3);
  EXPECT_EQ(img.at(20, 20), kBlue);
}

TEST(Image, LinesWithNonFiniteEndsDrawNothing) {
  Image img(10, 10, kWhite);
  img.draw_line(0, 0, std::nan(""), 5, kRed, 2.0);
  img.draw_line(0, 0, 5, std::numeric_limits<double>::infinity(), kRed, 2.0);
  EXPECT_EQ(count_color(img, kWhite), 100);
}

TEST(Image, HugeCoordinatesAreClippedNotOverflowed) {
  Image img(10, 10, kWhite);
  img.draw_line(-1e300, 5.5, 1e300, 5.5, kRed, 1.0);
  for (int x = 0; x < 10; ++x) EXPECT_EQ(img.at(x, 5), kRed);
  EXPECT_EQ(count_color(img, kRed), 10);
  img.fill_disc(1e300, -1e300, 1e10, kBlue);
  img.fill_disc(5, 5, 1e300, kBlue);  // covers everything
  EXPECT_EQ(count_color(img, kBlue), 100);
}

TEST(Image, DiscCoversItsCenterAndStaysWithinItsRadius) {
  Image img(30, 30, kWhite);
  img.fill_disc(15, 15, 6, kRed);
  EXPECT_EQ(img.at(15, 15), kRed);
  EXPECT_EQ(img.at(10, 15), kRed);
  for (int y = 0; y < 30; ++y)
    for (int x = 0; x < 30; ++x)
      if (img.at(x, y) != kWhite) {
        EXPECT_LE(std::hypot(x + 0.5 - 15, y + 0.5 - 15), 6.5 + 1e-9);
      }
  // Fully covered pixels: centers within r - 0.5 of the center.
  EXPECT_NEAR(count_color(img, kRed), 3.14159 * 5.5 * 5.5, 12);
}

TEST(Image, BlitCopiesAndClips) {
  Image src(3, 2, kRed);
  src.set(0, 0, kBlue);
  Image dst(4, 4, kWhite);
  dst.blit(src, 2, 3);  // only src (0..1, 0) lands inside
  EXPECT_EQ(dst.at(2, 3), kBlue);
  EXPECT_EQ(dst.at(3, 3), kRed);
  EXPECT_EQ(count_color(dst, kWhite), 14);
  Image dst2(4, 4, kWhite);
  dst2.blit(src, -1, -1);  // only src (1..2, 1) lands inside
  EXPECT_EQ(dst2.at(0, 0), kRed);
  EXPECT_EQ(dst2.at(1, 0), kRed);
  EXPECT_EQ(count_color(dst2, kRed), 2);
}

TEST(Image, MixAndScaled) {
  EXPECT_EQ(mix(Rgb{0, 0, 0}, Rgb{255, 255, 255}, 0.0), (Rgb{0, 0, 0}));
  EXPECT_EQ(mix(Rgb{0, 0, 0}, Rgb{255, 255, 255}, 1.0), (Rgb{255, 255, 255}));
  EXPECT_EQ(mix(Rgb{0, 100, 200}, Rgb{100, 100, 0}, 0.5), (Rgb{50, 100, 100}));
  EXPECT_EQ(scaled(Rgb{100, 200, 10}, 2.0), (Rgb{200, 255, 20}));
}

}  // namespace
}  // namespace sph
