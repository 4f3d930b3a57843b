#pragma once
/// \file Comparing neighbor modes on one scene (`sph compare`): timing, divergence from the
/// standard run against the chaos floor, energy, missed pairs, and side-by-side images.

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <sph/io/run_directory.h>
#include <sph/neighbors/strategy.h>
#include <sph/render/particles.h>
#include <sph/scene/scene_desc.h>
#include <sph/solver/simulation.h>

namespace sph {

struct CompareOptions {
  /// Modes to run; the first standard run is the reference. "standard" is added in front if
  /// missing (every comparison is against it).
  std::vector<NeighborMode> modes = neighbor_modes(NeighborModeSet::Compared);
  std::int64_t steps = 0;  ///< steps per run (the scene's numberOfSteps when 0)
  int samples = 100;       ///< positions are compared at about this many steps
  int frames = 3;          ///< side-by-side images at this many evenly spaced steps
  /// The chaos floor: a second standard run whose particles are displaced by this fraction of
  /// h when they appear (0: no chaos run).
  double perturbation = 1e-9;
  bool audit = true;  ///< audit every run's lists (not counted in the timings)
  /// When not empty, each mode's run (not the chaos-floor run) also writes its frames, as
  /// `sph run -o DIR` would, to runs_dir/<mode>/ (scene.json with the mode, frames/ on the
  /// scene's output schedule, formats and fields), and runs_dir/runs.txt lists them in order,
  /// so that `sph render` and `sph view` show the modes side by side. Writing is not timed.
  std::filesystem::path runs_dir;
};

/// One step of one run.
struct StepRecord {
  double time = 0;            ///< simulated time after the step, s
  double seconds = 0;         ///< wall seconds of the step's phases (audit excluded)
  double kinetic_energy = 0;  ///< J (J/m in 2D)
  std::uint64_t particles = 0, lists_rebuilt = 0, pairs_stored = 0, pairs_within_h = 0;
  std::uint64_t missed_pairs = 0;           ///< audit (0 without audit: see CompareResult::audited)
  std::uint64_t boundary_missed_pairs = 0;  ///< fluid-boundary pairs the lists missed (audit)
  double max_missed_penetration = 0;
};

/// Particle state at one sampled step, indexed by stable id (made from the frame view,
/// frame_data_of: the one conversion of a particle set to doubles).
struct Snapshot {
  std::int64_t step = 0;  ///< steps done (0: the initial state)
  double time = 0;
  std::vector<std::array<double, 3>> position;  ///< by id; NaN for ids not yet emitted
  std::vector<std::array<double, 3>> velocity;  ///< by id; only for image steps
  std::vector<std::array<double, 3>> initial;   ///< by id; only for image steps
  std::vector<BodyPoseRow> bodies;              ///< the floating bodies' poses; only for image steps
};

/// Everything recorded from one run.
struct RunRecord {
  std::string label;  ///< "standard", "adaptive", "verlet", "standard (perturbed)"
  NeighborMode mode = NeighborMode::Standard;
  bool perturbed = false;
  std::vector<StepRecord> steps;
  std::vector<Snapshot> samples;
  PhaseTimes totals;
  std::string failure;  ///< the error message if the run blew up ("" otherwise)

  /// Missed pairs summed over the steps (0 without audit).
  std::uint64_t missed_pairs() const {
    std::uint64_t n = 0;
    for (const StepRecord& s : steps) n += s.missed_pairs;
    return n;
  }
  /// Fluid-boundary missed pairs summed over the steps (0 without audit or boundary particles).
  std::uint64_t boundary_missed_pairs() const {
    std::uint64_t n = 0;
    for (const StepRecord& s : steps) n += s.boundary_missed_pairs;
    return n;
  }
};

/// Divergence of one run from the reference at one sampled step, in units of h, over the
/// particles present in both.
struct Divergence {
  std::int64_t step = 0;
  double time = 0;
  double rms = 0, max = 0;
};

struct CompareResult {
  std::string scene;
  int dimension = 3;
  std::string precision;
  int threads = 1;
  double h = 0, dt = 0, particle_radius = 0, particle_mass = 0, perturbation = 0;
  std::array<double, 3> box_lo{}, box_hi{};
  /// The scene's obstacles as the report's pictures draw them: image_obstacles[k] holds them where
  /// they are at image_steps[k] (moving obstacles move; the steps are fixed, step * dt).
  std::vector<std::vector<SolidBox>> image_obstacles;
  bool has_emitters = false;
  bool has_boundary_particles = false;  ///< Configuration.boundaryHandling: "particles"
  bool audited = false;                 ///< missed-pair figures exist (CompareOptions::audit)
  std::int64_t steps = 0;
  std::vector<std::int64_t> image_steps;
  std::vector<RunRecord> runs;  ///< runs[0] is the standard reference
  /// divergence[k] for runs[k] against runs[0] (empty for k = 0).
  std::vector<std::vector<Divergence>> divergence;
};

/// The standard algorithm's total step seconds: the mean over the standard runs (the reference
/// and the perturbed one do the same work), so that the order of the runs biases no ratio.
double standard_seconds(const CompareResult& result);

/// Called as runs progress: (run label, run index, run count, steps done, steps).
using CompareProgress = std::function<void(const std::string&, int, int, std::int64_t, std::int64_t)>;

/// Throws sph::Error if the modes cannot be compared on `desc`: a scene of CFL steps
/// (Configuration.cflMethod "cfl") would give each mode its own steps, and the comparison
/// compares the modes step by step.
void check_comparable(const SceneDesc& desc);

/// Runs every mode (and the chaos-floor run) on the scene, in this process, one after the
/// other, and computes the divergences. A run that blows up is recorded with its failure and
/// the steps it made. Throws sph::Error for a scene the modes cannot run.
CompareResult run_comparison(const SceneDesc& desc, const CompareOptions& options,
                             const CompareProgress& progress = {});

/// Creates `dir` (the comparison's output), checks that files can be created in it and removes
/// what an earlier comparison left there whose set depends on the options (images of other
/// steps, the audit's plot, runs.txt). Throws sph::Error naming the path, also if it is a run's
/// directory (holds run.json or scene.json).
void prepare_comparison_directory(const std::filesystem::path& dir);

/// Files written by write_comparison (relative to the output directory).
std::vector<std::string> comparison_files(const CompareResult& result);

/// Writes the CSVs, the plots, the side-by-side images and report.md into `dir` (which must
/// exist). Every file is written atomically.
void write_comparison(const std::filesystem::path& dir, const CompareResult& result);

}  // namespace sph
