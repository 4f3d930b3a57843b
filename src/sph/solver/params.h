#pragma once
/// \file SimulationParams: everything the solver needs, as plain values in SI units.
/// Scene files are turned into these by the scene layer; the solver never reads files.

#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

#include <sph/core/kernels.h>
#include <sph/core/vec.h>
#include <sph/neighbors/strategy.h>
#include <sph/solver/motion.h>
#include <sph/solver/shape.h>

namespace sph {

/// What the equation of state does with a density below the rest density.
enum class NegativePressure {
  Clamp,  ///< p = max(0, k (rho - rho0)): no tension; free surfaces stay smooth (default)
  Allow,  ///< p = k (rho - rho0) as in the paper: slight tension, clumping at free surfaces
};

/// Axis-aligned box [lo, hi], m.
template <int D>
struct Box {
  Vec<D, double> lo, hi;

  friend bool operator==(const Box&, const Box&) = default;
};

/// How the pressure force is discretized.
enum class PressureForce {
  /// Paper Eq. 5 (Mueller et al. 2003): -sum_j m_j (p_i + p_j) / (2 rho_j) grad W_ij, divided
  /// by rho_i. In the interior this approximates -grad(p) / 2: a tank settles at about twice
  /// rho0 g depth (docs/physics.md). Default, as the paper's method.
  Paper,
  /// Monaghan's symmetric form: -sum_j m_j (p_i / rho_i^2 + p_j / rho_j^2) grad W_ij, which
  /// approximates -grad(p) / rho: a tank settles at rho0 g depth.
  Symmetric,
  /// The symmetric form with the density kernel's gradient (poly6) instead of the spiky one:
  /// the force is then minus the gradient of the EOS's internal energy of the summed densities
  /// (variational SPH), so that inviscid motion conserves energy, and on the lattice at h = 2
  /// spacings a resting tank settles at rho0 g depth (docs/physics.md).
  Variational,
};

/// Whether the pressure force corrects the kernel gradient.
enum class GradientCorrection {
  None,  ///< the plain spiky gradient (the paper's method; default)
  /// Each particle's gradient renormalized by L_i = A_i^-1, A_i = sum_j V_j grad W_ij (x_j - x_i)^T,
  /// so that a linear pressure field has its exact gradient; pairs use (L_i + L_j) / 2, which
  /// keeps every pair's forces equal and opposite (momentum is conserved). At h = 2 spacings the
  /// plain gradient makes a resting tank's pressure 15-17 % high (docs/validation.md). Where
  /// A_i is nearly singular (det below 1/2: a particle at the surface or alone), L_i = I.
  Renormalize,
};

/// How the fluid's viscosity is discretized.
enum class ViscosityModel {
  /// Paper Eq. 6: mu (v_j - v_i) / (rho_i rho_j) times the viscosity kernel's Laplacian (with the
  /// cubic and Wendland kernels, Morris et al. 1997's Laplacian from the kernel gradient); default.
  Paper,
  /// Monaghan's (1992) artificial viscosity, Pi_ij = -alpha c0 h mu_ij / rho_ij for approaching
  /// pairs (mu_ij = v_ij . x_ij / (|x_ij|^2 + 0.01 h^2), rho_ij the mean density, h the kernel
  /// support), as a pressure-like pair term; FluidParams::alpha. The engineering codes' default.
  Artificial,
};

/// How the fluid's viscosity term (ViscosityModel::Paper: Eq. 6, or Morris et al.'s with the
/// cubic spline and Wendland C2) is integrated in time.
enum class ViscositySolve {
  /// In the force pass, with the step's velocities (forward Euler); the step is held below the
  /// viscous diffusion limit 0.125 h^2 rho0 / mu (default).
  Explicit,
  /// Backward Euler, solved by conjugate gradients on the step's pairs within h (viscosity.h): the
  /// velocities after the step satisfy m_i v_i = m_i v*_i + dt sum_j m_i k_ij (v_j - v_i). Stable
  /// at any step, so the viscous limit no longer bounds the step.
  Implicit,
};

/// Weakly compressible fluid: EOS p = k (rho - rho0).
struct FluidParams {
  double rest_density = 1000;  ///< rho0, kg/m^D
  double stiffness = 1000;     ///< k, m^2/s^2 (p in Pa per kg/m^3); the sound speed is sqrt(k)
  double viscosity = 0;        ///< dynamic viscosity mu of Eq. 6, Pa s (2D: kg/s)
  NegativePressure negative_pressure = NegativePressure::Clamp;
  PressureForce pressure_force = PressureForce::Paper;
  GradientCorrection gradient_correction = GradientCorrection::None;
  KernelKind kernel = KernelKind::Paper;  ///< the smoothing kernels of density, gradient and viscosity
  ViscosityModel viscosity_model = ViscosityModel::Paper;
  double alpha = 0.1;  ///< ViscosityModel::Artificial's coefficient (Monaghan 1992)
  ViscositySolve viscosity_solve = ViscositySolve::Explicit;
  /// ViscositySolve::Implicit: the solve's most iterations per step, and its tolerance: the
  /// residual as a % of the starting one (the explicit step's viscous impulse).
  int viscosity_max_iterations = 100;
  double viscosity_max_error = 0.1;  ///< %

