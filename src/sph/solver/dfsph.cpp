#include <sph/solver/dfsph.h>

#include <algorithm>
#include <cmath>

#include <sph/core/error.h>
#include <sph/core/parallel.h>
#include <sph/solver/gradient_correction.h>
#include <sph/solver/rigid_body.h>

namespace sph {

namespace {

/// beta_i is at least this fraction of a particle's inside a full lattice: a particle with few
/// neighbours whose kernel gradients nearly cancel (between boundary samples) cannot correct its
/// density through them, and would take a huge pressure trying.
constexpr double kBetaFloor = 0.1;

/// Each solve starts from a fraction of its last step's s (the papers' warm start). The projected
/// Jacobi steps only add pressure, so a warm start above the step's solution cannot be taken back:
/// with all of it (1.0) the 2D validation tank, at rest, gained energy and failed at step 105. The
/// density solve takes 0.8: against half (SPlisHSPlasH's choice for the divergence solve), the
/// resting tanks and the 2D wave flume take 38-54 % fewer iterations to their end and still settle;
/// with 0.9 the 2D tank no longer settled, and the 3D tank on 2.8 spacings fails at its third step
/// with 0.7 or 0.8 (it runs with 0.5). The divergence solve, whose pressure changes faster from
/// step to step, takes half.
constexpr double kWarmStartDensity = 0.8;
constexpr double kWarmStartDivergence = 0.5;

/// The largest gain of a Jacobi step the solves take whole (jacobi_gain): steps are scaled by
/// min(1, kMaxJacobiGain / gain). Each projected Jacobi step removes every compressed particle's
/// own compression as if its neighbours kept theirs; they do not, and on the worst mode of a
/// lattice the steps together remove gain times the compression. The surplus cannot be taken
/// back (the steps only add pressure), so it is thrown into the flow, and wider supports have
/// larger gains (cubic spline: 2.1 / 2.8 on 2 spacings in 2D / 3D, 2.7 / 4.4 on 2.5, 3.8 / 7.5 on
/// 3). Measured on the validation tanks, stopped at 0.5 s (docs/physics.md, "DFSPH", "Wide
/// supports"): taken whole, the 3D tank on 3 spacings (gain 7.5) peaked at 5.1e-2 J in its first
/// steps with a health warning and the 2D one on 4 (6.7) blew up at its second step; scaled to a
/// gain of 4 they peak at 1.6e-5 J and 8.4e-3 J. The supports up to 3 spacings in 2D and 2.15 in
/// 3D (the shipped scenes' 2 to 2.5 among them) keep whole steps.
constexpr double kMaxJacobiGain = 4;

/// A particle with at least this fraction of a lattice site's neighbours within h (fluid and
/// boundary) has a full neighbourhood (SPlisHSPlasH's divergence solve takes 20 of about 33 in
/// 3D and 7 of 12 in 2D, with h = 2 spacings).
constexpr double kFullNeighbourhood = 0.75;

/// The weight of a boundary sample's term when it carries a pressure of its own (BoundaryPressure
/// Mirror or Extrapolate, as in the WCSPH force): psi_b (s_i + s_b) grad W_ib with s_b = s_i is
/// twice Akinci's psi_b s_i grad W_ib (None). The constraint's boundary term takes the same
/// weight, so that the solve's matrix stays J M^-1 J^T (symmetric): with the force's weight alone
/// the floor layer of the resting 2D tank oscillated (neighbours in opposite phases, at up to
/// 0.1 m/s) and never settled.
constexpr double kSampleWeight = 2;

/// Adds the real field `name` (its units in 2D and 3D) to `ps` if absent.
template <int D, std::floating_point R>
void warm_field(ParticleSet<D, R>& ps, const char* name, const char* unit_2d, const char* unit_3d, const char* what) {
  if (ps.added_field_index(name) < 0) ps.add_field({name, FieldKind::Real, unit_2d, unit_3d, what});
}

/// Calls fluid(j, grad W_ij) for every listed neighbour j of i within h and solid(b, grad W_ib)
/// for every listed boundary sample b within h.
template <int D, std::floating_point R, class Fluid, class Solid>
void for_neighbours(const ParticleSet<D, R>& ps, std::size_t i, const NeighborLists& lists,
                    const SmoothingKernels<D, R>& kernels, const BoundaryView<D, R>& boundary, R h2, Fluid&& fluid,
                    Solid&& solid) {
  const Vec<D, R> xi = ps.position[i];
  for (const std::uint32_t j : lists.of(i)) {
    const Vec<D, R> rij = xi - ps.position[j];
    if (norm2(rij) >= h2) continue;
    fluid(j, kernels.gradient(rij));
  }
  if (boundary.active())
    for (const std::uint32_t b : boundary.lists->of(i)) {
      const Vec<D, R> rib = xi - boundary.position[b];
      if (norm2(rib) >= h2) continue;
      solid(b, kernels.gradient(rib));
    }
}

}  // namespace

template <int D, std::floating_point R>
DfsphSolver<D, R>::DfsphSolver(const DfsphParams& params, ParticleSet<D, R>& ps, R spacing)
    : params_(params), spacing_(spacing) {
  warm_field(ps, kDensityField, "m^4/(kg s^2)", "m^5/(kg s^2)",
             "DFSPH: the constant-density solve's s = p / rho^2 of the last step");
  warm_field(ps, kDivergenceField, "m^4/(kg s)", "m^5/(kg s)", "DFSPH: the divergence solve's s dt of the last step");
}

template <int D, std::floating_point R>
void DfsphSolver<D, R>::compute_factors(const ParticleSet<D, R>& ps, const NeighborLists& lists,
                                        const SmoothingKernels<D, R>& kernels, const BoundaryView<D, R>& boundary,
                                        std::span<const R> correction) {
  const std::size_t n = ps.size();
  SPH_CHECK(correction.empty() || correction.size() == n * D * D, "DFSPH: one gradient correction per particle");
  beta_.resize(n);
  const R h = kernels.radius(), h2 = h * h;
  // Once (the first call with particles: an emitter scene may start empty): the floor of beta,
  // kBetaFloor times a full lattice site's (where sum grad W = 0), and a full neighbourhood.
  if (!lattice_done_ && n > 0 && spacing_ > R(0)) {
    const int reach = static_cast<int>(std::ceil(h / spacing_));
    double squares = 0;
    int lattice = 0;  // a lattice site's neighbours within h
    Vec<D, R> x{};
    const auto visit = [&](auto&& self, int d) -> void {
      if (d == D) {
        const R r2 = norm2(x);
        if (r2 > R(0) && r2 < h2) squares += static_cast<double>(norm2(kernels.gradient(x))), ++lattice;
        return;
      }
      for (int k = -reach; k <= reach; ++k) {
        x[d] = static_cast<R>(k) * spacing_;
        self(self, d + 1);
      }
    };
    visit(visit, 0);
    beta_floor_ = static_cast<R>(kBetaFloor * squares) * ps.mass * ps.mass;
    full_count_ = static_cast<int>(std::ceil(kFullNeighbourhood * lattice));
    const double gain =
        jacobi_gain<D>(static_cast<double>(spacing_), static_cast<double>(h),
                       [&](const Vec<D, double>& r) { return vec_cast<double>(kernels.gradient(vec_cast<R>(r))); });
    relaxation_ = gain > kMaxJacobiGain ? static_cast<R>(kMaxJacobiGain / gain) : R(1);
    lattice_done_ = true;
  }
  full_.resize(n);
  solid_.resize(n);
  solid_rate_.assign(boundary.velocity.empty() ? 0 : n, R(0));
  // BoundaryPressure::Extrapolate: s_b = s_i + e_b, e_b = g . (x_b - x_i) / rho_i (p_b = p_i +
  // rho_i g . (x_b - x_i), as the WCSPH force's), whose part that does not depend on s is the
  // acceleration hydro_i = -sum_b psi_b e_b grad W_ib. A sample's pressure is clamped at 0 as
  // WCSPH's is, by the last step's s of the particle: e_b >= -s_i (the clamp at the free surface,
  // where a wall's samples above the particle would otherwise pull it up).
  const bool extrapolate = boundary.active() && boundary.extrapolate;
  hydro_.assign(extrapolate ? n : 0, Vec<D, R>{});
  const std::ptrdiff_t warm_index = ps.added_field_index(kDensityField);
  const std::vector<R>* last_s =
      extrapolate && warm_index >= 0 ? &ps.real_field(static_cast<std::size_t>(warm_index)) : nullptr;
  // Floating bodies: each body's share of sum_b psi_b grad W_ib, whose pressure the solves record.
  const bool bodies = boundary.active() && !boundary.body.empty() && boundary.body_acceleration;
  bodies_ = bodies ? boundary.bodies : 0;
  body_acceleration_ = bodies ? boundary.body_acceleration : nullptr;
  body_velocity_change_ = bodies ? boundary.body_velocity_change : nullptr;
  body_solid_.assign(n * bodies_, Vec<D, R>{});
  body_hydro_.assign(extrapolate ? n * bodies_ : 0, Vec<D, R>{});
  SPH_CHECK(bodies_ == 0 || boundary.body_response.empty() || boundary.body_response.size() == bodies_,
            "DFSPH: one response per floating body");
  body_response_ = bodies_ > 0 ? boundary.body_response : std::span<const typename BoundaryView<D, R>::BodyResponse>{};
  const R weight = boundary.sample_pressure ? static_cast<R>(kSampleWeight) : R(1);
  // The step's pairs within h, once: each solve iteration then reads m_j grad W_ij instead of
  // evaluating the kernel again (about half the entries of a list are within h).
  near_body_.assign(body_response_.empty() ? 0 : n, 0);
  begin_.resize(n + 1);
  parallel_for(n, [&](std::size_t i) {
    std::uint32_t count = 0;
    const Vec<D, R> xi = ps.position[i];
    for (const std::uint32_t j : lists.of(i)) count += norm2(xi - ps.position[j]) < h2;
    begin_[i + 1] = count;
  });
  begin_[0] = 0;
  for (std::size_t i = 0; i < n; ++i) begin_[i + 1] += begin_[i];
  pair_j_.resize(begin_[n]);
  pair_g_.resize(begin_[n]);
  parallel_for(n, [&](std::size_t i) {
    Vec<D, R> sum{}, solid{}, hydro{};
    bool near_body = false;
    const Vec<D, R> xi = ps.position[i];
    R squares = 0;
    int count = 0;
    std::size_t k = begin_[i];
    const R* li = correction.empty() ? nullptr : &correction[i * D * D];
    for_neighbours(
        ps, i, lists, kernels, boundary, h2,
        [&](std::uint32_t j, const Vec<D, R>& plain) {
          const Vec<D, R> g = li ? corrected_gradient<D, R>(li, &correction[std::size_t{j} * D * D], plain) : plain;
          const Vec<D, R> mg = g * ps.mass;
          pair_j_[k] = j, pair_g_[k] = mg, ++k;
          sum += mg;
          squares += ps.mass * norm2(g);
          ++count;
        },
        [&](std::uint32_t b, const Vec<D, R>& plain) {
          const Vec<D, R> g = li ? corrected_gradient<D, R>(li, li, plain) : plain;
          const R w = weight * boundary.psi[b];
          solid += g * w;
          if (!boundary.velocity.empty()) solid_rate_[i] += w * dot(boundary.velocity[b], g);
          const std::size_t body = bodies_ > 0 ? boundary.body[b] : 0;
          if (body != 0) body_solid_[i * bodies_ + body - 1] += g * w, near_body = true;
          if (extrapolate) {
            R e = dot(boundary.extrapolation, boundary.position[b] - xi) / ps.density[i];
            if (boundary.clamp && last_s) e = std::max(e, -std::max((*last_s)[i], R(0)));
            const Vec<D, R> a = g * (-boundary.psi[b] * e);
            hydro += a;
            if (body != 0) body_hydro_[i * bodies_ + body - 1] += a;
          }
          ++count;
        });
    sum += solid;
    solid_[i] = solid;
    if (extrapolate) hydro_[i] = hydro;
    // (strong coupling: each body's answer to i's own pressure, m_i (|g_ik|^2 / M_k + t . I_k^-1 t),
    // t = (x_i - c_k) x g_ik)
    R coupled = 0;
    for (std::size_t k = 0; k < body_response_.size(); ++k) {
      const Vec<D, R>& g = body_solid_[i * bodies_ + k];
      const Vec<3, R> t = body_moment(k, xi, g);
      const std::array<double, 9>& inv = body_response_[k].inverse_inertia;
      double turn = 0;
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) turn += double(t[a]) * inv[a * 3 + b] * double(t[b]);
      coupled += static_cast<R>(body_response_[k].inverse_mass * double(norm2(g)) + turn);
    }
    beta_[i] = std::max(norm2(sum) + ps.mass * (squares + coupled), beta_floor_);
    if (!body_response_.empty()) near_body_[i] = near_body;
    full_[i] = count >= full_count_;
  });
  // (strong coupling: the particles that touch a body, in order, which the bodies' sums visit)
  body_particles_.clear();
  for (std::size_t i = 0; i < near_body_.size(); ++i)
    if (near_body_[i]) body_particles_.push_back(static_cast<std::uint32_t>(i));
}

