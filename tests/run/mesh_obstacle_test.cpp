// Obstacles of any shape (Obstacles[].polygon in 2D, Obstacles[].geometryFile in 3D): a dam break
// flows around them and no particle gets inside them (their signed distance, checked as the run
// goes), with boundary particles and with penalty springs; a turning polygon stirs without letting
// fluid in; a closed surface holds the fluid inside it (inverted); fluid blocks lose the particles
// in a shape, and say so; a polygon and a mesh float as Archimedes and the box they are say; runs
// are the same for any thread count and resume bit for bit.

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
#include "support/thread_count.h"

namespace sph {
namespace {

using test::deepest_inside;
using test::TempDir;

using test::ThreadCount;

/// The fluid's viscosity: DFSPH's scenes' 1 Pa s (Eq. 6); WCSPH with penalty walls keeps the default
/// (Monaghan's artificial viscosity), which damps its pressure waves.
constexpr const char* kViscosity[2] = {"", R"(, "viscosity": 1.0)"};

/// The Configuration keys of each way to meet solids: boundary particles with DFSPH and CFL steps,
/// or penalty springs with WCSPH and the "auto" step.
std::string boundary_method(bool particles) {
  return particles ? R"("boundaryHandling": "particles", "kernel": "cubic", "simulationMethod": "dfsph",
                        "cflMaxTimeStepSize": 0.005)"
                   : R"("boundaryHandling": "penalty")";
}

/// A 2D dam break (a column 0.3 m x 0.4 m, spacing 2 cm) onto `obstacle` (an Obstacles entry), with
/// boundary particles and DFSPH, or penalty springs and WCSPH.
SceneDesc dam_break_2d(const std::string& obstacle, bool particles, double stop = 1.0) {
  const std::string method = boundary_method(particles);
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
    const std::string method = boundary_method(particles);
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
    const std::string method = boundary_method(particles);
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

TEST(MeshObstacle, TheBoulderExampleKeepsEveryParticleOutOfTheBoulder) {
  // scenes/examples/dam_break_boulder_3d.json through the water's impact on the boulder (its first
  // 0.6 s), every 5 steps: no particle centre deeper in the mesh than the tolerance.
  const SceneDesc desc =
      read_scene_file(SPH_SOURCE_DIR "/scenes/examples/dam_break_boulder_3d.json", {"Configuration.stopAt=0.6"});
  ASSERT_EQ(desc.body<3>().sim.shapes.size(), 1u);
  EXPECT_LT(deepest_over_run<3>(desc), kTolerance * desc.body<3>().sim.particle_radius);
}

TEST(MeshObstacle, AFloatingDiamondOfHalfTheWatersDensityFloatsHalfIn) {
  // A square turned 45 degrees (a polygon), density 500, its centre on the water's surface: half
  // its area under water, as Archimedes has it, and a square log of half the water's density
  // floats corner down. The water is one block; the particles in the square are left out.
  const SceneDesc desc = parse_scene(R"({
    "version": 1, "name": "diamond", "dimension": 2,
    "Configuration": { "precision": "double", "stopAt": 2.0, "particleRadius": 0.01, "kernelRadius": 0.04,
      "gravitation": [0, -9.81], "outputFps": 10, "boundaryHandling": "particles", "kernel": "cubic",
      "simulationMethod": "dfsph", "cflMaxTimeStepSize": 0.005 },
    "Fluid": { "density0": 1000, "viscosity": 1.0 },
    "Container": { "start": [0, 0], "end": [1.2, 0.6] },
    "FluidBlocks": [ { "start": [0, 0], "end": [1.2, 0.3] } ],
    "Obstacles": [ { "polygon": [[0.6, 0.2], [0.7, 0.3], [0.6, 0.4], [0.5, 0.3]], "dynamic": true,
                     "density": 500 } ]
  })",
                                     "diamond.json");
  RunDriver<2, double> run(desc, RunSettings{});
  const Simulation<2, double>& sim = run.simulation();
  double sum = 0, tilt = 0, mean_tilt = 0, level = 0, deepest = -1e300;
  int count = 0;
  RunCallbacks each;
  each.progress = [&](std::int64_t step, std::size_t) {
    if (step % 5 == 0) deepest = std::max(deepest, deepest_inside(sim));
    if (sim.time() < 1.0) return;
    const RigidBodyState<2>& b = sim.bodies().at(0);
    sum += b.position[1];
    const double angle = std::abs(2 * std::asin(b.orientation[3]));
    tilt = std::max(tilt, angle);
    mean_tilt += angle;
    // The free surface away from the body: the highest particle more than 0.3 m from it, plus a radius.
    double top = 0;
    for (const auto& x : sim.particles().position)
      if (std::abs(x[0] - b.position[0]) > 0.3) top = std::max(top, x[1] + 0.01);
    level += top;
    ++count;
  };
  const RunResult r = run.run(each);
  ASSERT_EQ(r.status, RunStatus::Completed) << r.message;
  EXPECT_TRUE(r.warnings.empty()) << (r.warnings.empty() ? "" : r.warnings[0]);
  ASSERT_GT(count, 0);
  // Its centre (its centroid, from the polygon) within 5 % of its 0.1 m half-diagonal of the
  // surface; still corner down, rocking in the waves the start makes (by less than a quarter of
  // the 45 degrees that would lay it on a face); no particle inside it past the tolerance.
  EXPECT_NEAR(sum / count, level / count, 0.005);
  EXPECT_LT(mean_tilt / count, 0.1);
  EXPECT_LT(tilt, 0.2);
  EXPECT_LT(deepest, kTolerance * 0.01);
}

