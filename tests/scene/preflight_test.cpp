// The preflight (scene/preflight.h): each whole-scene check refuses or warns on its side of its
// threshold and stays quiet on the other, with the advice it computes; and the refused scenes
// of the physics corpus (tests/app/trust/, verdict refused) are refused with their messages.

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <typeinfo>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sph/core/error.h>
#include <sph/scene/builders.h>
#include <sph/scene/preflight.h>
#include <sph/scene/preflight_geometry.h>
#include <sph/scene/scene_reader.h>
#include <sph/solver/wcsph.h>

#include "support/expect.h"
#include "support/scene_text.h"

namespace {

using sph::test::error_of;
using sph::test::parse;

using json = nlohmann::json;
namespace fs = std::filesystem;

/// A small valid 2D scene (spacing 0.02 m, 10 steps of 1e-4 s) that draws no warning.
json base_scene() {
  return json::parse(R"({
    "version": 1, "name": "t", "dimension": 2,
    "Configuration": { "timeStepSize": 1e-4, "numberOfSteps": 10, "particleRadius": 0.01, "kernelRadius": 0.04 },
    "Fluid": { "stiffness": 1000 },
    "Container": { "start": [0, 0], "end": [1, 1], "wallStiffness": 1e5 },
    "FluidBlocks": [ { "start": [0, 0], "end": [0.2, 0.2] } ]
  })");
}

/// The base scene with one 2D emitter: 4 particles across y at x = 0.05, emitting along +x.
json emitter_scene() {
  json j = base_scene();
  j["FluidBlocks"][0] = json::parse(R"({ "start": [0.6, 0], "end": [0.8, 0.2] })");
  // Walls that stop the 20 m/s jet within two radii (softer ones draw the defaults' warning).
  j["Container"]["wallStiffness"] = 2e6;
  j["Container"]["wallDamping"] = 500;
  j["Emitters"] = json::parse(
      R"([ { "translation": [0.05, 0.5], "direction": [1, 0], "velocity": 20.0, "width": 4, "maxParticles": 4 } ])");
  return j;
}

/// A 3D scene with a 6 x 6 nozzle (tank_fill_3d's, in a smaller box).
json emitter_scene_3d() {
  return json::parse(R"({
    "version": 1, "name": "t3", "dimension": 3,
    "Configuration": { "timeStepSize": 3e-4, "numberOfSteps": 20, "particleRadius": 0.01 },
    "Fluid": { "stiffness": 2000, "viscosity": 3 },
    "Container": { "start": [0, 0, 0], "end": [0.6, 0.6, 0.6], "wallStiffness": 2e5, "wallDamping": 300 },
    "Emitters": [ { "translation": [0.05, 0.4, 0.3], "direction": [1, 0, 0], "velocity": 4.5, "width": 6,
                    "height": 6, "maxParticles": 72 } ]
  })");
}

/// The scene's warnings, joined one per line ("" if none); a test failure if it is refused.
std::string warnings_of(const json& j, const std::vector<std::string>& overrides = {}) {
  std::string all;
  try {
    for (const auto& w : parse(j, overrides).warnings) all += w + "\n";
  } catch (const sph::Error& e) {
    ADD_FAILURE() << "refused: " << e.what();
  }
  return all;
}

// ---------------------------------------------------------------------------------------------
// Overlapping fluid blocks

TEST(Preflight, LatticeGapIsTheClosestPairOfTheTwoBlocksParticles) {
  const double dx = 0.02;
  using B = sph::Box<2>;
  // Sharing a face: the two nearest columns are a spacing apart.
  EXPECT_NEAR(sph::detail::lattice_gap<2>(B{{0, 0}, {0.2, 0.2}}, B{{0.2, 0}, {0.4, 0.2}}, dx), dx, 1e-12);
  // The same box twice: coincident particles.
  EXPECT_NEAR(sph::detail::lattice_gap<2>(B{{0, 0}, {0.2, 0.2}}, B{{0, 0}, {0.2, 0.2}}, dx), 0, 1e-12);
  // Shifted by a quarter spacing in x and y.
  EXPECT_NEAR(sph::detail::lattice_gap<2>(B{{0, 0}, {0.2, 0.2}}, B{{0.105, 0.105}, {0.3, 0.3}}, dx),
              std::sqrt(2.0) * 0.005, 1e-12);
  // Far apart in y: the gap is between the facing rows.
  EXPECT_NEAR(sph::detail::lattice_gap<2>(B{{0, 0}, {0.2, 0.2}}, B{{0, 0.5}, {0.2, 0.7}}, dx), 0.32, 1e-12);
}

