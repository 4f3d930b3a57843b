#pragma once
/// \file SPH smoothing kernels: those of Mueller, Charypar and Gross (2003), "Particle-Based
/// Fluid Simulation for Interactive Applications", Monaghan's (1992) cubic spline and Wendland's
/// (1995) C2 kernel, each with its own 2D and 3D normalization.
///
/// Kernels are value objects holding the support radius h; they have no static state.
/// All take distances in metres and return values in 1/m^D (W), 1/m^(D+1) (gradient) or
/// 1/m^(D+2) (Laplacian). Outside the support (r >= h) every function returns 0.
///
/// Normalizations (each kernel integrates to one over its support):
///   poly6      W = C (h^2 - r^2)^3,       C = 315 / (64 pi h^9) in 3D,  4 / (pi h^8) in 2D
///   spiky      W = C (h - r)^3,           C =  15 / (pi h^6)    in 3D, 10 / (pi h^5) in 2D
///   viscosity  lap W = C (h - r),         C =  45 / (pi h^6)    in 3D, 40 / (pi h^5) in 2D
///   cubic      W = C (6 (q^3 - q^2) + 1) for q <= 1/2, C 2 (1 - q)^3 for 1/2 < q < 1,
///                                         C =   8 / (pi h^3)    in 3D, 40 / (7 pi h^2) in 2D
///   Wendland   W = C (1 - q)^4 (1 + 4 q), C =  21 / (2 pi h^3)  in 3D,  7 / (pi h^2) in 2D
/// with q = r / h. The 2D viscosity kernel is the radial function with Laplacian C (h - r) that
/// vanishes with its derivative at r = h and integrates to one (see docs/physics.md for its
/// closed form).

#include <cmath>
#include <numbers>

#include <sph/core/vec.h>

namespace sph {

/// Poly6 kernel: used for density (paper Eq. 4), and its gradient for the variational pressure
/// force.
template <int D, std::floating_point R>
class Poly6Kernel {
 public:
  explicit Poly6Kernel(R h) : h_(h), h2_(h * h) {
    const double hd = static_cast<double>(h);
    const double pi = std::numbers::pi;
    norm_ = static_cast<R>(D == 3 ? 315.0 / (64.0 * pi * std::pow(hd, 9)) : 4.0 / (pi * std::pow(hd, 8)));
  }
  R h() const { return h_; }
  /// W(r) from the squared distance r2 = |x_i - x_j|^2.
  /// The constant C of W = C (h^2 - r^2)^3.
  R norm() const { return norm_; }
  R w_r2(R r2) const {
    if (r2 >= h2_) return R(0);
    const R d = h2_ - r2;
    return norm_ * d * d * d;
  }
  R w(R r) const { return w_r2(r * r); }
  /// W(0): the particle's own contribution to its density.
  R w_zero() const { return norm_ * h2_ * h2_ * h2_; }
  /// Gradient of W with respect to x_i, for rij = x_i - x_j at squared distance r2 = |rij|^2:
  /// -6 C (h^2 - r^2)^2 rij (the variational pressure force's). Zero for r2 >= h^2.
  Vec<D, R> gradient(const Vec<D, R>& rij, R r2) const {
    if (r2 >= h2_) return Vec<D, R>{};
    const R d = h2_ - r2;
    return rij * (R(-6) * norm_ * d * d);
  }

