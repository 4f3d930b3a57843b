// The strict scene reader: the paper scenes parse, and every user mistake is an sph::Error
// whose message names the problem (key path, line:col, what was expected).

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <typeinfo>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sph/core/error.h>
#include <sph/scene/builders.h>
#include <sph/scene/scene_reader.h>
#include <sph/scene/scene_writer.h>

#include "support/expect.h"
#include "support/scene_text.h"

namespace {

using sph::test::error_of;
using sph::test::parse;

using json = nlohmann::json;

/// A small valid 2D scene: 100 particles, no time-step warnings.
json valid_scene() {
  return json::parse(R"({
    "version": 1,
    "name": "t",
    "dimension": 2,
    "Configuration": { "timeStepSize": 1e-4, "numberOfSteps": 10, "particleRadius": 0.01, "kernelRadius": 0.04 },
    "Fluid": { "stiffness": 1000 },
    "Container": { "start": [0, 0], "end": [1, 1], "wallStiffness": 1e5 },
    "FluidBlocks": [ { "start": [0, 0], "end": [0.2, 0.2] } ]
  })");
}

/// A small valid 2D scene fed by an emitter only.
json valid_emitter_scene() {
  json j = valid_scene();
  j.erase("FluidBlocks");
  j["Emitters"] = json::parse(
      R"([ { "translation": [0.05, 0.5], "direction": [1, 0], "velocity": 20.0, "width": 4, "maxParticles": 100 } ])");
  return j;
}

// ---------------------------------------------------------------------------------------------
// The paper scenes

TEST(SceneReader, PaperDamBreak2d) {
  const sph::SceneDesc d = sph::read_scene_file(SPH_SOURCE_DIR "/scenes/paper/dam_break_2d.json");
  EXPECT_EQ(d.dimension, 2);
  EXPECT_EQ(d.name, "dam_break_2d");
  EXPECT_EQ(d.steps, 10000);
  EXPECT_EQ(sph::count_block_particles<2>(d.body<2>()), 3200u);
  EXPECT_TRUE(d.warnings.empty()) << d.warnings.front();
}

// DFSPH with the paper's kernels (poly6 density, spiky gradient) is what the docs say not to do:
// the reader says so, and is quiet with the cubic spline.
TEST(SceneReader, DfsphWithThePapersKernelsIsWarnedOf) {
  json j = valid_scene();
  j["Configuration"]["simulationMethod"] = "dfsph";
  j["Configuration"]["boundaryHandling"] = "particles";
  const sph::SceneDesc paper = sph::parse_scene(j.dump(), "dfsph.json");
  ASSERT_EQ(paper.warnings.size(), 1u);
  EXPECT_NE(paper.warnings[0].find("Configuration.kernel = \"paper\" with simulationMethod \"dfsph\""),
            std::string::npos)
      << paper.warnings[0];
  j["Configuration"]["kernel"] = "cubic";
  const sph::SceneDesc cubic = sph::parse_scene(j.dump(), "dfsph.json");
  EXPECT_TRUE(cubic.warnings.empty()) << cubic.warnings.front();
}

// A vector with one element that is not a number names that element, and a null is "null".
TEST(SceneReader, ABadVectorElementAndANullAreNamedAsTheyAre) {
  json j = valid_scene();
  j["FluidBlocks"][0]["end"] = json::parse(R"([0.2, "0.3"])");
  try {
    (void)sph::parse_scene(j.dump(), "v.json");
    ADD_FAILURE() << "accepted";
  } catch (const sph::Error& e) {
    EXPECT_NE(std::string(e.what()).find("as an array of 2 numbers, got string \"0.3\" in [1]"), std::string::npos)
        << e.what();
  }
  j = valid_scene();
  j["Configuration"]["particleRadius"] = nullptr;
  try {
    (void)sph::parse_scene(j.dump(), "n.json");
    ADD_FAILURE() << "accepted";
  } catch (const sph::Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find(", got null"), std::string::npos) << m;
    EXPECT_EQ(m.find("null null"), std::string::npos) << m;
  }
}

TEST(SceneReader, PaperBlock3d) {
  const sph::SceneDesc d = sph::read_scene_file(SPH_SOURCE_DIR "/scenes/paper/block_3d.json");
  EXPECT_EQ(d.dimension, 3);
  EXPECT_EQ(sph::count_block_particles<3>(d.body<3>()), 4000u);
  EXPECT_TRUE(d.body<3>().sim.emitters.empty());
  EXPECT_TRUE(d.warnings.empty()) << d.warnings.front();
}