template <int D, std::floating_point R>
template <class V>
R DfsphSolver<D, R>::density_rate(std::size_t i, V&& v) const {
  const Vec<D, R> vi = v(i);
  R rate = dot(vi, solid_[i]);
  for (std::size_t k = begin_[i]; k < begin_[i + 1]; ++k) rate += dot(vi - v(pair_j_[k]), pair_g_[k]);
  return rate;
}

template <int D, std::floating_point R>
void DfsphSolver<D, R>::accelerations(const std::vector<R>& x, std::vector<Vec<D, R>>& out) const {
  parallel_for(beta_.size(), [&](std::size_t i) {
    const R xi = x[i];
    Vec<D, R> a = solid_[i] * (-xi);
    for (std::size_t k = begin_[i]; k < begin_[i + 1]; ++k) a -= pair_g_[k] * (xi + x[pair_j_[k]]);
    out[i] = a;
  });
}

/// Up to this many blocks of kSumBlock particles near the bodies, their sums run on one thread.
constexpr std::size_t kSerialBodyBlocks = 4;

template <int D, std::floating_point R>
Vec<3, R> DfsphSolver<D, R>::body_moment(std::size_t k, const Vec<D, R>& x, const Vec<D, R>& g) const {
  Vec<3, R> moment{};
  add_moment<D>(moment, x, vec_cast<R>(body_response_[k].center), g);
  return moment;
}

