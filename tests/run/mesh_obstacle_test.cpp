// Obstacles of any shape (Obstacles[].polygon in 2D, Obstacles[].geometryFile in 3D): a dam break
// flows around them and no particle gets inside them (their signed distance, checked as the run
// goes), with boundary particles and with penalty springs; a turning polygon stirs without letting
// fluid in; a closed surface holds the fluid inside it (inverted); fluid blocks lose the particles
// in a shape, and say so; runs are the same for any thread count and resume bit for bit.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <sph/core/parallel.h>
#include <sph/run/driver.h>
#include <sph/scene/builders.h>
#include <sph/scene/scene_reader.h>

#include "support/resume.h"
#include "support/solids.h"
#include "support/temp_dir.h"

namespace sph {
namespace {

using test::deepest_inside;
using test::TempDir;

struct ThreadCount {
  int saved = num_threads();
  ~ThreadCount() { set_num_threads(saved); }
};

/// The fluid's viscosity: DFSPH's scenes' 1 Pa s (Eq. 6); WCSPH with penalty walls keeps the default
/// (Monaghan's artificial viscosity), which damps its pressure waves.
constexpr const char* kViscosity[2] = {"", R"(, "viscosity": 1.0)"};

/// A 2D dam break (a column 0.3 m x 0.4 m, spacing 2 cm) onto `obstacle` (an Obstacles entry), with
/// boundary particles and DFSPH, or penalty springs and WCSPH.
SceneDesc dam_break_2d(const std::string& obstacle, bool particles, double stop = 1.0) {
  const std::string method = particles
                                 ? R"("boundaryHandling": "particles", "kernel": "cubic", "simulationMethod": "dfsph",
                     "cflMaxTimeStepSize": 0.005)"
                                 : R"("boundaryHandling": "penalty")";
  return parse_scene(fmt::format(R"({{
    "version": 1, "name": "polygon", "dimension": 2,
    "Configuration": {{ "precision": "double", "stopAt": {}, "particleRadius": 0.01, "kernelRadius": 0.04,
      "gravitation": [0, -9.81], "outputFps": 20, {} }},
    "Fluid": {{ "density0": 1000{} }},
    "Container": {{ "start": [0, 0], "end": [1.2, 0.6] }},
    "FluidBlocks": [ {{ "start": [0, 0], "end": [0.3, 0.4] }} ],
    "Obstacles": [ {} ]
  }})",
                                 stop, method, kViscosity[particles], obstacle),
                     "polygon.json");
}

/// How deep a particle's centre may get inside a solid, in particle radii: the health monitor's
/// tolerance. Boundary particles hold the fluid about a radius off a face, but a sharp convex
/// corner (a tip narrower than a particle) pokes into the particles that meet it; penalty springs
/// let the fluid in by their squeeze.
constexpr double kTolerance = 1.0;

/// A wedge with a notch (concave), its vertices clockwise.
constexpr const char* kWedge = R"({ "polygon": [[0.6, 0], [0.7, 0.18], [0.76, 0.1], [0.84, 0.2], [0.9, 0]] })";

/// Runs `desc` to its end, checking every `every` steps: returns the deepest a particle got inside
/// an obstacle (m; negative: all outside) and expects the run to end without a health warning.
template <int D>
double deepest_over_run(const SceneDesc& desc, int every = 5) {
  RunDriver<D, double> run(desc, RunSettings{});
  const Simulation<D, double>& sim = run.simulation();
  double deepest = deepest_inside(sim);
  RunCallbacks each;
  each.progress = [&](std::int64_t step, std::size_t) {
    if (step % every == 0) deepest = std::max(deepest, deepest_inside(sim));
  };
  const RunResult r = run.run(each);
  EXPECT_EQ(r.status, RunStatus::Completed) << r.message;
  EXPECT_TRUE(r.warnings.empty()) << (r.warnings.empty() ? "" : r.warnings[0]);
  return deepest;
}

TEST(MeshObstacle, ADamBreakFlowsOverAConcavePolygonAndNoParticleGetsInside) {
  for (const bool particles : {true, false}) {
    SCOPED_TRACE(particles ? "boundary particles" : "penalty springs");
    const SceneDesc desc = dam_break_2d(kWedge, particles);
    const double r = desc.body<2>().sim.particle_radius;
    EXPECT_LT(deepest_over_run<2>(desc), kTolerance * r);
  }
}

TEST(MeshObstacle, ATurningPolygonStirsWithoutLettingFluidIn) {
  // A three-bladed star turning at 3 rad/s in a pool (moving samples, relisted every step).
  std::string star = R"({ "polygon": [)";
  for (int k = 0; k < 6; ++k) {
    const double a = k * 3.14159265358979 / 3, rad = k % 2 == 0 ? 0.16 : 0.04;
    star += fmt::format("{}[{:.6f}, {:.6f}]", k ? ", " : "", 0.6 + rad * std::cos(a), 0.3 + rad * std::sin(a));
  }
  star += R"(], "motion": { "type": "rotation", "center": [0.6, 0.3], "angularVelocity": 3, "rampTime": 0.2 } })";
  SceneDesc desc = parse_scene(fmt::format(R"({{
    "version": 1, "name": "star", "dimension": 2,
    "Configuration": {{ "precision": "double", "stopAt": 0.6, "particleRadius": 0.01, "kernelRadius": 0.04,
      "gravitation": [0, -9.81], "outputFps": 20, "boundaryHandling": "particles", "kernel": "cubic",
      "simulationMethod": "dfsph", "cflMaxTimeStepSize": 0.004 }},
    "Fluid": {{ "density0": 1000, "viscosity": 1.0 }},
    "Container": {{ "start": [0, 0], "end": [1.2, 0.7] }},
    "FluidBlocks": [ {{ "start": [0, 0], "end": [1.2, 0.5] }} ],
    "Obstacles": [ {} ]
  }})",
                                           star),
                               "star.json");
  // The pool's particles in the star are left out (and said so).
  ASSERT_EQ(desc.warnings.size(), 1u);
  EXPECT_NE(desc.warnings[0].find("FluidBlocks[0]:"), std::string::npos) << desc.warnings[0];
  const double r = desc.body<2>().sim.particle_radius;
  EXPECT_LT(deepest_over_run<2>(desc, 1), kTolerance * r);
}