TEST(SceneReader, PaperTankFill3d) {
  const sph::SceneDesc d = sph::read_scene_file(SPH_SOURCE_DIR "/scenes/paper/tank_fill_3d.json");
  EXPECT_EQ(d.dimension, 3);
  EXPECT_EQ(sph::count_block_particles<3>(d.body<3>()), 0u);
  ASSERT_EQ(d.body<3>().sim.emitters.size(), 1u);
  EXPECT_EQ(d.body<3>().sim.emitters[0].max_particles, 8000);
  EXPECT_EQ(d.body<3>().sim.emitters[0].width, 6);
  EXPECT_EQ(d.body<3>().sim.emitters[0].height, 6);
  EXPECT_TRUE(d.warnings.empty()) << d.warnings.front();
}

TEST(SceneReader, MinimalSceneParsesWithDefaults) {
  const sph::SceneDesc d = parse(valid_scene());
  EXPECT_EQ(d.source, "test.json");
  EXPECT_EQ(d.dimension, 2);
  EXPECT_EQ(d.steps, 10);
  EXPECT_EQ(sph::count_block_particles<2>(d.body<2>()), 100u);
  EXPECT_DOUBLE_EQ(d.body<2>().sim.fluid.stiffness, 1000.0);
  EXPECT_DOUBLE_EQ(d.body<2>().sim.fluid.rest_density, 1000.0);
  EXPECT_DOUBLE_EQ(d.body<2>().sim.gravity[1], -9.81);
  EXPECT_EQ(d.body<2>().sim.neighbors, sph::NeighborMode::Standard);
  EXPECT_TRUE(d.warnings.empty());
  const sph::SceneDesc e = parse(valid_emitter_scene());
  EXPECT_EQ(e.body<2>().sim.emitters.size(), 1u);
}

TEST(SceneReader, BoundaryPressureDefaultsToEachSolversForm) {
  // Weakly compressible SPH extrapolates the samples' pressure; DFSPH's samples carry none
  // (Akinci's term) unless the scene says otherwise.
  json j = valid_scene();
  j["Configuration"]["boundaryHandling"] = "particles";
  j["Configuration"]["kernel"] = "cubic";
  EXPECT_EQ(parse(j).body<2>().sim.boundary.pressure, sph::BoundaryPressure::Extrapolate);
  j["Configuration"]["simulationMethod"] = "dfsph";
  EXPECT_EQ(parse(j).body<2>().sim.boundary.pressure, sph::BoundaryPressure::None);
  for (const auto& [name, value] :
       {std::pair{"extrapolate", sph::BoundaryPressure::Extrapolate},
        std::pair{"mirror", sph::BoundaryPressure::Mirror}, std::pair{"none", sph::BoundaryPressure::None}}) {
    j["Configuration"]["boundaryPressure"] = name;
    EXPECT_EQ(parse(j).body<2>().sim.boundary.pressure, value) << name;
  }
  j["Configuration"]["boundaryPressure"] = "mirrored";
  const std::string m = error_of(j);
  EXPECT_CONTAINS(m, "boundaryPressure");
  EXPECT_CONTAINS(m, "none");
}

TEST(SceneReader, MissingFileNamesThePath) {
  const std::string path = SPH_SOURCE_DIR "/tests/scene/does_not_exist.json";
  try {
    sph::read_scene_file(path);
    FAIL() << "no error";
  } catch (const sph::Error& e) {
    EXPECT_CONTAINS(e.what(), path);
    EXPECT_EQ(e.where(), path);
  }
}

// ---------------------------------------------------------------------------------------------
// Keys: unknown, wrong type, missing

TEST(SceneReader, UnknownTopLevelKey) {
  json j = valid_scene();
  j["outputDir"] = "out";
  const std::string m = error_of(j);
  EXPECT_CONTAINS(m, "test.json: outputDir: unknown key");
  EXPECT_CONTAINS(m, "expected one of:");
  EXPECT_CONTAINS(m, "Configuration");
  EXPECT_CONTAINS(m, "FluidBlocks");
}

TEST(SceneReader, UnknownNestedKeyNamesPathAndListsKnownKeys) {
  json j = valid_scene();
  j["Fluid"]["stifness"] = 2000;  // typo next to the real key
  const std::string m = error_of(j);
  EXPECT_CONTAINS(m, "test.json: Fluid.stifness: unknown key (did you mean \"stiffness\"?); expected one of: ");
  EXPECT_CONTAINS(m, "density0");
  EXPECT_CONTAINS(m, "viscosity");
}

TEST(SceneReader, UnknownKeyInArrayElementNamesIndex) {
  json j = valid_scene();
  j["FluidBlocks"].push_back(json{{"start", {0.5, 0}}, {"end", {0.7, 0.2}}, {"colour", "blue"}});
  const std::string m = error_of(j);
  EXPECT_CONTAINS(m, "FluidBlocks[1].colour: unknown key");
  EXPECT_CONTAINS(m, "velocity");
}