template <int D, std::floating_point R>
template <class F>
void DfsphSolver<D, R>::body_motions(const ParticleSet<D, R>& ps, F&& force, std::vector<BodyMotion>& out) {
  const std::size_t nb = body_response_.size();
  out.assign(nb, BodyMotion{});
  if (nb == 0) return;
  constexpr std::size_t kPer = D + 3;
  const std::size_t n = body_particles_.size(), chunks = chunk_count<kSumBlock>(n);
  body_partial_.assign(chunks * nb * kPer, 0.0);
  const auto block = [&](std::size_t c, std::size_t first, std::size_t last) {
    double* o = &body_partial_[c * nb * kPer];
    for (std::size_t p = first; p < last; ++p)
      for (std::size_t k = 0, i = body_particles_[p]; k < nb; ++k) {
        const Vec<D, R> f = force(i, k);
        if (norm2(f) == R(0)) continue;
        const Vec<3, R> t = body_moment(k, ps.position[i], f);
        for (int d = 0; d < D; ++d) o[k * kPer + d] += static_cast<double>(f[d]);
        for (int a = 0; a < 3; ++a) o[k * kPer + D + a] += static_cast<double>(t[a]);
      }
  };
  // (a few blocks, as a body's neighbourhood usually is, are summed on this thread: waking the
  // others for each Jacobi iteration cost more than the sums; the blocks and their order are the
  // same either way)
  if (chunks <= kSerialBodyBlocks) {
    for (std::size_t c = 0; c < chunks; ++c) block(c, c * kSumBlock, std::min(n, (c + 1) * kSumBlock));
  } else {
    parallel_chunks<kSumBlock>(n, block);
  }
  for (std::size_t k = 0; k < nb; ++k) {
    double sum[kPer] = {};
    for (std::size_t c = 0; c < chunks; ++c)
      for (std::size_t a = 0; a < kPer; ++a) sum[a] += body_partial_[(c * nb + k) * kPer + a];
    const auto& response = body_response_[k];
    for (int d = 0; d < D; ++d) out[k].linear[d] = static_cast<R>(sum[d] * response.inverse_mass);
    for (int a = 0; a < 3; ++a) {
      double w = 0;
      for (int b = 0; b < 3; ++b) w += response.inverse_inertia[a * 3 + b] * sum[D + b];
      out[k].angular[a] = static_cast<R>(w);
    }
  }
}

