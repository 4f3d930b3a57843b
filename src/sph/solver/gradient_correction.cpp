#include <sph/solver/gradient_correction.h>

#include <sph/core/parallel.h>

namespace sph {

template <int D, std::floating_point R>
void gradient_corrections(const ParticleSet<D, R>& ps, const NeighborLists& lists,
                          const SmoothingKernels<D, R>& kernels, const BoundaryView<D, R>& boundary, R rest_density,
                          std::vector<R>& L) {
  L.resize(ps.size() * D * D);
  const bool solid = boundary.active();
  parallel_for(ps.size(), [&](std::size_t i) {
    R a[D][D] = {};
    const auto add = [&](const Vec<D, R>& rij, R v) {
      const Vec<D, R> g = kernels.gradient(rij);
      for (int r = 0; r < D; ++r)
        for (int c = 0; c < D; ++c) a[r][c] -= v * g[r] * rij[c];  // x_j - x_i = -rij
    };
    for (const std::uint32_t j : lists.of(i)) add(ps.position[i] - ps.position[j], ps.mass / ps.density[j]);
    if (solid)
      for (const std::uint32_t b : boundary.lists->of(i))
        add(ps.position[i] - boundary.position[b], boundary.psi[b] / rest_density);
    R* out = &L[i * D * D];
    R det;
    if constexpr (D == 2)
      det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
    else
      det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
            a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    if (!(det >= R(0.5))) {  // also NaN
      for (int r = 0; r < D; ++r)
        for (int c = 0; c < D; ++c) out[r * D + c] = r == c ? R(1) : R(0);
      return;
    }
    if constexpr (D == 2) {
      out[0] = a[1][1] / det, out[1] = -a[0][1] / det, out[2] = -a[1][0] / det, out[3] = a[0][0] / det;
    } else {
      // The adjugate's transpose over the determinant.
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) {
          const int r1 = (c + 1) % 3, r2 = (c + 2) % 3, c1 = (r + 1) % 3, c2 = (r + 2) % 3;
          out[r * 3 + c] = (a[r1][c1] * a[r2][c2] - a[r1][c2] * a[r2][c1]) / det;
        }
    }
  });
}

#define SPH_GRADIENT_CORRECTIONS(D, R)                                                                  \
  template void gradient_corrections<D, R>(const ParticleSet<D, R>&, const NeighborLists&,              \
                                           const SmoothingKernels<D, R>&, const BoundaryView<D, R>&, R, \
                                           std::vector<R>&);
SPH_GRADIENT_CORRECTIONS(2, float)
SPH_GRADIENT_CORRECTIONS(2, double)
SPH_GRADIENT_CORRECTIONS(3, float)
SPH_GRADIENT_CORRECTIONS(3, double)
#undef SPH_GRADIENT_CORRECTIONS

}  // namespace sph
