#pragma once
/// \file DFSPH: divergence-free SPH (Bender & Koschier, "Divergence-free smoothed particle
/// hydrodynamics", SCA 2015; "Divergence-Free SPH for Incompressible and Viscous Fluids", IEEE
/// TVCG 2017): two pressure solves per step on the step's neighbor lists.
///
/// Both solves find per-particle values s_i (a pressure over density squared, p_i / rho_i^2)
/// whose pressure accelerations
///   a_i(s) = -sum_j m_j (s_i + s_j) grad W_ij - sum_b w psi_b s_i grad W_ib
/// (fluid neighbours j, boundary samples b with psi_b in place of a mass; the symmetric pair
/// form, so momentum is conserved) cancel a predicted density error. The samples' weight w is
/// 1 when they have no pressure of their own (BoundaryPressure::None: Akinci et al. 2012's term)
/// and 2 when they take the particle's, s_b = s_i (Mirror, Extrapolate: psi_b (s_i + s_b)).
/// Extrapolate adds to s_b each sample's hydrostatic head e_b = g . (x_b - x_i) / rho_i (clamped
/// at -s_i by the last step's s), whose acceleration -sum_b psi_b e_b grad W_ib does not depend
/// on s and joins the step's other accelerations before the density solve. With the density
/// rate of a velocity field, the samples at the same weight,
///   (J v)_i = sum_j m_j (v_i - v_j) . grad W_ij + sum_b w psi_b v_i . grad W_ib,
/// the operator A s = -J a(s) is symmetric positive semi-definite (all particles have the same
/// mass: A = J M^-1 J^T m), and its diagonal is DFSPH's factor
///   beta_i = |sum_j m_j grad W_ij + sum_b w psi_b grad W_ib|^2 + m_i sum_j m_j |grad W_ij|^2
/// (the papers' alpha_i = rho_i / beta_i). Floating bodies (BoundaryView::body_response, strong
/// coupling) are more unknowns' worth of M: body k moves under s by A_k = (1 / m_k) sum_i m_i s_i
/// g_ik and alpha_k = I_k^-1 sum_i m_i s_i (x_i - c_k) x g_ik (g_ik = sum_{b of k} w psi_b grad
/// W_ib), which J sees through its samples' velocities, and beta_i gains
/// m_i (|g_ik|^2 / m_k + t . I_k^-1 t), t = (x_i - c_k) x g_ik.
///  - The constant-density solve (after the non-pressure forces, with v* = v + dt a): the
///    predicted error e_i = rho_i + dt (J v*)_i - rho0 must vanish, dt^2 A s = e, and the
///    accelerations a(s) are added to a.
///  - The divergence solve (at the start of a step, on the velocities): (J v)_i must vanish,
///    dt A s = J v, and v changes by dt a(s) (a change that does not depend on dt).
/// As in the papers, only compression is an error and no s is negative (no tension): the
/// solution is that of a complementarity problem (s >= 0, error <= 0, one of them 0 for each
/// particle). Each solve iterates the published projected Jacobi step
/// s += max(e, 0) / (dt^2 beta) (the density solve; the divergence solve's is e / (dt beta)):
/// every s only grows from its non-negative warm start, so none is ever negative and nothing
/// has to be released. A solve stops when the average compression over all particles is below
/// its tolerance (after at least its least iterations), or at its most iterations.
///
/// Each solve starts from its s of the last step (warm start; kept per particle as s for the
/// density solve and s dt for the divergence solve, the dt-free quantities). beta has a floor, a
/// tenth of a full lattice's: a particle among few neighbours whose gradients nearly cancel
/// would otherwise take a huge s. The gradient is the pressure force's (SmoothingKernels::gradient:
/// spiky with the paper's kernels, the density kernel's own with the cubic spline and Wendland
/// C2). Sums over particles are summed in fixed chunks: results are the same for any thread
/// count.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include <sph/core/particle_set.h>
#include <sph/neighbors/neighbor_lists.h>
#include <sph/solver/params.h>
#include <sph/solver/smoothing.h>
#include <sph/solver/solve_stats.h>
#include <sph/solver/wcsph.h>