TEST(Preflight, OverlappingBlocksAreRefusedNamingBothTheBoxAndWhereToEnd) {
  json j = base_scene();
  j["FluidBlocks"].push_back(json::parse(R"({ "start": [0.1, 0.1], "end": [0.3, 0.3] })"));
  const std::string m = error_of(j);
  EXPECT_CONTAINS(m, "FluidBlocks[1]");
  EXPECT_CONTAINS(m, "overlaps FluidBlocks[0]");
  EXPECT_CONTAINS(m, "in [0.1, 0.1] .. [0.2, 0.2]");
  EXPECT_CONTAINS(m, "shrink FluidBlocks[1] to start where FluidBlocks[0] ends along x: \"start\": [0.2, 0.1]");
}

TEST(Preflight, BlocksSharingAFaceOrOverlappingLessThanTheirLatticesAreAccepted) {
  json j = base_scene();
  j["FluidBlocks"].push_back(json::parse(R"({ "start": [0.2, 0], "end": [0.4, 0.2] })"));
  EXPECT_EQ(warnings_of(j), "");
  // The first block's box reaches 0.21 but its last column is at 0.19: the second's first
  // column at 0.205 is 0.015 m (3/4 spacing) from it.
  j["FluidBlocks"][0]["end"] = json::array({0.21, 0.2});
  j["FluidBlocks"][1]["start"] = json::array({0.195, 0});
  EXPECT_EQ(warnings_of(j), "");
  // At 0.185 the second's first column is 0.005 m (1/4 spacing) from the first's last: refused.
  j["FluidBlocks"][1]["start"] = json::array({0.185, 0});
  EXPECT_CONTAINS(error_of(j), "overlaps FluidBlocks[0]");
}

TEST(Preflight, TheSameBlockTwiceIsRefusedWithRemoveOne) {
  json j = base_scene();
  j["FluidBlocks"].push_back(j["FluidBlocks"][0]);
  const std::string m = error_of(j);
  EXPECT_CONTAINS(m, "0 m apart");
  EXPECT_CONTAINS(m, "remove FluidBlocks[0] or FluidBlocks[1]");
}

TEST(Preflight, ABlockInAnObstacleIsRefusedWhenReadWithWhereToEnd) {
  json j = base_scene();
  j["Obstacles"] = json::parse(R"([ { "start": [0.15, 0], "end": [0.3, 0.1] } ])");
  const std::string m = error_of(j);  // read_scene refuses it, not only build_particles
  EXPECT_CONTAINS(m, "FluidBlocks[0]");
  EXPECT_CONTAINS(m, "overlaps Obstacles[0]");
  EXPECT_CONTAINS(m, "shrink FluidBlocks[0] to end where Obstacles[0] starts along x: \"end\": [0.15, 0.2]");
  // Touching it (its particles a radius from the obstacle's face) is accepted.
  j["Obstacles"][0]["start"] = json::array({0.2, 0});
  EXPECT_EQ(warnings_of(j), "");
}

// ---------------------------------------------------------------------------------------------
// Nozzles

TEST(Preflight, ANozzleParticleCloserThanARadiusToTheWallIsRefusedWithWhereToMoveIt) {
  json j = emitter_scene();
  j["Emitters"][0]["translation"] = json::array({0.05, 0.96});  // top particle at 0.99: a radius inside
  EXPECT_EQ(warnings_of(j), "");
  j["Emitters"][0]["translation"] = json::array({0.05, 0.97});  // top particle at 1.0: on the wall
  const std::string m = error_of(j);
  EXPECT_CONTAINS(m, "Emitters[0]");
  EXPECT_CONTAINS(m, "corner particle 3 (of 4), at [0.05, 1]");
  EXPECT_CONTAINS(m, "0.01 m too close to or outside the container");
  EXPECT_CONTAINS(m, "\"translation\": [0.05, 0.96]");
  // Its centre a half radius from the side wall (the centre alone was checked before).
  j["Emitters"][0]["translation"] = json::array({0.005, 0.5});
  EXPECT_CONTAINS(error_of(j), "\"translation\": [0.01, 0.5]");
}

