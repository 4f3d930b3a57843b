#pragma once
/// \file The WCSPH operators of the paper (Section 3), as loops that gather into particle i.

#include <algorithm>
#include <array>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include <sph/core/particle_set.h>
#include <sph/neighbors/cluster_pairs.h>
#include <sph/neighbors/list_builder.h>
#include <sph/neighbors/neighbor_lists.h>
#include <sph/solver/params.h>

namespace sph {

/// The boundary particles a pass sees (boundary.h): the samples, their psi, each fluid
/// particle's list of samples and Akinci's friction sigma. Without lists (penalty walls) the
/// passes have no boundary terms.
template <int D, std::floating_point R>
struct BoundaryView {
  std::span<const Vec<D, R>> position;
  std::span<const R> psi;
  const NeighborLists* lists = nullptr;
  R friction = 0;
  /// BoundaryPressure::Extrapolate: the acceleration along which a sample's pressure is carried
  /// from the fluid particle's, p_b = p_i - rho_i extrapolation . (x_i - x_b) (gravity, for walls
  /// at rest), and whether p_b is clamped at 0. Mirror: `extrapolate` false, p_b = p_i.
  bool extrapolate = false;
  bool clamp = true;
  /// BoundaryPressure::None: the sample has no pressure (p_b = 0); else mirrored or extrapolated.
  bool sample_pressure = true;
  Vec<D, R> extrapolation{};
  /// Each sample's velocity (moving obstacles; empty: all at rest): the friction and the Eq. 7
  /// test see the fluid's velocity relative to it.
  std::span<const Vec<D, R>> velocity{};
  /// Floating bodies (rigid_body.h): each sample's body (0: none, s + 1: body s; empty: no sample
  /// floats) and the number of bodies. The passes add what each body gives each particle to
  /// body_acceleration (an acceleration, m/s^2: `bodies` entries per particle, particle i's from
  /// i * bodies; its boundary samples' pressure and friction terms, and with penalty walls the
  /// body's push) and, DFSPH's divergence solve, to body_velocity_change (a velocity change, m/s,
  /// laid out alike). Null: nothing is recorded.
  std::span<const std::uint16_t> body{};
  std::size_t bodies = 0;
  Vec<D, R>* body_acceleration = nullptr;
  Vec<D, R>* body_velocity_change = nullptr;
  /// DFSPH: how each floating body answers a force, in its pose of the step's start: 1 / its mass,
  /// its inertia tensor's inverse in the world's frame (row-major 3 x 3) and its centre of mass;
  /// and what the step changes its velocities by besides the fluid (gravity, contacts, the
  /// gyroscopic term; set once the step's dt is known, before the density solve). Empty: the
  /// solves take the bodies as moving at their velocities of the step's start (they answer after
  /// the step). Else (one per body) the solves also predict each body's motion under the pressure
  /// they solve for (docs/physics.md, "Floating bodies"). The solver reads it during the solves.
  struct BodyResponse {
    double inverse_mass = 0;
    std::array<double, 9> inverse_inertia{};
    Vec<D, double> center{};
    Vec<D, double> velocity_change{};
    Vec<3, double> angular_velocity_change{};
  };
  std::span<const BodyResponse> body_response{};
  /// Particle i's entries of body_acceleration (null when nothing is recorded).
  Vec<D, R>* body_row(std::size_t i) const { return body_acceleration ? body_acceleration + i * bodies : nullptr; }
  bool active() const { return lists != nullptr && lists->particle_count() > 0 && !position.empty(); }
};

/// Paper Eq. 4 and the EOS: rho_i = m_i W(0) + sum_j m_j W(|x_i - x_j|) (+ sum_b psi_b W(|x_i -
/// x_b|) over the boundary samples, Akinci et al. 2012 eq. 6), then p_i = k (rho_i - rho0),
/// clamped at 0 when negative pressure is NegativePressure::Clamp. W is the density kernel of
/// FluidParams::kernel: poly6 for the paper's, else the cubic spline or Wendland C2. Listed pairs
/// at or beyond h contribute nothing.
///
/// Returns the number of listed (directed) fluid pairs closer than h.
///
/// With `clusters` (cluster pairs covering every fluid pair within h: the verlet_clusters mode)
/// the fluid pairs are taken from them and `lists` is not read. The sums are the same terms,
/// added in another order: results agree with the per-particle lists' to rounding.
///
/// With `pairs_summed` (not with clusters), ps.density already holds each particle's sum over
/// its fluid pairs, made by a PairDensity while `lists` were built: the pass adds the rest (its
/// own mass's term, the boundary samples') and the pressure, and returns the lists' entries
/// (every entry is then closer than h). The same bits as the pass that sums over the lists.
template <int D, std::floating_point R>
std::uint64_t compute_density_pressure(ParticleSet<D, R>& ps, const NeighborLists& lists, R h, const FluidParams& fluid,
                                       const BoundaryView<D, R>& boundary = {},
                                       const ClusterPairs<D, R>* clusters = nullptr, bool pairs_summed = false);

/// The density sums over the fluid pairs, made while the lists are built
/// (NeighborStrategy::visit_pairs_with), from the squared distances the list build computed:
/// each list's sum_j m W(|x_ij|), the same terms added in the same lanes and order as
/// compute_density_pressure's pass over the lists (the same bits), without gathering the
/// neighbors' positions again. Each sum goes to the aimed set's density field, for
/// compute_density_pressure(..., pairs_summed = true) to complete. Lists must hold pairs closer
/// than h only (the standard mode's).
template <int D, std::floating_point R>
class PairDensity : public PairVisitor<R> {
 public:
  /// The set whose lists the next build makes (its density field receives the sums).
  void aim(ParticleSet<D, R>& ps) {
    density_ = ps.density.data();
    mass_ = ps.mass;
    particles_ = ps.size();
  }

