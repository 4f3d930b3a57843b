// Color maps: the published end colors, monotone luminance for viridis, clamping, the palette.

#include <cmath>
#include <set>
#include <tuple>

#include <gtest/gtest.h>

#include <sph/render/colormap.h>

namespace sph {
namespace {

double luminance(Rgb c) { return 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b; }

int distance(Rgb a, Rgb b) { return std::abs(a.r - b.r) + std::abs(a.g - b.g) + std::abs(a.b - b.b); }

TEST(Colormap, EndsMatchThePublishedMaps) {
  EXPECT_EQ(colormap(Colormap::Viridis, 0.0), (Rgb{68, 1, 84}));
  EXPECT_EQ(colormap(Colormap::Viridis, 1.0), (Rgb{253, 231, 37}));
  EXPECT_EQ(colormap(Colormap::Coolwarm, 0.0), (Rgb{59, 76, 192}));
  EXPECT_EQ(colormap(Colormap::Coolwarm, 1.0), (Rgb{180, 4, 38}));
  EXPECT_LE(distance(colormap(Colormap::Coolwarm, 0.5), Rgb{221, 221, 221}), 3);
  EXPECT_EQ(colormap(Colormap::Turbo, 0.0), (Rgb{48, 18, 59}));
  EXPECT_EQ(colormap(Colormap::Turbo, 1.0), (Rgb{122, 4, 3}));
}

TEST(Colormap, ClampsAndTreatsNanAsLow) {
  for (Colormap m : {Colormap::Viridis, Colormap::Coolwarm, Colormap::Turbo}) {
    EXPECT_EQ(colormap(m, -3.0), colormap(m, 0.0));
    EXPECT_EQ(colormap(m, 42.0), colormap(m, 1.0));
    EXPECT_EQ(colormap(m, std::nan("")), colormap(m, 0.0));
  }
}

TEST(Colormap, ViridisLuminanceRisesMonotonically) {
  double prev = -1.0;
  for (int i = 0; i <= 1000; ++i) {
    const double l = luminance(colormap(Colormap::Viridis, i / 1000.0));
    EXPECT_GE(l, prev - 0.5) << "t = " << i / 1000.0;  // allow 8-bit rounding
    prev = l;
  }
  EXPECT_GT(luminance(colormap(Colormap::Viridis, 1.0)) - luminance(colormap(Colormap::Viridis, 0.0)), 150.0);
}

TEST(Colormap, InterpolatesContinuously) {
  for (Colormap m : {Colormap::Viridis, Colormap::Coolwarm, Colormap::Turbo})
    for (int i = 0; i < 1000; ++i) EXPECT_LE(distance(colormap(m, i / 1000.0), colormap(m, (i + 1) / 1000.0)), 12) << i;
}

TEST(Colormap, ValueRangeVersion) {
  EXPECT_EQ(colormap(Colormap::Viridis, 5.0, 0.0, 10.0), colormap(Colormap::Viridis, 0.5));
  EXPECT_EQ(colormap(Colormap::Viridis, 10.0, 10.0, 0.0), colormap(Colormap::Viridis, 0.0));  // reversed
  EXPECT_EQ(colormap(Colormap::Viridis, 3.0, 2.0, 2.0), colormap(Colormap::Viridis, 0.5));
  EXPECT_EQ(colormap(Colormap::Viridis, std::nan(""), 0.0, 1.0, Rgb{1, 2, 3}), (Rgb{1, 2, 3}));
}

TEST(Colormap, NamesRoundTrip) {
  for (Colormap m : {Colormap::Viridis, Colormap::Coolwarm, Colormap::Turbo})
    EXPECT_EQ(colormap_from_name(colormap_name(m)), m);
  EXPECT_FALSE(colormap_from_name("jet").has_value());
}

TEST(SeriesColor, FirstEightAreDistinctAndReadableOnWhite) {
  std::set<std::tuple<int, int, int>> seen;
  for (int k = 0; k < 8; ++k) {
    const Rgb c = series_color(k);
    EXPECT_TRUE(seen.insert({c.r, c.g, c.b}).second) << k;
    EXPECT_LT(luminance(c), 200.0) << "too light for a line on white: " << k;
    for (int j = 0; j < k; ++j) EXPECT_GT(distance(c, series_color(j)), 80) << k << " vs " << j;
  }
  EXPECT_EQ(series_color(8), series_color(0));
  EXPECT_EQ(series_color(-1), series_color(7));
}

}  // namespace
}  // namespace sph
