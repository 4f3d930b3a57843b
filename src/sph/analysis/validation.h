#pragma once
/// \file Validation against experiment and physics (`sph validate`): the 2D dam break of
/// Martin & Moyce (1952), a resolution study, hydrostatic tanks in 2D and 3D, and conservation
/// of momentum and energy. The measures (front detector, front error, hydrostatic profile,
/// energies) are free functions on plain data so that they can be tested on synthetic fields;
/// run_validation runs the cases in this process and write_validation writes the report.
///
/// docs/validation.md describes each case, its targets and where the simulator disagrees.

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include <sph/core/vec.h>

namespace sph {

// ---- Martin & Moyce (1952) ------------------------------------------------------------------

/// One point of the surge front: Z = x / a (distance of the leading edge on the floor from the
/// back wall, over the column's base width a) at T = t sqrt(2 g / a).
struct FrontPoint {
  double T = 0, Z = 0;
};

/// Base width a of the experiment's column (2.25 in), m; the column is 2a high (n^2 = 2).
inline constexpr double kMartinMoyceA = 0.05715;

/// J. C. Martin and W. J. Moyce (1952), "An experimental study of the collapse of liquid columns
/// on a rigid horizontal plane", Phil. Trans. R. Soc. A 244:312-324, Table 2 (n^2 = 2), as in
/// ../shared/validation/martin_moyce_1952_front.csv: 16 points, the first being the initial
/// condition T = 0, Z = 1 (not part of the table).
std::span<const FrontPoint> martin_moyce_1952();

/// Scaled time T = t sqrt(2 g / a) of the experiment for t in s, |g| in m/s^2, a in m.
double martin_moyce_time(double t, double g, double a = kMartinMoyceA);

/// The surge front of a 2D dam break, m: the largest x among the particles on the floor (y below
/// floor + 2 spacing) that have at least `min_neighbors` other particles within h, plus half a
/// spacing (a particle's center is half a spacing inside the fluid it stands for, so a column
/// whose last particle is at a - spacing / 2 has its front at a). Requiring neighbors ignores
/// isolated spray ahead of the front. NaN when no particle qualifies. x and y must have equal
/// sizes (sph::Error otherwise).
double surge_front(std::span<const double> x, std::span<const double> y, double floor, double spacing, double h,
                   int min_neighbors = 3);

/// Linear interpolation of the samples (xs increasing) at x; NaN outside [xs.front(), xs.back()].
double interpolate(std::span<const double> xs, std::span<const double> ys, double x);

/// A simulated front Z(T) against the experiment.
struct FrontError {
  int points = 0;                      ///< experimental points compared
  bool complete = true;                ///< false if the simulation did not reach every point with T <= t_max
  double max = kNaN;                   ///< max |Z_sim - Z_exp|
  double rms = kNaN;                   ///< RMS of Z_sim - Z_exp
  double mean = kNaN;                  ///< mean of Z_sim - Z_exp (> 0: ahead)
  double worst_T = kNaN;               ///< T of the largest |dZ|
  std::vector<FrontPoint> experiment;  ///< the points compared
  std::vector<double> simulated;       ///< Z_sim at each of them (NaN if not reached)
};

/// Compares the simulated front (T increasing, same sizes) with the experimental points of
/// t_min < T <= t_max, interpolating Z_sim linearly at each experimental T. With the default
/// t_min = 0 the initial condition T = 0 (which every simulation matches by construction) is
/// left out, so it does not dilute the RMS.
FrontError front_error(std::span<const double> T, std::span<const double> Z, std::span<const FrontPoint> experiment,
                       double t_max, double t_min = 0);

// ---- Fluid states and energies ---------------------------------------------------------------

/// A fluid's state in doubles (positions and velocities padded with zeros to 3 components), made
/// from the frame view (frame_data_of) for the measures below.
struct FluidState {
  int dimension = 2;
  double time = 0;
  double particle_mass = 0;
  std::vector<std::array<double, 3>> position, velocity;
  std::vector<double> density, pressure;
};

/// Internal energy per unit mass of the barotropic EOS p = k (rho - rho0), clamped at 0 below
/// rho0: e(rho) = k (ln(rho / rho0) + rho0 / rho - 1) for rho > rho0, 0 otherwise. It is the
/// integral of p / rho^2 d rho from rho0, so de/drho = p / rho^2: the work the pressure does on a
/// particle whose density changes. J/kg.
double eos_internal_energy(double rho, double rho0, double stiffness);

/// Energy of a fluid in a closed box with penalty walls, J (J/m in 2D).
struct EnergyParts {
  double kinetic = 0;    ///< sum m |v|^2 / 2
  double potential = 0;  ///< sum m |g| (y - box.lo.y)  (gravity along -y)
  double internal = 0;   ///< sum m e(rho) (eos_internal_energy)
  double wall = 0;       ///< sum m k_w d^2 / 2 over the faces a particle penetrates by d
  double total() const { return kinetic + potential + internal + wall; }
};

/// What energy() needs about the simulation: box, gravity (along -y), EOS, walls.
struct EnergyModel {
  std::array<double, 3> box_lo{}, box_hi{};
  double gravity = 9.81;  ///< |g|, m/s^2, pointing to -y
  double rest_density = 1000, stiffness = 1000;
  double wall_stiffness = 0;   ///< k_w, 1/s^2 (0: no wall energy)
  double particle_radius = 0;  ///< a wall acts on particles closer than this to it
};

/// The energy of `state`. The wall energy is that of the springs' conservative part
/// (acceleration k_w d along the normal: energy k_w d^2 / 2 per unit mass); the damping part
/// only dissipates. The density is the one the state carries.
EnergyParts energy(const FluidState& state, const EnergyModel& model);

/// How much a series grew: the largest value minus the smallest value before it (0 if it never
/// increases).
double largest_rise(std::span<const double> values);

// ---- Hydrostatics ----------------------------------------------------------------------------

/// Height of the free surface, m: the top particle of every column of width `spacing` (over x in
/// 2D, over x and z in 3D), averaged over the columns, plus half a spacing. Gravity along -y.
double free_surface_height(const FluidState& state, double spacing);

/// Mean pressure of one depth bin against rho0 g depth.
struct DepthBin {
  double depth = 0;     ///< mean depth of the particles, m
  double pressure = 0;  ///< mean pressure, Pa (N/m in 2D)
  double ratio = 0;     ///< pressure / (rho0 g depth)
  std::size_t count = 0;
  bool compared = true;  ///< false for a bin with fewer than half the median count (cut by the floor)
};

/// max_layer_error's bins are one spacing deep: a tank that keeps its lattice has one layer of
/// particles in each. Bins of two spacings average a pressure that alternates from layer to layer
/// (which SPH's symmetric pressure force gives under a free surface: docs/validation.md, "DFSPH").
struct HydrostaticProfile {
  double surface = 0;          ///< free_surface_height, m
  std::vector<DepthBin> bins;  ///< bins of `bin_layers` spacings from `skip_layers` spacings down
  std::size_t particles = 0;   ///< interior particles below the skipped layers
  double mean_ratio = 0;       ///< mean of p / (rho0 g depth) over them
  double max_bin_error = 0;    ///< max |ratio - 1| over bins of at least 3 particles
  double max_layer_error = 0;  ///< the same over bins of one spacing (above)
  double max_compression = 0;  ///< max (rho - rho0) / rho0 over every particle
  double interior_density_min = 0, interior_density_max = 0;  ///< (rho - rho0) / rho0, interior
  double mean_density_error = 0;                              ///< mean |rho - rho0| / rho0 over the interior particles
};

struct HydrostaticModel {
  std::array<double, 3> box_lo{}, box_hi{};
  double gravity = 9.81, rest_density = 1000, spacing = 0, h = 0;
  double skip_layers = 2;  ///< particles less deep than this many spacings are not compared
  /// Particles closer than this to a side wall or the floor are not compared (< 0: h, where the
  /// kernel is cut by penalty walls; boundary particles fill it, so 0 compares the whole tank).
  double wall_margin = -1;
  double bin_layers = 2;  ///< depth bin width, spacings
};

/// Pressure against depth after settling. Only interior particles are compared: deeper than
/// skip_layers spacings, and farther than h from every wall (there the kernel is cut by the wall,
/// which the penalty walls do not fill). The density extremes are over every particle
/// (compression) and over the interior (variation).
HydrostaticProfile hydrostatic_profile(const FluidState& state, const HydrostaticModel& model);

/// The first time after which `values` stays below `fraction` of its peak (the time of the
/// first sample if it always does; NaN if the last sample is still above).
double settling_time(std::span<const double> times, std::span<const double> values, double fraction);

/// M_yy = -sum_j V_j (y_i - y_j) dW/dy_i on a perfect lattice of the given spacing (square in
/// 2D, cubic in 3D), with V_j = m / rho0 and m the lattice mass, for the spiky kernel's gradient
/// or (poly6_gradient, the variational pressure force) poly6's: the factor by which the discrete
/// pressure gradient of a linear pressure field differs from the exact one (1 for a consistent
/// gradient). A resting tank settles at p / (rho0 g d) of about 1 / M_yy.
double lattice_gradient_consistency(int dimension, double spacing, double h, bool poly6_gradient = false);

// ---- Running the cases ----------------------------------------------------------------------

/// The cases of `sph validate`.
inline constexpr std::array<const char*, 6> kValidationCases{"martin_moyce", "resolution", "hydrostatic",
                                                             "boundaries",   "dfsph",      "conservation"};

/// Throws sph::Error (naming --cases) unless `name` is one of kValidationCases: the cases, and the
/// one a misspelling was probably meant to be.
void check_validation_case(std::string_view name);

struct ValidationOptions {
  std::vector<std::string> cases{kValidationCases.begin(), kValidationCases.end()};
  bool quick = false;               ///< coarse, short versions with regression bounds (CI)
  std::filesystem::path scene_dir;  ///< holds martin_moyce_2d.json, hydrostatic_2d.json, ...
};

/// One check of a measured value against its bound.
struct ValidationCheck {
  std::string case_name, what;
  double value = 0;
  std::string target;  ///< the bound as text ("<= 0.15")
  bool pass = false;
  bool regression = false;  ///< a --quick regression bound, not the physical target
};

/// A run of the dam break with its front and energy.
struct FrontRun {
  std::string label;   ///< e.g. "a/40 standard"
  std::string mode;    ///< neighbor mode
  int resolution = 0;  ///< a / spacing
  double spacing = 0, dt = 0, seconds = 0;
  std::int64_t steps = 0;
  std::size_t particles = 0;
  std::string failure;  ///< the error if the run blew up
  std::vector<std::int64_t> step;
  std::vector<double> time, T, Z;
  std::vector<EnergyParts> energy;
  FrontError error;
  /// Resolution study: this front against the next coarser one's, at the experiment's times
  /// (max and RMS of Z_this - Z_coarser); empty for the coarsest.
  FrontError change;
};

/// The front `fine` compared with the front `coarse` (both T increasing) at the times of
/// `at.experiment` (the experimental points a front_error compared), as front_error does with
/// the experiment: how much a refinement moved the front. Points where `coarse` has no value
/// are left out and make the result incomplete.
FrontError front_change(std::span<const double> fine_T, std::span<const double> fine_Z,
                        std::span<const double> coarse_T, std::span<const double> coarse_Z, const FrontError& at);

/// A hydrostatic tank run.
struct HydrostaticRun {
  std::string label;  ///< "2D", "3D"
  int dimension = 2;
  double spacing = 0, h = 0, dt = 0, stiffness = 0, seconds = 0, rest_density = 0, gravity = 0;
  std::int64_t steps = 0;
  std::size_t particles = 0;
  std::string failure;
  std::vector<double> time, kinetic, surface;  ///< sampled history
  std::vector<EnergyParts> energy;             ///< at the same samples
  double initial_surface = 0, settling_time = 0, surface_drift = 0, predicted_ratio = 0;
  /// The profiles (`profile`, `whole`) are of each particle's position and pressure averaged over
  /// the samples of the run's last tenth (`averaged_samples` of them): the tank's lowest acoustic
  /// mode still rings, and a single frame catches it at one phase. `whole_last_frame`: the
  /// whole tank's max bin error in the last frame alone, for comparison.
  HydrostaticProfile profile;
  int averaged_samples = 0;
  double whole_last_frame = 0;
  /// The boundaries case: the boundary handling and kernel (scene names), the profile over the
  /// whole tank (wall_margin 0), and the most particles outside the container in any step.
  std::string boundary, kernel;
  HydrostaticProfile whole;
  std::uint64_t max_outside = 0;
  /// The steps taken, their mean time step (s; CFL steps vary) and DFSPH's mean iterations per
  /// step (constant-density and divergence solves; 0 with WCSPH).
  std::int64_t steps_taken = 0;
  double mean_dt = 0, mean_iterations = 0, mean_iterations_v = 0;
  /// Interior particles' (depth, pressure) at the end, for the plot.
  std::vector<std::array<double, 2>> scatter;
};

/// A free-blob momentum run.
struct MomentumRun {
  std::string label, mode;
  std::int64_t steps = 0;
  double seconds = 0, scale = 0;  ///< scale: sum m |v| at t = 0
  std::string failure;
  std::vector<double> time, drift;  ///< |P(t) - P(0)| / scale
  double max_drift = 0;
};

struct ValidationResult {
  bool quick = false;
  int threads = 1;
  double seconds = 0;
  std::vector<std::string> cases;
  std::vector<FrontRun> front_runs;  ///< martin_moyce (per mode) and resolution runs
  std::vector<HydrostaticRun> hydrostatic;
  std::vector<HydrostaticRun> boundaries;  ///< hydrostatic tanks per (boundary handling, kernel)
  std::vector<HydrostaticRun> dfsph;       ///< the DFSPH tanks (the dfsph case)
  std::vector<MomentumRun> momentum;
  std::vector<ValidationCheck> checks;