TEST(SceneReader, WrongTypeStringForNumber) {
  json j = valid_scene();
  j["Fluid"]["stiffness"] = "1000";
  const std::string m = error_of(j);
  EXPECT_CONTAINS(m, "Fluid.stiffness");
  EXPECT_CONTAINS(m, "got string \"1000\"");
}

TEST(SceneReader, WrongTypeObjectExpected) {
  json j = valid_scene();
  j["Configuration"] = json::array({1e-4, 10});
  const std::string m = error_of(j);
  EXPECT_CONTAINS(m, "Configuration: expected an object");
}

// timeStepSize became optional (absent is "auto", tests/scene/scene_defaults_test.cpp); the
// run's length is the required key of Configuration besides particleRadius.
TEST(SceneReader, MissingRequiredRunLength) {
  json j = valid_scene();
  j["Configuration"].erase("numberOfSteps");
  const std::string m = error_of(j);
  EXPECT_CONTAINS(m, "Configuration.numberOfSteps: missing required key");
  EXPECT_CONTAINS(m, "stopAt");
}

TEST(SceneReader, MissingContainer) {
  json j = valid_scene();
  j.erase("Container");
  EXPECT_CONTAINS(error_of(j), "Container: missing required key");
}

// ---------------------------------------------------------------------------------------------
// Values

TEST(SceneReader, KernelRadiusMustBePositive) {
  for (double h : {0.0, -0.04}) {
    json j = valid_scene();
    j["Configuration"]["kernelRadius"] = h;
    const std::string m = error_of(j);
    EXPECT_CONTAINS(m, "Configuration.kernelRadius");
    EXPECT_CONTAINS(m, "positive");
  }
}

TEST(SceneReader, TimeStepMustBePositive) {
  for (double dt : {0.0, -1e-4}) {
    json j = valid_scene();
    j["Configuration"]["timeStepSize"] = dt;
    const std::string m = error_of(j);
    EXPECT_CONTAINS(m, "Configuration.timeStepSize");
    EXPECT_CONTAINS(m, "positive time step");
  }
}

TEST(SceneReader, ParticleRadiusMustBePositive) {
  json j = valid_scene();
  j["Configuration"]["particleRadius"] = -0.01;
  const std::string m = error_of(j);
  EXPECT_CONTAINS(m, "Configuration.particleRadius");
  EXPECT_CONTAINS(m, "got -0.01");
}

TEST(SceneReader, KernelRadiusMustExceedParticleSpacing) {
  for (double h : {0.02, 0.015}) {  // 2 * particleRadius, and below it
    json j = valid_scene();
    j["Configuration"]["kernelRadius"] = h;
    const std::string m = error_of(j);
    EXPECT_CONTAINS(m, "Configuration.kernelRadius");
    EXPECT_CONTAINS(m, "must exceed the particle spacing");
  }
  json ok = valid_scene();
  ok["Configuration"]["kernelRadius"] = 0.021;
  EXPECT_NO_THROW(parse(ok));
}

TEST(SceneReader, VersionMustBeOne) {
  for (json v : {json(2), json(0), json(1.0), json("1")}) {
    json j = valid_scene();
    j["version"] = v;
    EXPECT_CONTAINS(error_of(j), "test.json: version: expected the scene format version 1");
  }
}

TEST(SceneReader, DimensionMustBeTwoOrThree) {
  json j = valid_scene();
  j["dimension"] = 4;
  const std::string m = error_of(j);
  EXPECT_CONTAINS(m, "dimension: expected the dimension 2 or 3");
  EXPECT_CONTAINS(m, "got 4");
}

TEST(SceneReader, GravitationNeedsDimensionComponents) {
  json j = valid_scene();
  j["Configuration"]["gravitation"] = {0, -9.81, 0};
  const std::string m = error_of(j);
  EXPECT_CONTAINS(m, "Configuration.gravitation");
  EXPECT_CONTAINS(m, "array of 2 numbers");
  j["Configuration"]["gravitation"] = {0, "down"};
  EXPECT_CONTAINS(error_of(j), "Configuration.gravitation");
}

TEST(SceneReader, UnknownNeighborMode) {
  json j = valid_scene();
  j["Configuration"]["neighbors"] = "octree";
  const std::string m = error_of(j);
  EXPECT_CONTAINS(m, "Configuration.neighbors");
  EXPECT_CONTAINS(m, "unknown value \"octree\"");
  EXPECT_CONTAINS(m, "\"standard\"");
}

