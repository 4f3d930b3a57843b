#pragma once
/// \file The health monitor: per-step statistics of a run (measured in the integrate pass, which
/// visits every particle anyway) judged against ONE table of physical thresholds, kHealthWatches
/// (docs/reliability.md, "Health monitor", explains each row and where its numbers come from).
///
/// A quantity past its warning threshold raises a warning once per kind (the run goes on; its
/// status becomes "completed with warnings: ..."); past its failure threshold the step throws
/// sph::Error naming the step, the time, the particle, the quantity and its value, and what to
/// change, computed from the scene and what was seen.

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <sph/core/state_stream.h>
#include <sph/solver/params.h>

namespace sph {

/// A particle counts as outside the container (or inside an obstacle) when its centre is farther
/// than this many initial spacings (2 particle radii) beyond the wall's plane: half a spacing is
/// one particle radius, so its whole disk (sphere) is past the wall. The penalty walls act inside
/// the box, in a contact zone one radius deep; the paper dam break's particles reach 0.27
/// spacings past the plane at its impacts (docs/reliability.md).
inline constexpr double kOutsideTolerance = 0.5;

/// What the health monitor watches, one bit each in HealthStats::new_warnings.
enum class HealthKind : std::uint8_t {
  Outside,      ///< particles outside the container
  InsideSolid,  ///< particles inside an obstacle
  Mach,         ///< max |v| / c0
  Compression,  ///< max rho / rho0
  Tension,      ///< min rho / rho0 (only with NegativePressure::Allow)
  Energy,       ///< total energy growth of a closed scene
  BodyInWall,   ///< a floating body's corner past the container's walls
};
inline constexpr std::size_t kHealthKinds = 7;

/// One row of the table: a quantity, its thresholds (a value above `warn` warns, above `fail`
/// fails; infinity: no such level) and why.
struct HealthWatch {
  HealthKind kind;
  const char* name;      ///< the key in summary.json's "warning_counts"
  const char* quantity;  ///< what is compared with the thresholds
  double warn;
  double fail;
  const char* unit;
  const char* why;
};

inline constexpr double kNoLimit = std::numeric_limits<double>::infinity();

/// The thresholds (docs/reliability.md is written next to this table; keep them together).
inline constexpr HealthWatch kHealthWatches[kHealthKinds] = {
    {HealthKind::Outside, "outside", "fraction of the particles outside the container", 0, 0.01, "of the particles",
     "a closed box holds its fluid; any particle past the wall plane means the walls are too soft for the speed "
     "or the head; past 1 % of the fluid (or one particle deeper than h, which no longer feels the fluid) the "
     "run has lost its fluid"},
    {HealthKind::InsideSolid, "inside_solid", "fraction of the particles inside an obstacle", 0, 0.01,
     "of the particles", "as outside the container, for the obstacles' faces"},
    {HealthKind::Mach, "mach", "max |v| / c0, c0 = sqrt(Fluid.stiffness)", 0.3, 1.0, "",
     "weakly compressible SPH keeps the density error about Ma^2 (Monaghan 1992, 2005: Ma <= 0.1 for 1 %); "
     "at Ma 0.3 it is about 10 %; a supersonic particle means the model no longer describes a liquid"},
    {HealthKind::Compression, "compression", "max rho / rho0 over particles with neighbours", 1.3, 2.0, "",
     "in steady flow WCSPH's density variation is about Ma^2 (Monaghan 2005), but an impact sends a pressure "
     "pulse rho0 c0 dv, a compression dv / c0 = Ma (water hammer): at the Mach warning level 0.3 that is 30 %; "
     "a fluid compressed to twice its rest density is no longer a liquid"},
    {HealthKind::Tension, "tension", "1 - min rho / rho0 over particles with neighbours (negativePressure allow)", 0.1,
     kNoLimit, "",
     "with negativePressure \"allow\" a particle 10 % below rest density pulls its neighbours (tensile "
     "instability, clumping at free surfaces); with \"clamp\" low density is a free surface and is not judged"},
    {HealthKind::Energy, "energy", "(E - E0) / (|E0| + M c0^2 / 2e4), closed scenes", 0.05, 1.0, "",
     "a closed viscous fluid between damped walls loses energy: E (kinetic + gravity + wall springs) cannot "
     "exceed E0, its initial value plus the initial internal energy of the equation of state (>= 0); above it "
     "the integration adds energy (dt too large, too little viscosity); the scale adds "
     "the kinetic energy of the mass M at Ma 0.01 so that a scene at rest is judged too"},
    {HealthKind::BodyInWall, "body_in_wall",
     "a floating body's deepest corner past the container's walls, in particle spacings", kOutsideTolerance, kNoLimit,
     "spacings",
     "a body's contact with the walls is a damped spring whose stiffness the longest step allows; a corner a "
     "particle radius deep into a wall means the springs give under the fluid's load, and the body's boundary "
     "samples crowd the wall's"},
};

/// The scene's scales the monitor needs (from SimulationParams).
struct HealthScene {
  int dimension = 3;
  double sound_speed = 1;  ///< c0 = sqrt(Fluid.stiffness), m/s
  double kernel_radius = 0, particle_radius = 0, rest_density = 1000;
  double stiffness = 0, viscosity = 0, wall_stiffness = 0, wall_damping = 0, time_step = 0;
  double gravity = 0;               ///< |g|, m/s^2
  double head = 0;                  ///< the container's extent along g (0 without gravity), m
  bool closed = true;               ///< no emitter (the energy is judged)
  bool tension = false;             ///< NegativePressure::Allow
  bool incompressible = false;      ///< SimulationMethod::Dfsph: the Mach number is not judged
  bool boundary_particles = false;  ///< BoundaryHandling::Particles (no wall springs to advise on)
  bool misses_pairs = false;        ///< NeighborMode::Adaptive: the lists can miss pairs coming into range
  bool implicit_viscosity = false;  ///< ViscositySolve::Implicit (no viscous step limit to advise on)
  /// CFL steps (`cflMethod` "cfl"): time_step is then cflMaxTimeStepSize, and the advice names it
  /// and cflFactor instead of timeStepSize.
  bool cfl = false;
  double cfl_factor = 0;
  /// Floating bodies' contact springs: their angular rate w = pi / (10 step) comes from this step,
  /// s (cflMaxTimeStepSize with CFL steps, else timeStepSize), 0 without bodies.
  double contact_step = 0;
};

template <int D>
HealthScene health_scene(const SimulationParams<D>& p);

/// What the integrate pass measured in one step (after the step's motion).
struct HealthStats {
  std::uint64_t outside = 0;       ///< particles beyond kOutsideTolerance spacings outside the container
  double outside_depth = 0;        ///< the deepest distance outside the container's planes, m (0: none)
  std::uint64_t outside_id = 0;    ///< its particle id
  double outside_speed = 0;        ///< its speed, m/s
  std::uint64_t inside_solid = 0;  ///< particles beyond the tolerance inside an obstacle
  double inside_depth = 0;         ///< the deepest distance inside an obstacle, m
  std::uint64_t inside_id = 0;
  double inside_speed = 0;
  double max_mach = 0;  ///< max |v| / c0
  std::uint64_t mach_id = 0;
  double rho_min = 1, rho_max = 1;  ///< density ratio range over particles with neighbours within h
  std::uint64_t rho_max_id = 0;
  /// kinetic + gravity (from the container's lowest point along g) + wall springs, J (J/m in 2D)
  double energy = 0;
  double body_depth = 0;            ///< the deepest corner of a floating body past a container wall, m (0: none)
  std::int64_t body_obstacle = -1;  ///< that body's index in the scene's Obstacles
  const char* body_wall = "";       ///< which wall: "-x", "+x", "-y", ... (its outward side; "" if none)
  std::uint32_t new_warnings = 0;   ///< bit (1 << HealthKind) per warning raised first in this step
};

/// Judges each step's HealthStats against kHealthWatches; remembers the warnings given and how
/// many steps each kind held (part of the simulation's state: saved in checkpoints).
class HealthMonitor {
 public:
  HealthMonitor() = default;
  /// `fail` false: the monitor measures and warns but never fails a step (SimulationParams::health_failures).
  explicit HealthMonitor(const HealthScene& scene, bool fail = true);