TEST(Preflight, A3dNozzleNamesItsCornerAndANozzleWiderThanTheContainerIsToldToNarrow) {
  json j = emitter_scene_3d();
  EXPECT_EQ(warnings_of(j), "");
  j["Emitters"][0]["translation"] = json::array({0.05, 0.55, 0.3});  // rows up to y = 0.6
  const std::string m = error_of(j);
  EXPECT_CONTAINS(m, "(of 6 x 6), at");
  EXPECT_CONTAINS(m, "\"translation\": [0.05, 0.54, 0.3]");
  j["Emitters"][0]["translation"] = json::array({0.05, 0.3, 0.3});
  j["Emitters"][0]["width"] = 31;  // 0.6 m across, in 0.6 - 2 radii of room
  EXPECT_CONTAINS(error_of(j), "make it narrower");
}

TEST(Preflight, ANozzleInOrAgainstAnObstacleIsRefused) {
  json j = emitter_scene();
  // Nozzle particles at y = 0.47 .. 0.53: an obstacle up to 0.455 is more than a radius away.
  j["Obstacles"] = json::parse(R"([ { "start": [0.02, 0.3], "end": [0.2, 0.455] } ])");
  EXPECT_EQ(warnings_of(j), "");
  j["Obstacles"][0]["end"] = json::array({0.2, 0.465});
  const std::string m = error_of(j);
  EXPECT_CONTAINS(m, "Emitters[0]");
  EXPECT_CONTAINS(m, "particle 0 (of 4), at [0.05, 0.47], is inside Obstacles[0]");
}

TEST(Preflight, ANozzleInTheInitialFluidIsRefused) {
  json j = emitter_scene();
  j["FluidBlocks"][0] = json::parse(R"({ "start": [0, 0.4], "end": [0.2, 0.6] })");
  const std::string m = error_of(j);
  EXPECT_CONTAINS(m, "is in the fluid of FluidBlocks[0]");
  EXPECT_CONTAINS(m, "move \"translation\" out of the fluid");
}

TEST(Preflight, AnObstacleOrBlockRightInFrontOfTheNozzleIsAWarning) {
  json j = emitter_scene();
  j["Obstacles"] = json::parse(R"([ { "start": [0.1, 0.4], "end": [0.2, 0.6] } ])");  // 0.05 m ahead
  const std::string w = warnings_of(j);
  EXPECT_CONTAINS(w, "Emitters[0]: Obstacles[0]");
  EXPECT_CONTAINS(w, "in front of the nozzle");
  j["Obstacles"][0]["start"] = json::array({0.15, 0.4});  // 0.1 m ahead: more than 4 spacings less a radius
  EXPECT_EQ(warnings_of(j), "");
  j.erase("Obstacles");
  j["FluidBlocks"][0] = json::parse(R"({ "start": [0.1, 0.4], "end": [0.2, 0.6] })");
  EXPECT_CONTAINS(warnings_of(j), "Emitters[0]: the fluid of FluidBlocks[0]");
}

// ---------------------------------------------------------------------------------------------
// Emitter windows

TEST(Preflight, AnEmitterEndingBeforeItStartsIsRefused) {
  json j = emitter_scene();
  j["Emitters"][0]["emitStartTime"] = 5e-4;
  j["Emitters"][0]["emitEndTime"] = 5e-4;
  const std::string m = error_of(j);
  EXPECT_CONTAINS(m, "Emitters[0].emitEndTime");
  EXPECT_CONTAINS(m, "not after emitStartTime");
  j["Emitters"][0]["emitEndTime"] = 6e-4;
  EXPECT_EQ(warnings_of(j), "");
}