 protected:
  R* density_ = nullptr;
  R mass_ = 0;
  std::size_t particles_ = 0;
};

/// The PairDensity of the fluid's density kernel with support h.
template <int D, std::floating_point R>
std::unique_ptr<PairDensity<D, R>> make_pair_density(R h, const FluidParams& fluid);

/// The damped penalty acceleration of the container walls and the obstacles on one particle.
/// A particle interacts with a wall plane when closer than `particle_radius` to it; the contact
/// pushes along the wall's normal and never pulls. A moving obstacle (motion.h) is met where its
/// pose puts it, and damps the particle's velocity relative to its own surface's.
template <int D, std::floating_point R>
class WallContact {
 public:
  /// `enabled` false (boundary particles): no wall acceleration at all. `poses`: each obstacle's
  /// pose now (empty: all at rest); `moving[k]` whether obstacle k moves (empty: none);
  /// `body[k]` obstacle k's floating body (0: none, s + 1: body s; empty: none floats);
  /// `shapes[k]` obstacle k's shape when it is not its box (shape.h; empty: all are boxes).
  WallContact(const Box<D>& container, const std::vector<Box<D>>& obstacles, R particle_radius, const WallParams& walls,
              bool enabled = true, std::span<const RigidPose<D>> poses = {}, std::span<const std::uint8_t> moving = {},
              std::span<const std::uint16_t> body = {}, std::span<const ObstacleShape<D>> shapes = {})
      : enabled_(enabled),
        lo_(vec_cast<R>(container.lo)),
        hi_(vec_cast<R>(container.hi)),
        obstacles_(&obstacles),
        poses_(poses),
        moving_(moving),
        body_(body),
        shapes_(shapes),
        radius_(particle_radius),
        ks_(static_cast<R>(walls.stiffness)),
        kd_(static_cast<R>(walls.damping)) {}

  /// Whether operator() is the container's walls alone (no obstacle), which container_push
  /// computes a register of particles at a time.
  bool container_only() const { return enabled_ && obstacles_->empty(); }

  /// operator() of container_only() walls on the lanes of a register of particles (P:
  /// simd::Pack<R>; x, v their positions and velocities): the same operations on each lane, so
  /// the same bits (-v as v (-1)).
  template <class P>
  void container_push(const P (&x)[D], const P (&v)[D], P (&a)[D]) const {
    const P zero = P::set1(R(0)), ks = P::set1(ks_), kd = P::set1(kd_), minus_one = P::set1(R(-1));
    const auto contact = [&](const P& penetration, const P& normal_velocity) {
      const P push = ks * penetration - kd * normal_velocity;
      return select(zero < push, push, zero);  // (std::max(0, push))
    };
    for (int d = 0; d < D; ++d) {
      a[d] = zero;
      const P pen_lo = P::set1(lo_[d] + radius_) - x[d];
      a[d] = select(pen_lo > zero, a[d] + contact(pen_lo, v[d]), a[d]);
      const P pen_hi = x[d] - P::set1(hi_[d] - radius_);
      a[d] = select(pen_hi > zero, a[d] - contact(pen_hi, v[d] * minus_one), a[d]);
    }
  }

