// Line plots: the data lands where it should, the legend names every series, log axes are
// logarithmic, and empty, NaN and non-positive data are handled.

#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include <sph/core/error.h>
#include <sph/render/plot.h>

namespace sph {
namespace {

constexpr Rgb kLineRed{230, 20, 20};
constexpr Rgb kLineGreen{20, 170, 40};
constexpr Rgb kMuted{140, 140, 140};  // the "no data" text
const double kNan = std::numeric_limits<double>::quiet_NaN();

Series line(std::vector<double> x, std::vector<double> y, Rgb color, std::string name = "line") {
  Series s;
  s.name = std::move(name);
  s.x = std::move(x);
  s.y = std::move(y);
  s.color = color;
  return s;
}

/// The longest horizontal run of color c in any row (the legend sample of a solid series).
struct HRun {
  int length = 0, row = -1, x0 = 0, x1 = -1;  ///< x0..x1 inclusive
};

HRun longest_run(const Image& img, Rgb c) {
  HRun best;
  for (int y = 0; y < img.height(); ++y) {
    int run = 0;
    for (int x = 0; x < img.width(); ++x) {
      run = img.at(x, y) == c ? run + 1 : 0;
      if (run > best.length) best = {run, y, x - run + 1, x};
    }
  }
  return best;
}

/// Pixels of color c that are not part of the legend sample `legend` (a few rows around it).
bool on_line(const Image& img, Rgb c, int x, int y, const HRun& legend) {
  if (img.at(x, y) != c) return false;
  return !(legend.row >= 0 && std::abs(y - legend.row) <= 3 && x >= legend.x0 - 3 && x <= legend.x1 + 3);
}

/// Mean row of the line pixels (color c, legend excluded) in column x, or NaN if none.
double mean_row(const Image& img, Rgb c, int x, const HRun& legend = {}) {
  double sum = 0;
  int n = 0;
  for (int y = 0; y < img.height(); ++y)
    if (on_line(img, c, x, y, legend)) {
      sum += y;
      ++n;
    }
  return n ? sum / n : kNan;
}

int count(const Image& img, Rgb c) {
  int n = 0;
  for (const Rgb& p : img.pixels()) n += p == c;
  return n;
}

/// Columns holding line pixels of color c (legend excluded).
std::vector<int> columns_with(const Image& img, Rgb c, const HRun& legend) {
  std::vector<int> cols;
  for (int x = 0; x < img.width(); ++x)
    if (!std::isnan(mean_row(img, c, x, legend))) cols.push_back(x);
  return cols;
}

TEST(Plot, RisingLineRisesAndTheLegendShowsItsColor) {
  PlotSpec spec;
  spec.title = "rising";
  spec.x_label = "x";
  spec.y_label = "y";
  std::vector<double> x, y;
  for (int i = 0; i <= 100; ++i) {
    x.push_back(i * 0.1);
    y.push_back(i * 0.1);
  }
  spec.series.push_back(line(x, y, kLineRed));
  const Image img = render_plot(spec, 900, 560);
  EXPECT_EQ(img.width(), 900);
  EXPECT_EQ(img.height(), 560);
  EXPECT_GT(count(img, kLineRed), 500);
  // The legend sample is a horizontal run of the series color; the diagonal line has none so long.
  const HRun legend = longest_run(img, kLineRed);
  EXPECT_GE(legend.length, 20);
  // The line: lower on the left, higher on the right, and straight.
  const std::vector<int> cols = columns_with(img, kLineRed, legend);
  ASSERT_GT(cols.size(), 600u);
  const int a = cols[cols.size() / 5], b = cols[cols.size() / 2], c = cols[cols.size() * 4 / 5];
  const double ya = mean_row(img, kLineRed, a, legend), yb = mean_row(img, kLineRed, b, legend),
               yc = mean_row(img, kLineRed, c, legend);
  EXPECT_GT(ya, yb + 50);  // image rows grow downwards
  EXPECT_GT(yb, yc + 50);
  EXPECT_NEAR(yb, ya + (b - a) * (yc - ya) / (c - a), 3.0);
}

TEST(Plot, LegendHasOneSamplePerSeriesAndDashedSamplesHaveGaps) {
  PlotSpec spec;
  spec.series.push_back(line({0, 1, 2}, {0, 1, 0}, kLineRed, "solid"));
  Series dashed = line({0, 1, 2}, {1, 0, 1}, kLineGreen, "dashed");
  dashed.dashed = true;
  spec.series.push_back(dashed);
  const Image img = render_plot(spec);
  EXPECT_GE(longest_run(img, kLineRed).length, 20);
  EXPECT_GT(count(img, kLineGreen), 100);
  EXPECT_LT(longest_run(img, kLineGreen).length, 15);  // dashes, not a solid sample
}

TEST(Plot, NanBreaksTheLine) {
  PlotSpec spec;
  std::vector<double> x, y;
  for (int i = 0; i <= 100; ++i) {
    x.push_back(i);
    y.push_back(i >= 40 && i <= 60 ? kNan : 50.0 + 0.2 * i);  // a gap over the middle fifth
  }
  spec.series.push_back(line(x, y, kLineRed, ""));
  const Image img = render_plot(spec);
  const HRun legend = longest_run(img, kLineRed);
  ASSERT_GE(legend.length, 20);
  const std::vector<int> cols = columns_with(img, kLineRed, legend);
  ASSERT_FALSE(cols.empty());
  // The data spans x = 0..100 and the axis too: the line covers the plot width but for the gap.
  const int first = cols.front(), last = cols.back(), span = last - first;
  EXPECT_GT(span, 700);
  int in_gap = 0;
  for (int col : cols) in_gap += col > first + span * 0.41 && col < first + span * 0.59;
  EXPECT_EQ(in_gap, 0);
  int left = 0, right = 0;
  for (int col : cols) {
    left += col < first + span * 0.38;
    right += col > first + span * 0.62;
  }
  EXPECT_GT(left, 250);
  EXPECT_GT(right, 250);
}

TEST(Plot, LogAxisStraightensAnExponential) {
  std::vector<double> x, y;
  for (int i = 0; i <= 40; ++i) {
    x.push_back(i * 0.1);
    y.push_back(std::pow(10.0, i * 0.1 - 2.0));  // 1e-2 .. 1e2
  }
  // Non-positive values are skipped on a log axis (and break the line).
  x.push_back(4.5);
  y.push_back(0.0);
  x.push_back(5.0);
  y.push_back(-1.0);
  PlotSpec spec;
  spec.log_y = true;
  spec.series.push_back(line(x, y, kLineRed));
  // Deviation from a straight line through the pixels at 50% and 90% of the drawn columns, at 70%
  // (the legend sits top left, away from these columns).
  auto straightness = [&](const Image& img) {
    const std::vector<int> cols = columns_with(img, kLineRed, longest_run(img, kLineRed));
    const int first = cols.front(), span = cols.back() - cols.front();
    const int a = first + span / 2, b = first + span * 7 / 10, c = first + span * 9 / 10;
    const double ya = mean_row(img, kLineRed, a), yb = mean_row(img, kLineRed, b), yc = mean_row(img, kLineRed, c);
    return std::abs(yb - (ya + (b - a) * (yc - ya) / (c - a)));
  };
  const Image log_img = render_plot(spec);
  EXPECT_LT(straightness(log_img), 3.0);
  spec.log_y = false;  // the same data on a linear axis bends strongly
  EXPECT_GT(straightness(render_plot(spec)), 30.0);
}

TEST(Plot, NoDataSaysSo) {
  PlotSpec empty_series;
  empty_series.title = "nothing";
  empty_series.series.push_back(line({}, {}, kLineRed, "empty"));
  PlotSpec all_nan;
  all_nan.series.push_back(line({kNan, 1, kNan}, {1, kNan, kNan}, kLineRed, "nan"));
  PlotSpec log_nonpositive;
  log_nonpositive.log_y = true;
  log_nonpositive.series.push_back(line({1, 2}, {0, -5}, kLineRed, "nonpositive"));
  PlotSpec no_series;
  for (const PlotSpec* spec : {&empty_series, &all_nan, &log_nonpositive, &no_series}) {
    const Image img = render_plot(*spec);
    // "no data" in gray near the middle of the image.
    int near_middle = 0;
    for (int y = img.height() / 3; y < img.height() * 2 / 3; ++y)
      for (int x = img.width() / 3; x < img.width() * 2 / 3; ++x) near_middle += img.at(x, y) == kMuted;
    EXPECT_GT(near_middle, 20);
  }
  // With data, no "no data" text.
  PlotSpec some;
  some.series.push_back(line({0, 1}, {0, 1}, kLineRed));
  EXPECT_EQ(count(render_plot(some), kMuted), 0);
}

TEST(Plot, SinglePointsAndConstantDataAreVisible) {
  PlotSpec spec;
  spec.series.push_back(line({3.0}, {7.0}, kLineRed, "one point"));
  spec.series.push_back(line({0, 1, 2, 3}, {7, 7, 7, 7}, kLineGreen, "flat"));
  const Image img = render_plot(spec);
  EXPECT_GT(count(img, kLineRed), 10);                  // the dot plus the legend's dot
  EXPECT_LT(longest_run(img, kLineRed).length, 8);      // a dot in the legend too, as the plot draws it
  EXPECT_GT(longest_run(img, kLineGreen).length, 100);  // the flat line
}

TEST(Plot, HugeAndTinyValuesAndManySeriesDoNotBreakTheLayout) {
  PlotSpec spec;
  spec.log_y = true;
  for (int k = 0; k < 6; ++k) {
    std::vector<double> x, y;
    for (int i = 0; i < 50; ++i) {
      x.push_back(1e7 + i * 1e5);
      y.push_back(std::pow(10.0, -30 + k * 10 + i * 0.1));
    }
    spec.series.push_back(line(x, y, Rgb{static_cast<std::uint8_t>(40 * k), 0, 0}, "s" + std::to_string(k)));
  }
  EXPECT_NO_THROW(render_plot(spec, 400, 300));
  EXPECT_NO_THROW(render_plot(spec, 160, 120));
  // Nearly constant data far from zero, and a range too wide for a double: no hang, no crash.
  PlotSpec odd;
  odd.series.push_back(line({1e17, 1e17 + 16, 1e17 + 32}, {1, 2, 3}, kLineRed));
  odd.series.push_back(line({0, 1}, {-1e308, 1e308}, kLineGreen));
  EXPECT_NO_THROW(render_plot(odd));
}

TEST(Plot, BadArgumentsThrow) {
  PlotSpec spec;
  EXPECT_THROW(render_plot(spec, 10, 10), Error);
  spec.series.push_back(line({1, 2, 3}, {1, 2}, kLineRed, "mismatched"));
  try {
    render_plot(spec);
    FAIL() << "expected sph::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("mismatched"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace sph
