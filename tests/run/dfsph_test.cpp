// DFSPH (Configuration.simulationMethod "dfsph"): its solves hold the density at rest where the
// weakly compressible solver at the same settings does not, the pressure it reports holds the
// column up, its steps are long, no pressure is negative, and its runs are deterministic and
// resume bit for bit.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <sph/core/error.h>
#include <sph/core/parallel.h>
#include <sph/run/driver.h>
#include <sph/scene/scene_reader.h>

#include "support/resume.h"
#include "support/temp_dir.h"
#include "support/thread_count.h"

namespace sph {
namespace {

using test::TempDir;

/// The validation's 2D DFSPH tank at twice its spacing (20 x 20 particles), to `stop` seconds.
SceneDesc coarse_tank(double stop, const std::vector<std::string>& more = {}) {
  std::vector<std::string> sets{"Configuration.particleRadius=0.005", "Configuration.kernelRadius=0.025",
                                "Configuration.stopAt=" + std::to_string(stop), "Configuration.outputFps=0"};
  sets.insert(sets.end(), more.begin(), more.end());
  return read_scene_file(SPH_SOURCE_DIR "/scenes/validation/hydrostatic_2d_dfsph.json", sets);
}

using test::ThreadCount;

struct TankRun {
  double rho_max = 0;       // the largest density / rho0 of any step
  double min_pressure = 0;  // the smallest pressure of any particle at any step, Pa
  double mean_dt = 0;       // s
  int unconverged = 0;      // density solves that ran out of iterations
  double bottom_ratio = 0;  // at the end: mean p / (rho0 g depth) of the particles in the lower half
  double bottom_error = 0;  // and their mean |rho - rho0| / rho0
  std::int64_t steps = 0;
};

TankRun run_tank(const SceneDesc& desc) {
  RunDriver<2, double> run(desc, RunSettings{});
  const SimulationParams<2>& p = run.simulation().params();
  TankRun out;
  out.min_pressure = 1e300;
  const bool by_time = desc.end_time > 0;  // (WCSPH takes fixed steps: stopAt is a step count)
  while (by_time ? run.simulation().time() < desc.end_time * (1 - 1e-12) : run.simulation().steps_done() < desc.steps) {
    const StepInfo& info = run.step();
    out.rho_max = std::max(out.rho_max, info.health.rho_max);
    out.unconverged += !info.density_solve.converged;
    for (const double pr : run.simulation().particles().pressure) out.min_pressure = std::min(out.min_pressure, pr);
  }
  const auto& ps = run.simulation().particles();
  out.steps = run.simulation().steps_done();
  out.mean_dt = run.simulation().time() / static_cast<double>(out.steps);
  double top = 0;
  for (const auto& x : ps.position) top = std::max(top, x[1]);
  const double surface = top + p.particle_radius, g = -p.gravity[1], rho0 = p.fluid.rest_density;
  double ratio = 0;
  int count = 0;
  for (std::size_t i = 0; i < ps.size(); ++i) {
    const double depth = surface - ps.position[i][1];
    if (depth < 0.5 * surface) continue;
    ratio += ps.pressure[i] / (rho0 * g * depth);
    out.bottom_error += std::abs(ps.density[i] / rho0 - 1);
    ++count;
  }
  out.bottom_ratio = ratio / count;
  out.bottom_error /= count;
  return out;
}

TEST(Dfsph, HoldsARestingTankAtRestDensityWithLongSteps) {
  const TankRun dfsph = run_tank(coarse_tank(0.6));
  EXPECT_EQ(dfsph.unconverged, 0) << "every constant-density solve reached maxError";
  EXPECT_LT(dfsph.rho_max, 1.01) << "no particle is ever compressed by a percent";
  EXPECT_LT(dfsph.bottom_error, 5e-4) << "the lower half is within 0.05 % of rest density";
  EXPECT_GE(dfsph.min_pressure, 0.0) << "no tension";
  // The pressure holds the column up: p near rho0 g depth in the lower half.
  EXPECT_NEAR(dfsph.bottom_ratio, 1.0, 0.25);
  // The weakly compressible solver at its acoustic limit (0.4 h / sqrt(stiffness)): DFSPH's CFL
  // steps are several times longer.
  const SceneDesc wcsph_desc = coarse_tank(0.6, {"Configuration.simulationMethod=\"wcsph\""});
  const SimulationParams<2>& w = wcsph_desc.body<2>().sim;
  const double acoustic = 0.4 * w.kernel_radius / std::sqrt(w.fluid.stiffness);
  EXPECT_GT(dfsph.mean_dt, 3 * acoustic);
  // and compresses the lower half more, at its short steps, than DFSPH does at its long ones.
  const TankRun wcsph = run_tank(wcsph_desc);
  EXPECT_GT(wcsph.bottom_error, 3 * dfsph.bottom_error);
}

TEST(Dfsph, TheGradientCorrectionReachesTheSolvesAndHoldsTheTank) {
  // (Fluid.gradientCorrection was once read and then ignored by DFSPH.)
  const TankRun plain = run_tank(coarse_tank(0.3));
  const TankRun corrected = run_tank(coarse_tank(0.3, {"Fluid.gradientCorrection=\"renormalize\""}));
  EXPECT_NE(plain.bottom_ratio, corrected.bottom_ratio);
  EXPECT_EQ(corrected.unconverged, 0);
  EXPECT_LT(corrected.rho_max, 1.01);
  EXPECT_LT(corrected.bottom_error, 5e-4);
  EXPECT_GE(corrected.min_pressure, 0.0);
  EXPECT_NEAR(corrected.bottom_ratio, 1.0, 0.25);
}

TEST(Dfsph, PenaltyWallsAreRefused) {
  try {
    (void)read_scene_file(SPH_SOURCE_DIR "/scenes/validation/hydrostatic_2d_dfsph.json",
                          {"Configuration.boundaryHandling=\"penalty\""});
    FAIL() << "DFSPH with penalty walls was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("DFSPH needs boundary particles"), std::string::npos) << e.what();
  }
}

// Wide supports start from rest as calmly as the usual ones (docs/physics.md, "DFSPH",
// "Kernels"). Before 2026-12-06 the 3D validation tank on 3 spacings failed in its first step
// (the samples beyond the first layer weighed too much, and the walls pushed on fluid at rest),
// and with that mended it still gained 6 % energy by its third step; the 2D tank on 4 spacings
// blew up at its second step (whole Jacobi steps on a lattice whose gain is 6.7).
TEST(Dfsph, WideSupportsRunFromRestWithoutAWarning) {
  const auto calm = [](auto& run, int steps, double bound) {
    double fastest = 0;
    for (int k = 0; k < steps; ++k) {
      run.step();
      fastest = std::max(fastest, run.simulation().max_speed());
    }
    EXPECT_LT(fastest, bound);
    EXPECT_TRUE(run.simulation().health().warnings().empty());
    for (const std::string& w : run.simulation().health().warnings()) ADD_FAILURE() << w;
  };
  {
    const SceneDesc wide2 = read_scene_file(SPH_SOURCE_DIR "/scenes/validation/hydrostatic_2d_dfsph.json",
                                            {"Configuration.kernelRadius=0.02"});  // 4 spacings
    EXPECT_TRUE(wide2.warnings.empty());
    RunDriver<2, double> run(wide2, RunSettings{});
    calm(run, 200, 0.5);  // m/s
  }
  const SceneDesc wide3 = read_scene_file(SPH_SOURCE_DIR "/scenes/validation/hydrostatic_3d_dfsph.json",
                                          {"Configuration.kernelRadius=0.015"});  // 3 spacings
  EXPECT_TRUE(wide3.warnings.empty());
  RunDriver<3, double> run(wide3, RunSettings{});
  calm(run, 30, 0.05);
}

TEST(Dfsph, ATankHeldToATenTimesTighterToleranceStaysAtRest) {
  // maxError 0.001 % (the default 0.01 %): with conjugate gradients in the density solve, before
  // 2026-12-05, the 2D tank gained energy from its 43rd step (the solve ran out of iterations,
  // and its negative pressures were released at once) and failed at step 187.
  const SceneDesc desc =
      read_scene_file(SPH_SOURCE_DIR "/scenes/validation/hydrostatic_2d_dfsph.json", {"Configuration.maxError=0.001"});
  RunDriver<2, double> run(desc, RunSettings{});
  double fastest = 0, error = 0;
  for (int k = 0; k < 250; ++k) {
    const StepInfo& info = run.step();
    fastest = std::max(fastest, run.simulation().max_speed());
    error = std::max(error, info.density_solve.error);
  }
  EXPECT_LT(fastest, 0.2);  // m/s (0.08 when measured)
  // % (every solve reached it when measured; one that runs out of iterations halves the next step)
  EXPECT_LT(error, 0.002);
  EXPECT_TRUE(run.simulation().health().warnings().empty());
}

TEST(Dfsph, TheThreadCountChangesNothing) {
  ThreadCount restore;
  const SceneDesc desc = coarse_tank(0.1);
  std::vector<std::vector<Vec<2, double>>> positions;
  std::vector<std::vector<double>> pressures;
  std::vector<std::int64_t> steps;
  for (int threads : {1, 2}) {
    set_num_threads(threads);
    RunDriver<2, double> run(desc, RunSettings{});
    while (run.simulation().time() < 0.1 * (1 - 1e-12)) run.step();
    positions.push_back(run.simulation().particles().position);
    pressures.push_back(run.simulation().particles().pressure);
    steps.push_back(run.simulation().steps_done());
  }
  EXPECT_EQ(steps[0], steps[1]);
  EXPECT_TRUE(positions[0] == positions[1]);
  EXPECT_TRUE(pressures[0] == pressures[1]);
}

TEST(Dfsph, AStoppedRunResumesBitForBit) {
  TempDir tmp;
  // The paper's tank in DFSPH: an emitter, CFL steps, the warm-start fields in the checkpoint.
  const SceneDesc desc = read_scene_file(
      SPH_SOURCE_DIR "/scenes/dfsph/tank_fill_3d.json",
      {"Configuration.stopAt=0.08", "Configuration.outputFps=100", "Configuration.neighbors=\"adaptive\""});
  EXPECT_EQ(test::expect_resume_gives_the_same_files<3>(desc, tmp.path(), 21).size(), 9u);
}

}  // namespace
}  // namespace sph
