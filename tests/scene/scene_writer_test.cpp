// The scene writer: scene_to_json writes every key of the format, and the reader reads it back
// to an equal SceneDesc, every floating value bit for bit; and SceneDesc's one body.

#include <cstring>
#include <filesystem>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sph/scene/direction.h>
#include <sph/scene/scene_keys.h>
#include <sph/scene/scene_reader.h>
#include <sph/scene/scene_writer.h>

#include "support/expect.h"

namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

/// Every scene file of the repository the reader accepts: scenes/ and the fuzz seeds.
std::vector<fs::path> scene_files() {
  std::vector<fs::path> out;
  for (const char* dir : {"/scenes", "/tests/fuzz/seeds", "/tests/fuzz/regressions"})
    for (const auto& e : fs::recursive_directory_iterator(fs::path(SPH_SOURCE_DIR) / (dir + 1)))
      if (e.path().extension() == ".json") out.push_back(e.path());
  return out;
}

/// A 3D scene that gives every key a value other than its default.
json every_key_3d() {
  return json::parse(R"({
    "version": 1, "name": "every-key_3d", "description": "each key set, none to its default", "units": "SI",
    "dimension": 3,
    "Configuration": {
      "precision": "float", "timeStepSize": 1.25e-4, "numberOfSteps": 77, "particleRadius": 0.011,
      "kernelRadius": 0.0451, "gravitation": [0.1, -9.7, 0.3], "neighbors": "verlet", "fullRebuildPeriod": 7,
      "verletSkin": 0.0061, "reorderPeriod": 5, "outputEveryNSteps": 0, "outputFps": 333.3,
      "outputFormats": ["ply", "vtk"], "outputFields": ["id", "pressure"], "cflMethod": "cfl",
      "cflFactor": 0.35, "cflMinTimeStepSize": 2.5e-6, "cflMaxTimeStepSize": 0.0021
    },
    "Fluid": { "density0": 998.2, "stiffness": 1234.5, "viscosity": 0.7, "negativePressure": "allow",
               "pressureForce": "variational", "gradientCorrection": "renormalize", "particleMass": 0.0011 },
    "Container": { "start": [-0.1, 0.05, 0], "end": [0.9, 1.1, 0.7], "wallStiffness": 3.3e5, "wallDamping": 12.5 },
    "FluidBlocks": [ { "start": [0, 0.1, 0.05], "end": [0.2, 0.3, 0.25], "velocity": [0.5, -0.25, 0.125] },
                     { "start": [0.5, 0.6, 0.1], "end": [0.6, 0.7, 0.2] } ],
    "Obstacles": [ { "start": [0.3, 0.05, 0.3], "end": [0.4, 0.2, 0.4],
                     "motion": { "type": "rotation", "axis": [0, 0.6, 0.8], "center": [0.35, 0.1, 0.35],
                                 "angularVelocity": -1.5, "rampTime": 0.25 } },
                   { "start": [0.6, 0.3, 0.3], "end": [0.7, 0.35, 0.4], "dynamic": true, "density": 650,
                     "velocity": [0.1, -0.2, 0.3], "angularVelocity": [0.5, -0.25, 2] },
                   { "geometryFile": ")" SPH_SOURCE_DIR R"(/tests/data/meshes/cube.ply", "scale": [0.1, 0.2, 0.15],
                     "translation": [0.7, 0.6, 0.45], "rotationAxis": [1, 2, 3], "rotationAngle": 0.3 },
                   { "geometryFile": ")" SPH_SOURCE_DIR R"(/tests/data/meshes/cube.stl", "scale": [0.9, 1, 0.6],
                     "translation": [-0.1, 0.1, 0], "inverted": true } ],
    "Emitters": [ { "translation": [0.05, 0.8, 0.35], "direction": [1, -0.3, 0.1], "velocity": 4.5, "width": 3,
                    "height": 2, "emitEveryNSteps": 40, "maxParticles": 120, "emitStartTime": 0.001,
                    "emitEndTime": 0.5 } ]
  })");
}