  friend bool operator==(const FluidParams&, const FluidParams&) = default;
};

/// Damped penalty springs at the container walls and obstacle faces. They act on particles
/// closer than one particle radius to a wall, as an acceleration along the wall normal:
/// a_n = max(0, stiffness * penetration - damping * v_n).
struct WallParams {
  double stiffness = 1e5;  ///< 1/s^2 (force per unit mass per metre of penetration)
  double damping = 100;    ///< 1/s

  friend bool operator==(const WallParams&, const WallParams&) = default;
};

/// What the container's walls and the obstacles are to the fluid.
enum class BoundaryHandling {
  Penalty,    ///< damped penalty springs (WallParams), the paper's walls
  Particles,  ///< boundary particles (Akinci et al. 2012): solids sampled by static particles (boundary.h)
};

/// What a boundary sample's volume V_b = 1 / delta_b counts in delta_b = sum_k W(x_b - x_k).
enum class BoundaryVolume {
  /// The samples, the fluid at rest on the fluid's side of the solid (its lattice sites within h)
  /// and the solid's lattice beyond the sampled layers: a solid in fluid at rest then reads
  /// exactly rho0 next to its walls, on any support (default).
  RestFluid,
  /// The samples alone (Akinci et al. 2012, eq. 4-5): the layer next to the fluid misses the
  /// fluid half of its support and weighs more, so fluid next to a wall reads a few % dense.
  Akinci,
};

/// The pressure a boundary sample b takes in its pair with fluid particle i.
enum class BoundaryPressure {
  /// p_b = p_i + rho_i g . (x_b - x_i) (clamped at 0 when negative pressure is clamped): the
  /// fluid's pressure carried to the sample along the hydrostatic gradient, a one-neighbor form
  /// of Adami et al. 2012's extrapolation. A resting fluid's pressure then grows with depth into
  /// the walls as it does in the fluid, and the layers next to the floor and the walls are not
  /// squeezed (default).
  Extrapolate,
  /// p_b = p_i (Akinci et al. 2012's mirroring): the sample below a resting particle has the
  /// particle's pressure, less than the fluid's at its depth.
  Mirror,
  /// p_b = 0: the sample has no pressure of its own, and its term is the particle's alone (with
  /// the symmetric forms p_i / rho_i^2: Akinci et al. 2012's eq. 10, and SPlisHSPlasH's DFSPH
  /// boundary term). A resting particle next to a wall then needs about twice the fluid's
  /// pressure at its depth to be held (DFSPH's default).
  None,
};

/// Boundary particles' settings.
struct BoundaryParams {
  BoundaryHandling handling = BoundaryHandling::Penalty;
  BoundaryVolume volume = BoundaryVolume::RestFluid;
  /// (the scene reader's default is None with DFSPH: SimulationMethod::Dfsph)
  BoundaryPressure pressure = BoundaryPressure::Extrapolate;
  /// Akinci et al. 2012's boundary viscosity sigma: nu = sigma h c0 / (2 rho_i) on approaching
  /// fluid-boundary pairs (0: free slip). It is also what damps sound waves at the walls
  /// (boundary particles reflect them): below about 0.2 a resting tank keeps ringing
  /// (docs/validation.md, "Boundaries").
  double friction = 0.2;

