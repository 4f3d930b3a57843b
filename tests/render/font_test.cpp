// The bitmap font: ink stays inside the advertised text box and fills it tightly, every printable
// character has its own glyph, unknown characters draw as boxes.

#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <sph/render/font.h>

#include "support/colors.h"

namespace sph {
namespace {

using test::kWhite;

constexpr Rgb kPen{10, 20, 30};

struct InkBox {
  int x0 = 1 << 30, y0 = 1 << 30, x1 = -1, y1 = -1;  ///< inclusive; x1 < 0: no ink
  bool empty() const { return x1 < 0; }
};

InkBox ink_box(const Image& img) {
  InkBox b;
  for (int y = 0; y < img.height(); ++y)
    for (int x = 0; x < img.width(); ++x)
      if (img.at(x, y) != kWhite) {
        b.x0 = std::min(b.x0, x);
        b.y0 = std::min(b.y0, y);
        b.x1 = std::max(b.x1, x);
        b.y1 = std::max(b.y1, y);
      }
  return b;
}

std::string printable() {
  std::string s;
  for (int c = 32; c <= 126; ++c) s += static_cast<char>(c);
  return s;
}

TEST(Font, MetricsScaleLinearly) {
  EXPECT_EQ(text_width(""), 0);
  EXPECT_EQ(text_width("A"), 5);
  EXPECT_EQ(text_width("AB"), 11);
  EXPECT_EQ(text_width("AB", 3), 33);
  EXPECT_EQ(text_height(), 9);
  EXPECT_EQ(text_height(2), 18);
  EXPECT_EQ(text_width("AB", 0), text_width("AB", 1));  // scales below 1 count as 1
}

TEST(Font, InkStaysInsideTheTextBox) {
  for (int scale : {1, 2, 3}) {
    for (const std::string& text : {printable(), std::string("Hello, world! p_q{g}"), std::string("\x01\x7f\xe9")}) {
      Image img(text_width(text, scale) + 40, text_height(scale) + 40, kWhite);
      draw_text(img, 17, 23, text, kPen, scale);
      const InkBox b = ink_box(img);
      ASSERT_FALSE(b.empty()) << text;
      EXPECT_GE(b.x0, 17);
      EXPECT_GE(b.y0, 23);
      EXPECT_LT(b.x1, 17 + text_width(text, scale)) << "scale " << scale << ": " << text;
      EXPECT_LT(b.y1, 23 + text_height(scale)) << "scale " << scale << ": " << text;
      for (const Rgb& p : img.pixels()) ASSERT_TRUE(p == kWhite || p == kPen);  // crisp, one color
    }
  }
}

TEST(Font, TheBoxIsTightForTextReachingAllItsEdges) {
  // 'H' touches the left column and the top row; 'g' reaches the last column and the lowest row.
  for (int scale : {1, 2}) {
    Image img(100, 60, kWhite);
    draw_text(img, 5, 7, "Hg", kPen, scale);
    const InkBox b = ink_box(img);
    EXPECT_EQ(b.x0, 5);
    EXPECT_EQ(b.y0, 7);
    EXPECT_EQ(b.x1, 5 + text_width("Hg", scale) - 1);
    EXPECT_EQ(b.y1, 7 + text_height(scale) - 1);
  }
}

TEST(Font, EveryPrintableCharacterHasItsOwnGlyph) {
  std::set<std::vector<std::uint8_t>> seen;
  for (int c = 33; c <= 126; ++c) {
    Image img(5, 9, kWhite);
    draw_text(img, 0, 0, std::string(1, static_cast<char>(c)), kPen);
    const std::vector<std::uint8_t> px(img.bytes().begin(), img.bytes().end());
    EXPECT_FALSE(ink_box(img).empty()) << "no ink for '" << static_cast<char>(c) << "'";
    EXPECT_TRUE(seen.insert(px).second) << "glyph for '" << static_cast<char>(c) << "' repeats another";
  }
  Image space(5, 9, kWhite);
  draw_text(space, 0, 0, " ", kPen);
  EXPECT_TRUE(ink_box(space).empty());
}

TEST(Font, UnknownCharactersDrawAsABoxAndUtf8CountsOnce) {
  Image img(5, 9, kWhite);
  draw_text(img, 0, 0, "\x01", kPen);
  for (int y = 0; y < 7; ++y) {
    EXPECT_EQ(img.at(0, y), kPen);
    EXPECT_EQ(img.at(4, y), kPen);
  }
  for (int x = 0; x < 5; ++x) EXPECT_EQ(img.at(x, 0), kPen);
  EXPECT_EQ(img.at(2, 3), kWhite);
  EXPECT_EQ(text_width("\xc3\xa9"), text_width("e"));  // é: one character
  EXPECT_EQ(text_width("a\xe2\x82\xac"
                       "b"),
            text_width("abc"));  // €: one character
}

TEST(Font, DrawingIsClippedAtTheImageEdges) {
  Image img(8, 5, kWhite);
  draw_text(img, -3, -4, "WWW", kPen, 2);  // must not crash or wrap around
  EXPECT_FALSE(ink_box(img).empty());
}

TEST(Font, VerticalTextIsTheHorizontalTextTurnedCounterClockwise) {
  const std::string text = "Ag1";
  Image h(text_width(text), text_height(), kWhite);
  draw_text(h, 0, 0, text, kPen);
  Image v(text_height() + 10, text_width(text) + 10, kWhite);
  draw_text_vertical(v, 4, 3, text, kPen);
  const InkBox b = ink_box(v);
  EXPECT_GE(b.x0, 4);
  EXPECT_GE(b.y0, 3);
  EXPECT_LT(b.x1, 4 + text_height());
  EXPECT_LT(b.y1, 3 + text_width(text));
  // Horizontal pixel (gx, gy) lands at (gy, width - 1 - gx): the start of the text at the bottom.
  for (int gy = 0; gy < h.height(); ++gy)
    for (int gx = 0; gx < h.width(); ++gx)
      ASSERT_EQ(h.at(gx, gy), v.at(4 + gy, 3 + h.width() - 1 - gx)) << gx << "," << gy;
}

}  // namespace
}  // namespace sph
