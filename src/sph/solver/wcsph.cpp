#include <sph/solver/wcsph.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <type_traits>

#include <sph/core/error.h>
#include <sph/core/kernels.h>
#include <sph/core/parallel.h>
#include <sph/core/simd.h>
#include <sph/core/storage.h>
#include <sph/solver/gradient_correction.h>
#include <sph/solver/smoothing.h>

namespace sph {

namespace {

using simd::Mask;

/// What the pair loops assume: lists for exactly these particles, and indices times D that fit
/// the 32-bit signed offsets of the vector gathers.
template <int D, std::floating_point R>
void check_pass_inputs(const ParticleSet<D, R>& ps, const NeighborLists& lists) {
  SPH_CHECK(lists.particle_count() == ps.size(), "neighbor lists do not cover the particles");
  SPH_CHECK(ps.size() * D < (std::size_t{1} << 31), "too many particles for 32-bit gather offsets");
}

/// What the cluster-pair passes assume: clusters of exactly these particles, and slot offsets
/// that fit 32 bits.
template <int D, std::floating_point R>
void check_cluster_inputs(const ParticleSet<D, R>& ps, const ClusterPairs<D, R>& clusters) {
  SPH_CHECK(clusters.particle_count() == ps.size(), "cluster pairs do not cover the particles");
  SPH_CHECK(clusters.slots().size() < (std::size_t{1} << 31), "too many particles for 32-bit cluster slots");
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
[[gnu::always_inline]] inline simd::Pack<R> pair_offsets(const simd::Pack<R> (&xi)[D], std::span<const R> pos,
                                                         const std::uint32_t* idx, simd::Pack<R> (&rij)[D]) {
  using P = simd::Pack<R>;
  P r2 = P::set1(R(0));
  P xj[D];
  simd::gather_vectors<D>(pos, idx, xj);
  for (int d = 0; d < D; ++d) {
    rij[d] = xi[d] - xj[d];
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

/// The paper's kernels: the loops write poly6, spiky and the viscosity kernel out; the object keeps
/// the pressure gradients' constants for gradient_factor (made once: the constructors call
/// std::pow).
template <int D, std::floating_point R>
class PackKernel<KernelKind::Paper, D, R> {
 public:
  using P = simd::Pack<R>;
  explicit PackKernel(R h)
      : hv(P::set1(h)),
        h2v(P::set1(h * h)),
        spiky_grad(P::set1(R(-3) * SpikyKernel<D, R>(h).norm())),
        poly6_grad(P::set1(R(-6) * Poly6Kernel<D, R>(h).norm())) {}
  P hv, h2v, spiky_grad, poly6_grad;
};

/// m_j W(|x_ij|) on the lanes in `in` (pairs closer than h), zero on the others.
template <KernelKind K, int D, std::floating_point R>
simd::Pack<R> density_term(const simd::Pack<R>& r2, Mask in, const simd::Pack<R>& mj, const simd::Pack<R>& h2v,
                           const simd::Pack<R>& normv, const PackKernel<K, D, R>& kernel) {
  using P = simd::Pack<R>;
  const P zero = P::set1(R(0));
  if constexpr (K == KernelKind::Paper) {
    (void)kernel;
    const P dd = h2v - r2;
    // Paper Eq. 4: m_j W_poly6 = m_j C (h^2 - r^2)^3 inside the support.
    return select(in, mj * (normv * dd * dd * dd), zero);
  } else {
    (void)normv;
    const P r = sqrt(select(in, r2, zero));
    return select(in, mj * kernel.w(r), zero);
  }
}

/// A density pass's kernel constants in registers, made once per pass: the kernels' constructors
/// call std::pow, which made per particle took 3 % of the paper's tank.
template <KernelKind K, int D, std::floating_point R>
struct DensityKernel {
  using P = simd::Pack<R>;
  explicit DensityKernel(R h) : h2v(P::set1(h * h)), normv(P::set1(Poly6Kernel<D, R>(h).norm())), kernel(h) {}
  P h2v, normv;
  PackKernel<K, D, R> kernel;
};

/// The density sum of one particle over one list: sum_j mass_j W(|x_i - x_j|) by lanes, with
/// the count of pairs closer than h added to `count`. `mass` is the fluid's one mass (R), or an
/// array indexed as the positions (const R*: the boundary samples' psi), gathered per neighbour.
/// (Not inlined: inlined into the density pass, with the mass broadcast, it made the pass slower,
/// 0.64 -> 0.97 s in the paper's 2D dam break and 33 -> 37 ms at 1M; out of line 0.78 s and 33 ms.)
template <KernelKind K, int D, std::floating_point R, class M>
[[gnu::noinline]] simd::Pack<R> density_sum(const simd::Pack<R> (&xi)[D], std::span<const R> pos, M mass,
                                            std::span<const std::uint32_t> nb, const DensityKernel<K, D, R>& dk,
                                            std::uint64_t& count) {
  using P = simd::Pack<R>;
  constexpr int W = simd::kLanes<R>;
  constexpr bool kGathered = std::is_same_v<M, const R*>;
  static_assert(kGathered || std::is_same_v<M, R>, "a mass for all, or one per neighbour");
  const std::uint32_t* idx = nb.data();
  P sum = P::set1(R(0)), one_mass = sum;
  if constexpr (!kGathered) one_mass = P::set1(mass);
  for (std::size_t k0 = 0; k0 < nb.size(); k0 += W) {
    const Mask valid = simd::first_lanes<R>(nb.size() - k0);
    P rij[D];
    const P r2 = pair_offsets<D>(xi, pos, idx + k0, rij);
    const Mask in = valid & (r2 < dk.h2v);
    if constexpr (kGathered)
      sum = sum + density_term<K, D>(r2, in, P::template gather<1>(mass, idx + k0, 0), dk.h2v, dk.normv, dk.kernel);
    else
      sum = sum + density_term<K, D>(r2, in, one_mass, dk.h2v, dk.normv, dk.kernel);
    count += static_cast<std::uint64_t>(__builtin_popcount(in));
  }
  return sum;
}

/// density_sum's sum over one list whose squared distances are at hand (PairDensity): the same
/// terms in the same lanes, loaded instead of computed from gathered positions.
template <KernelKind K, int D, std::floating_point R>
simd::Pack<R> density_sum_of(std::span<const R> r2s, R mass, const DensityKernel<K, D, R>& dk) {
  using P = simd::Pack<R>;
  constexpr int W = simd::kLanes<R>;
  const P one_mass = P::set1(mass);
  P sum = P::set1(R(0));
  for (std::size_t k0 = 0; k0 < r2s.size(); k0 += W) {
    const P r2 = P::load(r2s.data() + k0);
    const Mask in = simd::first_lanes<R>(r2s.size() - k0) & (r2 < dk.h2v);
    sum = sum + density_term<K, D>(r2, in, one_mass, dk.h2v, dk.normv, dk.kernel);
  }
  return sum;
}

/// Each list's lanes are kept (in the builder's room for the chunk) until a register's worth of
/// consecutive particles have theirs (a group of kLanes starts at a multiple of kLanes, so lies
/// within one chunk, which one thread visits in order), then the group's lanes are summed at once
/// (simd::sum_lanes_each: the same bits as one sum_lanes each, without a chain of scalar
/// additions per particle).
template <KernelKind K, int D, std::floating_point R>
class KernelPairDensity final : public PairDensity<D, R> {
 public:
  explicit KernelPairDensity(R h) : dk_(h) {}
  void visit(std::size_t i, std::span<const std::uint32_t> list, std::span<const R> r2, R* room) const override {
    (void)list;
    using P = simd::Pack<R>;
    constexpr std::size_t W = simd::kLanes<R>;
    static_assert(kChunkSize % W == 0, "a group of particles lies within one chunk");
    static_assert(W * W <= PairVisitor<R>::kRoom, "a group's lanes fit the builder's room");
    const std::size_t slot = i % W;
    density_sum_of<K, D>(r2, this->mass_, dk_).store(room + slot * W);
    if (slot == W - 1 || i + 1 == this->particles_) {
      P group[W];  // (all set: sum_lanes_each reads every pack of a group, used or not)
      for (std::size_t k = 0; k < W; ++k) group[k] = k <= slot ? P::load(room + k * W) : P::set1(R(0));
      simd::sum_lanes_each(group, static_cast<int>(slot + 1), this->density_ + (i - slot));
    }
  }

 private:
  DensityKernel<K, D, R> dk_;
};

/// What both density passes do with a particle's sum over its fluid pairs: add its own mass's
/// m_i W(0) and its boundary samples' psi_b W_ib (Akinci et al. 2012 eq. 6: psi in place of the
/// mass), store the density and the EOS pressure.
template <KernelKind K, int D, std::floating_point R>
class DensityStore {
 public:
  DensityStore(ParticleSet<D, R>& ps, R h, const FluidParams& fluid, const BoundaryView<D, R>& boundary)
      : ps_(ps),
        boundary_(boundary),
        dk_(h),
        w0_(SmoothingKernels<D, R>(fluid.kernel, h).w_zero()),
        rho0_(static_cast<R>(fluid.rest_density)),
        k_(static_cast<R>(fluid.stiffness)),
        clamp_(fluid.negative_pressure == NegativePressure::Clamp),
        walls_(boundary.active()),
        bpos_(walls_ ? flat(boundary.position) : std::span<const R>()) {}

  /// Particle i (at xi, in every lane), whose fluid pairs sum to `pairs`.
  void operator()(std::size_t i, const simd::Pack<R> (&xi)[D], R pairs, std::uint64_t& boundary_count) const {
    R rho = ps_.mass * w0_ + pairs;
    if (walls_)
      rho += simd::sum_lanes(density_sum<K, D>(xi, bpos_, static_cast<const R*>(boundary_.psi.data()),
                                               boundary_.lists->of(i), dk_, boundary_count));
    ps_.density[i] = rho;
    const R p = k_ * (rho - rho0_);
    ps_.pressure[i] = clamp_ ? std::max(p, R(0)) : p;
  }

 private:
  ParticleSet<D, R>& ps_;
  const BoundaryView<D, R>& boundary_;
  DensityKernel<K, D, R> dk_;
  R w0_, rho0_, k_;
  bool clamp_, walls_;
  std::span<const R> bpos_;
};

template <KernelKind K, int D, std::floating_point R>
std::uint64_t density_pass(ParticleSet<D, R>& ps, const NeighborLists& lists, R h, const FluidParams& fluid,
                           const BoundaryView<D, R>& boundary, std::vector<std::uint64_t>& within, bool pairs_summed) {
  using P = simd::Pack<R>;
  const DensityStore<K, D, R> store(ps, h, fluid, boundary);
  const DensityKernel<K, D, R> dk(h);
  const std::span<const R> pos = flat(ps.position);
  within.assign(chunk_count(ps.size()), 0);
  constexpr std::size_t W = simd::kLanes<R>;
  // A register's worth of particles at a time: their lanes are added together
  // (simd::sum_lanes_each: the same bits as one sum_lanes each), then each is stored.
  parallel_chunks(ps.size(), [&](std::size_t c, std::size_t b, std::size_t e) {
    std::uint64_t count = 0, boundary_count = 0;
    P group[W];  // (all set: the sums read every pack of a group, used or not)
    for (P& pack : group) pack = P::set1(R(0));
    R pairs[W];
    P xi[D];
    const auto at = [&](std::size_t i) {
      for (int d = 0; d < D; ++d) xi[d] = P::set1(ps.position[i][d]);
    };
    for (std::size_t g = b; g < e; g += W) {
      const std::size_t size = std::min(e - g, W);
      if (pairs_summed) {
        std::copy_n(ps.density.data() + g, size, pairs);
      } else {
        for (std::size_t k = 0; k < size; ++k) {
          at(g + k);
          group[k] = density_sum<K, D>(xi, pos, ps.mass, lists.of(g + k), dk, count);
        }
        simd::sum_lanes_each(group, static_cast<int>(size), pairs);
      }
      for (std::size_t k = 0; k < size; ++k) {
        at(g + k);
        store(g + k, xi, pairs[k], boundary_count);
      }
    }
    within[c] = count;
  });
  if (pairs_summed) return lists.entry_count();
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
                              Mask near) {
  using P = simd::Pack<R>;
  const P zero = P::set1(R(0)), one = P::set1(R(1));
  if constexpr (K == KernelKind::Paper) {
    if constexpr (kVariational) {
      const P d2 = kernel->h2v - r2;
      return select(near, kernel->poly6_grad * d2 * d2, zero);
    } else {
      const Mask apart = near & (r2 > zero);
      const P dh = kernel->hv - r;
      return select(apart, kernel->spiky_grad * dh * dh / select(apart, r, one), zero);
    }
  } else {
    return select(near, kernel->gradient_factor(r), zero);
  }
}

/// A particle's own terms of the force pass, one value per lane: the same particle in every lane
/// (per-particle lists) or the particles of an i-cluster laid out by the cluster-pair pattern.
template <int D, std::floating_point R>
struct ForceSide {
  simd::Pack<R> x[D], v[D];
  // Pressure term P_ij, symmetric in i and j, so that each pair's contributions are equal and
  // opposite: the paper's (p_i + p_j) / (2 rho_i rho_j), or p_i / rho_i^2 + p_j / rho_j^2.
  simd::Pack<R> pi_half, pi_sym, inv_rho, visc, morris, rho;
};

/// The scalars of ForceSide for particle i (mu: the viscosity the pass applies; lap_c: the
/// viscosity kernel's Laplacian constant), in the order ForceSide lists them after x and v.
template <int D, std::floating_point R>
std::array<R, 6> force_side_scalars(const ParticleSet<D, R>& ps, std::size_t i, R mu, R lap_c) {
  const R inv_rhoi = R(1) / ps.density[i];
  const R p = ps.pressure[i];
  return {R(0.5) * p * inv_rhoi, p * inv_rhoi * inv_rhoi, inv_rhoi,
          mu * inv_rhoi * lap_c, R(-2) * mu * inv_rhoi,   ps.density[i]};
}

/// A register of neighbors j: the offsets x_i - x_j, |x_ij|^2 and j's values. inv_rho is 1 /
/// rho_j: the pass over per-particle lists divides for each register, the pass over cluster
/// pairs loads it from ClusterData, which divided once per particle (the same value bit for bit:
/// a division is correctly rounded); rho itself is read only with the artificial viscosity.
template <int D, std::floating_point R>
struct ForceOther {
  simd::Pack<R> rij[D], r2, rho, inv_rho, mass, v[D], p;
};

/// The force pass's arithmetic: the pair terms of a register, a particle's boundary samples and
/// its total, shared by the pass over per-particle lists and the pass over cluster pairs.
/// Viscosity, the Eq. 7 test when kExitTest, gravity, the walls, the boundary samples, and the
/// pressure term of form kForm when kPressure (false with a gradient correction, whose pressure
/// term corrected_pressure_pass adds).
template <KernelKind K, PressureForce kForm, bool kPressure, bool kExitTest, int D, std::floating_point R>
class ForceTerms {
 public:
  using P = simd::Pack<R>;
  static constexpr int kW = simd::kLanes<R>;
  static constexpr bool kVariational = kForm == PressureForce::Variational;

  ForceTerms(ParticleSet<D, R>& ps, R h, const FluidParams& fluid, const Vec<D, R>& gravity,
             const WallContact<D, R>& walls, std::span<std::uint8_t> flags, R dt, const BoundaryView<D, R>& boundary,
             R exit_radius)
      : ps_(ps),
        h_(h),
        gravity_(gravity),
        walls_(walls),
        flags_(flags),
        boundary_(boundary),
        fc_(h, fluid, boundary),
        kernel_(h),
        hv_(P::set1(h)),
        h2v_(P::set1(h * h)),
        exit2v_(P::set1(exit_radius * exit_radius)),  // Eq. 7's radius: h, or the lists' radius
        lap_c_(ViscosityKernel<D, R>(h).laplacian_norm()),
        eps_h2_(P::set1(R(0.01) * h * h)),                // Monaghan's and Morris's 0.01 h^2 in |x_ij|^2 + 0.01 h^2
        art_i_(P::set1(R(-2) * fc_.alpha * fc_.c0 * h)),  // Monaghan's Pi_ij = -alpha c0 h mu_ij / rho_ij
        dtv_(P::set1(dt)) {
    solid_ = boundary.active();
    if (solid_) {
      bpos_ = flat(boundary.position);
      bvel_ = flat(boundary.velocity);  // (empty: the samples are at rest)
    }
    // (floating bodies: what each body's samples give a particle is recorded, per lane)
    sample_body_ = solid_ && boundary.body_acceleration && !boundary.body.empty() ? boundary.body.data() : nullptr;
  }

  R mu() const { return fc_.mu; }
  /// Monaghan's artificial viscosity: the only term that reads rho_j itself (not 1 / rho_j).
  bool artificial() const { return fc_.artificial; }
  R lap_c() const { return lap_c_; }
  bool solid() const { return solid_; }

  /// Particle i's ForceSide with i in every lane.
  ForceSide<D, R> side(std::size_t i) const {
    ForceSide<D, R> s;
    for (int d = 0; d < D; ++d) s.x[d] = P::set1(ps_.position[i][d]), s.v[d] = P::set1(ps_.velocity[i][d]);
    const std::array<R, 6> c = force_side_scalars(ps_, i, fc_.mu, lap_c_);
    s.pi_half = P::set1(c[0]), s.pi_sym = P::set1(c[1]), s.inv_rho = P::set1(c[2]);
    s.visc = P::set1(c[3]), s.morris = P::set1(c[4]), s.rho = P::set1(c[5]);
    return s;
  }

  /// Adds the pair terms of the lanes in `valid` to acc: -m_j P_ij times the spiky gradient
  /// -3 C (h - r)^2 rij / r (Eq. 5), and the viscosity term mu m_j (v_j - v_i) C_lap (h - r) /
  /// (rho_i rho_j) (Eq. 6); variational: the density kernel's gradient -6 C6 (h^2 - r^2)^2 rij.
  void pairs(const ForceSide<D, R>& i, const ForceOther<D, R>& j, Mask valid, P (&acc)[D]) const {
    const P zero = P::set1(R(0)), one = P::set1(R(1)), minus_one = P::set1(R(-1)), half = P::set1(R(0.5));
    const Mask near = valid & (j.r2 < h2v_);  // inside the support
    const P r = sqrt(select(near, j.r2, h2v_));
    const P dh = hv_ - r;
    const P inv_rhoj = j.inv_rho;
    P fp = zero, fv = zero;
    if constexpr (kPressure) {
      P pij;
      if constexpr (kForm == PressureForce::Paper)
        pij = (i.pi_half + half * j.p * i.inv_rho) * inv_rhoj;
      else
        pij = i.pi_sym + j.p * inv_rhoj * inv_rhoj;
      if constexpr (K != KernelKind::Paper) {
        fp = gradient_factor<K, false, D>(&kernel_, j.r2, r, near) * (minus_one * j.mass * pij);
      } else if constexpr (kVariational) {
        const P d2 = h2v_ - j.r2;
        fp = select(near, kernel_.poly6_grad * d2 * d2 * (minus_one * j.mass * pij), zero);
      } else {
        const Mask apart = near & (j.r2 > zero);  // and not coincident (gradient defined)
        fp = select(apart, (kernel_.spiky_grad * dh * dh / select(apart, r, one)) * (minus_one * j.mass * pij), zero);
      }
    }
    if (fc_.artificial) {
      // -m_j Pi_ij grad W_ij for approaching pairs (v_ij . x_ij < 0).
      P vr = zero;
      for (int d = 0; d < D; ++d) vr = vr + (i.v[d] - j.v[d]) * j.rij[d];
      const Mask approaching = near & (vr < zero);
      const P f = gradient_factor < K, kVariational && K == KernelKind::Paper, D > (&kernel_, j.r2, r, near);
      const P pi_ij = art_i_ * (vr / (j.r2 + eps_h2_)) / (i.rho + j.rho);
      fp = fp + select(approaching, minus_one * j.mass * pi_ij * f, zero);
    } else if constexpr (K == KernelKind::Paper) {
      fv = select(near, i.visc * j.mass * inv_rhoj * dh, zero);
    } else {
      // Morris et al. 1997: 2 mu m_j / (rho_i rho_j) (x_ij . grad W) / (r^2 + 0.01 h^2) (v_i - v_j).
      const P f = gradient_factor<K, false, D>(&kernel_, j.r2, r, near);
      fv = select(near, i.morris * j.mass * inv_rhoj * (f * j.r2) / (j.r2 + eps_h2_), zero);
    }
    for (int d = 0; d < D; ++d) {
      if constexpr (kPressure) {
        acc[d] = acc[d] + (j.rij[d] * fp + (j.v[d] - i.v[d]) * fv);
      } else {
        acc[d] = acc[d] + (j.v[d] - i.v[d]) * fv;
        if (fc_.artificial) acc[d] = acc[d] + j.rij[d] * fp;
      }
    }
  }

  /// Eq. 7 on the lanes in `valid`: flags j (and returns true) for each pair predicted beyond the
  /// exit radius after the step.
  bool exit_test(const ForceSide<D, R>& i, const ForceOther<D, R>& j, Mask valid, const std::uint32_t* idx) const {
    const P zero = P::set1(R(0));
    P q2 = zero;  // squared pair distance after the step, predicted with today's velocities
    for (int d = 0; d < D; ++d) {
      const P t = j.rij[d] + (i.v[d] - j.v[d]) * dtv_;
      q2 = q2 + t * t;
    }
    bool any = false;
    for (Mask out = valid & (q2 > exit2v_); out != 0; out &= out - 1) {
      any = true;
      set_flag(idx[static_cast<std::size_t>(__builtin_ctz(out))]);
    }
    return any;
  }

  /// Adds particle i's boundary samples to acc (i in every lane of `s`): the pair's pressure term
  /// with rho_b = rho_i and p_b mirrored (p_i: the paper's form gives p_i / rho_i^2, the symmetric
  /// ones 2 p_i / rho_i^2), extrapolated, or 0 (BoundaryPressure), psi_b for the mass, and Akinci's friction, nu =
  /// sigma h c0 / (2 rho_i). Returns whether Eq. 7 flags i for a sample.
  bool boundary(std::size_t i, const ForceSide<D, R>& s, P (&acc)[D]) const {
    const P zero = P::set1(R(0)), minus_one = P::set1(R(-1));
    const R* prs = ps_.pressure.data();
    const R inv_rhoi = R(1) / ps_.density[i];
    // (BoundaryPressure::None: p_b = 0, half the mirrored term)
    const R mirrored = (kForm == PressureForce::Paper ? R(1) : R(2)) * (boundary_.sample_pressure ? R(1) : R(0.5));
    const R pii = mirrored * prs[i] * inv_rhoi * inv_rhoi;
    const P pii_v = P::set1(kPressure ? pii : R(0));
    // Extrapolated: P_ib = w (p_i + p_b) / rho_i^2 with w = 1/2 (paper's form) or 1, and
    // p_b / rho_i^2 = p_i / rho_i^2 - (a . x_ib) / rho_i, clamped at 0 like p.
    const bool extrapolate = kPressure && boundary_.extrapolate;
    const R w = kForm == PressureForce::Paper ? R(0.5) : R(1);
    const P w_v = P::set1(w), pi_sym_b = P::set1(prs[i] * inv_rhoi * inv_rhoi);
    P ext_v[D];
    for (int d = 0; d < D; ++d) ext_v[d] = P::set1(boundary_.extrapolation[d] * inv_rhoi);
    const P nu_i = P::set1(fc_.friction * h_ * fc_.c0 * R(0.5) * inv_rhoi);
    const auto bnb = boundary_.lists->of(i);
    const std::uint32_t* bidx = bnb.data();
    // (recorded only for the particles that have a floating body's sample in their list)
    const bool record =
        sample_body_ && std::any_of(bnb.begin(), bnb.end(), [&](std::uint32_t b) { return sample_body_[b] != 0; });
    bool flag = false;
    for (std::size_t k0 = 0; k0 < bnb.size(); k0 += kW) {
      const Mask valid = simd::first_lanes<R>(bnb.size() - k0);
      P rib[D];
      const P r2 = pair_offsets<D>(s.x, bpos_, bidx + k0, rib);
      const Mask near = valid & (r2 < h2v_);
      const P r = sqrt(select(near, r2, h2v_));
      const P f = gradient_factor < K, kVariational && K == KernelKind::Paper, D > (&kernel_, r2, r, near);
      const P psib = P::template gather<1>(boundary_.psi.data(), bidx + k0, 0);
      // The velocity relative to the sample's (moving obstacles), else the particle's own.
      P vib[D];
      if (!bvel_.empty()) {
        simd::gather_vectors<D>(bvel_, bidx + k0, vib);
        for (int d = 0; d < D; ++d) vib[d] = s.v[d] - vib[d];
      } else {
        for (int d = 0; d < D; ++d) vib[d] = s.v[d];
      }
      P vr = zero;
      for (int d = 0; d < D; ++d) vr = vr + vib[d] * rib[d];
      const P pi_ib = minus_one * nu_i * select(vr < zero, vr, zero) / (r2 + eps_h2_);
      P pterm = pii_v;
      if (extrapolate) {
        P ax = zero;
        for (int d = 0; d < D; ++d) ax = ax + ext_v[d] * rib[d];
        const P pb = pi_sym_b - ax;
        pterm = w_v * (pi_sym_b + (boundary_.clamp ? select(pb > zero, pb, zero) : pb));
      }
      const P fb = minus_one * psib * (pterm + pi_ib) * f;
      if (record) {
        R fl[kW], rl[D][kW];
        fb.store(fl);
        for (int d = 0; d < D; ++d) rib[d].store(rl[d]);
        Vec<D, R>* row = boundary_.body_row(i);
        for (std::size_t l = 0; l < static_cast<std::size_t>(kW) && k0 + l < bnb.size(); ++l)
          if (const std::uint16_t o = sample_body_[bidx[k0 + l]]; o != 0)
            for (int d = 0; d < D; ++d) row[o - 1][d] += rl[d][l] * fl[l];
      }
      P q2 = zero;
      for (int d = 0; d < D; ++d) {
        acc[d] = acc[d] + rib[d] * fb;
        if constexpr (kExitTest) {
          const P t = rib[d] + vib[d] * dtv_;
          q2 = q2 + t * t;
        }
      }
      if constexpr (kExitTest)
        if ((valid & (q2 > exit2v_)) != 0) flag = true;
    }
    return flag;
  }

  /// Stores particle i's acceleration: gravity, the pair and boundary terms `pairs`, the walls.
  void finish(std::size_t i, const Vec<D, R>& pairs) const {
    Vec<D, R> a = gravity_;
    for (int d = 0; d < D; ++d) a[d] += pairs[d];
    a += walls_(ps_.position[i], ps_.velocity[i], boundary_.body_row(i));
    ps_.acceleration[i] = a;
  }

  /// finish() of particles b .. b + W - 1 (sums[d][l]: particle b + l's pair and boundary terms)
  /// when the walls are the container's alone: their push a register at a time, the same bits.
  void finish_register(std::size_t b, const R (&sums)[D][kW]) const {
    std::uint32_t own[kW];
    for (int l = 0; l < kW; ++l) own[l] = static_cast<std::uint32_t>(b) + static_cast<std::uint32_t>(l);
    P x[D], v[D], push[D];
    simd::gather_vectors<D>(flat(ps_.position), own, x);
    simd::gather_vectors<D>(flat(ps_.velocity), own, v);
    walls_.container_push(x, v, push);
    R a[D][kW];
    for (int d = 0; d < D; ++d) ((P::set1(gravity_[d]) + P::load(sums[d])) + push[d]).store(a[d]);
    for (int l = 0; l < kW; ++l)
      for (int d = 0; d < D; ++d) ps_.acceleration[b + static_cast<std::size_t>(l)][d] = a[d][l];
  }

  void set_flag(std::size_t q) const { std::atomic_ref<std::uint8_t>(flags_[q]).store(1, std::memory_order_relaxed); }

 private:
  ParticleSet<D, R>& ps_;
  R h_;
  Vec<D, R> gravity_;
  const WallContact<D, R>& walls_;
  std::span<std::uint8_t> flags_;
  const BoundaryView<D, R>& boundary_;
  ForceConstants<D, R> fc_;
  PackKernel<K, D, R> kernel_;
  P hv_, h2v_, exit2v_;
  R lap_c_;
  P eps_h2_, art_i_, dtv_;
  bool solid_ = false;
  std::span<const R> bpos_, bvel_;
  const std::uint16_t* sample_body_ = nullptr;
};

/// The force pass over per-particle lists: each particle's neighbors gathered a register at a time.
/// Each neighbor's 1 / rho and p are read side by side, from a copy made before the pass (in
/// `scratch`): one load of two values per neighbor instead of two gathers, and no division per
/// lane (a division is correctly rounded: the same bits).
template <KernelKind K, PressureForce kForm, bool kPressure, bool kExitTest, int D, std::floating_point R>
void force_pass(ParticleSet<D, R>& ps, const NeighborLists& lists, R h, const FluidParams& fluid,
                const Vec<D, R>& gravity, const WallContact<D, R>& walls, std::span<std::uint8_t> flags, R dt,
                const BoundaryView<D, R>& boundary, R exit_radius, ScratchBuffer& scratch) {
  using P = simd::Pack<R>;
  constexpr int W = simd::kLanes<R>;
  const ForceTerms<K, kForm, kPressure, kExitTest, D, R> terms(ps, h, fluid, gravity, walls, flags, dt, boundary,
                                                               exit_radius);
  const std::span<const R> pos = flat(ps.position), vel = flat(ps.velocity);
  const R* rho = ps.density.data();
  scratch.reserve(2 * ps.size() * sizeof(R));
  R* const inv_rho_p = scratch.place<R>(0, 2 * ps.size());
  const std::span<const R> inv_rho_and_ps(inv_rho_p, 2 * ps.size());  // (gather_vectors' view)
  parallel_for(ps.size(), [&, inv_rho_p](std::size_t i) {
    inv_rho_p[2 * i] = R(1) / ps.density[i];
    inv_rho_p[2 * i + 1] = ps.pressure[i];
  });
  // Every particle's mass, broadcast rather than gathered. (Captured as a real by value: a
  // register of it captured by reference made the 1M bench's force pass 8 % slower.)
  const R m = ps.mass;
  // Each thread's particles a register's worth at a time: their sums' lanes are added together
  // (simd::sum_lanes_each, the same bits as one sum_lanes each), then each particle finished.
  parallel_runs(ps.size(), [&, m](std::size_t first, std::size_t last) {
    P group[D][W];  // (all set: the sums read every pack of a group, used or not)
    for (auto& packs : group)
      for (P& pack : packs) pack = P::set1(R(0));
    std::size_t grouped = 0;
    for (std::size_t i = first; i < last; ++i) {
      const ForceSide<D, R> side = terms.side(i);
      P acc[D];
      for (int d = 0; d < D; ++d) acc[d] = P::set1(R(0));
      bool flag_i = false;
      const auto nb = lists.of(i);
      const std::uint32_t* idx = nb.data();
      for (std::size_t k0 = 0; k0 < nb.size(); k0 += W) {
        const Mask valid = simd::first_lanes<R>(nb.size() - k0);
        ForceOther<D, R> j;
        j.r2 = pair_offsets<D>(side.x, pos, idx + k0, j.rij);
        P inv_rho_and_p[2];
        simd::gather_vectors<2>(inv_rho_and_ps, idx + k0, inv_rho_and_p);
        j.inv_rho = inv_rho_and_p[0];
        if constexpr (kPressure) j.p = inv_rho_and_p[1];
        j.rho = terms.artificial() ? P::template gather<1>(rho, idx + k0, 0) : j.inv_rho;  // (unread without)
        j.mass = P::set1(m);
        simd::gather_vectors<D>(vel, idx + k0, j.v);
        terms.pairs(side, j, valid, acc);
        if constexpr (kExitTest) flag_i = terms.exit_test(side, j, valid, idx + k0) || flag_i;
      }
      if (terms.solid()) flag_i = terms.boundary(i, side, acc) || flag_i;
      if constexpr (kExitTest)
        if (flag_i) terms.set_flag(i);
      for (int d = 0; d < D; ++d) group[d][grouped] = acc[d];
      if (++grouped < static_cast<std::size_t>(W) && i + 1 < last) continue;
      R sums[D][W];
      for (int d = 0; d < D; ++d) simd::sum_lanes_each(group[d], static_cast<int>(grouped), sums[d]);
      const std::size_t b = i + 1 - grouped;
      if (grouped == static_cast<std::size_t>(W) && walls.container_only()) {
        terms.finish_register(b, sums);
      } else {
        for (std::size_t k = 0; k < grouped; ++k) {
          Vec<D, R> total;
          for (int d = 0; d < D; ++d) total[d] = sums[d][k];
          terms.finish(b + k, total);
        }
      }
      grouped = 0;
    }
  });
}

/// The particles' values in cluster slot order (ClusterPairs::slots()), one array per scalar,
/// each followed by a register of padding, so that a cluster's values are one contiguous load.
/// Empty slots hold a particle far away (no pair within h), at rest; the passes broadcast the
/// particles' one mass (an empty slot's pairs are masked out by distance, or are an empty i-slot's,
/// whose sums are not stored). The force pass
/// reads each particle's 1 / rho (inv_rho: one division per particle instead of one per lane of
/// each register), and its rho only with `densities` (the artificial viscosity).
template <int D, std::floating_point R>
struct ClusterData {
  std::vector<R> x[D], v[D], rho, inv_rho, p;

  void fill(const ParticleSet<D, R>& ps, std::span<const std::uint32_t> slots, bool forces, bool densities = false) {
    const std::size_t size = slots.size() + static_cast<std::size_t>(simd::kLanes<R>);
    // (the density pass leaves the force pass's arrays as they are: no shrinking and zero-filling
    // them again at every step)
    for (int d = 0; d < D; ++d) resize_with_room(x[d], size);
    if (forces) {
      for (int d = 0; d < D; ++d) resize_with_room(v[d], size);
      resize_with_room(inv_rho, size);
      if (densities) resize_with_room(rho, size);
      resize_with_room(p, size);
    }
    constexpr R kFar = R(1e18);  // (its square still fits a float)
    parallel_for(slots.size(), [&](std::size_t s) {
      const std::uint32_t i = slots[s];
      const bool empty = i == ClusterPairs<D, R>::kEmpty;
      for (int d = 0; d < D; ++d) {
        x[d][s] = empty ? kFar : ps.position[i][d];
        if (forces) v[d][s] = empty ? R(0) : ps.velocity[i][d];
      }
      if (forces) {
        inv_rho[s] = empty ? R(1) : R(1) / ps.density[i];
        if (densities) rho[s] = empty ? R(1) : ps.density[i];
        p[s] = empty ? R(0) : ps.pressure[i];
      }
    });
  }
};

/// The cluster passes' buffers, kept between steps (no allocation in steady state); one per
/// calling thread, handed to the pass's worker threads by reference.
template <int D, std::floating_point R>
ClusterData<D, R>& kept_cluster_data() {
  thread_local ClusterData<D, R> data;
  return data;
}

/// How a register holds a pair of clusters: G = lanes / kSize j-slots by kSize i-slots, lane l
/// pairing i-slot l / G with j-slot q G + l % G in part q (one part with floats, two with doubles).
template <int D, std::floating_point R>
struct ClusterLanes {
  static constexpr int kSize = ClusterPairs<D, R>::kSize;
  static constexpr int kW = simd::kLanes<R>;
  static constexpr int kG = kW / kSize;
  static constexpr int kParts = kSize / kG;
  static_assert(kW % kSize == 0 && kSize % kG == 0);
  using P = simd::Pack<R>;

  ClusterLanes() : spread(P::lane_pattern([](int l) { return l / kG; })) {
    for (int q = 0; q < kParts; ++q) {
      tile[q] = P::lane_pattern([q](int l) { return q * kG + l % kG; });
      self[q] = 0;
      for (int l = 0; l < kW; ++l)
        if (l / kG == q * kG + l % kG) self[q] |= Mask{1} << l;
    }
  }
  /// Lanes whose i-slot holds a particle in cluster c.
  static Mask real_i(std::span<const std::uint32_t> slots, std::size_t c) {
    Mask m = 0;
    for (int l = 0; l < kW; ++l)
      if (slots[c * kSize + static_cast<std::size_t>(l / kG)] != ClusterPairs<D, R>::kEmpty) m |= Mask{1} << l;
    return m;
  }
  simd::LanePattern<R> spread;        // lane l: i-slot l / G
  simd::LanePattern<R> tile[kParts];  // lane l: j-slot q G + l % G
  Mask self[kParts];                  // lanes pairing a slot with itself
};

/// The density pass over cluster pairs: the same sums as density_pass, each particle's fluid
/// pairs summed by lanes in its cluster's list order, then its boundary samples as there.
template <KernelKind K, int D, std::floating_point R>
std::uint64_t cluster_density_pass(ParticleSet<D, R>& ps, const ClusterPairs<D, R>& cp, R h, const FluidParams& fluid,
                                   const BoundaryView<D, R>& boundary, std::vector<std::uint64_t>& within,
                                   ClusterData<D, R>& data) {
  using P = simd::Pack<R>;
  using L = ClusterLanes<D, R>;
  constexpr int S = L::kSize;
  const L lanes;
  const DensityStore<K, D, R> store(ps, h, fluid, boundary);
  const std::span<const std::uint32_t> slots = cp.slots();
  data.fill(ps, slots, false);
  const DensityKernel<K, D, R> dk(h);
  const P zero = P::set1(R(0));
  const R m = ps.mass;  // (as in force_pass)
  const std::size_t clusters = cp.cluster_count();
  // Blocks of clusters, each counting its pairs (a count is the same in any order; the blocks are
  // small so that every thread has clusters: kChunkSize clusters, 1,024 particles, would give a
  // 4,000-particle scene four blocks).
  constexpr std::size_t kBlock = 64;
  const std::size_t blocks = (clusters + kBlock - 1) / kBlock;
  assign_with_room(within, blocks, std::uint64_t{0});  // (the clusters' count varies)
  parallel_for(blocks, [&, m](std::size_t chunk) {
    const P mass = P::set1(m);
    const std::size_t b = chunk * kBlock, e = std::min(clusters, b + kBlock);
    std::uint64_t count = 0, boundary_count = 0;
    for (std::size_t c = b; c < e; ++c) {
      const std::size_t base = c * S;
      P xi[D];
      for (int d = 0; d < D; ++d) xi[d] = P::permuted(&data.x[d][base], lanes.spread);
      const Mask real = L::real_i(slots, c);
      P sum = zero;
      for (const std::uint32_t jc : cp.of(c)) {
        const std::size_t jb = std::size_t{jc} * S;
        for (int q = 0; q < L::kParts; ++q) {
          P r2 = zero;
          for (int d = 0; d < D; ++d) {
            const P rij = xi[d] - P::permuted(&data.x[d][jb], lanes.tile[q]);
            r2 = r2 + rij * rij;
          }
          // (every register is summed, those with no pair within h too: their term is a few
          // operations, and a branch on them, taken at random, cost the 3D block twice the pass's
          // time; the force pass's terms are many, and it skips them)
          const Mask in = (jc == c ? real & ~lanes.self[q] : real) & (r2 < dk.h2v);
          sum = sum + density_term<K, D>(r2, in, mass, dk.h2v, dk.normv, dk.kernel);
          count += static_cast<std::uint64_t>(__builtin_popcount(in));
        }
      }
      R sums[S];
      simd::sum_lane_groups<L::kG>(sum, sums);
      for (int s = 0; s < S; ++s) {
        const std::uint32_t i = slots[base + static_cast<std::size_t>(s)];
        if (i == ClusterPairs<D, R>::kEmpty) continue;
        P x1[D];
        for (int d = 0; d < D; ++d) x1[d] = P::set1(ps.position[i][d]);
        store(i, x1, sums[s], boundary_count);
      }
    }
    within[chunk] = count;
  });
  std::uint64_t total = 0;
  for (std::uint64_t w : within) total += w;
  return total;
}

/// The force pass over cluster pairs: ForceTerms on registers of cluster pairs, each particle's
/// lanes summed in lane order, then its boundary samples (their own registers) and its walls.
template <KernelKind K, PressureForce kForm, bool kPressure, int D, std::floating_point R>
void cluster_force_pass(ParticleSet<D, R>& ps, const ClusterPairs<D, R>& cp, R h, const FluidParams& fluid,
                        const Vec<D, R>& gravity, const WallContact<D, R>& walls, R dt,
                        const BoundaryView<D, R>& boundary, ClusterData<D, R>& data) {
  using P = simd::Pack<R>;
  using L = ClusterLanes<D, R>;
  constexpr int S = L::kSize, W = simd::kLanes<R>;
  const L lanes;
  const ForceTerms<K, kForm, kPressure, false, D, R> terms(ps, h, fluid, gravity, walls, {}, dt, boundary, h);
  const std::span<const std::uint32_t> slots = cp.slots();
  const bool densities = terms.artificial();
  data.fill(ps, slots, true, densities);
  const Mask all = simd::first_lanes<R>(static_cast<std::size_t>(W));
  const P h2v = P::set1(h * h);
  const R* xs[D];
  const R* vs[D];
  for (int d = 0; d < D; ++d) xs[d] = data.x[d].data(), vs[d] = data.v[d].data();
  const R *rhos = data.rho.data(), *inv_rhos = data.inv_rho.data(), *prs = data.p.data();
  const R m = ps.mass;  // (as in force_pass)
  parallel_for(cp.cluster_count(), [&, m](std::size_t c) {
    const P mass = P::set1(m);
    const std::size_t base = c * S;
    ForceSide<D, R> side;
    for (int d = 0; d < D; ++d) {
      side.x[d] = P::permuted(&data.x[d][base], lanes.spread);
      side.v[d] = P::permuted(&data.v[d][base], lanes.spread);
    }
    R scalars[6][W] = {};
    for (int s = 0; s < S; ++s)
      if (const std::uint32_t i = slots[base + static_cast<std::size_t>(s)]; i != ClusterPairs<D, R>::kEmpty) {
        const std::array<R, 6> a = force_side_scalars(ps, i, terms.mu(), terms.lap_c());
        for (int k = 0; k < 6; ++k) scalars[k][s] = a[static_cast<std::size_t>(k)];
      }
    side.pi_half = P::permuted(scalars[0], lanes.spread), side.pi_sym = P::permuted(scalars[1], lanes.spread);
    side.inv_rho = P::permuted(scalars[2], lanes.spread), side.visc = P::permuted(scalars[3], lanes.spread);
    side.morris = P::permuted(scalars[4], lanes.spread), side.rho = P::permuted(scalars[5], lanes.spread);
    P acc[D];
    for (int d = 0; d < D; ++d) acc[d] = P::set1(R(0));
    // A register with no pair within h is skipped (its terms are many). With doubles (two
    // registers per cluster pair) which ones those are is found first, for a batch of the list
    // at a time, by their distances alone and without a branch, and then the others are
    // computed in the list's order: a branch on each, taken at random, cost the 3D block a third
    // of its force pass. With floats the branch stays: at 1M particles most registers hold a pair
    // within h, the branch is predicted, and computing their distances twice cost 15 % more.
    const std::span<const std::uint32_t> list = cp.of(c);
    const auto offsets = [&](std::uint32_t jc, int q, ForceOther<D, R>& j) {
      const std::size_t jb = std::size_t{jc} * S;
      j.r2 = P::set1(R(0));
      for (int d = 0; d < D; ++d) {
        j.rij[d] = side.x[d] - P::permuted(xs[d] + jb, lanes.tile[q]);
        j.r2 = j.r2 + j.rij[d] * j.rij[d];
      }
      return jc == c ? all & ~lanes.self[q] : all;
    };
    const auto add = [&](std::uint32_t jc, int q, ForceOther<D, R>& j, Mask valid) {
      const std::size_t jb = std::size_t{jc} * S;
      for (int d = 0; d < D; ++d) j.v[d] = P::permuted(vs[d] + jb, lanes.tile[q]);
      j.inv_rho = P::permuted(inv_rhos + jb, lanes.tile[q]);
      j.rho = densities ? P::permuted(rhos + jb, lanes.tile[q]) : j.inv_rho;  // (unread without)
      j.mass = mass;
      if constexpr (kPressure) j.p = P::permuted(prs + jb, lanes.tile[q]);
      terms.pairs(side, j, valid, acc);
    };
    if constexpr (L::kParts == 1) {
      for (const std::uint32_t jc : list) {
        ForceOther<D, R> j;
        const Mask valid = offsets(jc, 0, j);
        if ((valid & (j.r2 < h2v)) != 0) add(jc, 0, j, valid);
      }
    } else {
      constexpr std::size_t kBatch = 32;
      std::uint32_t active[kBatch * L::kParts];
      for (std::size_t k0 = 0; k0 < list.size(); k0 += kBatch) {
        const std::size_t k1 = std::min(list.size(), k0 + kBatch);
        std::size_t count = 0;
        for (std::size_t k = k0; k < k1; ++k)
          for (int q = 0; q < L::kParts; ++q) {
            ForceOther<D, R> j;
            const Mask valid = offsets(list[k], q, j);
            active[count] = static_cast<std::uint32_t>((k - k0) * L::kParts + static_cast<std::size_t>(q));
            count += (valid & (j.r2 < h2v)) != 0 ? 1 : 0;
          }
        for (std::size_t a = 0; a < count; ++a) {
          const std::uint32_t jc = list[k0 + active[a] / L::kParts];
          const int q = static_cast<int>(active[a] % L::kParts);
          ForceOther<D, R> j;
          const Mask valid = offsets(jc, q, j);
          add(jc, q, j, valid);
        }
      }
    }
    R sums[D][S];
    for (int d = 0; d < D; ++d) simd::sum_lane_groups<L::kG>(acc[d], sums[d]);
    for (int s = 0; s < S; ++s) {
      const std::uint32_t i = slots[base + static_cast<std::size_t>(s)];
      if (i == ClusterPairs<D, R>::kEmpty) continue;
      Vec<D, R> total;
      for (int d = 0; d < D; ++d) total[d] = sums[d][s];
      if (terms.solid()) {
        P bacc[D];
        for (int d = 0; d < D; ++d) bacc[d] = P::set1(R(0));
        terms.boundary(i, terms.side(i), bacc);
        for (int d = 0; d < D; ++d) total[d] += simd::sum_lanes(bacc[d]);
      }
      terms.finish(i, total);
    }
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
      acc -= corrected_gradient<D, R>(li, &L[std::size_t{j} * D * D], g) * (ps.mass * pij);
    }
    if (solid) {
      const R pii =
          (paper ? R(1) : R(2)) * (boundary.sample_pressure ? R(1) : R(0.5)) * ps.pressure[i] * inv_rhoi * inv_rhoi;
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
                                       const BoundaryView<D, R>& boundary, const ClusterPairs<D, R>* clusters,
                                       bool pairs_summed) {
  SPH_CHECK(!(clusters && pairs_summed), "pairs are summed while per-particle lists are built");
  if (clusters)
    check_cluster_inputs(ps, *clusters);
  else
    check_pass_inputs(ps, lists);
  if (boundary.active()) check_boundary_inputs(ps, boundary);
  thread_local std::vector<std::uint64_t> within;  // per-chunk counts, kept between steps
  ClusterData<D, R>& data = kept_cluster_data<D, R>();
  const auto run = [&]<KernelKind kKernel>() {
    return clusters ? cluster_density_pass<kKernel>(ps, *clusters, h, fluid, boundary, within, data)
                    : density_pass<kKernel>(ps, lists, h, fluid, boundary, within, pairs_summed);
  };
  switch (fluid.kernel) {
    case KernelKind::Cubic:
      return run.template operator()<KernelKind::Cubic>();
    case KernelKind::Wendland:
      return run.template operator()<KernelKind::Wendland>();
    case KernelKind::Paper:
      break;
  }
  return run.template operator()<KernelKind::Paper>();
}

template <int D, std::floating_point R>
void compute_accelerations(ParticleSet<D, R>& ps, const NeighborLists& lists, R h, const FluidParams& fluid,
                           const Vec<D, R>& gravity, const WallContact<D, R>& walls, std::span<std::uint8_t> exit_flags,
                           R dt, const BoundaryView<D, R>& boundary, R exit_radius, bool pressure_terms,
                           const ClusterPairs<D, R>* clusters, ScratchBuffer* scratch) {
  SPH_CHECK(exit_flags.empty() || exit_flags.size() == ps.size(), "one exit flag per particle");
  SPH_CHECK(!clusters || exit_flags.empty(), "no Eq. 7 test on cluster pairs");
  if (!(exit_radius > R(0))) exit_radius = h;
  if (clusters)
    check_cluster_inputs(ps, *clusters);
  else
    check_pass_inputs(ps, lists);
  if (boundary.active()) check_boundary_inputs(ps, boundary);
  ClusterData<D, R>& data = kept_cluster_data<D, R>();
  thread_local ScratchBuffer own;  // (without lent memory: kept between steps)
  ScratchBuffer& buffer = scratch ? *scratch : own;
  const auto run = [&]<KernelKind kKernel, PressureForce kForm, bool kPressure>() {
    if (clusters)
      cluster_force_pass<kKernel, kForm, kPressure>(ps, *clusters, h, fluid, gravity, walls, dt, boundary, data);
    else if (exit_flags.empty())
      force_pass<kKernel, kForm, kPressure, false>(ps, lists, h, fluid, gravity, walls, exit_flags, dt, boundary,
                                                   exit_radius, buffer);
    else
      force_pass<kKernel, kForm, kPressure, true>(ps, lists, h, fluid, gravity, walls, exit_flags, dt, boundary,
                                                  exit_radius, buffer);
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
      check_pass_inputs(ps, lists);
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

template <int D, std::floating_point R>
std::unique_ptr<PairDensity<D, R>> make_pair_density(R h, const FluidParams& fluid) {
  switch (fluid.kernel) {
    case KernelKind::Cubic:
      return std::make_unique<KernelPairDensity<KernelKind::Cubic, D, R>>(h);
    case KernelKind::Wendland:
      return std::make_unique<KernelPairDensity<KernelKind::Wendland, D, R>>(h);
    case KernelKind::Paper:
      break;
  }
  return std::make_unique<KernelPairDensity<KernelKind::Paper, D, R>>(h);
}

#define SPH_INSTANTIATE(D, R)                                                                                      \
  template std::uint64_t compute_density_pressure<D, R>(ParticleSet<D, R>&, const NeighborLists&, R,               \
                                                        const FluidParams&, const BoundaryView<D, R>&,             \
                                                        const ClusterPairs<D, R>*, bool);                          \
  template std::unique_ptr<PairDensity<D, R>> make_pair_density<D, R>(R, const FluidParams&);                      \
  template void compute_accelerations<D, R>(                                                                       \
      ParticleSet<D, R>&, const NeighborLists&, R, const FluidParams&, const Vec<D, R>&, const WallContact<D, R>&, \
      std::span<std::uint8_t>, R, const BoundaryView<D, R>&, R, bool, const ClusterPairs<D, R>*, ScratchBuffer*);
SPH_INSTANTIATE(2, float)
SPH_INSTANTIATE(2, double)
SPH_INSTANTIATE(3, float)
SPH_INSTANTIATE(3, double)
#undef SPH_INSTANTIATE
template double lattice_mass<2>(double, double, double, KernelKind);
template double lattice_mass<3>(double, double, double, KernelKind);

}  // namespace sph