TEST(Preflight, AnEmitterStartingAfterTheRunIsAWarningWithTheStepsItNeeds) {
  json j = emitter_scene();
  j["Emitters"][0]["emitStartTime"] = 2e-3;  // the run ends at 1e-3 s
  const std::string w = warnings_of(j);
  EXPECT_CONTAINS(w, "Emitters[0]: the emitter never emits");
  EXPECT_CONTAINS(w, "emitStartTime = 0.002 s is after the run's end at 0.001 s");
  EXPECT_CONTAINS(w, "raise numberOfSteps to at least 21");
  j["Emitters"][0]["emitStartTime"] = 1e300;  // more steps away than a scene may have
  EXPECT_CONTAINS(warnings_of(j), "start it earlier (numberOfSteps is at most 1e+12)");
  j["Emitters"][0]["emitStartTime"] = 5e-4;
  EXPECT_EQ(warnings_of(j), "");
}

TEST(Preflight, ABudgetItsWindowCannotEmitIsAWarningSayingHowManyWillBe) {
  json j = emitter_scene();
  j["Emitters"][0]["maxParticles"] = 100;  // 25 batches of 4, 16 steps apart: 384 steps
  // A run that ends first (one batch in 10 steps) is shortened on purpose: no warning.
  EXPECT_EQ(warnings_of(j), "");
  // A window that closes first (7 batches before 0.01 s) is named, with the end that would do.
  j["Emitters"][0]["emitEndTime"] = 0.01;
  const std::string w = warnings_of(j);
  EXPECT_CONTAINS(w,
                  "Emitters[0]: only 28 of its maxParticles = 100 particles are emitted before emitEndTime = "
                  "0.01 s; to emit them all, raise emitEndTime to at least 0.03845 s (or lower maxParticles to "
                  "28)");
  // The same warnings whether numberOfSteps comes from the file or a flag (a checkpoint's scene
  // reads back to the same SceneDesc).
  EXPECT_EQ(warnings_of(j, {"Configuration.numberOfSteps=10"}), w);
  EXPECT_EQ(warnings_of(j, {"Configuration.numberOfSteps=5000"}), w);
  j["Emitters"][0]["emitEndTime"] = 0.03845;
  EXPECT_EQ(warnings_of(j), "");
}

TEST(Preflight, AWindowBetweenTwoStepsNeverEmits) {
  json j = emitter_scene();
  j["Emitters"][0]["emitStartTime"] = 2.6e-4;  // the first step reaching it (less half a step) is step 3,
  j["Emitters"][0]["emitEndTime"] = 2.8e-4;    // at 3e-4 s: past the end
  EXPECT_CONTAINS(warnings_of(j),
                  "no step of the run falls between emitStartTime = 0.00026 s and emitEndTime = "
                  "0.00028 s; raise emitEndTime to at least 0.00035 s");
}

TEST(Preflight, EmittedInRunCountsWhatTheSimulationEmits) {
  json j = emitter_scene();
  j["Configuration"]["numberOfSteps"] = 200;
  j["FluidBlocks"][0] = json::parse(R"({ "start": [0.8, 0.8], "end": [0.84, 0.84] })");  // 4 particles
  struct Case {
    int max_particles, every;
    double start, end;
  };
  const std::vector<Case> cases = {{1000, 16, 0, 1},          {1000, 16, 0.00149, 1}, {1000, 16, 0.0015, 1},
                                   {1000, 20, 0.001, 0.0121}, {10, 16, 0, 1},         {1000, 11, 0.00234, 0.0099},
                                   {1000, 16, 0.03, 1}};
  for (const Case& c : cases) {
    j["Emitters"][0]["maxParticles"] = c.max_particles;
    j["Emitters"][0]["emitEveryNSteps"] = c.every;
    j["Emitters"][0]["emitStartTime"] = c.start;
    j["Emitters"][0]["emitEndTime"] = c.end;
    const sph::SceneDesc d = parse(j);
    auto sim = sph::make_simulation<2, double>(d);
    for (int s = 0; s < 200; ++s) sim.step();
    const auto expected = sph::detail::emitted_in_run<2>(d.body<2>().sim.emitters[0], 200, 1e-4);
    EXPECT_EQ(static_cast<std::int64_t>(sim.particles().size()) - 4, expected) << j["Emitters"][0].dump();
  }
}

// ---------------------------------------------------------------------------------------------
// Obstacles

