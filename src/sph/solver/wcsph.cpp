#include <sph/solver/wcsph.h>

#include <algorithm>
#include <atomic>
#include <cmath>

#include <sph/core/error.h>
#include <sph/core/kernels.h>
#include <sph/core/parallel.h>
#include <sph/core/simd.h>

namespace sph {

namespace {

using simd::Mask;

/// The scalars of a vector field, x0 y0 z0 x1 y1 z1 ..., so that pair loops gather lanes.
template <int D, std::floating_point R>
const R* flat(const std::vector<Vec<D, R>>& v) {
  static_assert(sizeof(Vec<D, R>) == D * sizeof(R));
  return reinterpret_cast<const R*>(v.data());
}

/// What the pair loops assume: lists for exactly these particles, and indices times D that fit
/// the 32-bit signed offsets of the vector gathers.
template <int D, std::floating_point R>
void check_pass_inputs(const ParticleSet<D, R>& ps, const NeighborLists& lists) {
  SPH_CHECK(lists.particle_count() == ps.size(), "neighbor lists do not cover the particles");
  SPH_CHECK(ps.size() * D < (std::size_t{1} << 31), "too many particles for 32-bit gather offsets");
}

/// rij = x_i - x_j for one register of neighbors j = idx[0..lanes), gathered from the flat
/// positions; returns |rij|^2, summed as norm2 does (the lists' distance test uses the same).
template <int D, std::floating_point R>
simd::Pack<R> pair_offsets(const simd::Pack<R> (&xi)[D], const R* pos, const std::uint32_t* idx,
                           simd::Pack<R> (&rij)[D]) {
  using P = simd::Pack<R>;
  P r2 = P::set1(R(0));
  for (int d = 0; d < D; ++d) {
    rij[d] = xi[d] - P::template gather<D>(pos, idx, d);
    r2 = r2 + rij[d] * rij[d];
  }
  return r2;
}

/// The pair loops below take a particle's neighbors simd::kLanes<R> at a time (one vector
/// register), each lane keeping its own partial sums, which are added in lane order at the
/// end. Lanes past the end of a list load some valid index (NeighborLists::kPadding) and are
/// masked out. The result is the same for any thread count and with or without AVX-512.

template <int D, std::floating_point R>
std::uint64_t density_pass(ParticleSet<D, R>& ps, const NeighborLists& lists, R h, const FluidParams& fluid,
                           std::vector<std::uint64_t>& within) {
  using P = simd::Pack<R>;
  constexpr int W = simd::kLanes<R>;
  const Poly6Kernel<D, R> poly6(h);
  const R w0 = poly6.w_zero();
  const R h2 = h * h;
  const R rho0 = static_cast<R>(fluid.rest_density);
  const R k = static_cast<R>(fluid.stiffness);
  const bool clamp = fluid.negative_pressure == NegativePressure::Clamp;
  const R* pos = flat(ps.position);
  const R* mass = ps.mass.data();
  const P h2v = P::set1(h2), normv = P::set1(poly6.norm()), zero = P::set1(R(0));
  within.assign(chunk_count(ps.size()), 0);
  parallel_chunks(ps.size(), [&](std::size_t c, std::size_t b, std::size_t e) {
    std::uint64_t count = 0;
    for (std::size_t i = b; i < e; ++i) {
      P xi[D];
      for (int d = 0; d < D; ++d) xi[d] = P::set1(ps.position[i][d]);
      const auto nb = lists.of(i);
      const std::uint32_t* idx = nb.data();
      P sum = zero;
      for (std::size_t k0 = 0; k0 < nb.size(); k0 += W) {
        const Mask valid = simd::first_lanes<R>(nb.size() - k0);
        P rij[D];
        const P r2 = pair_offsets<D>(xi, pos, idx + k0, rij);
        const Mask in = valid & (r2 < h2v);
        const P dd = h2v - r2;
        // Paper Eq. 4: m_j W_poly6 = m_j C (h^2 - r^2)^3 inside the support.
        sum = sum + select(in, P::template gather<1>(mass, idx + k0, 0) * (normv * dd * dd * dd), zero);
        count += static_cast<std::uint64_t>(__builtin_popcount(in));
      }
      const R rho = mass[i] * w0 + simd::sum_lanes(sum);
      ps.density[i] = rho;
      const R p = k * (rho - rho0);
      ps.pressure[i] = clamp ? std::max(p, R(0)) : p;
    }
    within[c] = count;
  });
  std::uint64_t total = 0;
  for (std::uint64_t w : within) total += w;
  return total;
}

/// The force pass: viscosity, the Eq. 7 test when kExitTest, gravity, the walls, and the pressure
/// term of form kForm when kPressure (false with a gradient correction, whose pressure term
/// corrected_pressure_pass adds).
template <PressureForce kForm, bool kPressure, bool kExitTest, int D, std::floating_point R>
void force_pass(ParticleSet<D, R>& ps, const NeighborLists& lists, R h, const FluidParams& fluid,
                const Vec<D, R>& gravity, const WallContact<D, R>& walls, std::span<std::uint8_t> flags, R dt) {
  using P = simd::Pack<R>;
  constexpr int W = simd::kLanes<R>;
  const P hv = P::set1(h), h2v = P::set1(h * h), zero = P::set1(R(0)), one = P::set1(R(1)), minus_one = P::set1(R(-1)),
          half = P::set1(R(0.5));
  const P grad_c = P::set1(R(-3) * SpikyKernel<D, R>(h).norm());
  const P grad6_c = P::set1(R(-6) * Poly6Kernel<D, R>(h).norm());
  const R lap_c = ViscosityKernel<D, R>(h).laplacian_norm();
  const R mu = static_cast<R>(fluid.viscosity);
  const R* pos = flat(ps.position);
  const R* vel = flat(ps.velocity);
  const R* rho = ps.density.data();
  const R* prs = ps.pressure.data();
  const R* mass = ps.mass.data();
  const P dtv = P::set1(dt);
  const auto set_flag = [&](std::size_t q) {
    std::atomic_ref<std::uint8_t>(flags[q]).store(1, std::memory_order_relaxed);
  };
  parallel_for(ps.size(), [&](std::size_t i) {
    P xi[D], vi[D], acc[D];
    bool flag_i = false;
    for (int d = 0; d < D; ++d) xi[d] = P::set1(ps.position[i][d]), vi[d] = P::set1(ps.velocity[i][d]), acc[d] = zero;
    const R inv_rhoi = R(1) / rho[i];
    // Pressure term P_ij, symmetric in i and j, so that each pair's contributions are equal
    // and opposite: the paper's (p_i + p_j) / (2 rho_i rho_j), or p_i / rho_i^2 + p_j / rho_j^2.
    const P pi_half = P::set1(R(0.5) * prs[i] * inv_rhoi);
    const P pi_sym = P::set1(prs[i] * inv_rhoi * inv_rhoi);
    const P inv_rhoi_v = P::set1(inv_rhoi);
    const P visc_i = P::set1(mu * inv_rhoi * lap_c);
    const auto nb = lists.of(i);
    const std::uint32_t* idx = nb.data();
    for (std::size_t k0 = 0; k0 < nb.size(); k0 += W) {
      const Mask valid = simd::first_lanes<R>(nb.size() - k0);
      P rij[D];
      const P r2 = pair_offsets<D>(xi, pos, idx + k0, rij);
      const Mask near = valid & (r2 < h2v);  // inside the support
      const P r = sqrt(select(near, r2, h2v));
      const P dh = hv - r;
      const P inv_rhoj = one / P::template gather<1>(rho, idx + k0, 0);
      const P mj = P::template gather<1>(mass, idx + k0, 0);
      // -m_j P_ij times the spiky gradient -3 C (h - r)^2 rij / r (Eq. 5), and the viscosity
      // term mu m_j (v_j - v_i) C_lap (h - r) / (rho_i rho_j) (Eq. 6).
      // Variational: the density kernel's gradient -6 C6 (h^2 - r^2)^2 rij instead.
      P fp = zero;
      if constexpr (kPressure) {
        const P pj = P::template gather<1>(prs, idx + k0, 0);
        P pij;
        if constexpr (kForm == PressureForce::Paper)
          pij = (pi_half + half * pj * inv_rhoi_v) * inv_rhoj;
        else
          pij = pi_sym + pj * inv_rhoj * inv_rhoj;
        if constexpr (kForm == PressureForce::Variational) {
          const P d2 = h2v - r2;
          fp = select(near, grad6_c * d2 * d2 * (minus_one * mj * pij), zero);
        } else {
          const Mask apart = near & (r2 > zero);  // and not coincident (gradient defined)
          fp = select(apart, (grad_c * dh * dh / select(apart, r, one)) * (minus_one * mj * pij), zero);
        }
      }
      const P fv = select(near, visc_i * mj * inv_rhoj * dh, zero);
      P q2 = zero;  // Eq. 7: squared pair distance after the step, predicted with today's velocities
      for (int d = 0; d < D; ++d) {
        const P vj = P::template gather<D>(vel, idx + k0, d);
        if constexpr (kPressure)
          acc[d] = acc[d] + (rij[d] * fp + (vj - vi[d]) * fv);
        else
          acc[d] = acc[d] + (vj - vi[d]) * fv;
        if constexpr (kExitTest) {
          const P t = rij[d] + (vi[d] - vj) * dtv;
          q2 = q2 + t * t;
        }
      }
      if constexpr (kExitTest)
        for (Mask out = valid & (q2 > h2v); out != 0; out &= out - 1) {
          flag_i = true;
          set_flag(idx[k0 + static_cast<std::size_t>(__builtin_ctz(out))]);
        }
    }
    if constexpr (kExitTest)
      if (flag_i) set_flag(i);
    Vec<D, R> a = gravity;
    for (int d = 0; d < D; ++d) a[d] += simd::sum_lanes(acc[d]);
    a += walls(ps.position[i], ps.velocity[i]);
    ps.acceleration[i] = a;
  });
}

/// The kernel gradient grad_i W(x_i - x_j) the pressure force uses, for rij = x_i - x_j: the
/// spiky kernel's, or poly6's for PressureForce::Variational; zero outside (0, h).
template <int D, std::floating_point R>
class PressureGradient {
 public:
  PressureGradient(R h, PressureForce form) : poly6_(h), spiky_(h), variational_(form == PressureForce::Variational) {}
  Vec<D, R> operator()(const Vec<D, R>& rij) const {
    const R r2 = norm2(rij);
    if (variational_) return poly6_.gradient(rij, r2);
    return spiky_.gradient(rij, std::sqrt(r2));
  }

