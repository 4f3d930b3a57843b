// Kernel properties: each kernel integrates to one in its dimension, gradients and Laplacians
// match finite differences of W, and lattice gradient sums vanish by symmetry.

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include <sph/core/kernels.h>

namespace sph {
namespace {

constexpr double kPi = std::numbers::pi;

/// Integral of a radial function over the D-ball of radius h (midpoint rule, fine mesh).
template <int D, class F>
double radial_integral(F&& w, double h, int n = 200000) {
  double s = 0;
  const double dr = h / n;
  for (int k = 0; k < n; ++k) {
    const double r = (k + 0.5) * dr;
    const double shell = D == 2 ? 2 * kPi * r : 4 * kPi * r * r;
    s += w(r) * shell * dr;
  }
  return s;
}

template <int D>
void check_normalization(double h) {
  EXPECT_NEAR(radial_integral<D>([&](double r) { return Poly6Kernel<D, double>(h).w(r); }, h), 1.0, 1e-6)
      << D << "D poly6";
  EXPECT_NEAR(radial_integral<D>([&](double r) { return SpikyKernel<D, double>(h).w(r); }, h), 1.0, 1e-6)
      << D << "D spiky";
  EXPECT_NEAR(radial_integral<D>([&](double r) { return ViscosityKernel<D, double>(h).w(r); }, h), 1.0, 1e-4)
      << D << "D viscosity";
}

TEST(Kernels, IntegrateToOne2D) {
  check_normalization<2>(0.02);
  check_normalization<2>(1.3);
}
TEST(Kernels, IntegrateToOne3D) {
  check_normalization<3>(0.04);
  check_normalization<3>(0.7);
}

TEST(Kernels, VanishOutsideSupport) {
  const double h = 0.1;
  const Poly6Kernel<3, double> p3(h);
  const Poly6Kernel<2, double> p2(h);
  const SpikyKernel<3, double> s3(h);
  const ViscosityKernel<2, double> v2(h);
  EXPECT_EQ(p3.w(h), 0.0);
  EXPECT_EQ(p2.w(1.5 * h), 0.0);
  EXPECT_EQ(s3.w(h), 0.0);
  EXPECT_EQ(v2.laplacian(h), 0.0);
  const Vec<3, double> r{{h, 0, 0}};
  EXPECT_EQ(norm(s3.gradient(r, h)), 0.0);
  EXPECT_GT(p3.w_zero(), 0.0);
  EXPECT_GT(p2.w(0.99 * h), 0.0);
}

template <int D>
void check_spiky_gradient(double h) {
  const SpikyKernel<D, double> k(h);
  for (double q : {0.1, 0.35, 0.6, 0.9}) {
    Vec<D, double> rij{};
    rij[0] = q * h * 0.6;
    rij[1] = q * h * 0.8;
    const double r = norm(rij);
    const double e = 1e-7 * h;
    // dW/dr along rij / r, by central differences.
    const double dwdr = (k.w(r + e) - k.w(r - e)) / (2 * e);
    const Vec<D, double> g = k.gradient(rij, r);
    for (int d = 0; d < D; ++d) EXPECT_NEAR(g[d], dwdr * rij[d] / r, 1e-6 * std::abs(dwdr) + 1e-12) << D << "D q=" << q;
  }
}
TEST(Kernels, SpikyGradientIsDerivativeOfW) {
  check_spiky_gradient<2>(0.02);
  check_spiky_gradient<3>(0.04);
}

template <int D>
void check_poly6_gradient(double h) {
  const Poly6Kernel<D, double> k(h);
  for (double q : {0.1, 0.35, 0.6, 0.9}) {
    Vec<D, double> rij{};
    rij[0] = q * h * 0.6;
    rij[1] = q * h * 0.8;
    const double r = norm(rij);
    const double e = 1e-7 * h;
    const double dwdr = (k.w(r + e) - k.w(r - e)) / (2 * e);
    const Vec<D, double> g = k.gradient(rij, r * r);
    for (int d = 0; d < D; ++d) EXPECT_NEAR(g[d], dwdr * rij[d] / r, 1e-6 * std::abs(dwdr) + 1e-12) << D << "D q=" << q;
  }
  Vec<D, double> at_h{};
  at_h[0] = h;
  EXPECT_EQ(norm(k.gradient(at_h, h * h)), 0.0);
  EXPECT_EQ(norm(k.gradient(Vec<D, double>{}, 0.0)), 0.0);  // flat at the center
}
TEST(Kernels, Poly6GradientIsDerivativeOfW) {
  check_poly6_gradient<2>(0.02);
  check_poly6_gradient<3>(0.04);
}

template <int D>
void check_viscosity_laplacian(double h) {
  const ViscosityKernel<D, double> k(h);
  for (double q : {0.2, 0.5, 0.8}) {
    const double r = q * h, e = 1e-4 * h;
    const double w0 = k.w(r), wp = k.w(r + e), wm = k.w(r - e);
    const double d2 = (wp - 2 * w0 + wm) / (e * e);
    const double d1 = (wp - wm) / (2 * e);
    const double lap = d2 + (D - 1) * d1 / r;  // radial Laplacian
    EXPECT_NEAR(lap, k.laplacian(r), 1e-4 * std::abs(k.laplacian(r))) << D << "D q=" << q;
  }
}
TEST(Kernels, ViscosityLaplacianMatchesW) {
  check_viscosity_laplacian<2>(0.02);
  check_viscosity_laplacian<3>(0.04);
}

template <int D>
void check_lattice_gradient_sum(double h, double dx) {
  const SpikyKernel<D, double> k(h);
  Vec<D, double> sum{};
  double magnitude = 0;
  const int n = static_cast<int>(h / dx) + 1;
  for (int a = -n; a <= n; ++a)
    for (int b = -n; b <= n; ++b)
      for (int c = (D == 3 ? -n : 0); c <= (D == 3 ? n : 0); ++c) {
        Vec<D, double> rij{};
        // x_i at the origin, x_j on the lattice: the sum over a full symmetric stencil is zero.
        rij[0] = -a * dx;
        rij[1] = -b * dx;
        if constexpr (D == 3) rij[2] = -c * dx;
        const double r = norm(rij);
        const auto g = k.gradient(rij, r);
        sum += g;
        magnitude += norm(g);
      }
  EXPECT_GT(magnitude, 0.0);
  EXPECT_LT(norm(sum), 1e-12 * magnitude) << D << "D";
}
TEST(Kernels, GradientSumVanishesOnSymmetricLattice) {
  check_lattice_gradient_sum<2>(0.02, 0.01);
  check_lattice_gradient_sum<3>(0.04, 0.02);
}

TEST(Kernels, FloatMatchesDouble) {
  const Poly6Kernel<3, float> pf(0.04f);
  const Poly6Kernel<3, double> pd(0.04);
  EXPECT_NEAR(pf.w(0.01f), pd.w(0.01), 1e-5 * pd.w(0.01));
  const ViscosityKernel<2, float> vf(0.02f);
  const ViscosityKernel<2, double> vd(0.02);
  EXPECT_NEAR(vf.laplacian(0.005f), vd.laplacian(0.005), 1e-5 * vd.laplacian(0.005));
}

}  // namespace
}  // namespace sph
