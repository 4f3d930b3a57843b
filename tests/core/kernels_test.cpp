// Kernel properties: each kernel integrates to one in its dimension, gradients and Laplacians
// match finite differences of W, lattice gradient sums vanish by symmetry, and (cubic spline,
// Wendland C2) a lattice with h = 2 spacings sums W to about one particle per volume.

#include <cmath>
#include <concepts>
#include <limits>
#include <numbers>
#include <utility>

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

/// Sum over a full symmetric lattice of spacing dx around x_i of the gradient of kernel k (any
/// kernel with gradient(rij, r)): zero by symmetry, relative to the sum of magnitudes.
template <int D, class Kernel>
void check_lattice_gradient_sum(const Kernel& k, double dx, const char* name) {
  Vec<D, double> sum{};
  double magnitude = 0;
  const int n = static_cast<int>(k.h() / dx) + 1;
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
  EXPECT_GT(magnitude, 0.0) << D << "D " << name;
  EXPECT_LT(norm(sum), 1e-12 * magnitude) << D << "D " << name;
}
TEST(Kernels, GradientSumVanishesOnSymmetricLattice) {
  check_lattice_gradient_sum<2>(SpikyKernel<2, double>(0.02), 0.01, "spiky");
  check_lattice_gradient_sum<3>(SpikyKernel<3, double>(0.04), 0.02, "spiky");
  check_lattice_gradient_sum<2>(CubicSplineKernel<2, double>(0.02), 0.01, "cubic");
  check_lattice_gradient_sum<3>(CubicSplineKernel<3, double>(0.04), 0.02, "cubic");
  check_lattice_gradient_sum<2>(WendlandC2Kernel<2, double>(0.02), 0.01, "Wendland");
  check_lattice_gradient_sum<3>(WendlandC2Kernel<3, double>(0.04), 0.02, "Wendland");
  // Off the h = 2 dx ratio too: neighbors at non-lattice-aligned fractions of h.
  check_lattice_gradient_sum<3>(CubicSplineKernel<3, double>(0.05), 0.02, "cubic");
  check_lattice_gradient_sum<2>(WendlandC2Kernel<2, double>(0.05), 0.02, "Wendland");
}

TEST(Kernels, FloatMatchesDouble) {
  const Poly6Kernel<3, float> pf(0.04f);
  const Poly6Kernel<3, double> pd(0.04);
  EXPECT_NEAR(pf.w(0.01f), pd.w(0.01), 1e-5 * pd.w(0.01));
  const ViscosityKernel<2, float> vf(0.02f);
  const ViscosityKernel<2, double> vd(0.02);
  EXPECT_NEAR(vf.laplacian(0.005f), vd.laplacian(0.005), 1e-5 * vd.laplacian(0.005));
}

// ---- Monaghan's cubic spline and Wendland's C2 kernel ---------------------------------------

/// Both new kernels share one API, so the checks below take the class template.
template <template <int, std::floating_point> class K, int D, std::floating_point R>
void check_new_normalization(double h, double tolerance, const char* name) {
  const K<D, R> k(static_cast<R>(h));
  const double integral = radial_integral<D>([&](double r) { return double(k.w(static_cast<R>(r))); }, h);
  EXPECT_NEAR(integral, 1.0, tolerance) << D << "D " << name << " h=" << h;
}
template <template <int, std::floating_point> class K>
void check_new_normalizations(const char* name) {
  check_new_normalization<K, 2, double>(0.02, 1e-8, name);
  check_new_normalization<K, 2, double>(1.3, 1e-8, name);
  check_new_normalization<K, 3, double>(0.04, 1e-8, name);
  check_new_normalization<K, 3, double>(0.7, 1e-8, name);
  check_new_normalization<K, 2, float>(0.02, 1e-5, name);
  check_new_normalization<K, 3, float>(0.04, 1e-5, name);
}
TEST(Kernels, CubicSplineIntegratesToOne) { check_new_normalizations<CubicSplineKernel>("cubic"); }
TEST(Kernels, WendlandC2IntegratesToOne) { check_new_normalizations<WendlandC2Kernel>("Wendland"); }