template <int D, std::floating_point R>
void DfsphSolver<D, R>::body_accelerations(const ParticleSet<D, R>& ps, const std::vector<R>& x,
                                           std::vector<BodyMotion>& out) {
  body_motions(
      ps, [&](std::size_t i, std::size_t k) { return body_solid_[i * bodies_ + k] * (ps.mass * x[i]); }, out);
}

template <int D, std::floating_point R>
R DfsphSolver<D, R>::body_rate(std::size_t i, const Vec<D, R>& xi, const std::vector<BodyMotion>& u) const {
  R rate = 0;
  if (u.empty() || !near_body_[i]) return rate;
  for (std::size_t k = 0; k < u.size(); ++k) {
    const Vec<D, R>& g = body_solid_[i * bodies_ + k];
    rate -= dot(u[k].linear, g) + dot(u[k].angular, body_moment(k, xi, g));
  }
  return rate;
}

template <int D, std::floating_point R>
void DfsphSolver<D, R>::apply(const ParticleSet<D, R>& ps, const std::vector<R>& x, std::vector<Vec<D, R>>& out,
                              std::vector<R>& ax) {
  accelerations(x, out);
  body_accelerations(ps, x, body_push_);
  parallel_for(beta_.size(), [&](std::size_t i) {
    ax[i] = -density_rate(i, [&](std::size_t j) { return out[j]; }) - body_rate(i, ps.position[i], body_push_);
  });
}