 private:
  R h_, h2_, norm_;
};

/// Spiky kernel: its gradient drives the pressure force (paper Eq. 5).
template <int D, std::floating_point R>
class SpikyKernel {
 public:
  explicit SpikyKernel(R h) : h_(h) {
    const double hd = static_cast<double>(h);
    const double pi = std::numbers::pi;
    norm_ = static_cast<R>(D == 3 ? 15.0 / (pi * std::pow(hd, 6)) : 10.0 / (pi * std::pow(hd, 5)));
  }
  R h() const { return h_; }
  /// The constant C of W = C (h - r)^3.
  R norm() const { return norm_; }
  R w(R r) const {
    if (r >= h_) return R(0);
    const R d = h_ - r;
    return norm_ * d * d * d;
  }
  /// Gradient of W with respect to x_i, for rij = x_i - x_j at distance r = |rij| > 0:
  /// -3 C (h - r)^2 rij / r. Returns zero for r == 0 (coincident particles) and r >= h.
  Vec<D, R> gradient(const Vec<D, R>& rij, R r) const {
    if (r >= h_ || r <= R(0)) return Vec<D, R>{};
    const R d = h_ - r;
    return rij * (R(-3) * norm_ * d * d / r);
  }

 private:
  R h_, norm_;
};

/// Viscosity kernel: its Laplacian drives the viscous force (paper Eq. 6).
template <int D, std::floating_point R>
class ViscosityKernel {
 public:
  explicit ViscosityKernel(R h) : h_(h) {
    const double hd = static_cast<double>(h);
    const double pi = std::numbers::pi;
    lap_norm_ = static_cast<R>(D == 3 ? 45.0 / (pi * std::pow(hd, 6)) : 40.0 / (pi * std::pow(hd, 5)));
  }
  R h() const { return h_; }
  /// The constant C of the Laplacian C (h - r).
  R laplacian_norm() const { return lap_norm_; }
  /// Laplacian of W: C (h - r) for r < h.
  R laplacian(R r) const { return r >= h_ ? R(0) : lap_norm_ * (h_ - r); }
  /// W itself (singular at r = 0 in both dimensions; only used to check normalization).
  R w(R r) const {
    if (r >= h_ || r <= R(0)) return R(0);
    const double hd = h_, rd = r;
    const double pi = std::numbers::pi;
    if constexpr (D == 3) {
      const double q = rd / hd;
      return static_cast<R>(15.0 / (2.0 * pi * hd * hd * hd) * (-q * q * q / 2.0 + q * q + 1.0 / (2.0 * q) - 1.0));
    } else {
      const double c = 40.0 / (pi * std::pow(hd, 5));
      return static_cast<R>(c * (hd * rd * rd / 4.0 - rd * rd * rd / 9.0 - 5.0 * hd * hd * hd / 36.0 -
                                 hd * hd * hd / 6.0 * std::log(rd / hd)));
    }
  }

 private:
  R h_, lap_norm_;
};

/// Monaghan's (1992) cubic B-spline M4, written on the support h (the neighbor search's radius,
/// so q = r / h in [0, 1]; Monaghan's own smoothing length is h / 2). Used for density and the
/// pressure gradient when Configuration.kernel is KernelKind::Cubic.
template <int D, std::floating_point R>
class CubicSplineKernel {
 public:
  explicit CubicSplineKernel(R h) : h_(h) {
    const double hd = static_cast<double>(h);
    const double pi = std::numbers::pi;
    const double sigma = D == 3 ? 8.0 / (pi * hd * hd * hd) : 40.0 / (7.0 * pi * hd * hd);
    norm_ = static_cast<R>(sigma);
    grad_norm_ = static_cast<R>(sigma / (hd * hd));
  }
  R h() const { return h_; }
  /// The constant sigma of W = sigma f(q), 1/m^D.
  R norm() const { return norm_; }
  /// W(r): sigma (6 (q^3 - q^2) + 1) for q <= 1/2, sigma 2 (1 - q)^3 for 1/2 < q < 1.
  R w(R r) const {
    if (r >= h_) return R(0);
    const R q = r / h_;  // correctly rounded, so q <= 1 whenever r < h
    if (q <= R(0.5)) return norm_ * (R(6) * (q * q * q - q * q) + R(1));
    const R d = R(1) - q;
    return norm_ * R(2) * d * d * d;
  }
  /// W from the squared distance r2 = |x_i - x_j|^2.
  R w_r2(R r2) const { return w(std::sqrt(r2)); }
  /// W(0) = sigma: the particle's own contribution to its density.
  R w_zero() const { return norm_; }
  /// (dW/dr) / r, 1/m^(D+2): sigma (18 q - 12) / h^2 for q <= 1/2 (finite at r = 0, where it is
  /// -12 sigma / h^2), -6 sigma (1 - q)^2 / (q h^2) for 1/2 < q < 1, 0 for r >= h.
  R gradient_factor(R r) const {
    if (r >= h_) return R(0);
    const R q = r / h_;
    if (q <= R(0.5)) return grad_norm_ * (R(18) * q - R(12));
    const R d = R(1) - q;
    return R(-6) * grad_norm_ * d * d / q;
  }
  /// Gradient of W with respect to x_i, for rij = x_i - x_j at distance r = |rij|:
  /// gradient_factor(r) rij (zero for coincident particles and for r >= h).
  Vec<D, R> gradient(const Vec<D, R>& rij, R r) const { return rij * gradient_factor(r); }