TEST(Preflight, AnObstacleOutsideTheContainerIsRefusedSayingWhollyOrPartly) {
  json j = base_scene();
  j["Obstacles"] = json::parse(R"([ { "start": [2, 2], "end": [3, 3] } ])");
  EXPECT_CONTAINS(error_of(j), "Obstacles[0]: the obstacle [2, 2] .. [3, 3] lies wholly outside the container");
  j["Obstacles"][0] = json::parse(R"({ "start": [0.9, 0], "end": [1.1, 0.1] })");
  const std::string m = error_of(j);
  EXPECT_CONTAINS(m, "is partly outside the container");
  EXPECT_CONTAINS(m, "clip it to [0.9, 0] .. [1, 0.1]");
  j["Obstacles"][0]["end"] = json::array({1, 0.1});
  EXPECT_EQ(warnings_of(j), "");
}

TEST(Preflight, ObstaclesCoveringTheContainerAreRefused) {
  json j = base_scene();
  j["Obstacles"] = json::parse(R"([ { "start": [0, 0], "end": [1, 0.6] }, { "start": [0, 0.5], "end": [1, 1] } ])");
  EXPECT_CONTAINS(error_of(j), "the 2 obstacles cover the whole container");
  EXPECT_NEAR(sph::detail::free_volume<2>(sph::Box<2>{{0, 0}, {1, 1}},
                                          {sph::Box<2>{{0, 0}, {1, 0.6}}, sph::Box<2>{{0, 0.5}, {1, 0.9}}}),
              0.1, 1e-12);
}

TEST(Preflight, FreeVolumeIsExactForFewObstaclesAndNeverBelowTheTruthForMany) {
  const sph::Box<2> box{{0, 0}, {1, 1}};
  auto strips = [](int n) {
    std::vector<sph::Box<2>> s;
    for (int i = 0; i < n; ++i) s.push_back(sph::Box<2>{{i / double(n), 0}, {(i + 1) / double(n), 1}});
    return s;
  };
  EXPECT_NEAR(sph::detail::free_volume<2>(box, strips(10)), 0, 1e-12);  // exact: the strips cover the box
  // 200 strips: past the exact computation's size, the box less its largest obstacle (an upper bound).
  EXPECT_NEAR(sph::detail::free_volume<2>(box, strips(200)), 1 - 1 / 200.0, 1e-12);
}

TEST(Preflight, EmittersOverfillingTheRoomObstaclesLeaveAreRefused) {
  json j = emitter_scene();
  j.erase("FluidBlocks");
  j["Configuration"]["numberOfSteps"] = 2000;
  j["Obstacles"] = json::parse(R"([ { "start": [0, 0], "end": [1, 0.96] } ])");  // 0.04 m^2: 100 particles
  j["Emitters"][0] = json::parse(R"({ "translation": [0.05, 0.98], "direction": [1, 0], "velocity": 20.0,
                                      "width": 1, "maxParticles": 100 })");
  EXPECT_EQ(warnings_of(j), "");
  j["Emitters"][0]["maxParticles"] = 110;
  const std::string m = error_of(j);
  EXPECT_CONTAINS(m, "Emitters: the 0 particles of the fluid blocks and the 110 the emitters add");
  EXPECT_CONTAINS(m, "lower the emitters' maxParticles to at most 100 in all");
}

// ---------------------------------------------------------------------------------------------
// Far from the origin

json shifted(json j, double by) {
  for (json* box : {&j["Container"], &j["FluidBlocks"][0]})
    for (const char* corner : {"start", "end"})
      for (auto& v : (*box)[corner]) v = v.get<double>() + by;
  return j;
}

TEST(Preflight, FloatCoordinatesFarFromTheOriginWarnThenAreRefused) {
  json j = base_scene();
  j["Configuration"]["precision"] = "float";
  EXPECT_EQ(warnings_of(shifted(j, 100)), "");          // 101 m: float spacing 1.2e-5 m, 6e-4 of 0.02 m
  const std::string w = warnings_of(shifted(j, 1000));  // 6e-3 of the spacing
  EXPECT_CONTAINS(w, "Container: coordinates reach 1001 m from the origin");
  EXPECT_CONTAINS(w, "use \"precision\": \"double\"");
  const std::string m = error_of(shifted(j, 1e4));  // 6e-2 of the spacing
  EXPECT_CONTAINS(m, "float positions are");
  EXPECT_CONTAINS(m, "subtract [10000.5, 10000.5] (the container's centre) from every coordinate");
  j["Configuration"]["precision"] = "double";
  EXPECT_EQ(warnings_of(shifted(j, 1e4)), "");
}

