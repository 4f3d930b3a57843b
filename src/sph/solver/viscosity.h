#pragma once
/// \file The fluid's viscosity integrated backward in time (FluidParams::viscosity_solve,
/// ViscositySolve::Implicit; Scene key Fluid.viscositySolver "implicit").
///
/// The explicit force pass (wcsph.h) adds the viscosity term with the step's velocities,
///   a_i += sum_j k_ij (v_j - v_i),
/// k_ij = mu m_j lap W_visc(r) / (rho_i rho_j) (paper Eq. 6) or, with the cubic spline and
/// Wendland C2, -2 mu m_j (x_ij . grad W_ij) / (rho_i rho_j (r^2 + 0.01 h^2)) (Morris et al.
/// 1997), and is stable only below the diffusion limit dt <= 0.125 h^2 rho0 / mu. This solve
/// takes the same term at the velocities after the step instead: with v* = v + dt a (every
/// other acceleration of the step: gravity, the walls, the boundary friction, WCSPH's pressure),
/// the velocities v after the step satisfy
///   m_i v_i + dt sum_j m_i k_ij (v_i - v_j) = m_i v*_i   for every particle i
/// over the step's pairs closer than h. m_i k_ij is symmetric in i and j (one pair term, equal and
/// opposite), so the matrix, the masses plus dt times a weighted graph Laplacian, is symmetric
/// positive definite: conjugate gradients, preconditioned by its diagonal, on all D components
/// at once. The solve starts from v* (so its starting residual is the explicit step's viscous
/// impulse) and stops when the residual is below FluidParams::viscosity_max_error % of the
/// starting one, or after viscosity_max_iterations. The velocity change becomes an
/// acceleration, a_i += (v_i - v*_i) / dt, so the rest of the step (DFSPH's density solve, the
/// integration) sees it like any other. As the backward Euler step of a diffusion it damps every
/// mode, however large dt: high viscosities run at the flow's steps. Momentum is conserved up to
/// the solve's tolerance (each pair's terms are equal and opposite). Sums over particles are
/// taken in fixed chunks: the result is the same for any thread count.

#include <cstdint>
#include <vector>

#include <sph/core/particle_set.h>
#include <sph/neighbors/neighbor_lists.h>
#include <sph/solver/params.h>
#include <sph/solver/solve_stats.h>

namespace sph {

template <int D, std::floating_point R>
class ImplicitViscosity {
 public:
  /// Adds to ps.acceleration the implicit viscous acceleration of a step of dt over the listed
  /// pairs closer than h (ps.acceleration holds the step's other accelerations; the densities
  /// are the step's). Returns the iterations and the final residual as a % of the starting one.
  SolveStats solve(ParticleSet<D, R>& ps, const NeighborLists& lists, R h, const FluidParams& fluid, R dt);

 private:
  /// y = A x: y_i = m_i x_i + sum_j w_ij (x_i - x_j).
  void apply(const std::vector<Vec<D, R>>& x, std::vector<Vec<D, R>>& y) const;
  /// sum_i a_i . b_i, in fixed chunks.
  double dot(const std::vector<Vec<D, R>>& a, const std::vector<Vec<D, R>>& b);

  // The step's pairs within h: particle i's are begin_[i] .. begin_[i+1], with w_ij = dt m_i k_ij.
  std::vector<std::size_t> begin_;
  std::vector<std::uint32_t> pair_j_;
  std::vector<R> pair_w_;
  std::vector<R> mass_, diag_;  // m_i, and the matrix's diagonal m_i + sum_j w_ij
  std::vector<Vec<D, R>> x_, r_, z_, p_, ap_, b_;
  std::vector<double> partial_;  // per-chunk sums (kept: no allocation in a steady run)
};

extern template class ImplicitViscosity<2, float>;
extern template class ImplicitViscosity<2, double>;
extern template class ImplicitViscosity<3, float>;
extern template class ImplicitViscosity<3, double>;

}  // namespace sph
