#pragma once
/// \file The kernel-gradient correction (FluidParams::gradient_correction, Renormalize): each
/// particle's L_i = A_i^-1 with A_i = sum_j V_j grad_i W_ij (x_j - x_i)^T, so that a linear field
/// gets its exact gradient in a full neighbourhood. The pressure terms of both solvers use it
/// the same way: a fluid pair's gradient becomes (L_i + L_j) / 2 grad W_ij (equal and opposite
/// for the two particles: momentum stays conserved), a boundary sample's L_i grad W_ib.

#include <concepts>
#include <vector>

#include <sph/core/particle_set.h>
#include <sph/neighbors/neighbor_lists.h>
#include <sph/solver/smoothing.h>
#include <sph/solver/wcsph.h>

namespace sph {

/// Fills L (D x D per particle, row-major; resized to ps.size() D^2) with L_i = A_i^-1,
/// A_i = sum_j V_j grad_i W_ij (x_j - x_i)^T over the listed neighbours (V_j = m_j / rho_j, the
/// densities of this step) and the boundary samples (V_b = psi_b / rest_density), or with the
/// identity where det A_i < 1/2: at a free surface or for a lone particle A_i is far from I and
/// nearly singular. The buffer is reused: no allocation once it has its size.
template <int D, std::floating_point R>
void gradient_corrections(const ParticleSet<D, R>& ps, const NeighborLists& lists,
                          const SmoothingKernels<D, R>& kernels, const BoundaryView<D, R>& boundary, R rest_density,
                          std::vector<R>& L);

/// m g with m = (L_i + L_j) / 2 (li, lj: rows of gradient_corrections' L); with lj == li, L_i g.
template <int D, std::floating_point R>
Vec<D, R> corrected_gradient(const R* li, const R* lj, const Vec<D, R>& g) {
  Vec<D, R> out{};
  for (int r = 0; r < D; ++r) {
    R gc = 0;
    for (int c = 0; c < D; ++c) gc += R(0.5) * (li[r * D + c] + lj[r * D + c]) * g[c];
    out[r] = gc;
  }
  return out;
}

}  // namespace sph