TEST(Preflight, DoubleCoordinatesFarFromTheOriginWarnThenAreRefused) {
  const json j = base_scene();
  EXPECT_EQ(warnings_of(shifted(j, 1e10)), "");                            // 1.1e-4 of the spacing
  EXPECT_CONTAINS(warnings_of(shifted(j, 1e11)), "double positions are");  // 1.1e-3
  const std::string m = error_of(shifted(j, 1e12));                        // 1.1e-2
  EXPECT_CONTAINS(m, "move the scene near the origin");
  EXPECT_TRUE(m.find("precision") == std::string::npos) << m;
}

// ---------------------------------------------------------------------------------------------
// Particle mass

TEST(Preflight, AParticleMassFarFromTheLatticeMassWarnsThenIsRefused) {
  const double lattice = sph::lattice_mass<2>(1000, 0.02, 0.04);
  json j = base_scene();
  for (double f : {1.05, 1 / 1.05}) {
    j["Fluid"]["particleMass"] = f * lattice;
    EXPECT_EQ(warnings_of(j), "") << f;
  }
  for (double f : {9.0, 1 / 9.0}) {
    j["Fluid"]["particleMass"] = f * lattice;
    const std::string w = warnings_of(j);
    EXPECT_CONTAINS(w, "Fluid.particleMass: particleMass = ");
    EXPECT_CONTAINS(w, f > 1 ? "will expand" : "will contract");
    EXPECT_CONTAINS(w, fmt::format("use particleMass {:.6g}", lattice));
  }
  for (double f : {11.0, 1 / 11.0}) {
    j["Fluid"]["particleMass"] = f * lattice;
    const std::string m = error_of(j);
    EXPECT_CONTAINS(m, "Fluid.particleMass");
    EXPECT_CONTAINS(m, f > 1 ? "would explode" : "would collapse");
    EXPECT_CONTAINS(m, fmt::format("use particleMass {:.6g}", lattice));
  }
}

// ---------------------------------------------------------------------------------------------
// negativePressure "allow"

TEST(Preflight, AllowWithAFreeSurfaceIsAWarningAndAFullBoxIsNot) {
  json j = base_scene();
  j["Fluid"]["negativePressure"] = "allow";
  const std::string w = warnings_of(j);
  EXPECT_CONTAINS(w, "Fluid.negativePressure: \"allow\" with a free surface (the fluid blocks fill 4 %");
  EXPECT_CONTAINS(w, "turns to gas");
  EXPECT_CONTAINS(w, "use \"clamp\"");
  j["FluidBlocks"][0]["end"] = json::array({1, 1});  // the fluid fills the box: no surface
  j["Configuration"]["gravitation"] = json::array({0, 0});
  EXPECT_EQ(warnings_of(j), "");
  j["Fluid"]["negativePressure"] = "clamp";
  j["FluidBlocks"][0]["end"] = json::array({0.2, 0.2});
  EXPECT_EQ(warnings_of(j), "");
}

// ---------------------------------------------------------------------------------------------
// The paper and validation scenes pass with no warning

TEST(Preflight, ThePaperAndValidationScenesDrawNoWarning) {
  int scenes = 0;
  for (const auto& e : fs::recursive_directory_iterator(fs::path(SPH_SOURCE_DIR) / "scenes")) {
    if (e.path().extension() != ".json") continue;
    ++scenes;
    const sph::SceneDesc d = sph::read_scene_file(e.path().string());
    EXPECT_TRUE(d.warnings.empty()) << e.path() << ": " << d.warnings.front();
  }
  EXPECT_GE(scenes, 11);
}

// ---------------------------------------------------------------------------------------------
// The refused scenes of the physics corpus