TEST(MeshObstacle, AFloatingMeshBoxMovesAsTheSameBox) {
  // A box of density 500 dropped from above the water, as a box and as a mesh of a box: the same
  // mass, centre and inertia (from the mesh) and the same coupling, so the same fall and float.
  const auto settle = [](const std::string& obstacle) {
    const SceneDesc desc = parse_scene(fmt::format(R"({{
      "version": 1, "name": "float3d", "dimension": 3,
      "Configuration": {{ "precision": "double", "stopAt": 0.8, "particleRadius": 0.02, "kernelRadius": 0.08,
        "gravitation": [0, -9.81, 0], "outputFps": 10, "boundaryHandling": "particles", "kernel": "cubic",
        "simulationMethod": "dfsph", "cflMaxTimeStepSize": 0.005 }},
      "Fluid": {{ "density0": 1000, "viscosity": 1.0 }},
      "Container": {{ "start": [0, 0, 0], "end": [0.4, 0.4, 0.4] }},
      "FluidBlocks": [ {{ "start": [0, 0, 0], "end": [0.4, 0.16, 0.4] }} ],
      "Obstacles": [ {} ]
    }})",
                                                   obstacle),
                                       "float3d.json");
    RunDriver<3, double> run(desc, RunSettings{});
    const RunResult r = run.run();
    EXPECT_EQ(r.status, RunStatus::Completed) << r.message;
    EXPECT_TRUE(r.warnings.empty()) << (r.warnings.empty() ? "" : r.warnings[0]);
    return run.simulation().bodies().at(0).position;
  };
  const Vec<3, double> box = settle(R"({ "start": [0.1, 0.2, 0.1], "end": [0.3, 0.28, 0.3], "dynamic": true,
                                         "density": 500 })");
  const Vec<3, double> mesh = settle(fmt::format(R"({{ "geometryFile": "{}", "scale": [0.2, 0.08, 0.2],
      "translation": [0.1, 0.2, 0.1], "dynamic": true, "density": 500 }})",
                                                 SPH_SOURCE_DIR "/tests/data/meshes/cube.stl"));
  // Fallen onto the water and floating (not at its start, not through the floor)...
  EXPECT_LT(box[1], 0.2);
  EXPECT_GT(box[1], 0.1);
  // ...and the mesh where the box is, within a tenth of a spacing.
  for (int d = 0; d < 3; ++d) EXPECT_NEAR(mesh[d], box[d], 0.004) << d;
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