/// Its 2D counterpart (2D emitters have no height).
json every_key_2d() {
  return json::parse(R"({
    "version": 1, "name": "every-key_2d", "description": "each key set, none to its default", "units": "SI",
    "dimension": 2,
    "Configuration": {
      "precision": "double", "timeStepSize": 1e-4, "numberOfSteps": 50, "particleRadius": 0.01,
      "kernelRadius": 0.033, "gravitation": [0, -9.81], "neighbors": "adaptive", "fullRebuildPeriod": 13,
      "verletSkin": 0.004, "reorderPeriod": 0, "outputEveryNSteps": 3, "outputFps": 0, "flagNearMovingBodies": false,
      "outputFormats": ["vtu", "ply", "vtk"], "outputFields": [], "boundaryHandling": "particles",
      "simulationMethod": "dfsph", "minIterations": 3, "maxIterations": 77, "maxError": 0.05,
      "enableDivergenceSolver": false, "maxIterationsV": 33, "maxErrorV": 2.5
    },
    "Fluid": { "density0": 1001, "stiffness": 2000, "viscosity": 0.01, "negativePressure": "clamp",
               "pressureForce": "symmetric", "gradientCorrection": "none", "particleMass": 0.1,
               "viscositySolver": "implicit", "viscosityMaxIterations": 17, "viscosityMaxError": 0.07 },
    "Container": { "start": [0, 0], "end": [1, 1], "wallStiffness": 1e5, "wallDamping": 0.5 },
    "FluidBlocks": [ { "start": [0, 0], "end": [0.2, 0.2], "velocity": [-0.3, 0.7] } ],
    "Obstacles": [ { "start": [0.5, 0], "end": [0.6, 0.1],
                     "motion": { "type": "oscillation", "direction": [3, 4], "amplitude": 0.02, "period": 0.7,
                                 "phase": 0.5, "rampTime": 0.1 } },
                   { "start": [0.7, 0], "end": [0.8, 0.3],
                     "motion": { "type": "keyframes", "center": [0.75, 0.1],
                                 "keys": [ { "time": 0.001, "translation": [0, 0], "rotation": 0 },
                                           { "time": 0.004, "translation": [0.05, 0.1], "rotation": 0.2 } ] } },
                   { "start": [0.85, 0.5], "end": [0.95, 0.55], "dynamic": true, "density": 700,
                     "velocity": [-0.5, 0.25], "angularVelocity": 1.5 },
                   { "polygon": [[0.3, 0.6], [0.6, 0.6], [0.5, 0.7], [0.6, 0.85], [0.3, 0.85]],
                     "motion": { "type": "rotation", "angularVelocity": 0.5 } },
                   { "polygon": [[-0.2, -0.2], [1.2, -0.2], [1.2, 1.2], [-0.2, 1.2]], "inverted": true } ],
    "Emitters": [ { "translation": [0.05, 0.5], "direction": [3, 7], "velocity": 20.0, "width": 4,
                    "emitEveryNSteps": 12, "maxParticles": 100, "emitStartTime": 0.25, "emitEndTime": 1e300 } ]
  })");
}

/// Reads `text`, writes it, reads that: the two SceneDescs are equal, and writing the second
/// gives the same text (so every floating value came back bit for bit, the sign of zero too).
void expect_round_trip(const std::string& text, const std::string& source) {
  SCOPED_TRACE(source);
  const sph::SceneDesc d = sph::parse_scene(text, source);
  const std::string written = sph::scene_text(d);
  const sph::SceneDesc again = sph::parse_scene(written, source);
  EXPECT_TRUE(again == d) << written;
  EXPECT_EQ(sph::scene_text(again), written);
  EXPECT_EQ(again.warnings, d.warnings);
}

/// The keys of `j`, an object.
std::set<std::string> keys_of(const json& j) {
  std::set<std::string> out;
  for (auto it = j.begin(); it != j.end(); ++it) out.insert(it.key());
  return out;
}
std::set<std::string> set_of(const std::vector<std::string>& v) { return {v.begin(), v.end()}; }

TEST(SceneWriter, EveryRepositorySceneReadsBackEqual) {
  const auto files = scene_files();
  ASSERT_GE(files.size(), 10u);
  for (const fs::path& f : files) expect_round_trip(sph::read_scene_text(f.string()), f.string());
}