TEST(SceneReader, NegativePressureBadValue) {
  json j = valid_scene();
  j["Fluid"]["negativePressure"] = "zero";
  const std::string m = error_of(j);
  EXPECT_CONTAINS(m, "Fluid.negativePressure");
  EXPECT_CONTAINS(m, "\"clamp\", \"allow\"");
  j["Fluid"]["negativePressure"] = true;
  EXPECT_CONTAINS(error_of(j), "got boolean true");
}

TEST(SceneReader, PressureForceTakesEachFormAndRefusesOthers) {
  json j = valid_scene();
  EXPECT_EQ(parse(j).body<2>().sim.fluid.pressure_force, sph::PressureForce::Paper);
  const std::pair<const char*, sph::PressureForce> forms[] = {{"paper", sph::PressureForce::Paper},
                                                              {"symmetric", sph::PressureForce::Symmetric},
                                                              {"variational", sph::PressureForce::Variational}};
  for (const auto& [name, form] : forms) {
    j["Fluid"]["pressureForce"] = name;
    EXPECT_EQ(parse(j).body<2>().sim.fluid.pressure_force, form) << name;
  }
  j["Fluid"]["pressureForce"] = "spiky";
  const std::string m = error_of(j);
  EXPECT_CONTAINS(m, "Fluid.pressureForce");
  EXPECT_CONTAINS(m, "\"paper\", \"symmetric\", \"variational\"");
}

TEST(SceneReader, NumberOfStepsMustBeAPositiveInteger) {
  for (json v : {json(10.5), json(10.0), json(0), json(-3), json("10"), json(1e13)}) {
    json j = valid_scene();
    j["Configuration"]["numberOfSteps"] = v;
    EXPECT_CONTAINS(error_of(j), "Configuration.numberOfSteps: expected a number of steps between 1 and 1e12");
  }
  json j = valid_scene();
  j["Configuration"]["numberOfSteps"] = std::uint64_t{18446744073709551615ull};
  EXPECT_CONTAINS(error_of(j), "Configuration.numberOfSteps");
}

// ---------------------------------------------------------------------------------------------
// Geometry and particles

TEST(SceneReader, BlockOutsideContainer) {
  json j = valid_scene();
  j["FluidBlocks"][0]["end"] = {0.2, 1.5};
  const std::string m = error_of(j);
  EXPECT_CONTAINS(m, "FluidBlocks[0]");
  EXPECT_CONTAINS(m, "not inside the container");
}

TEST(SceneReader, BlockEndBeforeStart) {
  json j = valid_scene();
  j["FluidBlocks"][0]["start"] = {0.2, 0.2};
  j["FluidBlocks"][0]["end"] = {0.3, 0.1};
  const std::string m = error_of(j);
  EXPECT_CONTAINS(m, "FluidBlocks[0].end: must be greater than \"start\"");
  EXPECT_CONTAINS(m, "[0.2, 0.2]");
  EXPECT_CONTAINS(m, "[0.3, 0.1]");
}

TEST(SceneReader, BlockThinnerThanParticleSpacing) {
  json j = valid_scene();
  j["FluidBlocks"][0]["end"] = {0.2, 0.015};  // spacing is 0.02
  const std::string m = error_of(j);
  EXPECT_CONTAINS(m, "FluidBlocks[0].end");
  EXPECT_CONTAINS(m, "thinner than one particle spacing");
}

TEST(SceneReader, NoParticlesAtAll) {
  json j = valid_scene();
  j.erase("FluidBlocks");
  EXPECT_CONTAINS(error_of(j), "no particles");
  j["FluidBlocks"] = json::array();
  EXPECT_CONTAINS(error_of(j), "no particles");
}

TEST(SceneReader, HugeParticleCountIsRefused) {
  json j = valid_scene();
  j["Configuration"]["particleRadius"] = 1e-6;
  j["Configuration"]["kernelRadius"] = 4e-6;
  j["Configuration"]["timeStepSize"] = 1e-8;
  const std::string m = error_of(j);
  EXPECT_CONTAINS(m, "FluidBlocks");
  EXPECT_CONTAINS(m, "at most 2e9");
}

TEST(SceneReader, EmitterTooSlowBatchesOverlap) {
  json j = valid_emitter_scene();
  j["Emitters"][0]["velocity"] = 1.0;  // 1 m/s * 16 steps * 1e-4 s = 1.6 mm < 2 cm spacing
  const std::string m = error_of(j);
  EXPECT_CONTAINS(m, "Emitters[0].velocity");
  EXPECT_CONTAINS(m, "batches would overlap");
  EXPECT_CONTAINS(m, "12.5 m/s");  // the speed that would work: 0.02 / (16 * 1e-4)
}