  /// The wall acceleration of a particle at x with velocity v; with `body_row` (the particle's
  /// entries of BoundaryView::body_acceleration) each floating body's push is also added there.
  Vec<D, R> operator()(const Vec<D, R>& x, const Vec<D, R>& v, Vec<D, R>* body_row = nullptr) const {
    Vec<D, R> a{};
    if (!enabled_) return a;
    // Container: particles inside the box, pushed back from each of its 2D faces.
    for (int d = 0; d < D; ++d) {
      const R pen_lo = lo_[d] + radius_ - x[d];
      if (pen_lo > 0) a[d] += contact(pen_lo, v[d]);
      const R pen_hi = x[d] - (hi_[d] - radius_);
      if (pen_hi > 0) a[d] -= contact(pen_hi, -v[d]);
    }
    // Obstacles: a particle inside the box grown by one radius is pushed out through the
    // nearest face (a moving one's, in the obstacle's own frame, with the velocity relative to
    // its surface there, and the push turned back into the world's frame).
    for (std::size_t k = 0; k < obstacles_->size(); ++k) {
      const Box<D>& b = (*obstacles_)[k];
      if (k < moving_.size() && moving_[k]) {
        const RigidPose<D>& pose = poses_[k];
        const Vec<D, double> xw = vec_cast<double>(x);
        const Vec<D, double> xb = pose.to_rest(xw);
        const Vec<D, double> vb = pose.unrotate(vec_cast<double>(v) - pose.velocity_at(xw));
        Vec<D, R> push{};
        if (push_out(k, b, vec_cast<R>(xb), vec_cast<R>(vb), push)) {
          const Vec<D, R> turned = vec_cast<R>(pose.rotate(vec_cast<double>(push)));
          a += turned;
          if (body_row && k < body_.size() && body_[k] != 0) body_row[body_[k] - 1] += turned;
        }
        continue;
      }
      push_out(k, b, x, v, a);
    }
    return a;
  }

 private:
  /// Acceleration of a penalty contact along its normal: never attractive.
  R contact(R penetration, R normal_velocity) const {
    return std::max(R(0), ks_ * penetration - kd_ * normal_velocity);
  }
  /// Adds to `a` the push out of obstacle k (its box b, grown by one radius) on a particle at x
  /// with velocity v, in the obstacle's frame; false (nothing added) if x is outside it. A shape
  /// (shape.h) pushes along its outward normal at the nearest point of its surface, by the depth
  /// within one radius of it.
  bool push_out(std::size_t k, const Box<D>& b, const Vec<D, R>& x, const Vec<D, R>& v, Vec<D, R>& a) const {
    if (k < shapes_.size() && !shapes_[k].empty()) {
      const ObstacleShape<D>& shape = shapes_[k];
      if (!shape.inverted)
        for (int d = 0; d < D; ++d)
          if (!(x[d] > static_cast<R>(b.lo[d]) - radius_ && x[d] < static_cast<R>(b.hi[d]) + radius_)) return false;
      const SurfaceDistance<D> s = shape.solid_distance(vec_cast<double>(x), static_cast<double>(radius_));
      if (!(s.distance < static_cast<double>(radius_))) return false;
      const Vec<D, R> n = vec_cast<R>(s.normal);
      a += n * contact(radius_ - static_cast<R>(s.distance), dot(n, v));
      return true;
    }
    R best = std::numeric_limits<R>::max();
    int best_d = -1;
    R best_sign = 0;
    for (int d = 0; d < D; ++d) {
      const R to_lo = x[d] - (static_cast<R>(b.lo[d]) - radius_);
      const R to_hi = (static_cast<R>(b.hi[d]) + radius_) - x[d];
      if (to_lo <= 0 || to_hi <= 0) return false;
      if (to_lo < best) best = to_lo, best_d = d, best_sign = R(-1);
      if (to_hi < best) best = to_hi, best_d = d, best_sign = R(1);
    }
    if (best_d < 0) return false;  // (a non-finite position: the blow-up check reports it)
    a[best_d] += best_sign * contact(best, best_sign * v[best_d]);
    return true;
  }

