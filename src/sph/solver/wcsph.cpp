#include <sph/solver/wcsph.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <type_traits>

#include <sph/core/error.h>
#include <sph/core/kernels.h>
#include <sph/core/parallel.h>
#include <sph/core/simd.h>
#include <sph/solver/gradient_correction.h>
#include <sph/solver/smoothing.h>

namespace sph {

namespace {

using simd::Mask;

/// The scalars of a vector field, x0 y0 z0 x1 y1 z1 ..., so that pair loops gather lanes.
template <int D, std::floating_point R>
const R* flat(std::span<const Vec<D, R>> v) {
  static_assert(sizeof(Vec<D, R>) == D * sizeof(R));
  return reinterpret_cast<const R*>(v.data());
}
template <int D, std::floating_point R>
const R* flat(const std::vector<Vec<D, R>>& v) {
  return flat(std::span<const Vec<D, R>>(v));
}

/// What the pair loops assume: lists for exactly these particles, and indices times D that fit
/// the 32-bit signed offsets of the vector gathers.
template <int D, std::floating_point R>
void check_pass_inputs(const ParticleSet<D, R>& ps, const NeighborLists& lists) {
  SPH_CHECK(lists.particle_count() == ps.size(), "neighbor lists do not cover the particles");
  SPH_CHECK(ps.size() * D < (std::size_t{1} << 31), "too many particles for 32-bit gather offsets");
}

/// What the boundary terms assume: a boundary list per particle, indices below the samples
/// (checked when the lists are built and loaded), and sample offsets that fit the gathers.
template <int D, std::floating_point R>
void check_boundary_inputs(const ParticleSet<D, R>& ps, const BoundaryView<D, R>& boundary) {
  SPH_CHECK(boundary.lists->particle_count() == ps.size(), "boundary lists do not cover the particles");
  SPH_CHECK(boundary.psi.size() == boundary.position.size(), "one psi per boundary sample");
  SPH_CHECK(boundary.position.size() * D < (std::size_t{1} << 31),
            "too many boundary samples for 32-bit gather offsets");
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

/// The cubic spline's and Wendland C2's W and gradient factor (dW/dr) / r on a register of
/// distances r < h (kernels.h's formulas and constants; lanes at or beyond h are the caller's
/// to mask). The paper's kernels are written out in the loops, which need no square root for
/// poly6.
template <KernelKind K, int D, std::floating_point R>
class PackKernel {
 public:
  using P = simd::Pack<R>;
  explicit PackKernel(R h) : inv_h_(P::set1(R(1) / h)) {
    using Scalar = std::conditional_t<K == KernelKind::Cubic, CubicSplineKernel<D, R>, WendlandC2Kernel<D, R>>;
    const Scalar k(h);
    norm_ = P::set1(k.norm());
    grad_norm_ = P::set1(k.norm() / (h * h));
  }
  P w(const P& r) const {
    const P one = P::set1(R(1)), q = r * inv_h_, d = one - q;
    if constexpr (K == KernelKind::Cubic) {
      const P inner = norm_ * (P::set1(R(6)) * (q * q * q - q * q) + one);
      const P outer = norm_ * P::set1(R(2)) * d * d * d;
      return select(q > P::set1(R(0.5)), outer, inner);
    } else {
      const P d2 = d * d;
      return norm_ * d2 * d2 * (one + P::set1(R(4)) * q);
    }
  }
  P gradient_factor(const P& r) const {
    const P one = P::set1(R(1)), q = r * inv_h_, d = one - q;
    if constexpr (K == KernelKind::Cubic) {
      const Mask outer = q > P::set1(R(0.5));
      const P inner_f = grad_norm_ * (P::set1(R(18)) * q - P::set1(R(12)));
      const P outer_f = P::set1(R(-6)) * grad_norm_ * d * d / select(outer, q, one);
      return select(outer, outer_f, inner_f);
    } else {
      return P::set1(R(-20)) * grad_norm_ * d * d * d;
    }
  }

 private:
  P inv_h_, norm_{}, grad_norm_{};
};

/// The paper's kernels need no object: the loops write poly6, spiky and the viscosity kernel out.
template <int D, std::floating_point R>
class PackKernel<KernelKind::Paper, D, R> {
 public:
  explicit PackKernel(R) {}
};

/// The density sum of one particle over one list: sum_j mass_j W(|x_i - x_j|) by lanes, with
/// the count of pairs closer than h added to `count`.
template <KernelKind K, int D, std::floating_point R>
simd::Pack<R> density_sum(const simd::Pack<R> (&xi)[D], const R* pos, const R* mass, std::span<const std::uint32_t> nb,
                          R h, std::uint64_t& count) {
  using P = simd::Pack<R>;
  constexpr int W = simd::kLanes<R>;
  const P h2v = P::set1(h * h), zero = P::set1(R(0));
  const P normv = P::set1(Poly6Kernel<D, R>(h).norm());
  const std::uint32_t* idx = nb.data();
  P sum = zero;
  [[maybe_unused]] const PackKernel<K, D, R> kernel(h);
  for (std::size_t k0 = 0; k0 < nb.size(); k0 += W) {
    const Mask valid = simd::first_lanes<R>(nb.size() - k0);
    P rij[D];
    const P r2 = pair_offsets<D>(xi, pos, idx + k0, rij);
    const Mask in = valid & (r2 < h2v);
    if constexpr (K == KernelKind::Paper) {
      const P dd = h2v - r2;
      // Paper Eq. 4: m_j W_poly6 = m_j C (h^2 - r^2)^3 inside the support.
      sum = sum + select(in, P::template gather<1>(mass, idx + k0, 0) * (normv * dd * dd * dd), zero);
    } else {
      const P r = sqrt(select(in, r2, zero));
      sum = sum + select(in, P::template gather<1>(mass, idx + k0, 0) * kernel.w(r), zero);
    }
    count += static_cast<std::uint64_t>(__builtin_popcount(in));
  }
  return sum;
}

template <KernelKind K, int D, std::floating_point R>
std::uint64_t density_pass(ParticleSet<D, R>& ps, const NeighborLists& lists, R h, const FluidParams& fluid,
                           const BoundaryView<D, R>& boundary, std::vector<std::uint64_t>& within) {
  using P = simd::Pack<R>;
  const R w0 = SmoothingKernels<D, R>(fluid.kernel, h).w_zero();
  const R rho0 = static_cast<R>(fluid.rest_density);
  const R k = static_cast<R>(fluid.stiffness);
  const bool clamp = fluid.negative_pressure == NegativePressure::Clamp;
  const R* pos = flat(ps.position);
  const R* mass = ps.mass.data();
  const bool walls = boundary.active();
  const R* bpos = walls ? flat(boundary.position) : nullptr;
  const R* psi = boundary.psi.data();
  within.assign(chunk_count(ps.size()), 0);
  parallel_chunks(ps.size(), [&](std::size_t c, std::size_t b, std::size_t e) {
    std::uint64_t count = 0, boundary_count = 0;
    for (std::size_t i = b; i < e; ++i) {
      P xi[D];
      for (int d = 0; d < D; ++d) xi[d] = P::set1(ps.position[i][d]);
      const P sum = density_sum<K, D>(xi, pos, mass, lists.of(i), h, count);
      R rho = mass[i] * w0 + simd::sum_lanes(sum);
      // Akinci et al. 2012 eq. 6: the samples' psi_b W_ib, psi in place of the mass.
      if (walls) rho += simd::sum_lanes(density_sum<K, D>(xi, bpos, psi, boundary.lists->of(i), h, boundary_count));
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

/// The force pass's per-run constants.
template <int D, std::floating_point R>
struct ForceConstants {
  ForceConstants(R h, const FluidParams& fluid, const BoundaryView<D, R>& boundary)
      : h(h),
        // (ViscositySolve::Implicit: the viscosity solve adds it after this pass, viscosity.h)
        mu(fluid.viscosity_solve == ViscositySolve::Implicit ? R(0) : static_cast<R>(fluid.viscosity)),
        c0(static_cast<R>(std::sqrt(std::max(fluid.stiffness, 0.0)))),
        artificial(fluid.viscosity_model == ViscosityModel::Artificial),
        alpha(static_cast<R>(fluid.alpha)),
        friction(boundary.friction) {}
  R h, mu, c0;
  bool artificial;
  R alpha, friction;
};

/// The gradient factor f (grad_i W_ij = f rij) of the pressure force's kernel on a register:
/// the spiky kernel's (poly6's for kVariational) with the paper's kernels, the density kernel's
/// own otherwise; zero outside `near` (and, for spiky, at r = 0).
template <KernelKind K, bool kVariational, int D, std::floating_point R>
simd::Pack<R> gradient_factor(const PackKernel<K, D, R>* kernel, const simd::Pack<R>& r2, const simd::Pack<R>& r,
                              Mask near, R h) {
  using P = simd::Pack<R>;
  const P zero = P::set1(R(0)), one = P::set1(R(1));
  if constexpr (K == KernelKind::Paper) {
    if constexpr (kVariational) {
      const P d2 = P::set1(h * h) - r2;
      return select(near, P::set1(R(-6) * Poly6Kernel<D, R>(h).norm()) * d2 * d2, zero);
    } else {
      const Mask apart = near & (r2 > zero);
      const P dh = P::set1(h) - r;
      return select(apart, P::set1(R(-3) * SpikyKernel<D, R>(h).norm()) * dh * dh / select(apart, r, one), zero);
    }
  } else {
    return select(near, kernel->gradient_factor(r), zero);
  }
}

/// The force pass: viscosity, the Eq. 7 test when kExitTest, gravity, the walls, the boundary
/// samples, and the pressure term of form kForm when kPressure (false with a gradient
/// correction, whose pressure term corrected_pressure_pass adds).
template <KernelKind K, PressureForce kForm, bool kPressure, bool kExitTest, int D, std::floating_point R>
void force_pass(ParticleSet<D, R>& ps, const NeighborLists& lists, R h, const FluidParams& fluid,
                const Vec<D, R>& gravity, const WallContact<D, R>& walls, std::span<std::uint8_t> flags, R dt,
                const BoundaryView<D, R>& boundary, R exit_radius) {
  using P = simd::Pack<R>;
  constexpr int W = simd::kLanes<R>;
  constexpr bool kVariational = kForm == PressureForce::Variational;
  const P hv = P::set1(h), h2v = P::set1(h * h), zero = P::set1(R(0)), one = P::set1(R(1)), minus_one = P::set1(R(-1)),
          half = P::set1(R(0.5));
  const P exit2v = P::set1(exit_radius * exit_radius);  // Eq. 7's radius: h, or the lists' radius
  const P grad_c = P::set1(R(-3) * SpikyKernel<D, R>(h).norm());
  const P grad6_c = P::set1(R(-6) * Poly6Kernel<D, R>(h).norm());
  const R lap_c = ViscosityKernel<D, R>(h).laplacian_norm();
  const ForceConstants<D, R> fc(h, fluid, boundary);
  const R mu = fc.mu;
  const P eps_h2 = P::set1(R(0.01) * h * h);  // Monaghan's and Morris's 0.01 h^2 in |x_ij|^2 + 0.01 h^2
  const R* pos = flat(ps.position);
  const R* vel = flat(ps.velocity);
  const R* rho = ps.density.data();
  const R* prs = ps.pressure.data();
  const R* mass = ps.mass.data();
  const bool solid = boundary.active();
  const R* bpos = solid ? flat(boundary.position) : nullptr;
  const R* psi = boundary.psi.data();
  const R* bvel = solid && !boundary.velocity.empty() ? flat(boundary.velocity) : nullptr;
  // (floating bodies: what each body's samples give a particle is recorded, per lane)
  const std::uint16_t* sample_body =
      solid && boundary.body_acceleration && !boundary.body.empty() ? boundary.body.data() : nullptr;
  const P dtv = P::set1(dt);
  const PackKernel<K, D, R> kernel_value(h);
  const PackKernel<K, D, R>* kernel = &kernel_value;
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
    const P morris_i = P::set1(R(-2) * mu * inv_rhoi);
    // Monaghan's Pi_ij = -alpha c0 h mu_ij / rho_ij, rho_ij = (rho_i + rho_j) / 2.
    const P art_i = P::set1(R(-2) * fc.alpha * fc.c0 * h);
    const P rhoi_v = P::set1(rho[i]);
    const auto nb = lists.of(i);
    const std::uint32_t* idx = nb.data();
    for (std::size_t k0 = 0; k0 < nb.size(); k0 += W) {
      const Mask valid = simd::first_lanes<R>(nb.size() - k0);
      P rij[D];
      const P r2 = pair_offsets<D>(xi, pos, idx + k0, rij);
      const Mask near = valid & (r2 < h2v);  // inside the support
      const P r = sqrt(select(near, r2, h2v));
      const P dh = hv - r;
      const P rhoj = P::template gather<1>(rho, idx + k0, 0);
      const P inv_rhoj = one / rhoj;
      const P mj = P::template gather<1>(mass, idx + k0, 0);
      P vj[D];
      for (int d = 0; d < D; ++d) vj[d] = P::template gather<D>(vel, idx + k0, d);
      // -m_j P_ij times the spiky gradient -3 C (h - r)^2 rij / r (Eq. 5), and the viscosity
      // term mu m_j (v_j - v_i) C_lap (h - r) / (rho_i rho_j) (Eq. 6).
      // Variational: the density kernel's gradient -6 C6 (h^2 - r^2)^2 rij instead.
      P fp = zero, fv = zero;
      if constexpr (kPressure) {
        const P pj = P::template gather<1>(prs, idx + k0, 0);
        P pij;
        if constexpr (kForm == PressureForce::Paper)
          pij = (pi_half + half * pj * inv_rhoi_v) * inv_rhoj;
        else
          pij = pi_sym + pj * inv_rhoj * inv_rhoj;
        if constexpr (K != KernelKind::Paper) {
          fp = gradient_factor<K, false, D>(kernel, r2, r, near, h) * (minus_one * mj * pij);
        } else if constexpr (kVariational) {
          const P d2 = h2v - r2;
          fp = select(near, grad6_c * d2 * d2 * (minus_one * mj * pij), zero);
        } else {
          const Mask apart = near & (r2 > zero);  // and not coincident (gradient defined)
          fp = select(apart, (grad_c * dh * dh / select(apart, r, one)) * (minus_one * mj * pij), zero);
        }
      }
      if (fc.artificial) {
        // -m_j Pi_ij grad W_ij for approaching pairs (v_ij . x_ij < 0).
        P vr = zero;
        for (int d = 0; d < D; ++d) vr = vr + (vi[d] - vj[d]) * rij[d];
        const Mask approaching = near & (vr < zero);
        const P f = gradient_factor < K, kVariational && K == KernelKind::Paper, D > (kernel, r2, r, near, h);
        const P pi_ij = art_i * (vr / (r2 + eps_h2)) / (rhoi_v + rhoj);
        fp = fp + select(approaching, minus_one * mj * pi_ij * f, zero);
      } else if constexpr (K == KernelKind::Paper) {
        fv = select(near, visc_i * mj * inv_rhoj * dh, zero);
      } else {
        // Morris et al. 1997: 2 mu m_j / (rho_i rho_j) (x_ij . grad W) / (r^2 + 0.01 h^2) (v_i - v_j).
        const P f = gradient_factor<K, false, D>(kernel, r2, r, near, h);
        fv = select(near, morris_i * mj * inv_rhoj * (f * r2) / (r2 + eps_h2), zero);
      }
      P q2 = zero;  // Eq. 7: squared pair distance after the step, predicted with today's velocities
      for (int d = 0; d < D; ++d) {
        if constexpr (kPressure) {
          acc[d] = acc[d] + (rij[d] * fp + (vj[d] - vi[d]) * fv);
        } else {
          acc[d] = acc[d] + (vj[d] - vi[d]) * fv;
          if (fc.artificial) acc[d] = acc[d] + rij[d] * fp;
        }
        if constexpr (kExitTest) {
          const P t = rij[d] + (vi[d] - vj[d]) * dtv;
          q2 = q2 + t * t;
        }
      }
      if constexpr (kExitTest)
        for (Mask out = valid & (q2 > exit2v); out != 0; out &= out - 1) {
          flag_i = true;
          set_flag(idx[k0 + static_cast<std::size_t>(__builtin_ctz(out))]);
        }
    }
    if (solid) {
      // Boundary samples: the pair's pressure term with p_b = p_i, rho_b = rho_i (the paper's
      // form: p_i / rho_i^2; the symmetric ones: 2 p_i / rho_i^2), psi_b for the mass, and
      // Akinci's friction, nu = sigma h c0 / (2 rho_i).
      const R pii = kForm == PressureForce::Paper ? prs[i] * inv_rhoi * inv_rhoi : R(2) * prs[i] * inv_rhoi * inv_rhoi;
      const P pii_v = P::set1(kPressure ? pii : R(0));
      // Extrapolated: P_ib = w (p_i + p_b) / rho_i^2 with w = 1/2 (paper's form) or 1, and
      // p_b / rho_i^2 = p_i / rho_i^2 - (a . x_ib) / rho_i, clamped at 0 like p.
      const bool extrapolate = kPressure && boundary.extrapolate;
      const R w = kForm == PressureForce::Paper ? R(0.5) : R(1);
      const P w_v = P::set1(w), pi_sym_b = P::set1(prs[i] * inv_rhoi * inv_rhoi);
      P ext_v[D];
      for (int d = 0; d < D; ++d) ext_v[d] = P::set1(boundary.extrapolation[d] * inv_rhoi);
      const P nu_i = P::set1(fc.friction * h * fc.c0 * R(0.5) * inv_rhoi);
      const auto bnb = boundary.lists->of(i);
      const std::uint32_t* bidx = bnb.data();
      // (recorded only for the particles that have a floating body's sample in their list)
      const bool record =
          sample_body && std::any_of(bnb.begin(), bnb.end(), [&](std::uint32_t b) { return sample_body[b] != 0; });
      for (std::size_t k0 = 0; k0 < bnb.size(); k0 += W) {
        const Mask valid = simd::first_lanes<R>(bnb.size() - k0);
        P rib[D];
        const P r2 = pair_offsets<D>(xi, bpos, bidx + k0, rib);
        const Mask near = valid & (r2 < h2v);
        const P r = sqrt(select(near, r2, h2v));
        const P f = gradient_factor < K, kVariational && K == KernelKind::Paper, D > (kernel, r2, r, near, h);
        const P psib = P::template gather<1>(psi, bidx + k0, 0);
        // The velocity relative to the sample's (moving obstacles), else the particle's own.
        P vib[D];
        for (int d = 0; d < D; ++d) vib[d] = bvel ? vi[d] - P::template gather<D>(bvel, bidx + k0, d) : vi[d];
        P vr = zero;
        for (int d = 0; d < D; ++d) vr = vr + vib[d] * rib[d];
        const P pi_ib = minus_one * nu_i * select(vr < zero, vr, zero) / (r2 + eps_h2);
        P pterm = pii_v;
        if (extrapolate) {
          P ax = zero;
          for (int d = 0; d < D; ++d) ax = ax + ext_v[d] * rib[d];
          const P pb = pi_sym_b - ax;
          pterm = w_v * (pi_sym_b + (boundary.clamp ? select(pb > zero, pb, zero) : pb));
        }
        const P fb = minus_one * psib * (pterm + pi_ib) * f;
        if (record) {
          R fl[W], rl[D][W];
          fb.store(fl);
          for (int d = 0; d < D; ++d) rib[d].store(rl[d]);
          Vec<D, R>* row = boundary.body_row(i);
          for (std::size_t l = 0; l < static_cast<std::size_t>(W) && k0 + l < bnb.size(); ++l)
            if (const std::uint16_t o = sample_body[bidx[k0 + l]]; o != 0)
              for (int d = 0; d < D; ++d) row[o - 1][d] += rl[d][l] * fl[l];
        }
        P q2 = zero;
        for (int d = 0; d < D; ++d) {
          acc[d] = acc[d] + rib[d] * fb;
          if constexpr (kExitTest) {
            const P t = rib[d] + vib[d] * dtv;
            q2 = q2 + t * t;
          }
        }
        if constexpr (kExitTest)
          if ((valid & (q2 > exit2v)) != 0) flag_i = true;
      }
    }
    if constexpr (kExitTest)
      if (flag_i) set_flag(i);
    Vec<D, R> a = gravity;
    for (int d = 0; d < D; ++d) a[d] += simd::sum_lanes(acc[d]);
    a += walls(ps.position[i], ps.velocity[i], boundary.body_row(i));
    ps.acceleration[i] = a;
  });
}

/// Adds the pressure accelerations with corrected gradients: each pair's term of the plain
/// force (in its form) with grad W_ij replaced by (L_i + L_j) / 2 grad W_ij; a boundary sample's
/// (its pressure extrapolated or mirrored, as in the force pass) by L_i grad W_ib.
template <int D, std::floating_point R>
void corrected_pressure_pass(ParticleSet<D, R>& ps, const NeighborLists& lists, R h, const FluidParams& fluid,
                             const BoundaryView<D, R>& boundary) {
  const SmoothingKernels<D, R> kernels(fluid, h);
  const R rho0 = static_cast<R>(fluid.rest_density);
  // Kept between steps (no allocation in steady state); a reference, so that the pass's worker
  // threads see the calling thread's buffer, not thread_local ones of their own.
  thread_local std::vector<R> kept;
  std::vector<R>& L = kept;
  gradient_corrections(ps, lists, kernels, boundary, rho0, L);
  const bool paper = fluid.pressure_force == PressureForce::Paper;
  const bool solid = boundary.active();
  parallel_for(ps.size(), [&](std::size_t i) {
    const R* li = &L[i * D * D];
    const R inv_rhoi = R(1) / ps.density[i];
    Vec<D, R> acc{};
    for (const std::uint32_t j : lists.of(i)) {
      const Vec<D, R> g = kernels.gradient(ps.position[i] - ps.position[j]);
      const R inv_rhoj = R(1) / ps.density[j];
      const R pij = paper ? (R(0.5) * ps.pressure[i] + R(0.5) * ps.pressure[j]) * inv_rhoi * inv_rhoj
                          : ps.pressure[i] * inv_rhoi * inv_rhoi + ps.pressure[j] * inv_rhoj * inv_rhoj;
      acc -= corrected_gradient<D, R>(li, &L[std::size_t{j} * D * D], g) * (ps.mass[j] * pij);
    }
    if (solid) {
      const R pii = (paper ? R(1) : R(2)) * ps.pressure[i] * inv_rhoi * inv_rhoi;
      const R w = paper ? R(0.5) : R(1), pi_sym = ps.pressure[i] * inv_rhoi * inv_rhoi;
      for (const std::uint32_t b : boundary.lists->of(i)) {
        const Vec<D, R> xib = ps.position[i] - boundary.position[b];
        const Vec<D, R> g = kernels.gradient(xib);
        R pib = pii;
        if (boundary.extrapolate) {
          R pb = pi_sym - dot(boundary.extrapolation, xib) * inv_rhoi;
          if (boundary.clamp) pb = std::max(pb, R(0));
          pib = w * (pi_sym + pb);
        }
        const Vec<D, R> gc = corrected_gradient<D, R>(li, li, g);  // L_i grad W_ib
        acc -= gc * (boundary.psi[b] * pib);
        if (!boundary.body.empty() && boundary.body_acceleration && boundary.body[b] != 0)
          boundary.body_row(i)[boundary.body[b] - 1] -= gc * (boundary.psi[b] * pib);
      }
    }
    ps.acceleration[i] += acc;
  });
}

}  // namespace

template <int D, std::floating_point R>
std::uint64_t compute_density_pressure(ParticleSet<D, R>& ps, const NeighborLists& lists, R h, const FluidParams& fluid,
                                       const BoundaryView<D, R>& boundary) {
  check_pass_inputs(ps, lists);
  if (boundary.active()) check_boundary_inputs(ps, boundary);
  thread_local std::vector<std::uint64_t> within;  // per-chunk counts, kept between steps
  switch (fluid.kernel) {
    case KernelKind::Cubic:
      return density_pass<KernelKind::Cubic>(ps, lists, h, fluid, boundary, within);
    case KernelKind::Wendland:
      return density_pass<KernelKind::Wendland>(ps, lists, h, fluid, boundary, within);
    case KernelKind::Paper:
      break;
  }
  return density_pass<KernelKind::Paper>(ps, lists, h, fluid, boundary, within);
}

template <int D, std::floating_point R>
void compute_accelerations(ParticleSet<D, R>& ps, const NeighborLists& lists, R h, const FluidParams& fluid,
                           const Vec<D, R>& gravity, const WallContact<D, R>& walls, std::span<std::uint8_t> exit_flags,
                           R dt, const BoundaryView<D, R>& boundary, R exit_radius, bool pressure_terms) {
  SPH_CHECK(exit_flags.empty() || exit_flags.size() == ps.size(), "one exit flag per particle");
  if (!(exit_radius > R(0))) exit_radius = h;
  check_pass_inputs(ps, lists);
  if (boundary.active()) check_boundary_inputs(ps, boundary);
  const auto run = [&]<KernelKind kKernel, PressureForce kForm, bool kPressure>() {
    if (exit_flags.empty())
      force_pass<kKernel, kForm, kPressure, false>(ps, lists, h, fluid, gravity, walls, exit_flags, dt, boundary,
                                                   exit_radius);
    else
      force_pass<kKernel, kForm, kPressure, true>(ps, lists, h, fluid, gravity, walls, exit_flags, dt, boundary,
                                                  exit_radius);
  };
  // The kernel's pass for each form; with the cubic spline and Wendland C2 the variational
  // form is the symmetric one (the pressure gradient is the density kernel's anyway).
  const auto run_kernel = [&]<KernelKind kKernel>() {
    if (!pressure_terms) {
      run.template operator()<kKernel, PressureForce::Paper, false>();
      return;
    }
    if (fluid.gradient_correction == GradientCorrection::Renormalize) {
      // The form only matters to the pressure terms, which the corrected pass adds.
      run.template operator()<kKernel, PressureForce::Paper, false>();
      corrected_pressure_pass(ps, lists, h, fluid, boundary);
      return;
    }
    switch (fluid.pressure_force) {
      case PressureForce::Paper:
        run.template operator()<kKernel, PressureForce::Paper, true>();
        return;
      case PressureForce::Symmetric:
        run.template operator()<kKernel, PressureForce::Symmetric, true>();
        return;
      case PressureForce::Variational:
        if constexpr (kKernel == KernelKind::Paper)
          run.template operator()<kKernel, PressureForce::Variational, true>();
        else
          run.template operator()<kKernel, PressureForce::Symmetric, true>();
        return;
    }
  };
  switch (fluid.kernel) {
    case KernelKind::Paper:
      run_kernel.template operator()<KernelKind::Paper>();
      return;
    case KernelKind::Cubic:
      run_kernel.template operator()<KernelKind::Cubic>();
      return;
    case KernelKind::Wendland:
      run_kernel.template operator()<KernelKind::Wendland>();
      return;
  }
}

template <int D>
double lattice_mass(double rest_density, double spacing, double h, KernelKind kernel) {
  // The scene reader keeps h within 10 spacings; the sum costs (2 h / spacing)^D terms.
  SPH_CHECK(spacing > 0 && h > 0 && h / spacing <= 1000, "lattice_mass: h / spacing out of range");
  const SmoothingKernels<D, double> kernels(kernel, h);
  const auto w = [&](double r) { return kernels.w_r2(r * r); };
  const int n = static_cast<int>(std::ceil(h / spacing)) + 1;
  double sum = 0;
  if constexpr (D == 2) {
    for (int a = -n; a <= n; ++a)
      for (int b = -n; b <= n; ++b) sum += w(spacing * std::sqrt(double(a * a + b * b)));
  } else {
    for (int a = -n; a <= n; ++a)
      for (int b = -n; b <= n; ++b)
        for (int c = -n; c <= n; ++c) sum += w(spacing * std::sqrt(double(a * a + b * b + c * c)));
  }
  return rest_density / sum;
}

#define SPH_INSTANTIATE(D, R)                                                                                       \
  template std::uint64_t compute_density_pressure<D, R>(ParticleSet<D, R>&, const NeighborLists&, R,                \
                                                        const FluidParams&, const BoundaryView<D, R>&);             \
  template void compute_accelerations<D, R>(ParticleSet<D, R>&, const NeighborLists&, R, const FluidParams&,        \
                                            const Vec<D, R>&, const WallContact<D, R>&, std::span<std::uint8_t>, R, \
                                            const BoundaryView<D, R>&, R, bool);
SPH_INSTANTIATE(2, float)
SPH_INSTANTIATE(2, double)
SPH_INSTANTIATE(3, float)
SPH_INSTANTIATE(3, double)
#undef SPH_INSTANTIATE
template double lattice_mass<2>(double, double, double, KernelKind);
template double lattice_mass<3>(double, double, double, KernelKind);

}  // namespace sph