TEST(SceneWriter, ASceneThatSetsEveryKeyReadsBackEqual) {
  for (const json& j : {every_key_2d(), every_key_3d()}) expect_round_trip(j.dump(), "every_key.json");
  // The 3D scene's values really are not the defaults (a reader that ignored a key would be caught).
  const sph::SceneDesc d = sph::parse_scene(every_key_3d().dump(), "every_key.json");
  const sph::SimulationParams<3> defaults;
  const auto& sim = d.body<3>().sim;
  EXPECT_NE(sim.fluid.pressure_force, defaults.fluid.pressure_force);
  EXPECT_NE(sim.fluid.gradient_correction, defaults.fluid.gradient_correction);
  EXPECT_NE(sim.reorder_period, sim.full_rebuild_period);
  EXPECT_EQ(d.output.fields, (std::vector<std::string>{"pressure", "id"}));
  EXPECT_EQ(sim.emitters.at(0).end_time, 0.5);
  EXPECT_EQ(sim.time_stepping, sph::TimeStepping::Cfl);
  EXPECT_NE(sim.cfl, defaults.cfl);
}

TEST(SceneWriter, ARunOfCflStepsToATimeWritesItsStopAt) {
  // CFL steps and stopAt: the run ends at that time (numberOfSteps is then only the most steps
  // the smallest step and the steps shortened to end on a barrier could take), so the writer
  // gives stopAt, and frames by time by default.
  json j = every_key_2d();
  j["Configuration"].erase("numberOfSteps");
  j["Configuration"].erase("outputEveryNSteps");
  j["Configuration"].erase("outputFps");
  j["Configuration"]["stopAt"] = 0.25;
  j["Configuration"]["cflMethod"] = "cfl";
  j["Configuration"]["cflMinTimeStepSize"] = 1e-5;
  expect_round_trip(j.dump(), "cfl_stop_at.json");
  const sph::SceneDesc d = sph::parse_scene(j.dump(), "cfl_stop_at.json");
  EXPECT_EQ(d.end_time, 0.25);
  EXPECT_EQ(d.steps, 25000 + 2 * (100 + 1)) << "stopAt / cflMinTimeStepSize, and two for each frame's time and the end";
  EXPECT_EQ(d.output.fps, 400.0) << "100 frames by default";
  EXPECT_EQ(d.output.every_steps, 0);
  const json w = json::parse(sph::scene_text(d));
  EXPECT_EQ(w["Configuration"]["stopAt"], 0.25);
  EXPECT_FALSE(w["Configuration"].contains("numberOfSteps"));
  // Fixed steps: stopAt is still turned into steps, and written as numberOfSteps.
  j["Configuration"]["cflMethod"] = "none";
  const sph::SceneDesc fixed = sph::parse_scene(j.dump(), "fixed_stop_at.json");
  EXPECT_EQ(fixed.end_time, 0.0);
  EXPECT_EQ(fixed.steps, 2500);
}