  bool passed() const {
    for (const auto& c : checks)
      if (!c.pass) return false;
    return true;
  }
};

/// Progress lines ("martin_moyce: a/40 standard 50 %").
using ValidationProgress = std::function<void(const std::string&)>;

/// Runs the selected cases in this process, one run after the other. Throws sph::Error for an
/// unknown case or a missing or invalid scene; a run that blows up is recorded (its checks miss).
ValidationResult run_validation(const ValidationOptions& options, const ValidationProgress& progress = {});

/// Reads every scene the selected cases need (run_validation does it first too), so that an unknown
/// case or a missing or invalid scene is refused before anything is run or written.
void check_validation_scenes(const ValidationOptions& options);

/// Files write_validation writes (relative to the output directory).
std::vector<std::string> validation_files(const ValidationResult& result);

/// Creates `dir` (the validation's output) and checks that files can be created in it. Throws
/// sph::Error naming the path. An earlier validation's files stay until write_validation.
void prepare_validation_directory(const std::filesystem::path& dir);

/// Removes every file an earlier validation may have written in `dir` (their set depends on the
/// cases run), so that it holds only this run's results, then writes report.md, the CSVs and the
/// plots (which must exist), each atomically.
void write_validation(const std::filesystem::path& dir, const ValidationResult& result);

}  // namespace sph