  friend bool operator==(const BoundaryParams&, const BoundaryParams&) = default;
};

/// An emitter: a rectangular nozzle of width x height particles (height ignored in 2D) at
/// spacing `spacing`, centered at `origin`, facing `direction`, adding one layer of particles
/// moving at `speed` every `every_steps` steps, from `start_time` until `max_particles` were
/// emitted or `end_time` passed.
template <int D>
struct EmitterParams {
  Vec<D, double> origin{};
  Vec<D, double> direction{};  ///< unit vector
  double speed = 1;            ///< m/s
  int width = 1;
  int height = 1;
  double spacing = 0;  ///< m
  int every_steps = 16;
  std::int64_t max_particles = 0;
  double start_time = 0;
  double end_time = std::numeric_limits<double>::infinity();

  friend bool operator==(const EmitterParams&, const EmitterParams&) = default;
};

/// How the fluid's pressure is computed.
enum class SimulationMethod {
  /// Weakly compressible SPH (the paper): pressure from the EOS p = k (rho - rho0), explicit.
  Wcsph,
  /// Divergence-free SPH (Bender & Koschier 2015, 2017): pressures solved each step so that the
  /// velocity field is divergence-free and the predicted density is rho0 (dfsph.h).
  Dfsph,
};

/// Why DFSPH refuses penalty walls (the scene reader and Simulation say it).
inline constexpr const char* kDfsphNeedsBoundaryParticles =
    "DFSPH needs boundary particles: penalty springs push with forces the pressure solve does not see, and at "
    "DFSPH's large time steps they are unstable; set Configuration.boundaryHandling to \"particles\"";

/// Why the implicit viscosity refuses Monaghan's artificial viscosity (the reader and Simulation).
inline constexpr const char* kImplicitViscosityNeedsPaperModel =
    "the implicit viscosity solves the viscosity term of viscosityModel \"paper\" (Eq. 6, or Morris's with the cubic "
    "spline and Wendland C2); Monaghan's artificial viscosity acts only on approaching pairs, which no linear solve "
    "can take: set viscosityModel to \"paper\" or viscositySolver to \"explicit\"";

/// DFSPH's two solves (Configuration keys of SPlisHSPlasH's names; docs/scene-format.md).
struct DfsphParams {
  int min_iterations = 2;         ///< constant-density solve: at least this many iterations
  int max_iterations = 100;       ///< and at most this many
  double max_error = 0.01;        ///< its tolerance: average compression (rho* - rho0) / rho0, %
  bool divergence_solver = true;  ///< run the divergence solve
  int max_iterations_v = 100;     ///< divergence solve: at most this many iterations
  double max_error_v = 10;        ///< its tolerance: average (D rho / Dt) / rho0, % per second

  friend bool operator==(const DfsphParams&, const DfsphParams&) = default;
};

/// How the time step is chosen.
enum class TimeStepping {
  Fixed,  ///< every step takes SimulationParams::time_step
  /// Each step takes the Courant-Friedrichs-Lewy step of the state it starts from (CflParams),
  /// shortened to land exactly on emission times, frame times and the end of the run.
  Cfl,
};

/// The CFL step (TimeStepping::Cfl, Simulation::next_time_step): the advective limit
/// dt <= factor 0.4 d / u (d the particle diameter, u the largest of |v| + dt_last |a|: a
/// particle moves at most 0.4 factor diameters, SPlisHSPlasH's rule), the acoustic limit with
/// the flow's speed, dt <= 0.8 * 0.4 h / (c0 + u), the scene's other limits as timeStepSize
/// "auto" takes them (time_step.h), at most twice the last step, clamped to [min_dt, max_dt].
struct CflParams {
  double factor = 0.5;   ///< Configuration.cflFactor
  double min_dt = 1e-5;  ///< s, Configuration.cflMinTimeStepSize
  double max_dt = 5e-3;  ///< s, Configuration.cflMaxTimeStepSize