template <int D, std::floating_point R>
template <typename DfsphSolver<D, R>::Solve kSolve>
SolveStats DfsphSolver<D, R>::solve(ParticleSet<D, R>& ps, R rho0, R dt) {
  constexpr bool kDensity = kSolve == Solve::Density;
  const std::size_t n = ps.size();
  SPH_CHECK(beta_.size() == n, "DFSPH: compute_factors before the solves");
  SolveStats stats;
  if (n == 0 || !(dt > R(0))) return stats;
  std::vector<R>& warm =
      ps.real_field(static_cast<std::size_t>(ps.added_field_index(kDensity ? kDensityField : kDivergenceField)));
  // Errors are scale (b - A s): a density (scale dt^2) or a density rate (scale dt).
  const R scale = kDensity ? dt * dt : dt;
  // The warm start keeps the dt-free quantity: s (density solve), dt s (divergence solve).
  const R warm_scale = kDensity ? R(1) : dt;
  const int min_iterations = kDensity ? std::max(params_.min_iterations, 0) : 0;
  const int max_iterations = kDensity ? params_.max_iterations : params_.max_iterations_v;
  // Tolerance on the average error over rho0: % and % per second.
  const double tolerance =
      0.01 * (kDensity ? params_.max_error : params_.max_error_v) * static_cast<double>(rho0) * static_cast<double>(n);
  for (auto* v : {&b_, &s_, &p_, &as_}) v->assign(n, R(0));
  acc_s_.resize(n);
  acc_p_.resize(n);

  // (the extrapolated samples' push that does not depend on s acts like the other forces: the
  // density solve's prediction sees it)
  if (kDensity && !hydro_.empty())
    parallel_for(n, [&](std::size_t i) {
      ps.acceleration[i] += hydro_[i];
      if (body_acceleration_)
        for (std::size_t k = 0; k < bodies_; ++k) body_acceleration_[i * bodies_ + k] += body_hydro_[i * bodies_ + k];
    });
  // Strong coupling, density solve: each body's velocity change in the step from all but the
  // pressure solved for (the extrapolated samples' push and the friction's reaction, the divergence
  // solve's change; gravity, contacts and the gyroscopic term from its response), which its
  // samples' velocities do not hold yet.
  body_change_.clear();
  if (kDensity) {
    body_motions(
        ps,
        [&](std::size_t i, std::size_t k) {
          Vec<D, R> change = body_acceleration_[i * bodies_ + k] * dt;
          if (body_velocity_change_) change += body_velocity_change_[i * bodies_ + k];
          return change * (-ps.mass);
        },
        body_change_);
    for (std::size_t k = 0; k < body_change_.size(); ++k) {
      body_change_[k].linear += vec_cast<R>(body_response_[k].velocity_change);
      body_change_[k].angular += vec_cast<R>(body_response_[k].angular_velocity_change);
    }
  }
  // The right-hand side b (an error over scale), and the warm start.
  parallel_for(n, [&](std::size_t i) {
    R err;
    // (moving obstacles: the samples' own velocities count, sum_b psi_b (v_i - v_b) . grad W_ib)
    const R moving = solid_rate_.empty() ? R(0) : solid_rate_[i];
    if constexpr (kDensity)
      err = ps.density[i] - rho0 +
            dt * (density_rate(i, [&](std::size_t j) { return ps.velocity[j] + ps.acceleration[j] * dt; }) - moving +
                  body_rate(i, ps.position[i], body_change_));
    else
      err = density_rate(i, [&](std::size_t j) { return ps.velocity[j]; }) - moving;
    // (the divergence solve leaves out the particles without a full neighbourhood: at a free
    // surface or in a splash, their velocity divergence is the kernel's truncation, not a flow
    // to correct; SPlisHSPlasH does the same)
    if (!kDensity && !full_[i]) err = 0;
    b_[i] = err / scale;
    s_[i] = R(kDensity ? kWarmStartDensity : kWarmStartDivergence) * std::max(warm[i] / warm_scale, R(0));
  });

  // The error of the current s: the average compression (as the papers measure it).
  const auto compression = [&](std::size_t i) { return static_cast<double>(std::max(scale * (b_[i] - as_[i]), R(0))); };
  apply(ps, s_, acc_s_, as_);
  double error = sph::chunked_sum(n, partial_, compression);
  int iterations = 0;
  const auto finished = [&] {
    return iterations >= max_iterations || (iterations >= min_iterations && error <= tolerance);
  };
  // The published iteration (projected Jacobi): each compressed particle adds the pressure that
  // would remove its own compression, ds = e / (scale beta) >= 0, so no s is ever negative.
  // Two passes an iteration: the accelerations a(ds) of the step ds (each particle's needs its
  // neighbours' ds), then per particle A ds, the update, its compression (summed in chunked_sum's
  // fixed blocks) and the next iteration's ds (which no other particle reads in that pass).
  // (relaxation_: the step's scale on wide supports, kMaxJacobiGain; exactly 1 on the usual
  // ones, which leaves the step's bits as they are)
  const auto step_of = [&](std::size_t i) { return relaxation_ * (std::max(b_[i] - as_[i], R(0)) / beta_[i]); };
  if (!finished()) parallel_for(n, [&](std::size_t i) { p_[i] = step_of(i); });
  while (!finished()) {
    accelerations(p_, acc_p_);
    body_accelerations(ps, p_, body_push_);
    ++iterations;
    partial_.assign(chunk_count<kSumBlock>(n), 0.0);
    parallel_chunks<kSumBlock>(n, [&](std::size_t c, std::size_t first, std::size_t last) {
      double sum = 0;
      for (std::size_t i = first; i < last; ++i) {
        s_[i] += p_[i];
        acc_s_[i] += acc_p_[i];
        as_[i] += -density_rate(i, [&](std::size_t j) { return acc_p_[j]; });
        as_[i] -= body_rate(i, ps.position[i], body_push_);  // (0 away from the bodies)
        sum += compression(i);
        p_[i] = step_of(i);
      }
      partial_[c] = sum;
    });
    error = 0;
    for (const double part : partial_) error += part;
  }
  stats.iterations = iterations;
  stats.error = 100.0 * error / static_cast<double>(n) / static_cast<double>(rho0);
  stats.converged = error <= tolerance;
  // The pressure of the step: the divergence solve's velocity change dt_v a(s_v) = dt a(s_v dt_v
  // / dt) at the step's start acts with this solve's, a(s) being linear in s.
  const std::vector<R>* divergence =
      kDensity ? &ps.real_field(static_cast<std::size_t>(ps.added_field_index(kDivergenceField))) : nullptr;
  parallel_for(n, [&](std::size_t i) {
    warm[i] = s_[i] * warm_scale;
    if constexpr (kDensity) {
      ps.acceleration[i] += acc_s_[i];
      ps.pressure[i] = (s_[i] + (*divergence)[i] / dt) * ps.density[i] * ps.density[i];
    } else {
      ps.velocity[i] += acc_s_[i] * dt;
    }
    // Floating bodies: body k's samples' share of a(s), -s_i sum_{b of k} psi_b grad W_ib.
    Vec<D, R>* out = kDensity ? body_acceleration_ : body_velocity_change_;
    if (out)
      for (std::size_t k = 0; k < bodies_; ++k)
        out[i * bodies_ + k] -= body_solid_[i * bodies_ + k] * (kDensity ? s_[i] : s_[i] * dt);
  });
  return stats;
}

template <int D, std::floating_point R>
SolveStats DfsphSolver<D, R>::divergence_solve(ParticleSet<D, R>& ps, R rho0, R dt) {
  return solve<Solve::Divergence>(ps, rho0, dt);
}

template <int D, std::floating_point R>
SolveStats DfsphSolver<D, R>::density_solve(ParticleSet<D, R>& ps, R rho0, R dt) {
  return solve<Solve::Density>(ps, rho0, dt);
}

template class DfsphSolver<2, float>;
template class DfsphSolver<2, double>;
template class DfsphSolver<3, float>;
template class DfsphSolver<3, double>;

}  // namespace sph