/// W, gradient_factor and the gradient are exactly zero at and beyond h, and W is positive (and
/// never negative through rounding) just inside it; W(0) = w_zero() = norm().
template <template <int, std::floating_point> class K, int D, std::floating_point R>
void check_new_support(R h, const char* name) {
  const K<D, R> k(h);
  EXPECT_EQ(k.h(), h);
  for (R r : {h, R(1.5) * h, R(10) * h}) {
    Vec<D, R> rij{};
    rij[D - 1] = r;
    EXPECT_EQ(k.w(r), R(0)) << D << "D " << name << " r/h=" << r / h;
    EXPECT_EQ(k.w_r2(r * r), R(0)) << D << "D " << name << " r/h=" << r / h;
    EXPECT_EQ(k.gradient_factor(r), R(0)) << D << "D " << name << " r/h=" << r / h;
    EXPECT_EQ(norm(k.gradient(rij, r)), R(0)) << D << "D " << name << " r/h=" << r / h;
  }
  EXPECT_GT(k.w(R(0.99) * h), R(0)) << D << "D " << name;
  EXPECT_LT(k.gradient_factor(R(0.99) * h), R(0)) << D << "D " << name;
  const R just_inside = std::nextafter(h, R(0));
  EXPECT_GE(k.w(just_inside), R(0)) << D << "D " << name;
  EXPECT_LE(k.gradient_factor(just_inside), R(0)) << D << "D " << name;
  EXPECT_EQ(k.w_zero(), k.norm()) << D << "D " << name;
  EXPECT_EQ(k.w(R(0)), k.w_zero()) << D << "D " << name;
  EXPECT_EQ(k.w_r2(R(0)), k.w_zero()) << D << "D " << name;
}
template <template <int, std::floating_point> class K>
void check_new_supports(const char* name) {
  check_new_support<K, 2, double>(0.02, name);
  check_new_support<K, 3, double>(0.04, name);
  check_new_support<K, 2, float>(0.02f, name);
  check_new_support<K, 3, float>(0.04f, name);
  check_new_support<K, 3, float>(0.7f, name);
}
TEST(Kernels, CubicSplineVanishesOutsideSupport) { check_new_supports<CubicSplineKernel>("cubic"); }
TEST(Kernels, WendlandC2VanishesOutsideSupport) { check_new_supports<WendlandC2Kernel>("Wendland"); }

/// The cubic spline's two pieces meet at q = 1/2 with the same value (sigma / 4) and slope.
template <int D, std::floating_point R>
void check_cubic_continuity(R h) {
  const CubicSplineKernel<D, R> k(h);
  const R half = h / R(2);
  const R below = std::nextafter(half, R(0)), above = std::nextafter(half, h);
  const R tolerance = 64 * std::numeric_limits<R>::epsilon() * k.norm();
  EXPECT_NEAR(k.w(below), k.w(above), tolerance) << D << "D";
  EXPECT_NEAR(k.w(half), k.norm() / R(4), tolerance) << D << "D";
  EXPECT_NEAR(k.w(above), k.norm() / R(4), tolerance) << D << "D";
  // dW/dr / r is -3 sigma / h^2 from both sides.
  const R gradient_scale = k.norm() / (h * h);
  EXPECT_NEAR(k.gradient_factor(below), k.gradient_factor(above),
              64 * std::numeric_limits<R>::epsilon() * gradient_scale)
      << D << "D";
  EXPECT_NEAR(k.gradient_factor(above), R(-3) * gradient_scale, 64 * std::numeric_limits<R>::epsilon() * gradient_scale)
      << D << "D";
}
TEST(Kernels, CubicSplineContinuousAtHalf) {
  check_cubic_continuity<2, double>(0.02);
  check_cubic_continuity<3, double>(0.04);
  check_cubic_continuity<2, float>(0.02f);
  check_cubic_continuity<3, float>(0.04f);
}

/// gradient(rij, r) against dW/dr rij / r by central differences of w, off-axis, at several q
/// on both of the cubic's pieces.
template <template <int, std::floating_point> class K, int D>
void check_new_gradient(double h, const char* name) {
  const K<D, double> k(h);
  for (double q : {0.05, 0.1, 0.35, 0.49, 0.51, 0.6, 0.75, 0.9, 0.98}) {
    Vec<D, double> rij{};
    rij[0] = q * h * 0.6;
    rij[1] = q * h * 0.8;
    const double r = norm(rij);
    const double e = 1e-7 * h;
    const double dwdr = (k.w(r + e) - k.w(r - e)) / (2 * e);
    const Vec<D, double> g = k.gradient(rij, r);
    for (int d = 0; d < D; ++d)
      EXPECT_NEAR(g[d], dwdr * rij[d] / r, 1e-6 * std::abs(dwdr) + 1e-12) << D << "D " << name << " q=" << q;
    EXPECT_NEAR(k.gradient_factor(r), dwdr / r, 1e-6 * std::abs(dwdr / r)) << D << "D " << name << " q=" << q;
  }
}
TEST(Kernels, CubicSplineGradientIsDerivativeOfW) {
  check_new_gradient<CubicSplineKernel, 2>(0.02, "cubic");
  check_new_gradient<CubicSplineKernel, 3>(0.04, "cubic");
}
TEST(Kernels, WendlandC2GradientIsDerivativeOfW) {
  check_new_gradient<WendlandC2Kernel, 2>(0.02, "Wendland");
  check_new_gradient<WendlandC2Kernel, 3>(0.04, "Wendland");
}