  bool enabled_;
  Vec<D, R> lo_, hi_;
  const std::vector<Box<D>>* obstacles_;
  std::span<const RigidPose<D>> poses_;
  std::span<const std::uint8_t> moving_;
  std::span<const std::uint16_t> body_;
  std::span<const ObstacleShape<D>> shapes_;
  R radius_, ks_, kd_;
};

/// Accelerations from pressure (Eq. 5, spiky gradient), viscosity (Eq. 6 with (v_j - v_i),
/// viscosity-kernel Laplacian), gravity, the walls (`walls`) and the boundary particles
/// (`boundary`), in one pass over the particles:
///   a_i = g + sum_j m_j [ -P_ij grad W_spiky(x_i - x_j) + mu (v_j - v_i) / (rho_i rho_j) lap W_visc ]
///         + walls(x_i, v_i)
/// with P_ij = (p_i + p_j) / (2 rho_i rho_j) (PressureForce::Paper: Eq. 5's force density
/// divided by rho_i) or p_i / rho_i^2 + p_j / rho_j^2 (PressureForce::Symmetric; and
/// PressureForce::Variational, which takes poly6's gradient in place of the spiky one). With
/// GradientCorrection::Renormalize the pressure term's gradient is (L_i + L_j) / 2 grad W_ij
/// (a second pass over the pairs). Every pair term is antisymmetric (m_i a_i = -m_j a_j), so
/// total momentum is conserved when lists are symmetric.
///
/// Other kernels (FluidParams::kernel): the cubic spline's or Wendland C2's gradient replaces the
/// spiky one (and poly6's: Variational is then Symmetric), and the viscosity term is Morris et
/// al. 1997's, 2 mu m_j / (rho_i rho_j) (x_ij . grad W_ij) / (|x_ij|^2 + 0.01 h^2) (v_i - v_j).
/// ViscosityModel::Artificial replaces Eq. 6 by Monaghan's -m_j Pi_ij grad W_ij (params.h).
///
/// Boundary samples b (Akinci et al. 2012): the pressure term of the pair with rho_b = rho_i and
/// p_b the fluid's pressure extrapolated to the sample (BoundaryView::extrapolate:
/// p_b = p_i + rho_i g . (x_b - x_i)) or mirrored (p_b = p_i), psi_b for m_j:
/// -psi_b P_ib grad W_ib), and the boundary
/// friction -psi_b Pi_ib grad W_ib with Pi_ib = -nu min(v_i . x_ib, 0) / (|x_ib|^2 + 0.01 h^2),
/// nu = sigma h c0 / (2 rho_i). The Eq. 7 test covers fluid-boundary pairs (the samples do not
/// move: |x_i - x_b + dt u_i| > h flags i).
///
/// If `exit_flags` is not empty (one per particle), the same pass also evaluates paper Eq. 7
/// for every listed pair, |x_i - x_j + dt (u_i - u_j)|^2 > h^2, and sets exit_flags[i] and
/// exit_flags[j] to 1 when it holds (flags are only ever set, never cleared, so concurrent
/// setting is race-free and the result is the same for any thread count). This pass gathers
/// every neighbor's position and velocity anyway, so the test costs a few operations per pair.
/// `exit_radius` replaces h in the test where it is positive (the adaptive_exact mode's lists
/// reach h + skin, and a pair is flagged when it is predicted to leave them).
///
/// `pressure_terms` false leaves the pressure terms out (fluid pairs and boundary samples): the
/// non-pressure accelerations that DFSPH's solves start from (dfsph.h).
///
/// `clusters`: as for compute_density_pressure (no Eq. 7 test then: exit_flags must be empty).
/// `lists` is read only by the gradient correction's pass.
///
/// `scratch`: memory the pass over lists may use for its copy of each particle's 1 / rho and p
/// (2 reals a particle; NeighborStrategy::scratch_until_update), else a buffer of its own, kept.
template <int D, std::floating_point R>
void compute_accelerations(ParticleSet<D, R>& ps, const NeighborLists& lists, R h, const FluidParams& fluid,
                           const Vec<D, R>& gravity, const WallContact<D, R>& walls,
                           std::span<std::uint8_t> exit_flags = {}, R dt = 0, const BoundaryView<D, R>& boundary = {},
                           R exit_radius = 0, bool pressure_terms = true, const ClusterPairs<D, R>* clusters = nullptr,
                           ScratchBuffer* scratch = nullptr);

/// Particle mass such that a particle inside a lattice of spacing dx (square in 2D, cubic in
/// 3D) has exactly density rho0 under the density kernel's sum of Eq. 4 with support h (poly6
/// for the paper's kernels).
template <int D>
double lattice_mass(double rest_density, double spacing, double h, KernelKind kernel = KernelKind::Paper);

}  // namespace sph