namespace sph {

/// The gain of a Jacobi step of the solves on a resting lattice of spacing `spacing` (square in
/// 2D, cubic in 3D) with support h: the largest eigenvalue of D^-1 A, A = J M^-1 J^T on equal
/// masses and D its diagonal. A pressure mode s_j = cos(k . x_j) is an eigenvector, with the
/// eigenvalue |sum_r sin(k . r) grad W(r)|^2 / sum_r |grad W(r)|^2 over the lattice's offsets r
/// within h; the largest over a grid of 33 (2D) or 17 (3D) wave numbers per axis in [0, pi /
/// spacing] (a lower bound of the true largest, within a few %). `gradient(r)`: grad W at offset r
/// (a Vec<D, double>).
template <int D, class Gradient>
double jacobi_gain(double spacing, double h, Gradient&& gradient) {
  const int reach = static_cast<int>(std::ceil(h / spacing));
  std::vector<std::array<double, D>> offsets, grads;  // in spacings; grad W
  double squares = 0;
  std::array<int, D> n{};
  for (int d = 0; d < D; ++d) n[d] = -reach;
  for (;;) {
    Vec<D, double> r;
    for (int d = 0; d < D; ++d) r[d] = n[d] * spacing;
    const double r2 = norm2(r);
    if (r2 > 0 && r2 < h * h) {
      const Vec<D, double> g = gradient(r);
      std::array<double, D> o, gd;
      for (int d = 0; d < D; ++d) o[d] = n[d], gd[d] = static_cast<double>(g[d]);
      offsets.push_back(o);
      grads.push_back(gd);
      for (int d = 0; d < D; ++d) squares += gd[d] * gd[d];
    }
    int d = 0;
    while (d < D && ++n[d] > reach) n[d++] = -reach;
    if (d == D) break;
  }
  if (!(squares > 0)) return 0;
  const int samples = D == 2 ? 33 : 17;
  constexpr double kPi = 3.14159265358979323846;
  double best = 0;
  std::array<int, D> m{};
  for (;;) {
    std::array<double, D> H{};
    for (std::size_t j = 0; j < offsets.size(); ++j) {
      double phase = 0;
      for (int d = 0; d < D; ++d) phase += kPi * m[d] / (samples - 1) * offsets[j][d];
      const double s = std::sin(phase);
      for (int d = 0; d < D; ++d) H[d] += s * grads[j][d];
    }
    double h2 = 0;
    for (int d = 0; d < D; ++d) h2 += H[d] * H[d];
    best = std::max(best, h2 / squares);
    int d = 0;
    while (d < D && ++m[d] == samples) m[d++] = 0;
    if (d == D) break;
  }
  return best;
}

/// The DFSPH solves of one run. Its warm-start values are particle fields (added to the
/// ParticleSet by the constructor): they follow reordering, emission and checkpoints.
template <int D, std::floating_point R>
class DfsphSolver {
 public:
  /// Field names of the warm-start values in the ParticleSet.
  static constexpr const char* kDensityField = "dfsph_density_s";
  static constexpr const char* kDivergenceField = "dfsph_divergence_s_dt";

  /// Adds the warm-start fields to `ps` (if absent). `spacing`: the particles' rest spacing
  /// (2 particleRadius), which sets the floor of beta (a tenth of a full lattice's).
  DfsphSolver(const DfsphParams& params, ParticleSet<D, R>& ps, R spacing);

  /// Computes beta_i of the particles' positions, and keeps the step's pairs within h (with
  /// m_j grad W_ij) for the solves. `correction`: the kernel-gradient correction's L
  /// (gradient_corrections, D x D per particle; empty: none). With it every gradient of the
  /// solves, the constraint's as the force's, is corrected as in the WCSPH pressure force:
  /// (L_i + L_j) / 2 grad W_ij for a pair, L_i grad W_ib for a boundary sample, so A stays
  /// symmetric and a linear pressure gets its exact gradient in the interior.
  void compute_factors(const ParticleSet<D, R>& ps, const NeighborLists& lists, const SmoothingKernels<D, R>& kernels,
                       const BoundaryView<D, R>& boundary, std::span<const R> correction = {});
  /// The divergence solve: changes ps.velocity. Needs compute_factors of this state.
  SolveStats divergence_solve(ParticleSet<D, R>& ps, R rho0, R dt);
  /// The constant-density solve: adds the pressure accelerations to ps.acceleration (which holds
  /// the non-pressure ones) and sets ps.pressure (Pa) to the step's: rho^2 (s + s_v dt_v / dt)
  /// with the divergence solve's s_v of this step (run before it with the last step dt_v: its
  /// velocity change dt_v a(s_v) acts with dt a(s), so the two solves share the load of a
  /// resting column). Needs compute_factors.
  SolveStats density_solve(ParticleSet<D, R>& ps, R rho0, R dt);

  /// beta_i of the last compute_factors (tests).
  const std::vector<R>& factors() const { return beta_; }
  /// The scale of the solves' Jacobi steps: min(1, 4 / jacobi_gain of the particles' lattice),
  /// set by the first compute_factors with particles (1 before it).
  R relaxation() const { return relaxation_; }