  friend bool operator==(const CflParams&, const CflParams&) = default;
};

template <int D>
struct SimulationParams {
  double time_step = 1e-4;  ///< dt, s (fixed; with TimeStepping::Cfl the first step's largest)
  SimulationMethod method = SimulationMethod::Wcsph;
  DfsphParams dfsph;  ///< SimulationMethod::Dfsph's solves
  TimeStepping time_stepping = TimeStepping::Fixed;
  CflParams cfl;
  double particle_radius = 0.01;  ///< m; particles are spaced 2 radii apart initially
  double kernel_radius = 0.04;    ///< h, m
  double particle_mass = 0;       ///< kg (same for all particles)
  Vec<D, double> gravity{};       ///< m/s^2
  FluidParams fluid;
  WallParams walls;  ///< BoundaryHandling::Penalty's springs
  BoundaryParams boundary;
  Box<D> container;               ///< closed box holding the fluid
  std::vector<Box<D>> obstacles;  ///< solid boxes, as they are at rest (motion.h)
  /// Each obstacle's prescribed motion (Obstacles[].motion), in the obstacles' order; shorter
  /// than `obstacles` (empty: none moves) means the others are at rest. See obstacle_motion().
  std::vector<ObstacleMotion<D>> motions;
  /// Each obstacle's rigid body (Obstacles[].dynamic; rigid_body.h), in the obstacles' order;
  /// shorter than `obstacles` (empty: none floats) means the others are not dynamic. A dynamic
  /// obstacle has no motion. See obstacle_body().
  std::vector<BodyParams<D>> bodies;
  /// Each obstacle's shape when it is not a box (Obstacles[].polygon, Obstacles[].geometryFile;
  /// shape.h), in the obstacles' order; `obstacles[k]` is then the shape's bounding box. Shorter
  /// than `obstacles` (empty: all are boxes), or an empty shape, means a box. See obstacle_shape().
  std::vector<ObstacleShape<D>> shapes;
  std::vector<EmitterParams<D>> emitters;
  NeighborMode neighbors = NeighborMode::Standard;
  int full_rebuild_period = 200;  ///< adaptive mode
  /// Adaptive mode: every step, the fluid particles within reach of a moving obstacle (h plus the
  /// obstacle's travel in the step) are flagged for a rebuild of their lists, whatever Eq. 7
  /// says (the paper's Section 6 suggestion; Configuration.flagNearMovingBodies).
  bool flag_near_moving = true;
  /// Every this many steps (from step 0), particles are reordered in memory along a Morton
  /// curve and every list is rebuilt; 0 never reorders. Defaults to full_rebuild_period so
  /// that adaptive runs rebuild nothing extra.
  int reorder_period = 200;
  double verlet_skin = 0;   ///< verlet mode: skin, m; 0 means kDefaultSkinFraction * h
  double tracked_skin = 0;  ///< tracked modes: skin, m; 0 means automatic (tracked_skin())
  /// Audit the lists every step against exact lists (StepInfo::audit); costs about one
  /// standard list build per step.
  bool audit = false;
  /// The health monitor (health.h) fails a step past a failure threshold; false: it only
  /// measures and warns (tests of machinery on deliberately unphysical setups).
  bool health_failures = true;