TEST(SceneReader, EmitterOutsideContainer) {
  json j = valid_emitter_scene();
  j["Emitters"][0]["translation"] = {1.5, 0.5};
  const std::string m = error_of(j);
  EXPECT_CONTAINS(m, "Emitters[0].translation");
  EXPECT_CONTAINS(m, "outside the container");
}

// ---------------------------------------------------------------------------------------------
// Time step: far too large is refused, slightly too large is a warning

TEST(SceneReader, TimeStepFarTooLargeIsRefused) {
  json j = valid_scene();
  j["Configuration"]["timeStepSize"] = 0.01;  // acoustic CFL limit 1.0 h / sqrt(k) = 1.26e-3 s
  const std::string m = error_of(j);
  EXPECT_CONTAINS(m, "timeStepSize");
  EXPECT_CONTAINS(m, "unstable");
  EXPECT_CONTAINS(m, "acoustic CFL");
}

TEST(SceneReader, TimeStepSlightlyTooLargeIsAWarning) {
  json j = valid_scene();
  j["Configuration"]["timeStepSize"] = 7e-4;  // above 0.4 h / c = 5.06e-4, below h / c = 1.26e-3
  sph::SceneDesc d;
  ASSERT_NO_THROW(d = parse(j));
  ASSERT_EQ(d.warnings.size(), 1u);
  EXPECT_CONTAINS(d.warnings[0], "acoustic CFL");
  EXPECT_CONTAINS(d.warnings[0], "may be unstable");
}

// ---------------------------------------------------------------------------------------------
// JSON text

TEST(SceneReader, EmptyAndWhitespaceOnlyFiles) {
  for (const char* text : {"", " ", "\n\n", " \t\r\n  "}) {
    const std::string m = error_of(std::string(text));
    EXPECT_CONTAINS(m, "test.json: the scene file is empty");
  }
}

TEST(SceneReader, MalformedJsonNamesLineAndColumn) {
  // The second comma on line 3 is at column 15.
  const std::string m = error_of(std::string("{\n  \"version\": 1,\n  \"name\": \"x\",,\n}\n"));
  EXPECT_CONTAINS(m, "test.json:3:15: JSON syntax error");
  EXPECT_CONTAINS(m, "unexpected ','");
  // A trailing comma: the offending '}' is on line 4, column 1.
  EXPECT_CONTAINS(error_of(std::string("{\n  \"version\": 1,\n  \"name\": \"x\",\n}\n")), "test.json:4:1:");
  // Truncated text: the error is at the end of the input.
  EXPECT_CONTAINS(error_of(std::string("{\n  \"version\": 1")), "test.json:2:15:");
  // Comments are not JSON.
  EXPECT_CONTAINS(error_of(std::string("{\n  // a comment\n  \"version\": 1\n}")), "test.json:2:3:");
}

TEST(SceneReader, DuplicateKeysAreRefused) {
  const std::string text = valid_scene().dump(2);
  std::string dup = text;
  const auto pos = dup.find("\"stiffness\": 1000");
  ASSERT_NE(pos, std::string::npos);
  dup.insert(pos, "\"stiffness\": 2000,\n");
  const std::string m = error_of(dup);
  // The repeated key is the original one, now at the start of the line after the inserted one.
  const auto line = 2 + std::count(dup.begin(), dup.begin() + static_cast<std::ptrdiff_t>(pos), '\n');
  EXPECT_CONTAINS(m, "test.json:" + std::to_string(line) + ":1: key \"stiffness\" appears twice");
  // The place is that of the key repeated in its own object, not of one of the same name in a
  // sibling, a parent or a child object, nor of a string value that reads like it.
  const std::string nested =
      "{\n \"a\": [{\"k\": 1}, {\"k\": \"\\\"b\\\"\"}],\n \"b\": {\"k\": {\"k\": 3}, \"x\\\"\": 1, \"b\": 0},\n  "
      "\"b\": 2\n}";
  EXPECT_CONTAINS(error_of(nested), "test.json:4:3: key \"b\" appears twice");
  // The same key in two different objects is fine.
  json j = valid_scene();
  j["FluidBlocks"].push_back(json{{"start", {0.5, 0}}, {"end", {0.7, 0.2}}});
  EXPECT_NO_THROW(parse(j));
}

TEST(SceneReader, TopLevelMustBeAnObject) {
  EXPECT_CONTAINS(error_of(std::string("[") + valid_scene().dump() + "]"),
                  "expected a JSON object { ... } at the top level, got an array");
  EXPECT_CONTAINS(error_of(std::string("42")), "at the top level, got number");
  EXPECT_CONTAINS(error_of(std::string("\"scene\"")), "at the top level, got string");
}