 private:
  enum class Solve { Density, Divergence };
  template <Solve kSolve>
  SolveStats solve(ParticleSet<D, R>& ps, R rho0, R dt);
  /// out = a(x): the pressure accelerations of a field x.
  void accelerations(const std::vector<R>& x, std::vector<Vec<D, R>>& out) const;
  /// out = a(x), then ax = A x = -J out.
  void apply(const ParticleSet<D, R>& ps, const std::vector<R>& x, std::vector<Vec<D, R>>& out, std::vector<R>& ax);
  /// The moment (x - c_k) x g of g at x about body k's centre (2D: z only; add_moment).
  Vec<3, R> body_moment(std::size_t k, const Vec<D, R>& x, const Vec<D, R>& g) const;
  /// A body's linear and angular velocity, or their changes (strong coupling).
  struct BodyMotion {
    Vec<D, R> linear{};
    Vec<3, R> angular{};
  };
  /// Strong coupling: out[k] = body k's linear and angular velocity change under the forces
  /// force(i, k) (N s: particle i's on body k, acting along a line through x_i), summed in fixed
  /// blocks (the same for any thread count). Empty without strong coupling.
  template <class F>
  void body_motions(const ParticleSet<D, R>& ps, F&& force, std::vector<BodyMotion>& out);
  /// out = body k's accelerations under the pressure field x: the reaction to its samples' push
  /// on the fluid, force m_i x_i g_ik with g_ik = sum_{b of k} w psi_b grad W_ib.
  void body_accelerations(const ParticleSet<D, R>& ps, const std::vector<R>& x, std::vector<BodyMotion>& out);
  /// The bodies' share of particle i's density rate when they move with u (one per body):
  /// -sum_k (u_k.linear . g_ik + u_k.angular . ((x_i - c_k) x g_ik)) (the force g_ik acts along
  /// lines through x_i: its moment about c_k is the same taken at x_i as at the samples).
  R body_rate(std::size_t i, const Vec<D, R>& xi, const std::vector<BodyMotion>& u) const;
  /// (J v)_i: the density rate of particle i under the velocities v(j), on the step's pairs.
  template <class V>
  R density_rate(std::size_t i, V&& v) const;

  DfsphParams params_;
  R spacing_;
  // A full lattice site's values, found on the first compute_factors with particles: the floor
  // of beta and the neighbours within h that make a full neighbourhood.
  bool lattice_done_ = false;
  R beta_floor_ = 0;
  int full_count_ = 0;
  R relaxation_ = 1;
  std::vector<R> beta_;             // per particle: A's diagonal
  std::vector<std::uint8_t> full_;  // per particle: a full neighbourhood (compute_factors)
  // The step's fluid pairs within h (compute_factors): particle i's are begin_[i] .. begin_[i+1],
  // each its neighbour j and m_j grad W_ij; and sum_b psi_b grad W_ib over its boundary samples.
  std::vector<std::size_t> begin_;
  std::vector<std::uint32_t> pair_j_;
  std::vector<Vec<D, R>> pair_g_;
  std::vector<Vec<D, R>> solid_;
  // BoundaryPressure::Extrapolate: each particle's acceleration from its samples' pressure beyond
  // its own (-sum_b psi_b e_b grad W_ib), and each body's share of it (empty: mirrored samples).
  std::vector<Vec<D, R>> hydro_, body_hydro_;
  // Moving obstacles: sum_b psi_b v_b . grad W_ib, the samples' share of the density rate (empty
  // when every sample is at rest).
  std::vector<R> solid_rate_;
  // Floating bodies (BoundaryView::body): each particle's sum_b psi_b grad W_ib per body, and
  // where the solves record the bodies' pressure (compute_factors' view's arrays; null: none).
  std::size_t bodies_ = 0;
  std::vector<Vec<D, R>> body_solid_;
  Vec<D, R>* body_acceleration_ = nullptr;
  Vec<D, R>* body_velocity_change_ = nullptr;
  // Strong coupling (BoundaryView::body_response): how each body answers a force; the bodies'
  // accelerations under the iteration's pressure step; the density solve's prediction of each
  // body's velocity change from all but its pressure.
  std::span<const typename BoundaryView<D, R>::BodyResponse> body_response_;
  std::vector<BodyMotion> body_push_, body_change_;
  std::vector<double> body_partial_;
  std::vector<std::uint8_t> near_body_;        // per particle: a body's sample within h
  std::vector<std::uint32_t> body_particles_;  // the particles near a body, in order
  std::vector<R> b_, s_, p_, as_;              // b, s, the iteration's ds, A s
  std::vector<Vec<D, R>> acc_s_, acc_p_;
  std::vector<double> partial_;  // per-chunk sums
};

extern template class DfsphSolver<2, float>;
extern template class DfsphSolver<2, double>;
extern template class DfsphSolver<3, float>;
extern template class DfsphSolver<3, double>;

}  // namespace sph