 private:
  Poly6Kernel<D, R> poly6_;
  SpikyKernel<D, R> spiky_;
  bool variational_;
};

/// L_i = A_i^-1 with A_i = sum_j V_j grad_i W_ij (x_j - x_i)^T (row-major D x D per particle),
/// or the identity where det A_i < 1/2 (see GradientCorrection::Renormalize).
template <int D, std::floating_point R>
std::vector<R> gradient_corrections(const ParticleSet<D, R>& ps, const NeighborLists& lists,
                                    const PressureGradient<D, R>& gradient) {
  std::vector<R> L(ps.size() * D * D);
  parallel_for(ps.size(), [&](std::size_t i) {
    R a[D][D] = {};
    for (const std::uint32_t j : lists.of(i)) {
      const Vec<D, R> rij = ps.position[i] - ps.position[j];
      const Vec<D, R> g = gradient(rij);
      const R v = ps.mass[j] / ps.density[j];
      for (int r = 0; r < D; ++r)
        for (int c = 0; c < D; ++c) a[r][c] -= v * g[r] * rij[c];  // x_j - x_i = -rij
    }
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
  return L;
}

/// Adds the pressure accelerations with corrected gradients: each pair's term of the plain
/// force (in its form) with grad W_ij replaced by (L_i + L_j) / 2 grad W_ij.
template <int D, std::floating_point R>
void corrected_pressure_pass(ParticleSet<D, R>& ps, const NeighborLists& lists, R h, const FluidParams& fluid) {
  const PressureGradient<D, R> gradient(h, fluid.pressure_force);
  const std::vector<R> L = gradient_corrections(ps, lists, gradient);
  const bool paper = fluid.pressure_force == PressureForce::Paper;
  parallel_for(ps.size(), [&](std::size_t i) {
    const R* li = &L[i * D * D];
    const R inv_rhoi = R(1) / ps.density[i];
    Vec<D, R> acc{};
    for (const std::uint32_t j : lists.of(i)) {
      const Vec<D, R> g = gradient(ps.position[i] - ps.position[j]);
      const R inv_rhoj = R(1) / ps.density[j];
      const R pij = paper ? (R(0.5) * ps.pressure[i] + R(0.5) * ps.pressure[j]) * inv_rhoi * inv_rhoj
                          : ps.pressure[i] * inv_rhoi * inv_rhoi + ps.pressure[j] * inv_rhoj * inv_rhoj;
      const R* lj = &L[std::size_t{j} * D * D];
      for (int r = 0; r < D; ++r) {
        R gc = 0;
        for (int c = 0; c < D; ++c) gc += R(0.5) * (li[r * D + c] + lj[r * D + c]) * g[c];
        acc[r] -= ps.mass[j] * pij * gc;
      }
    }
    ps.acceleration[i] += acc;
  });
}

}  // namespace

template <int D, std::floating_point R>
std::uint64_t compute_density_pressure(ParticleSet<D, R>& ps, const NeighborLists& lists, R h,
                                       const FluidParams& fluid) {
  check_pass_inputs(ps, lists);
  thread_local std::vector<std::uint64_t> within;  // per-chunk counts, kept between steps
  return density_pass(ps, lists, h, fluid, within);
}

template <int D, std::floating_point R>
void compute_accelerations(ParticleSet<D, R>& ps, const NeighborLists& lists, R h, const FluidParams& fluid,
                           const Vec<D, R>& gravity, const WallContact<D, R>& walls, std::span<std::uint8_t> exit_flags,
                           R dt) {
  SPH_CHECK(exit_flags.empty() || exit_flags.size() == ps.size(), "one exit flag per particle");
  check_pass_inputs(ps, lists);
  const auto run = [&]<PressureForce kForm, bool kPressure>() {
    if (exit_flags.empty())
      force_pass<kForm, kPressure, false>(ps, lists, h, fluid, gravity, walls, exit_flags, dt);
    else
      force_pass<kForm, kPressure, true>(ps, lists, h, fluid, gravity, walls, exit_flags, dt);
  };
  if (fluid.gradient_correction == GradientCorrection::Renormalize) {
    run.template operator()<PressureForce::Paper, false>();  // the form only matters to the pressure term
    corrected_pressure_pass(ps, lists, h, fluid);
    return;
  }
  switch (fluid.pressure_force) {
    case PressureForce::Paper:
      run.template operator()<PressureForce::Paper, true>();
      break;
    case PressureForce::Symmetric:
      run.template operator()<PressureForce::Symmetric, true>();
      break;
    case PressureForce::Variational:
      run.template operator()<PressureForce::Variational, true>();
      break;
  }
}

template <int D>
double lattice_mass(double rest_density, double spacing, double h) {
  // The scene reader keeps h within 10 spacings; the sum costs (2 h / spacing)^D terms.
  SPH_CHECK(spacing > 0 && h > 0 && h / spacing <= 1000, "lattice_mass: h / spacing out of range");
  const Poly6Kernel<D, double> poly6(h);
  const int n = static_cast<int>(std::ceil(h / spacing)) + 1;
  double sum = 0;
  if constexpr (D == 2) {
    for (int a = -n; a <= n; ++a)
      for (int b = -n; b <= n; ++b) sum += poly6.w(spacing * std::sqrt(double(a * a + b * b)));
  } else {
    for (int a = -n; a <= n; ++a)
      for (int b = -n; b <= n; ++b)
        for (int c = -n; c <= n; ++c) sum += poly6.w(spacing * std::sqrt(double(a * a + b * b + c * c)));
  }
  return rest_density / sum;
}

#define SPH_INSTANTIATE(D, R)                                                                                \
  template std::uint64_t compute_density_pressure<D, R>(ParticleSet<D, R>&, const NeighborLists&, R,         \
                                                        const FluidParams&);                                 \
  template void compute_accelerations<D, R>(ParticleSet<D, R>&, const NeighborLists&, R, const FluidParams&, \
                                            const Vec<D, R>&, const WallContact<D, R>&, std::span<std::uint8_t>, R);
SPH_INSTANTIATE(2, float)
SPH_INSTANTIATE(2, double)
SPH_INSTANTIATE(3, float)
SPH_INSTANTIATE(3, double)
#undef SPH_INSTANTIATE
template double lattice_mass<2>(double, double, double);
template double lattice_mass<3>(double, double, double);

}  // namespace sph