  friend bool operator==(const SimulationParams&, const SimulationParams&) = default;
};

/// Obstacle k's motion (MotionType::None when it is at rest).
template <int D>
const ObstacleMotion<D>& obstacle_motion(const SimulationParams<D>& p, std::size_t k) {
  static const ObstacleMotion<D> kAtRest;
  return k < p.motions.size() ? p.motions[k] : kAtRest;
}

/// Obstacle k's rigid body (not dynamic when it has none).
template <int D>
const BodyParams<D>& obstacle_body(const SimulationParams<D>& p, std::size_t k) {
  static const BodyParams<D> kFixed;
  return k < p.bodies.size() ? p.bodies[k] : kFixed;
}

/// Obstacle k's shape, or nullptr when it is a box (`obstacles[k]`).
template <int D>
const ObstacleShape<D>* obstacle_shape(const SimulationParams<D>& p, std::size_t k) {
  return k < p.shapes.size() && !p.shapes[k].empty() ? &p.shapes[k] : nullptr;
}

/// Whether any obstacle of `p` has a shape other than a box.
template <int D>
bool any_shape(const SimulationParams<D>& p) {
  return std::any_of(p.shapes.begin(), p.shapes.end(), [](const ObstacleShape<D>& s) { return !s.empty(); });
}

/// The signed distance of the point X (in obstacle k's frame at rest, m) to obstacle k's solid,
/// negative inside it, and the solid's outward normal there: exact for a box; for a shape, exact
/// where X may be within `reach` of the surface or is inside the solid, elsewhere a lower bound
/// above `reach` (ObstacleShape::solid_distance). A box's normal inside it is its nearest face's.
template <int D>
SurfaceDistance<D> obstacle_distance(const SimulationParams<D>& p, std::size_t k, const Vec<D, double>& X,
                                     double reach) {
  if (const ObstacleShape<D>* shape = obstacle_shape(p, k)) return shape->solid_distance(X, reach);
  const Box<D>& b = p.obstacles[k];
  SurfaceDistance<D> s;
  double out2 = 0, in = std::numeric_limits<double>::infinity();
  int face = 0;
  double face_sign = 1;
  for (int d = 0; d < D; ++d) {
    const double below = b.lo[d] - X[d], above = X[d] - b.hi[d];
    if (below > 0) out2 += below * below, s.normal[d] = -below;
    if (above > 0) out2 += above * above, s.normal[d] = above;
    if (-below < in) in = -below, face = d, face_sign = -1;
    if (-above < in) in = -above, face = d, face_sign = 1;
  }
  if (out2 > 0) {
    s.distance = std::sqrt(out2);
    s.normal = s.normal * (1.0 / s.distance);
    return s;
  }
  s.distance = -in;
  s.normal = Vec<D, double>{};
  s.normal[face] = face_sign;
  return s;
}

/// Whether obstacle k moves: by a prescribed motion, or as a floating body.
template <int D>
bool obstacle_moves(const SimulationParams<D>& p, std::size_t k) {
  return obstacle_motion(p, k).moves() || obstacle_body(p, k).dynamic;
}

/// Whether any obstacle of `p` moves (a prescribed motion, or a floating body).
template <int D>
bool any_obstacle_moves(const SimulationParams<D>& p) {
  for (std::size_t k = 0; k < p.obstacles.size(); ++k)
    if (obstacle_moves(p, k)) return true;
  return false;
}

/// Whether any obstacle of `p` is a floating body.
template <int D>
bool any_dynamic_body(const SimulationParams<D>& p) {
  return std::any_of(p.bodies.begin(), p.bodies.end(), [](const BodyParams<D>& b) { return b.dynamic; });
}

/// Monaghan's artificial viscosity coefficient alpha the default viscosity is equivalent to
/// (and the health monitor's advice names).
inline constexpr double kArtificialViscosityAlpha = 0.1;

/// The dynamic viscosity (Pa s; kg/s in 2D) equivalent to Monaghan's artificial viscosity with
/// coefficient alpha: nu = alpha h c0 / (2 (D + 2)) (Monaghan 2005, section 4.3), mu = rho0 nu,
/// with h the kernel support radius and c0 = sqrt(stiffness).
inline double viscosity_for_sound_speed(int dimension, double alpha, double kernel_radius, double sound_speed,
                                        double rest_density) {
  return rest_density * alpha * kernel_radius * sound_speed / (2.0 * (dimension + 2));
}

}  // namespace sph