// ---------------------------------------------------------------------------------------------
// --set overrides

TEST(SceneReaderOverrides, ChangesANumber) {
  const sph::SceneDesc d = parse(valid_scene(), {"Fluid.stiffness=2000"});
  EXPECT_DOUBLE_EQ(d.body<2>().sim.fluid.stiffness, 2000.0);
}

TEST(SceneReaderOverrides, ChangesAnArrayElementsVector) {
  const sph::SceneDesc d = parse(valid_scene(), {"FluidBlocks[0].end=[0.5,0.7]"});
  ASSERT_EQ(d.body<2>().blocks.size(), 1u);
  EXPECT_DOUBLE_EQ(d.body<2>().blocks[0].box.hi[0], 0.5);
  EXPECT_DOUBLE_EQ(d.body<2>().blocks[0].box.hi[1], 0.7);
  EXPECT_EQ(sph::count_block_particles<2>(d.body<2>()), 25u * 35u);
}

TEST(SceneReaderOverrides, PlainTextValueBecomesAString) {
  json j = valid_scene();
  j["Configuration"]["neighbors"] = "brute_force";
  const sph::SceneDesc d = parse(j, {"Configuration.neighbors=standard"});
  EXPECT_EQ(d.body<2>().sim.neighbors, sph::NeighborMode::Standard);
  const sph::SceneDesc b = parse(valid_scene(), {"Configuration.neighbors=brute_force"});
  EXPECT_EQ(b.body<2>().sim.neighbors, sph::NeighborMode::BruteForce);
}

TEST(SceneReaderOverrides, LaterOverrideWins) {
  const sph::SceneDesc d = parse(valid_scene(), {"Fluid.stiffness=2000", "Fluid.stiffness=1500"});
  EXPECT_DOUBLE_EQ(d.body<2>().sim.fluid.stiffness, 1500.0);
}

TEST(SceneReaderOverrides, AddsAnOptionalKey) {
  const sph::SceneDesc d = parse(valid_scene(), {"Fluid.viscosity=0.5"});
  EXPECT_DOUBLE_EQ(d.body<2>().sim.fluid.viscosity, 0.5);
}

TEST(SceneReaderOverrides, UnknownKeyMentionsSet) {
  const std::string m = error_of(valid_scene(), {"Fluid.stifness=2000"});
  EXPECT_CONTAINS(m, "--set Fluid.stifness");
  EXPECT_CONTAINS(m, "unknown key");
  EXPECT_CONTAINS(m, "stiffness");
}

TEST(SceneReaderOverrides, BadValueMentionsSet) {
  const std::string m = error_of(valid_scene(), {"Fluid.stiffness=-5"});
  EXPECT_CONTAINS(m, "--set Fluid.stiffness");
  EXPECT_CONTAINS(m, "got -5");
  // A non-JSON value becomes a string, which a number key then refuses.
  const std::string s = error_of(valid_scene(), {"Fluid.stiffness=stiff"});
  EXPECT_CONTAINS(s, "--set Fluid.stiffness");
  EXPECT_CONTAINS(s, "got string \"stiff\"");
}

TEST(SceneReaderOverrides, IndexOutOfRange) {
  const std::string m = error_of(valid_scene(), {"FluidBlocks[3].end=[0.5,0.7]"});
  EXPECT_CONTAINS(m, "--set FluidBlocks[3].end");
  EXPECT_CONTAINS(m, "index 3 does not exist");
}

TEST(SceneReaderOverrides, IndexIntoANonArray) {
  const std::string m = error_of(valid_scene(), {"Fluid[0]=1"});
  EXPECT_CONTAINS(m, "--set Fluid[0]");
  EXPECT_CONTAINS(m, "not an array");
}

TEST(SceneReaderOverrides, MalformedOverride) {
  for (const char* o : {"Fluid.stiffness", "=2000"}) {
    const std::string m = error_of(valid_scene(), {o});
    EXPECT_CONTAINS(m, "--set");
    EXPECT_CONTAINS(m, "KEY=VALUE");
  }
  EXPECT_CONTAINS(error_of(valid_scene(), {"FluidBlocks[x].end=[1,1]"}), "bad array index");
}

TEST(SceneReaderOverrides, EffectiveSceneShowsOverrides) {
  const std::string text =
      sph::scene_text(sph::parse_scene(valid_scene().dump(), "test.json", {"Fluid.stiffness=2000"}));
  EXPECT_EQ(json::parse(text)["Fluid"]["stiffness"], 2000);
}

// ---------------------------------------------------------------------------------------------
// Mistakes that once gave a crash or a misleading message; each comment says what happened
// before the fix, each test checks the fixed behaviour.