TEST(MeshObstacle, AClosedPolygonHoldsTheFluidInsideIt) {
  // An octagonal vessel (inverted: the solid is outside it) with water sloshing inside.
  std::string vessel = R"({ "polygon": [)";
  for (int k = 0; k < 8; ++k) {
    const double a = (k + 0.5) * 3.14159265358979 / 4;
    vessel += fmt::format("{}[{:.6f}, {:.6f}]", k ? ", " : "", 0.5 + 0.4 * std::cos(a), 0.5 + 0.4 * std::sin(a));
  }
  vessel += R"(], "inverted": true })";
  for (const bool particles : {true, false}) {
    SCOPED_TRACE(particles ? "boundary particles" : "penalty springs");
    const std::string method = particles
                                   ? R"("boundaryHandling": "particles", "kernel": "cubic", "simulationMethod": "dfsph",
                       "cflMaxTimeStepSize": 0.005)"
                                   : R"("boundaryHandling": "penalty")";
    const SceneDesc desc = parse_scene(fmt::format(R"({{
      "version": 1, "name": "vessel", "dimension": 2,
      "Configuration": {{ "precision": "double", "stopAt": 0.8, "particleRadius": 0.01, "kernelRadius": 0.04,
        "gravitation": [0, -9.81], "outputFps": 20, {} }},
      "Fluid": {{ "density0": 1000{} }},
      "Container": {{ "start": [0, 0], "end": [1, 1] }},
      "FluidBlocks": [ {{ "start": [0.1, 0.1], "end": [0.6, 0.5] }} ],
      "Obstacles": [ {} ]
    }})",
                                                   method, kViscosity[particles], vessel),
                                       "vessel.json");
    // The block's corners outside the octagon are left out.
    ASSERT_FALSE(desc.warnings.empty());
    EXPECT_NE(desc.warnings[0].find("FluidBlocks[0]: "), std::string::npos) << desc.warnings[0];
    const double r = desc.body<2>().sim.particle_radius;
    EXPECT_LT(deepest_over_run<2>(desc), kTolerance * r);
  }
}

TEST(MeshObstacle, A3DDamBreakGoesAroundATurnedMeshAndNoParticleGetsInside) {
  for (const bool particles : {true, false}) {
    SCOPED_TRACE(particles ? "boundary particles" : "penalty springs");
    const std::string method = particles
                                   ? R"("boundaryHandling": "particles", "kernel": "cubic", "simulationMethod": "dfsph",
                       "cflMaxTimeStepSize": 0.005)"
                                   : R"("boundaryHandling": "penalty")";
    // The unit cube, scaled to 0.16 m x 0.3 m x 0.16 m and turned 45 degrees about y: an edge meets the flow.
    const SceneDesc desc =
        parse_scene(fmt::format(R"({{
      "version": 1, "name": "mesh", "dimension": 3,
      "Configuration": {{ "precision": "double", "stopAt": 0.5, "particleRadius": 0.02, "kernelRadius": 0.08,
        "gravitation": [0, -9.81, 0], "outputFps": 20, {} }},
      "Fluid": {{ "density0": 1000{} }},
      "Container": {{ "start": [0, 0, 0], "end": [1.2, 0.6, 0.4] }},
      "FluidBlocks": [ {{ "start": [0, 0, 0], "end": [0.32, 0.4, 0.4] }} ],
      "Obstacles": [ {{ "geometryFile": "{}", "scale": [0.16, 0.3, 0.16], "translation": [0.7, 0, 0.09],
                        "rotationAxis": [0, 1, 0], "rotationAngle": 0.7853981633974483 }} ]
    }})",
                                method, kViscosity[particles], SPH_SOURCE_DIR "/tests/data/meshes/cube.obj"),
                    "mesh.json");
    const double r = desc.body<3>().sim.particle_radius;
    EXPECT_LT(deepest_over_run<3>(desc), kTolerance * r);
  }
}

TEST(MeshObstacle, ThreadCountsAgreeAndAResumedRunIsTheSame) {
  ThreadCount restore;
  TempDir tmp;
  const SceneDesc desc = dam_break_2d(kWedge, true, 0.3);
  std::vector<std::vector<double>> ends;
  for (const int threads : {1, 2}) {
    set_num_threads(threads);
    RunDriver<2, double> run(desc, RunSettings{});
    ASSERT_EQ(run.run().status, RunStatus::Completed);
    std::vector<double> x;
    for (const auto& p : run.simulation().particles().position) x.insert(x.end(), {p[0], p[1]});
    ends.push_back(x);
  }
  EXPECT_EQ(ends[0], ends[1]);
  test::expect_resume_gives_the_same_files<2>(desc, tmp.path(), 40, {"frames.pvd", "solids.pvd"});
}

}  // namespace
}  // namespace sph