TEST(SceneWriter, WritesEveryDeclaredKeyOfEveryObject) {
  for (const json& j : {every_key_2d(), every_key_3d()}) {
    const sph::SceneDesc d = sph::parse_scene(j.dump(), "every_key.json");
    const json w = json::parse(sph::scene_text(d));
    EXPECT_EQ(keys_of(w), set_of(sph::detail::kRootKeys));
    // Every Configuration key but stopAt, which the writer gives as the numberOfSteps it means.
    std::set<std::string> configuration = set_of(sph::detail::kConfigurationKeys);
    for (const std::string& k : sph::detail::kWriterResolvedKeys) EXPECT_EQ(configuration.erase(k), 1u) << k;
    EXPECT_EQ(keys_of(w["Configuration"]), configuration);
    EXPECT_EQ(keys_of(w["Fluid"]), set_of(sph::detail::kFluidKeys));
    EXPECT_EQ(keys_of(w["Container"]), set_of(sph::detail::kContainerKeys));
    EXPECT_EQ(keys_of(w["FluidBlocks"][0]), set_of(sph::detail::kFluidBlockKeys));
    // Every obstacle key among the obstacles: a floating body's own keys only on the floating one.
    std::set<std::string> obstacle_keys;
    for (const json& o : w["Obstacles"]) {
      const std::set<std::string> keys = keys_of(o);
      obstacle_keys.insert(keys.begin(), keys.end());
      EXPECT_EQ(keys.count("density"), o["dynamic"].get<bool>() ? 1u : 0u);
    }
    // (a 2D obstacle has no mesh keys, a 3D one no polygon)
    std::set<std::string> expected = set_of(sph::detail::kObstacleKeys);
    if (d.dimension == 2)
      for (const char* k : {"geometryFile", "translation", "rotationAxis", "rotationAngle", "scale"}) expected.erase(k);
    else
      expected.erase("polygon");
    EXPECT_EQ(obstacle_keys, expected);
    for (const json& o : w["Obstacles"]) {  // each motion with every key of its type
      const sph::MotionType type =
          sph::detail::value_named(sph::detail::kMotionTypeNames, o["motion"]["type"].get<std::string>());
      EXPECT_EQ(keys_of(o["motion"]), set_of(sph::detail::motion_keys(type, d.dimension)));
      if (type == sph::MotionType::Keyframes) {
        EXPECT_EQ(keys_of(o["motion"]["keys"][0]), set_of(sph::detail::kMotionKeyKeys));
      }
    }
    EXPECT_EQ(keys_of(w["Emitters"][0]), set_of(sph::detail::emitter_keys(d.dimension)));
  }
}

TEST(SceneWriter, WritesTheDefaultsTheReaderFilledIn) {
  const json j = json::parse(R"({
    "version": 1, "dimension": 2,
    "Configuration": { "timeStepSize": 1e-4, "numberOfSteps": 1000, "particleRadius": 0.01 },
    "Fluid": { "stiffness": 1000 },
    "Container": { "start": [0, 0], "end": [1, 1], "wallStiffness": 1e5 },
    "Emitters": [ { "translation": [0.05, 0.5], "direction": [2, 0], "velocity": 20.0, "width": 4,
                    "maxParticles": 100 } ]
  })");
  const sph::SceneDesc d = sph::parse_scene(j.dump(), "defaults.json");
  const json w = json::parse(sph::scene_text(d));
  EXPECT_EQ(w["name"], "scene");
  EXPECT_EQ(w["Configuration"]["kernelRadius"], 0.04);
  EXPECT_EQ(w["Configuration"]["outputEveryNSteps"], 10) << "numberOfSteps / 100";
  EXPECT_EQ(w["Configuration"]["reorderPeriod"], 200);
  EXPECT_EQ(w["Configuration"]["outputFields"],
            json(std::vector<std::string>(std::begin(sph::kFrameFieldNames), std::end(sph::kFrameFieldNames))));
  EXPECT_EQ(w["Fluid"]["particleMass"], d.body<2>().sim.particle_mass);
  EXPECT_EQ(w["Emitters"][0]["direction"], json({1.0, 0.0})) << "normalized";
  EXPECT_FALSE(w["Emitters"][0].contains("emitEndTime")) << "JSON has no infinity; absent is never";
  EXPECT_EQ(w["Emitters"][0]["emitStartTime"], 0.0);
}

TEST(SceneWriter, OverridesAreInTheWrittenScene) {
  const json j = every_key_2d();
  const sph::SceneDesc d =
      sph::parse_scene(j.dump(), "every_key.json", {"Fluid.stiffness=2500", "Configuration.neighbors=verlet"});
  const json w = json::parse(sph::scene_text(d));
  EXPECT_EQ(w["Fluid"]["stiffness"], 2500);
  EXPECT_EQ(w["Configuration"]["neighbors"], "verlet");
  // A setting changed on the struct is what is written (no text to drift from it).
  sph::SceneDesc e = d;
  e.set_neighbors(sph::NeighborMode::Standard);
  EXPECT_EQ(json::parse(sph::scene_text(e))["Configuration"]["neighbors"], "standard");
}

