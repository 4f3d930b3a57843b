#include <sph/solver/viscosity.h>

#include <cmath>

#include <sph/core/error.h>
#include <sph/core/parallel.h>
#include <sph/solver/smoothing.h>

namespace sph {

template <int D, std::floating_point R>
void ImplicitViscosity<D, R>::apply(const std::vector<Vec<D, R>>& x, std::vector<Vec<D, R>>& y) const {
  parallel_for(mass_.size(), [&](std::size_t i) {
    const Vec<D, R> xi = x[i];
    Vec<D, R> sum = xi * mass_[i];
    for (std::size_t k = begin_[i]; k < begin_[i + 1]; ++k) sum += (xi - x[pair_j_[k]]) * pair_w_[k];
    y[i] = sum;
  });
}

template <int D, std::floating_point R>
double ImplicitViscosity<D, R>::dot(const std::vector<Vec<D, R>>& a, const std::vector<Vec<D, R>>& b) {
  return chunked_sum(mass_.size(), partial_, [&](std::size_t i) {
    double s = 0;
    for (int d = 0; d < D; ++d) s += static_cast<double>(a[i][d]) * static_cast<double>(b[i][d]);
    return s;
  });
}

template <int D, std::floating_point R>
SolveStats ImplicitViscosity<D, R>::solve(ParticleSet<D, R>& ps, const NeighborLists& lists, R h,
                                          const FluidParams& fluid, R dt) {
  SolveStats stats;
  const std::size_t n = ps.size();
  SPH_CHECK(lists.particle_count() == n, "implicit viscosity: neighbor lists do not cover the particles");
  if (n == 0 || !(dt > R(0)) || !(fluid.viscosity > 0)) return stats;
  const R h2 = h * h;
  const SmoothingKernels<D, R> kernels(fluid, h);
  const R mu = static_cast<R>(fluid.viscosity);
  // The step's pairs within h, and w_ij = dt m_i k_ij = dt mu L(r) (m_i m_j) / (rho_i rho_j)
  // (SmoothingKernels::viscosity_laplacian): the same number for (i, j) and (j, i), so the matrix
  // is exactly symmetric.
  begin_.resize(n + 1);
  begin_[0] = 0;
  parallel_for(n, [&](std::size_t i) {
    std::size_t count = 0;
    const Vec<D, R> xi = ps.position[i];
    for (const std::uint32_t j : lists.of(i)) count += norm2(xi - ps.position[j]) < h2;
    begin_[i + 1] = count;
  });
  for (std::size_t i = 0; i < n; ++i) begin_[i + 1] += begin_[i];
  pair_j_.resize(begin_[n]);
  pair_w_.resize(begin_[n]);
  mass_.resize(n);
  diag_.resize(n);
  for (auto* v : {&x_, &r_, &z_, &p_, &ap_, &b_}) v->resize(n);
  parallel_for(n, [&](std::size_t i) {
    const Vec<D, R> xi = ps.position[i];
    const R mi = ps.mass, inv_rhoi = R(1) / ps.density[i];
    R diag = mi;
    std::size_t k = begin_[i];
    for (const std::uint32_t j : lists.of(i)) {
      const R r2 = norm2(xi - ps.position[j]);
      if (!(r2 < h2)) continue;
      const R w = dt * mu * kernels.viscosity_laplacian(r2) * ((mi * ps.mass) * (inv_rhoi * (R(1) / ps.density[j])));
      pair_j_[k] = j, pair_w_[k] = w, ++k;
      diag += w;
    }
    mass_[i] = mi;
    diag_[i] = diag;
    // v* = v + dt a, the right-hand side m_i v*_i, and the start x = v*.
    x_[i] = ps.velocity[i] + ps.acceleration[i] * dt;
    b_[i] = x_[i] * mi;
  });
  // r = b - A x, z = r / diag, p = z.
  apply(x_, ap_);
  parallel_for(n, [&](std::size_t i) {
    r_[i] = b_[i] - ap_[i];
    p_[i] = z_[i] = r_[i] * (R(1) / diag_[i]);
  });
  const double start = std::sqrt(dot(r_, r_));
  const double tolerance = 0.01 * fluid.viscosity_max_error * start;
  double rz = dot(r_, z_), residual = start;
  while (residual > tolerance && stats.iterations < fluid.viscosity_max_iterations) {
    apply(p_, ap_);
    ++stats.iterations;
    const double pap = dot(p_, ap_);
    if (!(pap > 0)) break;  // (A is positive definite: only round-off ends here)
    const R alpha = static_cast<R>(rz / pap);
    parallel_for(n, [&](std::size_t i) {
      x_[i] += p_[i] * alpha;
      r_[i] -= ap_[i] * alpha;
      z_[i] = r_[i] * (R(1) / diag_[i]);
    });
    residual = std::sqrt(dot(r_, r_));
    if (residual <= tolerance) break;
    const double rz_new = dot(r_, z_);
    const R beta = static_cast<R>(rz_new / rz);
    rz = rz_new;
    parallel_for(n, [&](std::size_t i) { p_[i] = z_[i] + p_[i] * beta; });
  }
  stats.error = start > 0 ? 100.0 * residual / start : 0.0;
  stats.converged = residual <= tolerance;
  // The velocity change as an acceleration of the step: v* + dt a_visc = x.
  parallel_for(n, [&](std::size_t i) {
    ps.acceleration[i] += (x_[i] - (ps.velocity[i] + ps.acceleration[i] * dt)) * (R(1) / dt);
  });
  return stats;
}

template class ImplicitViscosity<2, float>;
template class ImplicitViscosity<2, double>;
template class ImplicitViscosity<3, float>;
template class ImplicitViscosity<3, double>;

}  // namespace sph