TEST(Preflight, TheCorpusRefusedScenesAreRefusedWithTheirMessages) {
  const fs::path dir = fs::path(SPH_SOURCE_DIR) / "tests" / "app" / "trust";
  int refused = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().extension() != ".expect") continue;
    std::ifstream in(e.path());
    std::vector<std::string> messages;
    bool is_refused = false;
    for (std::string line; std::getline(in, line);) {
      if (line.rfind("verdict: ", 0) == 0) is_refused = line == "verdict: refused";
      if (line.rfind("message: ", 0) == 0) messages.push_back(line.substr(9));
    }
    if (!is_refused) continue;
    ++refused;
    fs::path scene = e.path();
    scene.replace_extension(".json");
    try {
      sph::read_scene_file(scene.string());
      ADD_FAILURE() << scene << " was accepted";
    } catch (const sph::Error& err) {
      SCOPED_TRACE(scene.string());
      for (const std::string& m : messages) EXPECT_CONTAINS(std::string(err.what()), m);
    }
  }
  EXPECT_GE(refused, 14);
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Moving obstacles

namespace {

/// The base scene with a paddle left of the block that oscillates along x.
json paddle_scene(double amplitude, double period) {
  json j = base_scene();
  j["FluidBlocks"][0] = json::parse(R"({ "start": [0.3, 0], "end": [0.8, 0.2] })");
  j["Obstacles"] = json::array();
  j["Obstacles"].push_back(json::parse(R"({ "start": [0.1, 0], "end": [0.2, 0.4] })"));
  j["Obstacles"][0]["motion"] = {
      {"type", "oscillation"}, {"direction", {1, 0}}, {"amplitude", amplitude}, {"period", period}};
  return j;
}

}  // namespace

TEST(Preflight, AMovingObstacleTooFastForTheFixedStepIsWarnedAbout) {
  // 5 cm at 1 s is at most 0.31 m/s: well under 0.4 diameters a step.
  EXPECT_EQ(warnings_of(paddle_scene(0.05, 1.0)).find("cannot follow"), std::string::npos);
  // 5 cm at 20 ms: 15.7 m/s, 0.79 diameters in a step of 1 ms.
  json j = paddle_scene(0.05, 0.02);
  j["Configuration"]["timeStepSize"] = 1e-3;
  const std::string fast = warnings_of(j);
  EXPECT_NE(fast.find("Obstacles[0].motion: the obstacle's surface moves up to 15.7 m/s"), std::string::npos) << fast;
  EXPECT_NE(fast.find("take steps of at most"), std::string::npos) << fast;
  // A period of a few steps.
  const std::string coarse = warnings_of(paddle_scene(1e-4, 1e-3));
  EXPECT_NE(coarse.find("sampled too coarsely"), std::string::npos) << coarse;
}

TEST(Preflight, AMotionThatOverflowsIsRefused) {
  json j = paddle_scene(0.05, 1.0);
  j["Obstacles"][0]["motion"] = json::parse(
      R"({ "type": "keyframes", "keys": [ { "time": 0 }, { "time": 0.001, "rotation": 1e308 }, { "time": 0.002, "rotation": -1e308 } ] })");
  const std::string e = error_of(j);
  EXPECT_NE(e.find("Obstacles[0].motion: the motion's pose at t = "), std::string::npos) << e;
  EXPECT_NE(e.find("is not finite"), std::string::npos) << e;
}

TEST(Preflight, AnObstacleMovingOverANozzleIsWarnedAbout) {
  json j = emitter_scene();  // a nozzle at x = 0.05 around y = 0.5, emitting along +x for the run's 1 ms
  j["Obstacles"] = json::parse(R"([ { "start": [0.2, 0.4], "end": [0.3, 0.6],
      "motion": { "type": "keyframes", "keys": [ { "time": 0 }, { "time": 0.0008, "translation": [-0.2, 0] } ] } } ])");
  const std::string w = warnings_of(j);
  EXPECT_NE(w.find("Emitters[0]: Obstacles[0] moves over the nozzle while it emits"), std::string::npos) << w;
  // The same box moving away from the nozzle: no such warning.
  j["Obstacles"][0]["motion"]["keys"][1]["translation"] = {0.2, 0};
  EXPECT_EQ(warnings_of(j).find("moves over the nozzle"), std::string::npos);
}