/// At r = 0, gradient_factor is finite and equals its limit, which W itself gives:
/// W(r) = W(0) + W''(0) r^2 / 2 + O(r^3) and (dW/dr) / r -> W''(0), so 2 (W(r) - W(0)) / r^2 at
/// small r. The closed forms are -12 sigma / h^2 (cubic) and -20 sigma / h^2 (Wendland). The
/// gradient of coincident particles is the zero vector.
template <template <int, std::floating_point> class K, int D>
void check_new_gradient_at_zero(double h, double limit_in_sigma_over_h2, const char* name) {
  const K<D, double> k(h);
  const double at_zero = k.gradient_factor(0.0);
  EXPECT_TRUE(std::isfinite(at_zero)) << D << "D " << name;
  const double r = 1e-4 * h;
  const double from_w = 2 * (k.w(r) - k.w_zero()) / (r * r);
  EXPECT_NEAR(at_zero, from_w, 1e-3 * std::abs(from_w)) << D << "D " << name;
  EXPECT_NEAR(at_zero, limit_in_sigma_over_h2 * k.norm() / (h * h), 1e-12 * std::abs(at_zero)) << D << "D " << name;
  EXPECT_NEAR(k.gradient_factor(1e-9 * h), at_zero, 1e-6 * std::abs(at_zero)) << D << "D " << name;
  const Vec<D, double> g = k.gradient(Vec<D, double>{}, 0.0);
  EXPECT_TRUE(all_finite(g)) << D << "D " << name;
  EXPECT_EQ(norm(g), 0.0) << D << "D " << name;
  const K<D, float> kf(static_cast<float>(h));
  EXPECT_TRUE(std::isfinite(kf.gradient_factor(0.0f))) << D << "D float " << name;
  EXPECT_TRUE(all_finite(kf.gradient(Vec<D, float>{}, 0.0f))) << D << "D float " << name;
}
TEST(Kernels, CubicSplineGradientFactorFiniteAtZero) {
  check_new_gradient_at_zero<CubicSplineKernel, 2>(0.02, -12.0, "cubic");
  check_new_gradient_at_zero<CubicSplineKernel, 3>(0.04, -12.0, "cubic");
}
TEST(Kernels, WendlandC2GradientFactorFiniteAtZero) {
  check_new_gradient_at_zero<WendlandC2Kernel, 2>(0.02, -20.0, "Wendland");
  check_new_gradient_at_zero<WendlandC2Kernel, 3>(0.04, -20.0, "Wendland");
}

/// Lattice density: x_i on a square/cubic lattice of spacing dx, h = 2 dx; sum_j W(x_i - x_j)
/// dx^D (x_i itself included) is a quadrature of the kernel's integral, so about one.
template <template <int, std::floating_point> class K, int D, std::floating_point R>
void check_lattice_density(double dx, const char* name) {
  const K<D, R> k(static_cast<R>(2 * dx));
  const int n = 3;  // > h / dx
  double sum = 0;
  for (int a = -n; a <= n; ++a)
    for (int b = -n; b <= n; ++b)
      for (int c = (D == 3 ? -n : 0); c <= (D == 3 ? n : 0); ++c) {
        const double r2 = (double(a) * a + double(b) * b + double(c) * c) * dx * dx;
        sum += k.w_r2(static_cast<R>(r2));
      }
  const double density = sum * std::pow(dx, D);
  EXPECT_NEAR(density, 1.0, 0.05) << D << "D " << name << (sizeof(R) == 4 ? " float" : " double")
                                  << ": sum_j W dx^D = " << density;
}
template <template <int, std::floating_point> class K>
void check_lattice_densities(const char* name) {
  check_lattice_density<K, 2, double>(0.01, name);
  check_lattice_density<K, 3, double>(0.02, name);
  check_lattice_density<K, 2, float>(0.01, name);
  check_lattice_density<K, 3, float>(0.02, name);
}
TEST(Kernels, CubicSplineLatticeDensityNearOne) { check_lattice_densities<CubicSplineKernel>("cubic"); }
TEST(Kernels, WendlandC2LatticeDensityNearOne) { check_lattice_densities<WendlandC2Kernel>("Wendland"); }