  /// The bound E0 (J, J/m in 2D: the initial energy plus the initial internal energy) and the
  /// total mass (kg) of the initial state.
  void set_initial(double energy, double mass) { initial_energy_ = energy, total_mass_ = mass; }
  double initial_energy() const { return initial_energy_; }

  /// Judges step `step` (0-based; `time` after it) of `particles` particles: sets
  /// stats.new_warnings and counts; throws sph::Error on a failure.
  void check(HealthStats& stats, std::int64_t step, double time, std::size_t particles);

  /// The warnings given so far, in the order they were first raised.
  std::vector<std::string> warnings() const;
  /// The warning of one kind ("" if never raised).
  const std::string& warning(HealthKind kind) const { return messages_[static_cast<std::size_t>(kind)]; }
  /// Steps in which each kind's warning condition held.
  const std::array<std::int64_t, kHealthKinds>& counts() const { return counts_; }
  /// The largest Mach number and density ratio range seen so far, and the largest energy.
  double max_mach() const { return max_mach_; }
  double rho_max() const { return rho_max_; }
  double rho_min() const { return rho_min_; }
  double max_energy() const { return max_energy_; }

  void save_state(StateWriter& out) const;
  void load_state(StateReader& in);

 private:
  double energy_scale() const;
  void warn(HealthStats& stats, HealthKind kind, std::string message);

  HealthScene scene_;
  bool fail_ = true;
  double initial_energy_ = 0, total_mass_ = 0;
  std::array<std::string, kHealthKinds> messages_;
  std::array<std::int64_t, kHealthKinds> counts_{};
  std::array<std::int64_t, kHealthKinds> order_{};  // order_[k]: rank at which kind k was raised (0: never)
  std::int64_t raised_ = 0;
  double max_mach_ = 0, rho_max_ = 0, rho_min_ = kNoLimit, max_energy_ = -kNoLimit;
};

}  // namespace sph