template <int D>
bool same_bits(const sph::Vec<D, double>& a, const sph::Vec<D, double>& b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

template <int D>
void check_directions(int count) {
  std::mt19937_64 rng(D);
  std::uniform_real_distribution<double> u(-1, 1);
  int not_fixed = 0;
  for (int i = 0; i < count; ++i) {
    sph::Vec<D, double> v;
    for (int d = 0; d < D; ++d) v[d] = i % 7 == 0 && d == 1 ? 0.0 : u(rng) * (i % 3 == 0 ? 1e-150 : 1.0);
    const auto unit = sph::detail::unit_direction<D>(v);
    ASSERT_TRUE(unit);
    if (!same_bits<D>(*sph::detail::unit_direction<D>(*unit), *unit)) ++not_fixed;
    const auto back = sph::detail::unit_direction<D>(sph::detail::direction_giving<D>(*unit));
    ASSERT_TRUE(back);
    ASSERT_TRUE(same_bits<D>(*back, *unit)) << "direction " << i;
  }
  // The reason for direction_giving: writing the unit vector itself would not do.
  EXPECT_GT(not_fixed, count / 100);
}

TEST(SceneWriter, EveryUnitDirectionHasADirectionThatReadsBackToIt) {
  check_directions<2>(100000);
  check_directions<3>(100000);
  EXPECT_FALSE(sph::detail::unit_direction<3>({}));
}

TEST(SceneWriter, ADirectionThatDoesNotNormalizeToItselfReadsBackEqual) {
  // Directions whose unit vector is not a fixed point of the reader's normalization.
  json j = every_key_3d();
  int tried = 0;
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int found = 0; found < 5 && tried < 10000; ++tried) {
    const sph::Vec<3, double> v{{u(rng), u(rng), u(rng)}};
    const auto unit = *sph::detail::unit_direction<3>(v);
    if (*sph::detail::unit_direction<3>(unit) == unit) continue;
    ++found;
    j["Emitters"][0]["direction"] = {v[0], v[1], v[2]};
    expect_round_trip(j.dump(), "direction.json");
  }
  EXPECT_LT(tried, 10000);
}

// ---------------------------------------------------------------------------------------------
// SceneDesc holds one body, of its dimension.

TEST(SceneDescBody, OnlyTheScenesDimensionHasABody) {
  sph::SceneDesc d = sph::parse_scene(every_key_2d().dump(), "every_key.json");
  EXPECT_EQ(d.dimension, 2);
  EXPECT_EQ(d.body<2>().sim.full_rebuild_period, 13);
  EXPECT_THROW((void)d.body<3>(), std::logic_error);
  d.set_body<3>();
  EXPECT_EQ(d.dimension, 3);
  EXPECT_TRUE(d.body<3>().blocks.empty());
  EXPECT_THROW((void)d.body<2>(), std::logic_error);
  // A dimension set by hand without a body of that dimension is caught, not read as the other.
  d.dimension = 2;
  EXPECT_THROW((void)d.body<2>(), std::logic_error);
  EXPECT_THROW(d.set_audit(true), std::logic_error);
}

TEST(SceneDescBody, SettingsOfAnyDimensionReachTheBody) {
  for (const json& j : {every_key_2d(), every_key_3d()}) {
    sph::SceneDesc d = sph::parse_scene(j.dump(), "every_key.json");
    d.set_audit(true);
    d.set_neighbors(sph::NeighborMode::BruteForce);
    const int dim = d.visit_body([]<int D>(sph::SceneBody<D>& b) {
      EXPECT_TRUE(b.sim.audit);
      EXPECT_EQ(b.sim.neighbors, sph::NeighborMode::BruteForce);
      return D;
    });
    EXPECT_EQ(dim, d.dimension);
  }
}

TEST(SceneDescBody, EqualityComparesTheBody) {
  const sph::SceneDesc a = sph::parse_scene(every_key_3d().dump(), "every_key.json");
  sph::SceneDesc b = a;
  EXPECT_TRUE(a == b);
  b.body<3>().sim.emitters.at(0).direction[2] = -b.body<3>().sim.emitters.at(0).direction[2];
  EXPECT_FALSE(a == b);
  b = a;
  b.set_audit(true);
  EXPECT_FALSE(a == b);
}

}  // namespace