/// The viscosity the solver pairs with these kernels (Morris, Fox and Zhu 1997; docs/physics.md):
/// 2 sum_j V_j (x_ij . grad_i W_ij) / (|x_ij|^2 + epsilon h^2) (A_i - A_j) approximates the
/// Laplacian of A. For A = |x|^2 (Laplacian 2 D) on a lattice of spacing dx with h = 2 dx, x_i at
/// the origin. The solver's epsilon = 0.01 lowers every term by r^2 / (r^2 + 0.01 h^2), which is
/// 0.96 for the nearest neighbors (r = h / 2), hence the wider tolerance with it.
template <template <int, std::floating_point> class K, int D>
void check_lattice_laplacian(double dx, double epsilon, double tolerance, const char* name) {
  const double h = 2 * dx;
  const K<D, double> k(h);
  const int n = 3;  // > h / dx
  double sum = 0;
  for (int a = -n; a <= n; ++a)
    for (int b = -n; b <= n; ++b)
      for (int c = (D == 3 ? -n : 0); c <= (D == 3 ? n : 0); ++c) {
        Vec<D, double> xij{};  // x_i - x_j
        xij[0] = -a * dx;
        xij[1] = -b * dx;
        if constexpr (D == 3) xij[2] = -c * dx;
        const double r2 = norm2(xij);
        if (r2 == 0) continue;           // j = i adds nothing (A_i - A_j = 0); 0 / 0 without epsilon
        const double a_i = 0, a_j = r2;  // A = |x|^2
        sum += 2 * dot(xij, k.gradient(xij, std::sqrt(r2))) / (r2 + epsilon * h * h) * (a_i - a_j);
      }
  const double laplacian = sum * std::pow(dx, D);
  EXPECT_NEAR(laplacian / (2 * D), 1.0, tolerance)
      << D << "D " << name << " epsilon=" << epsilon << ": lattice Laplacian of |x|^2 = " << laplacian << ", exact "
      << 2 * D;
}
TEST(Kernels, MorrisLaplacianOfQuadraticOnLattice) {
  for (const auto& [epsilon, tolerance] : {std::pair{0.0, 0.03}, std::pair{0.01, 0.07}}) {
    check_lattice_laplacian<CubicSplineKernel, 2>(0.01, epsilon, tolerance, "cubic");
    check_lattice_laplacian<CubicSplineKernel, 3>(0.02, epsilon, tolerance, "cubic");
    check_lattice_laplacian<WendlandC2Kernel, 2>(0.01, epsilon, tolerance, "Wendland");
    check_lattice_laplacian<WendlandC2Kernel, 3>(0.02, epsilon, tolerance, "Wendland");
  }
}

template <template <int, std::floating_point> class K, int D>
void check_new_float_matches_double(double h, const char* name) {
  const K<D, float> kf(static_cast<float>(h));
  const K<D, double> kd(h);
  EXPECT_NEAR(kf.norm(), kd.norm(), 1e-6 * kd.norm()) << D << "D " << name;
  for (double q : {0.0, 0.2, 0.45, 0.55, 0.8, 0.95}) {
    const double r = q * h;
    const float rf = static_cast<float>(r);
    EXPECT_NEAR(kf.w(rf), kd.w(r), 1e-5 * kd.w(r)) << D << "D " << name << " q=" << q;
    EXPECT_NEAR(kf.w_r2(rf * rf), kd.w(r), 1e-5 * kd.w(r)) << D << "D " << name << " q=" << q;
    EXPECT_NEAR(kf.gradient_factor(rf), kd.gradient_factor(r), 1e-5 * std::abs(kd.gradient_factor(r)))
        << D << "D " << name << " q=" << q;
  }
}
TEST(Kernels, CubicAndWendlandFloatMatchesDouble) {
  check_new_float_matches_double<CubicSplineKernel, 2>(0.02, "cubic");
  check_new_float_matches_double<CubicSplineKernel, 3>(0.04, "cubic");
  check_new_float_matches_double<WendlandC2Kernel, 2>(0.02, "Wendland");
  check_new_float_matches_double<WendlandC2Kernel, 3>(0.04, "Wendland");
}

}  // namespace
}  // namespace sph