// Before the fix: a number too large for a double ("1e999") makes nlohmann throw json::out_of_range (406), which
// parse_json and apply_overrides do not catch: the sph CLI exits 70 ("internal error") with a
// message that names neither the file, nor the line, nor the key.
TEST(SceneReaderRobustness, NumberOverflowIsAnSphError) {
  json j = valid_scene();
  std::string text = j.dump(2);
  const std::size_t at = text.find("\"stiffness\": 1000");
  text.replace(at, 17, "\"stiffness\": -1e999");
  // Its line and column, which nlohmann's exception does not give.
  const auto line = 1 + std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n');
  const auto column = at + 13 - text.rfind('\n', at);
  EXPECT_CONTAINS(error_of(text), "test.json:" + std::to_string(line) + ":" + std::to_string(column) +
                                      ": the number -1e999 is beyond a double's range");
  EXPECT_CONTAINS(error_of(valid_scene(), {"Fluid.stiffness=1e999"}), "--set Fluid.stiffness");
  // A key repeated in a --set value's object was silently the last one's value until 2026-12-07.
  EXPECT_CONTAINS(error_of(valid_scene(), {"Fluid={\"density0\": 1000, \"stiffness\": 1, \"stiffness\": 2}"}),
                  "--set Fluid: key \"stiffness\" appears twice");
}

// Before the fix: a misspelt *required* key is reported as the required key missing, without naming the typo
// ("Fluid.stiffness: missing required key" for "stifness").
TEST(SceneReaderRobustness, MisspeltRequiredKeyNamesTheTypo) {
  json j = valid_scene();
  j["Fluid"].erase("stiffness");
  j["Fluid"]["stifness"] = 1000;
  EXPECT_CONTAINS(error_of(j), "Fluid.stifness");
}

// Before the fix: --set of a key path whose first part is unknown (or that creates a new object) is blamed on the
// file: "test.json: Foo: unknown key", without "--set".
TEST(SceneReaderRobustness, OverrideCreatingUnknownObjectMentionsSet) {
  EXPECT_CONTAINS(error_of(valid_scene(), {"Foo.bar=1"}), "--set Foo.bar");
  EXPECT_CONTAINS(error_of(valid_scene(), {"Configuration.foo.bar=1"}), "--set Configuration.foo.bar");
}

// Before the fix: unknown keys are only reported after everything else was validated, so a misspelt section is
// reported as the consequence of its absence ("FluidBlocks: the scene has no particles").
TEST(SceneReaderRobustness, MisspeltSectionNamesTheTypo) {
  json j = valid_scene();
  j["FluidBlock"] = j["FluidBlocks"];
  j.erase("FluidBlocks");
  EXPECT_CONTAINS(error_of(j), "FluidBlock: unknown key");
  json k = valid_scene();
  k["configuration"] = k["Configuration"];
  k.erase("Configuration");
  EXPECT_CONTAINS(error_of(k), "configuration: unknown key");
}

// Before the fix: the time-step refusal is thrown with where = "Configuration.timeStepSize" only: unlike every
// other scene error it does not name the file, nor the --set flag that set the value.
TEST(SceneReaderRobustness, TimeStepRefusalNamesFileAndSet) {
  json j = valid_scene();
  j["Configuration"]["timeStepSize"] = 0.01;
  EXPECT_CONTAINS(error_of(j), "test.json: Configuration.timeStepSize");
  EXPECT_CONTAINS(error_of(valid_scene(), {"Configuration.timeStepSize=0.01"}), "--set Configuration.timeStepSize");
}

// Before the fix: describe() dumps the offending value recursively before truncating it: a deeply nested value
// (100000 levels) overflows the stack (SIGSEGV) instead of giving an error. Run in a child process.
TEST(SceneReaderRobustness, DeeplyNestedValueDoesNotCrash) {
  const std::string text = std::string(100000, '[') + std::string(100000, ']');
  EXPECT_EXIT(
      {
        try {
          sph::parse_scene(text, "test.json");
        } catch (const sph::Error&) {
          std::exit(0);
        }
        std::exit(1);
      },
      testing::ExitedWithCode(0), "");
}

