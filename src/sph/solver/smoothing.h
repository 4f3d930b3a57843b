#pragma once
/// \file SmoothingKernels: the run's choice of kernels (FluidParams::kernel, pressure_force) as
/// scalar functions, for the code outside the vector pair loops: the gradient correction, the
/// boundary samples' volumes, the lattice mass, the health monitor's own-density test and the
/// implicit viscosity. The vector loops of wcsph.cpp evaluate the same formulas with the same
/// constants.

#include <cmath>

#include <sph/core/kernels.h>
#include <sph/solver/params.h>

namespace sph {

template <int D, std::floating_point R>
class SmoothingKernels {
 public:
  SmoothingKernels(KernelKind kind, R h, bool variational = false)
      : kind_(kind), variational_(variational), h_(h), poly6_(h), spiky_(h), cubic_(h), wendland_(h), visc_(h) {}
  SmoothingKernels(const FluidParams& fluid, R h)
      : SmoothingKernels(fluid.kernel, h, fluid.pressure_force == PressureForce::Variational) {}

  KernelKind kind() const { return kind_; }
  /// The support h, m.
  R radius() const { return h_; }
  /// The density kernel W (poly6 for the paper's kernels) from the squared distance.
  R w_r2(R r2) const {
    switch (kind_) {
      case KernelKind::Cubic:
        return cubic_.w_r2(r2);
      case KernelKind::Wendland:
        return wendland_.w_r2(r2);
      case KernelKind::Paper:
        break;
    }
    return poly6_.w_r2(r2);
  }
  R w_zero() const { return w_r2(R(0)); }
  /// The gradient grad_i W(x_i - x_j) the pressure force uses, for rij = x_i - x_j: the spiky
  /// kernel's (poly6's for PressureForce::Variational) with the paper's kernels, the density
  /// kernel's own otherwise; zero outside [0, h) and, for spiky, at r = 0.
  Vec<D, R> gradient(const Vec<D, R>& rij) const {
    const R r2 = norm2(rij);
    switch (kind_) {
      case KernelKind::Cubic:
        return cubic_.gradient(rij, std::sqrt(r2));
      case KernelKind::Wendland:
        return wendland_.gradient(rij, std::sqrt(r2));
      case KernelKind::Paper:
        break;
    }
    if (variational_) return poly6_.gradient(rij, r2);
    return spiky_.gradient(rij, std::sqrt(r2));
  }

  /// The viscosity term's Laplacian weight L(r), for a pair at squared distance r2 < h^2, as the
  /// force pass takes it (ViscosityModel::Paper): a_i += mu m_j L / (rho_i rho_j) (v_j - v_i), with
  /// L the viscosity kernel's Laplacian (paper Eq. 6) or, with the cubic spline and Wendland C2,
  /// Morris et al.'s -2 (x_ij . grad W_ij) / (r^2 + 0.01 h^2).
  R viscosity_laplacian(R r2) const {
    const R r = std::sqrt(r2);
    switch (kind_) {
      case KernelKind::Cubic:
        return R(-2) * (cubic_.gradient_factor(r) * r2) / (r2 + R(0.01) * h_ * h_);
      case KernelKind::Wendland:
        return R(-2) * (wendland_.gradient_factor(r) * r2) / (r2 + R(0.01) * h_ * h_);
      case KernelKind::Paper:
        break;
    }
    return visc_.laplacian(r);
  }

 private:
  KernelKind kind_;
  bool variational_;
  R h_;
  Poly6Kernel<D, R> poly6_;
  SpikyKernel<D, R> spiky_;
  CubicSplineKernel<D, R> cubic_;
  WendlandC2Kernel<D, R> wendland_;
  ViscosityKernel<D, R> visc_;
};

}  // namespace sph
