// The measures of `sph validate` on synthetic data with known answers.

#include <sph/analysis/validation.h>

#include <cmath>
#include <filesystem>
#include <vector>

#include <gtest/gtest.h>

#include <sph/core/error.h>

#include "support/temp_dir.h"

namespace sph {
namespace {

/// A block of particles on a lattice of spacing dx: columns [0, nx) x rows [0, ny), centers half
/// a spacing inside the block.
void add_block(std::vector<double>& x, std::vector<double>& y, double x0, double y0, int nx, int ny, double dx) {
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j) x.push_back(x0 + (i + 0.5) * dx), y.push_back(y0 + (j + 0.5) * dx);
}

TEST(MartinMoyceData, MatchesTheTableAsTranscribed) {
  const auto data = martin_moyce_1952();
  ASSERT_EQ(data.size(), 16u);
  EXPECT_EQ(data.front().T, 0.0);
  EXPECT_EQ(data.front().Z, 1.0);
  EXPECT_DOUBLE_EQ(data[1].T, 0.41);
  EXPECT_DOUBLE_EQ(data[1].Z, 1.11);
  EXPECT_DOUBLE_EQ(data.back().T, 3.33);
  EXPECT_DOUBLE_EQ(data.back().Z, 4.11);
  for (std::size_t k = 1; k < data.size(); ++k) {
    EXPECT_GT(data[k].T, data[k - 1].T);
    EXPECT_GT(data[k].Z, data[k - 1].Z);
    // The Ritter dry-bed bound: no front runs faster than Z = 1 + 2T.
    EXPECT_LT(data[k].Z, 1 + 2 * data[k].T);
  }
  // T = t sqrt(2 g / a): t = sqrt(a / (2 g)) gives T = 1.
  EXPECT_NEAR(martin_moyce_time(std::sqrt(kMartinMoyceA / (2 * 9.81)), 9.81), 1.0, 1e-12);
}

TEST(SurgeFront, ColumnFrontIsItsWidth) {
  const double dx = 0.01, h = 0.02;
  std::vector<double> x, y;
  add_block(x, y, 0.0, 0.0, 10, 20, dx);
  // Last column at 0.095; plus half a spacing: the block's face at 0.1.
  EXPECT_NEAR(surge_front(x, y, 0.0, dx, h), 0.1, 1e-12);
}

TEST(SurgeFront, IgnoresIsolatedSprayAndFlyingParticles) {
  const double dx = 0.01, h = 0.02;
  std::vector<double> x, y;
  add_block(x, y, 0.0, 0.0, 10, 3, dx);
  // A lone droplet on the floor ahead of the front, a pair (each has one neighbor), and a
  // particle far ahead but above the floor band.
  x.push_back(0.5), y.push_back(0.005);
  x.push_back(0.3), y.push_back(0.005);
  x.push_back(0.31), y.push_back(0.005);
  x.push_back(0.8), y.push_back(0.05);
  EXPECT_NEAR(surge_front(x, y, 0.0, dx, h), 0.1, 1e-12);
  // Fewer neighbors required: the pair counts as fluid.
  EXPECT_NEAR(surge_front(x, y, 0.0, dx, h, 1), 0.315, 1e-12);
  // A small clump of four touching particles on the floor counts as the front.
  for (double px : {0.6, 0.605, 0.61, 0.615}) x.push_back(px), y.push_back(0.004);
  EXPECT_NEAR(surge_front(x, y, 0.0, dx, h), 0.62, 1e-12);
}

TEST(SurgeFront, FloorOffsetAndEmptyCases) {
  const double dx = 0.01, h = 0.02;
  std::vector<double> x, y;
  add_block(x, y, 1.0, 2.0, 5, 5, dx);
  EXPECT_NEAR(surge_front(x, y, 2.0, dx, h), 1.05, 1e-12);
  // Nothing on this floor.
  EXPECT_TRUE(std::isnan(surge_front(x, y, 0.0, dx, h)));
  std::vector<double> short_y(y.begin(), y.end() - 1);
  EXPECT_THROW(surge_front(x, short_y, 2.0, dx, h), Error);
}

TEST(FrontError, InterpolatesLinearly) {
  const std::vector<double> xs{0, 1, 3}, ys{0, 10, 30};
  EXPECT_DOUBLE_EQ(interpolate(xs, ys, 0.5), 5.0);
  EXPECT_DOUBLE_EQ(interpolate(xs, ys, 1.0), 10.0);
  EXPECT_DOUBLE_EQ(interpolate(xs, ys, 2.5), 25.0);
  EXPECT_DOUBLE_EQ(interpolate(xs, ys, 3.0), 30.0);
  EXPECT_TRUE(std::isnan(interpolate(xs, ys, 3.5)));
  EXPECT_TRUE(std::isnan(interpolate(xs, ys, -0.1)));
}

TEST(FrontError, MaxRmsAndMeanOnMadeUpData) {
  // Simulation Z = 1 + T; experiment points chosen so the differences are known.
  const std::vector<double> T{0, 1, 2, 3, 4}, Z{1, 2, 3, 4, 5};
  const std::vector<FrontPoint> exp{{0, 1}, {0.5, 1.4}, {1.5, 2.7}, {2.5, 3.5}, {3.5, 4.0}};
  const FrontError e = front_error(T, Z, exp, 3.0);
  // T = 0 is left out by default; T = 3.5 is beyond t_max. Differences: +0.1, -0.2, 0.
  EXPECT_EQ(e.points, 3);
  EXPECT_TRUE(e.complete);
  EXPECT_NEAR(e.max, 0.2, 1e-12);  // at T = 1.5: 2.5 - 2.7
  EXPECT_NEAR(e.worst_T, 1.5, 1e-12);
  EXPECT_NEAR(e.rms, std::sqrt((0.1 * 0.1 + 0.2 * 0.2) / 3), 1e-12);
  EXPECT_NEAR(e.mean, (0.1 - 0.2) / 3, 1e-12);
  // With T = 0 included (t_min below 0) it adds one exact point.
  const FrontError e0 = front_error(T, Z, exp, 3.0, -1);
  EXPECT_EQ(e0.points, 4);
  EXPECT_NEAR(e0.rms, std::sqrt((0.1 * 0.1 + 0.2 * 0.2) / 4), 1e-12);
}

TEST(FrontError, IncompleteWhenTheRunStoppedEarly) {
  const std::vector<double> T{0, 1}, Z{1, 2};
  const std::vector<FrontPoint> exp{{0.5, 1.5}, {2.0, 3.0}};
  const FrontError e = front_error(T, Z, exp, 3.0);
  EXPECT_FALSE(e.complete);
  EXPECT_EQ(e.points, 1);
  EXPECT_NEAR(e.max, 0.0, 1e-12);
}

TEST(FrontChange, ComparesTwoFrontsAtTheExperimentsTimes) {
  // The fine front is the coarse one plus 0.1 T: at the compared times 0.5, 1.5 and 2.5 the
  // changes are 0.05, 0.15 and 0.25.
  const std::vector<double> Tc{0, 1, 2, 3}, Zc{1, 2, 3, 4};
  const std::vector<double> Tf{0, 3}, Zf{1, 4.3};
  const std::vector<FrontPoint> exp{{0.5, 9}, {1.5, 9}, {2.5, 9}};
  const FrontError at = front_error(Tf, Zf, exp, 3.0);
  const FrontError c = front_change(Tf, Zf, Tc, Zc, at);
  EXPECT_EQ(c.points, 3);
  EXPECT_TRUE(c.complete);
  EXPECT_NEAR(c.max, 0.25, 1e-12);
  EXPECT_NEAR(c.worst_T, 2.5, 1e-12);
  EXPECT_NEAR(c.mean, 0.15, 1e-12);
  EXPECT_NEAR(c.rms, std::sqrt((0.05 * 0.05 + 0.15 * 0.15 + 0.25 * 0.25) / 3), 1e-12);
  // A coarse run that stopped at T = 2 has no value at 2.5: that point is left out.
  const std::vector<double> Ts{0, 1, 2}, Zs{1, 2, 3};
  const FrontError s = front_change(Tf, Zf, Ts, Zs, at);
  EXPECT_FALSE(s.complete);
  EXPECT_EQ(s.points, 2);
  EXPECT_NEAR(s.max, 0.15, 1e-12);
}

TEST(EosInternalEnergy, FormulaAndDerivativeIsPOverRhoSquared) {
  const double rho0 = 1000, k = 400;
  EXPECT_EQ(eos_internal_energy(rho0, rho0, k), 0.0);
  EXPECT_EQ(eos_internal_energy(990, rho0, k), 0.0);  // clamped: no tension, no energy
  EXPECT_NEAR(eos_internal_energy(1010, rho0, k), k * (std::log(1.01) + 1 / 1.01 - 1), 1e-12);
  for (double rho : {1000.5, 1005.0, 1020.0, 1100.0}) {
    const double eps = 1e-4;
    const double de = (eos_internal_energy(rho + eps, rho0, k) - eos_internal_energy(rho - eps, rho0, k)) / (2 * eps);
    const double p = k * (rho - rho0);
    EXPECT_NEAR(de, p / (rho * rho), 1e-9 * std::max(1.0, p / (rho * rho))) << rho;
  }
  // Small compression: e ~ k (d rho)^2 / (2 rho0^2), to first order in d rho / rho0 = 1e-3.
  const double small = k * 1.0 / (2 * rho0 * rho0);
  EXPECT_NEAR(eos_internal_energy(1001, rho0, k), small, 2e-3 * small);
}

TEST(Energy, PartsOfASimpleState) {
  FluidState s;
  s.dimension = 2;
  s.particle_mass = 2.0;
  s.position = {{0.5, 1.0, 0}, {0.005, 0.5, 0}};
  s.velocity = {{3, 4, 0}, {0, 0, 0}};
  s.density = {1000, 1010};
  EnergyModel m;
  m.box_lo = {0, 0, 0};
  m.box_hi = {1, 2, 0};
  m.gravity = 10;
  m.rest_density = 1000;
  m.stiffness = 400;
  m.wall_stiffness = 1e6;
  m.particle_radius = 0.01;
  const EnergyParts e = energy(s, m);
  EXPECT_NEAR(e.kinetic, 0.5 * 2 * 25, 1e-12);
  EXPECT_NEAR(e.potential, 2 * 10 * (1.0 + 0.5), 1e-12);
  EXPECT_NEAR(e.internal, 2 * eos_internal_energy(1010, 1000, 400), 1e-12);
  // The second particle is 0.005 m inside the left wall's reach of 0.01 m.
  EXPECT_NEAR(e.wall, 0.5 * 2 * 1e6 * 0.005 * 0.005, 1e-12);
  EXPECT_NEAR(e.total(), e.kinetic + e.potential + e.internal + e.wall, 1e-12);
}

TEST(Energy, LargestRise) {
  EXPECT_EQ(largest_rise(std::vector<double>{5, 4, 3, 2}), 0.0);
  EXPECT_DOUBLE_EQ(largest_rise(std::vector<double>{5, 3, 4, 2, 2.5}), 1.0);
  EXPECT_DOUBLE_EQ(largest_rise(std::vector<double>{1, 2, 0, 3}), 3.0);
}

/// A 2D or 3D lattice of water of height H at rest, with the exact hydrostatic pressure (and the
/// density the EOS gives for it).
FluidState exact_tank(int dimension, double dx, int nx, int ny, double rho0, double g, double k) {
  FluidState s;
  s.dimension = dimension;
  const double H = ny * dx;
  const int nz = dimension == 3 ? nx : 1;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (int l = 0; l < nz; ++l) {
        const std::array<double, 3> x{(i + 0.5) * dx, (j + 0.5) * dx, dimension == 3 ? (l + 0.5) * dx : 0.0};
        const double p = rho0 * g * (H - x[1]);
        s.position.push_back(x);
        s.velocity.push_back({0, 0, 0});
        s.pressure.push_back(p);
        s.density.push_back(rho0 + p / k);
      }
  return s;
}

TEST(Hydrostatic, ExactFieldGivesRatioOne) {
  for (int dim : {2, 3}) {
    const double dx = 0.01, rho0 = 1000, g = 9.81, k = 1e6;
    const int n = 20;
    const FluidState s = exact_tank(dim, dx, n, n, rho0, g, k);
    EXPECT_NEAR(free_surface_height(s, dx), n * dx, 1e-12) << dim;
    HydrostaticModel m;
    m.box_lo = {0, 0, 0};
    m.box_hi = {n * dx, 0.5, dim == 3 ? n * dx : 0.0};
    m.gravity = g;
    m.rest_density = rho0;
    m.spacing = dx;
    m.h = 2 * dx;
    const HydrostaticProfile p = hydrostatic_profile(s, m);
    EXPECT_NEAR(p.mean_ratio, 1.0, 1e-12) << dim;
    EXPECT_LT(p.max_bin_error, 1e-12) << dim;
    EXPECT_LT(p.max_layer_error, 1e-12) << dim;
    EXPECT_GT(p.bins.size(), 5u);
    // Interior only: (n - 4) columns (per horizontal axis) of the rows deeper than 2 spacings and
    // more than h above the floor.
    const std::size_t cols = dim == 3 ? (n - 4) * (n - 4) : (n - 4);
    EXPECT_EQ(p.particles, cols * (n - 2 - 2));
    EXPECT_NEAR(p.max_compression, rho0 * g * (n - 0.5) * dx / k / rho0, 1e-12);
  }
}

TEST(Hydrostatic, DetectsAPressureTooHigh) {
  const double dx = 0.01;
  FluidState s = exact_tank(2, dx, 20, 20, 1000, 9.81, 1e6);
  for (double& p : s.pressure) p *= 1.1;
  HydrostaticModel m;
  m.box_hi = {0.2, 0.5, 0};
  m.spacing = dx;
  m.h = 2 * dx;
  const HydrostaticProfile p = hydrostatic_profile(s, m);
  EXPECT_NEAR(p.mean_ratio, 1.1, 1e-12);
  EXPECT_NEAR(p.max_bin_error, 0.1, 1e-12);
}

// What DFSPH and WCSPH give under a free surface (docs/validation.md, "DFSPH"): the pressure of
// alternate layers off by +-0.6 rho0 g dx. Two-spacing bins hold one layer of each sign and
// average it out; the layers do not.
TEST(Hydrostatic, LayersSeeAPressureThatAlternatesFromLayerToLayer) {
  const double dx = 0.01, rho0 = 1000, g = 9.81;
  FluidState s = exact_tank(2, dx, 20, 20, rho0, g, 1e6);
  const double surface = free_surface_height(s, dx);
  for (std::size_t i = 0; i < s.position.size(); ++i) {
    const long layer = std::lround((surface - s.position[i][1]) / dx - 0.5);  // 0 at the top
    s.pressure[i] += (layer % 2 == 0 ? -0.6 : 0.6) * rho0 * g * dx;
  }
  HydrostaticModel m;
  m.box_hi = {0.2, 0.5, 0};
  m.gravity = g;
  m.rest_density = rho0;
  m.spacing = dx;
  m.h = 2 * dx;
  const HydrostaticProfile p = hydrostatic_profile(s, m);
  EXPECT_LT(p.max_bin_error, 1e-12);
  // The worst layer is the first compared one, the third (depth 2.5 dx): 0.6 / 2.5.
  EXPECT_NEAR(p.max_layer_error, 0.6 / 2.5, 1e-12);
}

TEST(Hydrostatic, SettlingTime) {
  const std::vector<double> t{0, 1, 2, 3, 4, 5}, ke{0, 10, 5, 0.2, 0.05, 0.01};
  EXPECT_DOUBLE_EQ(settling_time(t, ke, 0.01), 4.0);  // 0.2 > 0.1 at t = 3; below from t = 4
  EXPECT_DOUBLE_EQ(settling_time(t, ke, 0.03), 3.0);
  const std::vector<double> still{1, 1, 1, 1, 1, 1};
  EXPECT_TRUE(std::isnan(settling_time(t, still, 0.5)));
}

TEST(Hydrostatic, LatticeGradientConsistency) {
  // The spiky gradient at h = 2 spacings under-estimates a linear pressure's gradient (M_yy < 1);
  // at larger h it approaches 1.
  const double m2 = lattice_gradient_consistency(2, 0.005, 0.01);
  const double m3 = lattice_gradient_consistency(3, 0.005, 0.01);
  EXPECT_GT(m2, 0.8);
  EXPECT_LT(m2, 0.95);
  EXPECT_GT(m3, 0.85);
  EXPECT_LT(m3, 1.0);
  // Independent of the scale.
  EXPECT_NEAR(lattice_gradient_consistency(2, 1.0, 2.0), m2, 1e-9);
  EXPECT_NEAR(lattice_gradient_consistency(2, 0.005, 0.02), 1.0, 0.05);
  // Poly6's gradient (the variational force) is consistent on the square lattice at h = 2
  // spacings in 2D (M_yy is minus the relative change of the poly6 density under a stretch along
  // y, which there goes as 1 / stretch like a continuum's) and 5 % over in 3D.
  EXPECT_NEAR(lattice_gradient_consistency(2, 0.005, 0.01, true), 1.0, 0.005);
  const double p3 = lattice_gradient_consistency(3, 0.005, 0.01, true);
  EXPECT_GT(p3, 1.03);
  EXPECT_LT(p3, 1.08);
}

}  // namespace
}  // namespace sph

namespace sph {
namespace {

// An earlier validation's report stays until this one writes its own: a run stopped on the way
// (Ctrl-C in the minutes of a full validation) used to leave the directory empty.
TEST(ValidationFiles, AnEarlierReportStaysUntilTheNewOneIsWritten) {
  test::TempDir dir;
  test::spit(dir / "report.md", "earlier\n");
  test::spit(dir / "front.png", "earlier\n");
  prepare_validation_directory(dir.path());
  EXPECT_EQ(test::slurp(dir / "report.md"), "earlier\n");
  ValidationResult res;
  res.cases = {"conservation"};
  write_validation(dir.path(), res);
  EXPECT_NE(test::slurp(dir / "report.md"), "earlier\n");
  EXPECT_FALSE(std::filesystem::exists(dir / "front.png")) << "a case this run did not run";
}

}  // namespace
}  // namespace sph
