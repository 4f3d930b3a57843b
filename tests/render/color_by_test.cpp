// Coloring particles by a quantity of a frame: names, units, values, run-wide ranges, colors.

#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include <sph/core/error.h>
#include <sph/render/color_by.h>

#include "support/expect.h"

namespace {

using namespace sph;

/// A run of `dim` dimensions in the box [0, 2] x [0, 1] x [0, 4] (z flat in 2D), mass 0.5.
RunDirectory test_run(int dim) {
  RunDirectory run;
  run.dir = "/runs/test";
  run.dimension = dim;
  run.particle_mass = 0.5;
  run.box_lo = {0, 0, 0};
  run.box_hi = {2, 1, dim == 3 ? 4.0 : 0.0};
  return run;
}

/// Two particles: at rest, and moving with velocity (3, 4, 0).
FrameData two_particles() {
  FrameData f;
  f.size = 2;
  f.position = {0.5, 0.5, 0, 1.5, 0.5, 0};
  f.fields.push_back({"velocity", 3, {0, 0, 0, 3, 4, 0}});
  f.fields.push_back({"density", 1, {990, 1010}});
  f.fields.push_back({"pressure", 1, {0, 250}});
  f.fields.push_back({"initial_position", 3, {0, 0, 0, 2, 1, 4}});
  return f;
}

TEST(ColorBy, NamesRoundTripAndUnknownNamesAreRefused) {
  for (ColorBy by : kColorByAll) {
    ASSERT_EQ(color_by_from_name(color_by_name(by)), by);
    EXPECT_CONTAINS(color_by_names(), std::string(color_by_name(by)));
  }
  EXPECT_FALSE(color_by_from_name("Speed"));
  EXPECT_FALSE(color_by_from_name("velocity"));
  EXPECT_FALSE(color_by_from_name(""));
}

TEST(ColorBy, LabelsCarryTheUnitOfTheDimension) {
  EXPECT_EQ(color_by_label(ColorBy::Density, 2), "density (kg/m^2)");
  EXPECT_EQ(color_by_label(ColorBy::Density, 3), "density (kg/m^3)");
  EXPECT_EQ(color_by_label(ColorBy::KineticEnergy, 2), "kinetic energy (J/m)");
  EXPECT_EQ(color_by_label(ColorBy::Pressure, 3), "pressure (Pa)");
  EXPECT_EQ(color_by_label(ColorBy::Speed, 3), "speed (m/s)");
  EXPECT_FALSE(color_by_is_scalar(ColorBy::InitialPosition));
  EXPECT_TRUE(color_by_is_scalar(ColorBy::Pressure));
}

TEST(ColorBy, ValuesAreComputedFromTheFields) {
  const RunDirectory run = test_run(3);
  const FrameData f = two_particles();
  EXPECT_EQ(color_values(f, ColorBy::Speed, run), (std::vector<double>{0.0, 5.0}));
  EXPECT_EQ(color_values(f, ColorBy::KineticEnergy, run), (std::vector<double>{0.0, 0.5 * 0.5 * 25.0}));
  EXPECT_EQ(color_values(f, ColorBy::Density, run), (std::vector<double>{990, 1010}));
  EXPECT_EQ(color_values(f, ColorBy::Pressure, run), (std::vector<double>{0, 250}));
  EXPECT_EQ(color_values(f, ColorBy::InitialPosition, run), (std::vector<double>{0, 1}));  // initial height
}

TEST(ColorBy, AMissingFieldNamesTheFieldAndTheRun) {
  const RunDirectory run = test_run(2);
  FrameData f = two_particles();
  f.fields.erase(f.fields.begin());  // no velocity
  try {
    color_values(f, ColorBy::Speed, run);
    FAIL() << "expected sph::Error";
  } catch (const Error& e) {
    EXPECT_CONTAINS(e.what(), "'velocity'");
    EXPECT_CONTAINS(e.what(), "/runs/test");
    EXPECT_CONTAINS(e.what(), "--fields");
  }
  EXPECT_NO_THROW(color_values(f, ColorBy::Density, run));
  f.fields[0].values.pop_back();  // density: one value short
  EXPECT_THROW(color_values(f, ColorBy::Density, run), Error);
}

TEST(ColorBy, RangesStartAtZeroForSpeedAndIgnoreAFewOutliers) {
  std::vector<std::vector<double>> frames(2);
  for (int i = 0; i < 1000; ++i) frames[i % 2].push_back(1.0 + i / 1000.0);  // 1 .. 2
  frames[0].push_back(500.0);                                                // one spray particle
  frames[1].push_back(std::numeric_limits<double>::quiet_NaN());
  const auto [lo, hi] = color_range(ColorBy::Speed, frames);
  EXPECT_EQ(lo, 0.0);
  EXPECT_GT(hi, 1.98);
  EXPECT_LT(hi, 2.0);
  const auto [dlo, dhi] = color_range(ColorBy::Density, frames);  // percentiles at both ends
  EXPECT_GT(dlo, 1.0);
  EXPECT_LT(dlo, 1.01);
  EXPECT_NEAR(dhi, hi, 1e-12);
}

TEST(ColorBy, DegenerateRangesStillHaveWidth) {
  const std::vector<std::vector<double>> none{{std::nan("")}};
  EXPECT_EQ(color_range(ColorBy::Density, none), (std::pair<double, double>{0.0, 1.0}));
  const std::vector<std::vector<double>> flat{{1000.0, 1000.0}};
  const auto [lo, hi] = color_range(ColorBy::Density, flat);
  EXPECT_LT(lo, 1000.0);
  EXPECT_GT(hi, 1000.0);
  const std::vector<std::vector<double>> still{{0.0, 0.0}};
  const auto [slo, shi] = color_range(ColorBy::Speed, still);
  EXPECT_LT(slo, shi);
}

TEST(ColorBy, ScalarColorsFollowTheMapOverTheRange) {
  const RunDirectory run = test_run(3);
  const ColorSpec spec{ColorBy::Speed, Colormap::Viridis, 0.0, 5.0};
  const std::vector<Rgb> c = particle_colors(two_particles(), spec, run);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c[0], colormap(Colormap::Viridis, 0.0));
  EXPECT_EQ(c[1], colormap(Colormap::Viridis, 1.0));
  const ColorSpec narrow{ColorBy::Speed, Colormap::Viridis, 0.0, 10.0};
  EXPECT_EQ(particle_colors(two_particles(), narrow, run)[1], colormap(Colormap::Viridis, 0.5));
}

TEST(ColorBy, InitialPositionGivesEachAxisAChannel) {
  const RunDirectory run = test_run(3);
  const ColorSpec spec{ColorBy::InitialPosition};
  const std::vector<Rgb> c = particle_colors(two_particles(), spec, run);
  EXPECT_EQ(c[0], (Rgb{40, 40, 40}));     // the low corner: dim, never black
  EXPECT_EQ(c[1], (Rgb{255, 255, 255}));  // the high corner
  EXPECT_EQ(initial_position_color({1, 0, 0}, run.box_lo, run.box_hi), (Rgb{147, 40, 40}));  // x halfway
  const RunDirectory flat = test_run(2);  // z has no extent: its channel stays dim
  EXPECT_EQ(particle_colors(two_particles(), spec, flat)[1], (Rgb{255, 255, 40}));
}

}  // namespace