 private:
  R h_, norm_, grad_norm_;  // grad_norm_ = sigma / h^2
};

/// Wendland's (1995) C2 kernel in the form of Dehnen and Aly (2012), "Improving convergence in
/// smoothed particle hydrodynamics simulations without pairing instability": positive Fourier
/// transform, so no pairing instability. Used for density and the pressure gradient when
/// Configuration.kernel is KernelKind::Wendland.
template <int D, std::floating_point R>
class WendlandC2Kernel {
 public:
  explicit WendlandC2Kernel(R h) : h_(h) {
    const double hd = static_cast<double>(h);
    const double pi = std::numbers::pi;
    const double sigma = D == 3 ? 21.0 / (2.0 * pi * hd * hd * hd) : 7.0 / (pi * hd * hd);
    norm_ = static_cast<R>(sigma);
    grad_norm_ = static_cast<R>(sigma / (hd * hd));
  }
  R h() const { return h_; }
  /// The constant sigma of W = sigma (1 - q)^4 (1 + 4 q), 1/m^D.
  R norm() const { return norm_; }
  /// W(r) = sigma (1 - q)^4 (1 + 4 q) for q < 1.
  R w(R r) const {
    if (r >= h_) return R(0);
    const R q = r / h_;
    const R d = R(1) - q;
    const R d2 = d * d;
    return norm_ * d2 * d2 * (R(1) + R(4) * q);
  }
  /// W from the squared distance r2 = |x_i - x_j|^2.
  R w_r2(R r2) const { return w(std::sqrt(r2)); }
  /// W(0) = sigma: the particle's own contribution to its density.
  R w_zero() const { return norm_; }
  /// (dW/dr) / r = -20 sigma (1 - q)^3 / h^2, 1/m^(D+2), for r < h (-20 sigma / h^2 at r = 0);
  /// 0 for r >= h.
  R gradient_factor(R r) const {
    if (r >= h_) return R(0);
    const R d = R(1) - r / h_;
    return R(-20) * grad_norm_ * d * d * d;
  }
  /// Gradient of W with respect to x_i, for rij = x_i - x_j at distance r = |rij|:
  /// gradient_factor(r) rij (zero for coincident particles and for r >= h).
  Vec<D, R> gradient(const Vec<D, R>& rij, R r) const { return rij * gradient_factor(r); }

 private:
  R h_, norm_, grad_norm_;  // grad_norm_ = sigma / h^2
};

/// Configuration.kernel: which smoothing kernels the solver uses.
enum class KernelKind {
  Paper,     ///< Mueller et al. 2003: poly6 density, spiky pressure gradient, viscosity-kernel Laplacian
  Cubic,     ///< Monaghan 1992 cubic spline for density and gradient; viscosity by Morris et al. 1997's
             ///< Laplacian approximation
  Wendland,  ///< Wendland C2 (1995; Dehnen & Aly 2012), the same way
};

}  // namespace sph