TEST(MemoryEstimate, CountsBlocksAndEmitterBudgetsAndGrowsWithPrecisionAndSkin) {
  const std::string dir = SPH_SOURCE_DIR "/scenes/paper/";
  const sph::SceneDesc dam = sph::read_scene_file(dir + "dam_break_2d.json");
  const sph::SceneDesc tank = sph::read_scene_file(dir + "tank_fill_3d.json");
  EXPECT_EQ(sph::max_particles(dam), 3200u);
  EXPECT_EQ(sph::max_particles(tank), 8000u) << "the tank starts empty: its emitter's budget";
  const double d = sph::estimated_run_bytes(dam);
  // 2D double: 4 vectors (64 bytes), 2 scalars (16), an id (8); 4 pi neighbors of 4 bytes with
  // 1/16 room, and 8 bytes of offsets (61); the grid's coordinates and index (20): 169 bytes.
  EXPECT_GT(d / 3200, 165.0);
  EXPECT_LT(d / 3200, 175.0);
  const sph::SceneDesc dam_float =
      sph::read_scene_file(dir + "dam_break_2d.json", {"Configuration.precision=\"float\""});
  EXPECT_LT(sph::estimated_run_bytes(dam_float), d);
  const sph::SceneDesc dam_verlet =
      sph::read_scene_file(dir + "dam_break_2d.json", {"Configuration.neighbors=\"verlet\""});
  EXPECT_GT(sph::estimated_run_bytes(dam_verlet), d) << "verlet lists reach h + skin";
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Frame output: Configuration.outputEveryNSteps, outputFps, outputFormats, outputFields

TEST(SceneReaderOutput, Defaults) {
  const sph::SceneDesc d = parse(valid_scene());  // 10 steps
  EXPECT_EQ(d.output.every_steps, 1) << "max(1, steps / 100)";
  EXPECT_EQ(d.output.fps, 0.0);
  EXPECT_EQ(d.output.formats, std::vector<sph::FrameFormat>{sph::FrameFormat::Vtu});
  EXPECT_EQ(d.output.fields, (std::vector<std::string>{"velocity", "density", "pressure", "id", "initial_position"}));
  json j = valid_scene();
  j["Configuration"]["numberOfSteps"] = 1000;
  EXPECT_EQ(parse(j).output.every_steps, 10);
}

TEST(SceneReaderOutput, FpsReplacesTheDefaultStepInterval) {
  json j = valid_scene();
  j["Configuration"]["outputFps"] = 24.5;
  const sph::SceneDesc d = parse(j);
  EXPECT_EQ(d.output.fps, 24.5);
  EXPECT_EQ(d.output.every_steps, 0);
  // Both, one of them 0: fine.
  j["Configuration"]["outputEveryNSteps"] = 0;
  EXPECT_EQ(parse(j).output.fps, 24.5);
  j["Configuration"]["outputEveryNSteps"] = 3;
  j["Configuration"]["outputFps"] = 0;
  EXPECT_EQ(parse(j).output.every_steps, 3);
  EXPECT_EQ(parse(j).output.fps, 0.0);
  j["Configuration"]["outputFps"] = 30;
  const std::string m = error_of(j);
  EXPECT_CONTAINS(m, "outputEveryNSteps = 3");
  EXPECT_CONTAINS(m, "outputFps = 30");
  // Through --set, the message names the override.
  EXPECT_CONTAINS(error_of(valid_scene(), {"Configuration.outputEveryNSteps=2", "Configuration.outputFps=10"}),
                  "--set Configuration.output");
}

TEST(SceneReaderOutput, FormatsAndFieldsInTheirCanonicalOrder) {
  json j = valid_scene();
  j["Configuration"]["outputFormats"] = {"ply", "vtu"};
  j["Configuration"]["outputFields"] = {"id", "velocity"};
  const sph::SceneDesc d = parse(j);
  EXPECT_EQ(d.output.formats, (std::vector<sph::FrameFormat>{sph::FrameFormat::Ply, sph::FrameFormat::Vtu}));
  EXPECT_EQ(d.output.fields, (std::vector<std::string>{"velocity", "id"}));
  j["Configuration"]["outputFields"] = json::array();
  EXPECT_TRUE(parse(j).output.fields.empty()) << "positions only";
  // The effective scene keeps the keys, so that a checkpoint's scene reproduces them.
  const sph::SceneDesc again = sph::parse_scene(sph::scene_text(d), "again.json");
  EXPECT_EQ(again.output.formats, d.output.formats);
  EXPECT_EQ(again.output.fields, d.output.fields);
}

TEST(SceneReaderOutput, MistakesNameTheKey) {
  EXPECT_CONTAINS(error_of(valid_scene(), {"Configuration.outputFormats=[\"vtu\",\"stl\"]"}),
                  "Configuration.outputFormats[1]: unknown value \"stl\"");
  EXPECT_CONTAINS(error_of(valid_scene(), {"Configuration.outputFormats=[]"}), "at least one frame format");
  EXPECT_CONTAINS(error_of(valid_scene(), {"Configuration.outputFields=velocity"}), "an array of");
  EXPECT_CONTAINS(error_of(valid_scene(), {"Configuration.outputFps=-1"}), "frame rate >= 0");
}
