// Scene scale estimates (scene/scales.h) and the defaults the reader derives from them, with
// numbers worked out by hand in the comments.

#include <cmath>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sph/core/error.h>
#include <sph/scene/scales.h>
#include <sph/scene/scene_reader.h>
#include <sph/scene/scene_writer.h>
#include <sph/solver/time_step.h>

#include "support/expect.h"
#include "support/scene_text.h"

namespace {

using sph::test::error_of;
using sph::test::parse;

using json = nlohmann::json;

/// 0.2 m x 0.2 m of water at rest in a 1 m x 1 m box, particleRadius 0.01, h = 0.04.
json tank_2d() {
  return json::parse(R"({ "version": 1, "dimension": 2,
    "Configuration": { "numberOfSteps": 10, "particleRadius": 0.01 },
    "Container": { "start": [0, 0], "end": [1, 1] },
    "FluidBlocks": [ { "start": [0, 0], "end": [0.2, 0.2] } ] })");
}

TEST(SceneScales, TankAtRest2d) {
  const sph::SceneDesc d = parse(tank_2d());
  const sph::SceneScales s = sph::scene_scales<2>(d.body<2>());
  EXPECT_DOUBLE_EQ(s.gravity, 9.81);
  EXPECT_DOUBLE_EQ(s.fall_height, 0.2);
  EXPECT_DOUBLE_EQ(s.head, 0.2);                             // the block's top; it fills only 0.04 m of the box
  EXPECT_DOUBLE_EQ(s.max_speed, std::sqrt(2 * 9.81 * 0.2));  // 1.98 m/s
  // k = (10 v)^2 = 100 * 2 g H = 392.4; the default designs for 1.5 v: 2.25 * 392.4 = 882.9.
  EXPECT_NEAR(sph::stiffness_for_speed(s.max_speed), 392.4, 1e-9);
  EXPECT_NEAR(sph::default_stiffness(s), 882.9, 1e-9);
  // Head: g H / (dx f r) = 9.81 * 0.2 / (0.02 * 0.5 * 0.01) = 19620; impact (v / r)^2 = 3.924 / 1e-4 = 39240,
  // and for the default 1.5 v: 2.25 * 39240 = 88290.
  EXPECT_NEAR(sph::wall_stiffness_for_head(s, 0.01, 0.5), 19620, 1e-6);
  EXPECT_NEAR(sph::wall_stiffness_for_impact(s.max_speed, 0.01), 39240, 1e-6);
  EXPECT_NEAR(sph::default_wall_stiffness(s, 0.01, 882.9), 88290, 1e-6);
  // Cannot hold: the head at penetration r (9810), the impact within 2 r (3.924 / 4e-4 = 9810).
  EXPECT_NEAR(sph::least_holding_wall_stiffness(s, 0.01, 882.9), 9810, 1e-6);
  EXPECT_NEAR(sph::critical_wall_damping(88290), 2 * std::sqrt(88290.0), 1e-9);  // 594.3
  // nu = alpha h c0 / (2 (D + 2)) = 0.1 * 0.04 * 19.809 / 8 = 9.9045e-3 m^2/s; mu = rho0 nu (and
  // for the default c0 = sqrt(882.9) = 29.714: 14.857).
  EXPECT_NEAR(sph::viscosity_for_sound_speed(2, 0.1, 0.04, std::sqrt(392.4), 1000), 9.90454, 1e-5);
  EXPECT_NEAR(sph::viscosity_for_sound_speed(3, 0.1, 0.04, std::sqrt(392.4), 1000), 7.92363, 1e-5);

  // The reader filled in exactly these.
  const auto& sim = d.body<2>().sim;
  EXPECT_NEAR(sim.fluid.stiffness, 882.9, 1e-9);
  EXPECT_NEAR(sim.fluid.viscosity, 14.8568, 1e-4);
  EXPECT_NEAR(sim.walls.stiffness, 88290, 1e-6);
  EXPECT_NEAR(sim.walls.damping, 594.273, 1e-3);
  // dt: the smallest warning limit is the acoustic CFL 0.4 h / c0 = 0.4 * 0.04 / 29.714 = 5.385e-4
  // (viscous 0.125 h^2 / nu = 0.0135, wall spring 0.5 / 297.1 = 1.68e-3, damping 0.5 / 594.3 =
  // 8.41e-4, gravity 0.25 sqrt(h / g) = 0.016); auto takes 0.8 of it: 4.308e-4 s.
  EXPECT_NEAR(sim.time_step, 0.8 * 0.4 * 0.04 / std::sqrt(882.9), 1e-12);
  EXPECT_DOUBLE_EQ(sim.time_step, sph::auto_time_step<2>(sim));
  EXPECT_TRUE(d.warnings.empty()) << d.warnings.front();
}

TEST(SceneScales, MovingBlockEmitterAndFillDepth3d) {
  // Gravity along -z; a 0.5 x 0.5 x 0.1 block moving at 3 m/s; an emitter at z = 0.3, 2 m/s.
  const sph::SceneDesc d = parse(json::parse(R"({ "version": 1, "dimension": 3,
    "Configuration": { "numberOfSteps": 10, "particleRadius": 0.01, "gravitation": [0, 0, -9.81] },
    "Container": { "start": [0, 0, 0], "end": [1, 2, 0.5] },
    "FluidBlocks": [ { "start": [0, 0, 0], "end": [0.5, 0.5, 0.1], "velocity": [3, 0, 0] } ],
    "Emitters": [ { "translation": [0.8, 1, 0.3], "direction": [-1, 0, 0], "velocity": 2, "width": 2,
                    "height": 2, "maxParticles": 1000 } ] })"));
  const sph::SceneScales s = sph::scene_scales<3>(d.body<3>());
  EXPECT_DOUBLE_EQ(s.fall_height, 0.3);  // the nozzle
  // Fill depth: (0.025 + 1000 * 0.02^3) m^3 over the 1 x 2 m floor = 0.0165 m, below the block's top 0.1 m.
  EXPECT_DOUBLE_EQ(s.head, 0.1);
  // Block: 3^2 + 2 g 0.1 = 10.962; emitter: 2^2 + 2 g 0.3 = 9.886; the larger.
  EXPECT_NEAR(s.max_speed, std::sqrt(9 + 2 * 9.81 * 0.1), 1e-12);
  // Without emitEveryNSteps, the emitter waits the fewest steps (more than the usual 16 at the
  // auto time step) for a batch to move one spacing.
  const auto& sim = d.body<3>().sim;
  const auto& e = sim.emitters.at(0);
  EXPECT_GT(e.every_steps, 16);
  EXPECT_GE(e.speed * e.every_steps * sim.time_step, 0.02);
  EXPECT_LT(e.speed * (e.every_steps - 1) * sim.time_step, 0.02);
}

TEST(SceneScales, WithCflStepsAnEmitterWithoutAnIntervalMakesAContinuousJet) {
  // DFSPH takes CFL steps, its batches come every emitEveryNSteps * timeStepSize seconds, and its
  // "auto" timeStepSize is long: the usual 16 would put the layers many spacings apart. Absent,
  // the interval is the fewest steps in which a layer moves one spacing (0.02 m here).
  const json scene = json::parse(R"({ "version": 1, "dimension": 3,
    "Configuration": { "particleRadius": 0.01, "stopAt": 1.0, "simulationMethod": "dfsph",
                       "boundaryHandling": "particles" },
    "Container": { "start": [0, 0, 0], "end": [0.5, 0.5, 0.5] },
    "Emitters": [ { "translation": [0.05, 0.35, 0.25], "direction": [1, 0, 0], "velocity": 3, "width": 5,
                    "height": 5, "maxParticles": 3000 } ] })");
  for (const bool fixed_step : {false, true}) {
    const sph::SceneDesc d = parse(
        scene, fixed_step ? std::vector<std::string>{"Configuration.timeStepSize=0.001"} : std::vector<std::string>{});
    const auto& sim = d.body<3>().sim;
    const auto& e = sim.emitters.at(0);
    EXPECT_LT(e.every_steps, 16) << "timeStepSize " << sim.time_step;
    EXPECT_GE(e.speed * e.every_steps * sim.time_step, 0.02 * (1 - 1e-12));
    EXPECT_LT(e.speed * (e.every_steps - 1) * sim.time_step, 0.02);
  }
  // Fixed steps keep the paper's 16 when the time step is given.
  const sph::SceneDesc fixed =
      parse(scene, {"Configuration.simulationMethod=\"wcsph\"", "Configuration.boundaryHandling=\"penalty\"",
                    "Configuration.timeStepSize=0.0005"});
  EXPECT_EQ(fixed.body<3>().sim.emitters.at(0).every_steps, 16);
}

TEST(SceneScales, EmittersFillingATankSetTheHead) {
  // 2500 particles of 0.01 m spacing: 0.25 m^2 over a 0.5 m floor fills 0.5 m (the nozzle is at 0.8 m).
  const sph::SceneDesc d = parse(json::parse(R"({ "version": 1, "dimension": 2,
    "Configuration": { "numberOfSteps": 10, "particleRadius": 0.005 },
    "Container": { "start": [0, 0], "end": [0.5, 1] },
    "Emitters": [ { "translation": [0.1, 0.8], "direction": [1, 0], "velocity": 2, "width": 4,
                    "maxParticles": 2500 } ] })"));
  const sph::SceneScales s = sph::scene_scales<2>(d.body<2>());
  EXPECT_DOUBLE_EQ(s.fall_height, 0.8);
  EXPECT_NEAR(s.head, 0.5, 1e-12);
  EXPECT_NEAR(s.max_speed, std::sqrt(4 + 2 * 9.81 * 0.8), 1e-12);
}

TEST(SceneScales, TiltedGravity) {
  // g = (-3, -4), |g| = 5, down = (-0.6, -0.8): the floor is the corner (0, 0), the block's top
  // the corner (0.5, 0.5), 0.6 * 0.5 + 0.8 * 0.5 = 0.7 m above it.
  json j = tank_2d();
  j["Configuration"]["gravitation"] = {-3, -4};
  j["FluidBlocks"][0]["end"] = {0.5, 0.5};
  const sph::SceneScales s = sph::scene_scales<2>(parse(j).body<2>());
  EXPECT_DOUBLE_EQ(s.gravity, 5);
  EXPECT_NEAR(s.fall_height, 0.7, 1e-12);
  EXPECT_NEAR(s.max_speed, std::sqrt(2 * 5 * 0.7), 1e-12);
}

TEST(SceneScales, WithoutGravityOnlyMotionSetsTheSpeed) {
  json j = tank_2d();
  j["Configuration"]["gravitation"] = {0, 0};
  j["FluidBlocks"][0]["velocity"] = {0.3, 0.4};
  const sph::SceneDesc d = parse(j);
  const sph::SceneScales s = sph::scene_scales<2>(d.body<2>());
  EXPECT_EQ(s.head, 0);
  EXPECT_DOUBLE_EQ(s.max_speed, 0.5);
  EXPECT_NEAR(d.body<2>().sim.fluid.stiffness, 56.25, 1e-12);  // (10 * 1.5 * 0.5)^2
  // Still: no speed to derive a stiffness from; with one given, the walls stop c0 / 10.
  j["FluidBlocks"][0].erase("velocity");
  const std::string m = error_of(j);
  EXPECT_CONTAINS(m, "Fluid.stiffness");
  EXPECT_CONTAINS(m, "no gravity, and neither its fluid nor an obstacle moves");
  j["Fluid"]["stiffness"] = 400;
  EXPECT_NEAR(parse(j).body<2>().sim.walls.stiffness, 9e4, 1e-6);  // (1.5 * 2 m/s / 0.01 m)^2
}

// A moving obstacle stirs the fluid at its surface's speed: without gravity it sets the speed
// (the scene was refused as one where "nothing moves" until 2026-12-07), and with gravity the
// larger of the two does.
TEST(SceneScales, AMovingObstaclesSurfaceSpeedCounts) {
  json j = tank_2d();
  j["Configuration"]["gravitation"] = {0, 0};
  // A 0.2 x 0.1 m paddle turning at 4 rad/s about its centre: its corners at 0.1118 m, 0.447 m/s.
  j["Obstacles"] = json::parse(R"([{ "start": [0.4, 0.5], "end": [0.6, 0.6],
    "motion": { "type": "rotation", "center": [0.5, 0.55], "angularVelocity": 4 } }])");
  const double corner = 4 * std::sqrt(0.1 * 0.1 + 0.05 * 0.05);
  EXPECT_NEAR(sph::scene_scales<2>(parse(j).body<2>()).max_speed, corner, 1e-9);
  // Ramped up over a second: the same speed once it is reached.
  j["Obstacles"][0]["motion"]["rampTime"] = 1.0;
  EXPECT_NEAR(sph::scene_scales<2>(parse(j).body<2>()).max_speed, corner, 1e-9);
  // An oscillation of amplitude A and period T peaks at 2 pi A / T.
  j["Obstacles"][0]["motion"] = json::parse(R"({ "type": "oscillation", "direction": [1, 0], "amplitude": 0.05,
    "period": 0.5 })");
  EXPECT_NEAR(sph::scene_scales<2>(parse(j).body<2>()).max_speed, 2 * M_PI * 0.05 / 0.5, 1e-3);
  // Keyframes: the fastest interval's speed (0.1 m in 0.05 s).
  j["Obstacles"][0]["motion"] = json::parse(R"({ "type": "keyframes", "keys": [
    { "time": 0, "translation": [0, 0] }, { "time": 1, "translation": [0.1, 0] },
    { "time": 1.05, "translation": [0.2, 0] } ] })");
  EXPECT_NEAR(sph::scene_scales<2>(parse(j).body<2>()).max_speed, 2.0, 1e-9);
  // A floating body launched at 0.3 m/s.
  j["Obstacles"][0].erase("motion");
  j["Obstacles"][0]["dynamic"] = true;
  j["Obstacles"][0]["density"] = 500;
  j["Obstacles"][0]["velocity"] = {0, 0.3};
  EXPECT_NEAR(sph::scene_scales<2>(parse(j).body<2>()).max_speed, 0.3, 1e-12);
  // With gravity, the fall from the block's top (1.98 m/s) is faster than the body.
  j["Configuration"].erase("gravitation");
  EXPECT_NEAR(sph::scene_scales<2>(parse(j).body<2>()).max_speed, std::sqrt(2 * 9.81 * 0.2), 1e-12);
}

TEST(SceneDefaults, ExplicitValuesAreKept) {
  json j = tank_2d();
  j["Fluid"] = {{"stiffness", 1000}, {"viscosity", 0.5}};
  j["Container"]["wallStiffness"] = 1e5;
  j["Container"]["wallDamping"] = 0;
  j["Configuration"]["timeStepSize"] = 1e-4;
  const sph::SceneDesc d = parse(j);
  const auto& sim = d.body<2>().sim;
  EXPECT_EQ(sim.fluid.stiffness, 1000);
  EXPECT_EQ(sim.fluid.viscosity, 0.5);
  EXPECT_EQ(sim.walls.stiffness, 1e5);
  EXPECT_EQ(sim.walls.damping, 0);
  EXPECT_EQ(sim.time_step, 1e-4);
}

TEST(SceneDefaults, AutoTimeStepFollowsTheGivenValues) {
  json j = tank_2d();
  j["Configuration"]["timeStepSize"] = "auto";
  j["Fluid"]["stiffness"] = 1e4;  // c0 = 100: acoustic 0.4 * 0.04 / 100 = 1.6e-4
  const sph::SceneDesc d = parse(j);
  const auto& sim = d.body<2>().sim;
  EXPECT_NEAR(sim.time_step, 0.8 * 1.6e-4, 1e-15);
  // --set gives "auto" too (a plain string).
  json k = tank_2d();
  k["Configuration"]["timeStepSize"] = 1e-5;
  EXPECT_DOUBLE_EQ(parse(k, {"Configuration.timeStepSize=auto"}).body<2>().sim.time_step,
                   parse(tank_2d()).body<2>().sim.time_step);
}

TEST(SceneDefaults, StopAtGivesTheSteps) {
  json j = tank_2d();
  j["Configuration"].erase("numberOfSteps");
  j["Configuration"]["timeStepSize"] = 1e-4;
  j["Configuration"]["stopAt"] = 0.5;
  EXPECT_EQ(parse(j).steps, 5000);  // a whole number of steps (0.5 / 1e-4 rounds to 5000.000000000001)
  j["Configuration"]["stopAt"] = 0.50001;
  EXPECT_EQ(parse(j).steps, 5001);  // the first step reaching it
  j["Configuration"]["stopAt"] = 1e-9;
  EXPECT_EQ(parse(j).steps, 1);
  j["Configuration"]["stopAt"] = 1e9;
  EXPECT_CONTAINS(error_of(j), "at most 1e12 steps");
  j["Configuration"]["stopAt"] = 0.5;
  j["Configuration"]["numberOfSteps"] = 10;
  EXPECT_CONTAINS(error_of(j), "Configuration.stopAt: numberOfSteps and stopAt both say when the run ends");
}

TEST(SceneDefaults, TheEffectiveSceneGivesTheComputedValuesAndReadsBackEqual) {
  json j = tank_2d();
  j["Configuration"].erase("numberOfSteps");
  j["Configuration"]["stopAt"] = 0.05;
  const sph::SceneDesc d = parse(j);
  const json w = json::parse(sph::scene_text(d));
  const auto& sim = d.body<2>().sim;
  EXPECT_EQ(w["Configuration"]["timeStepSize"], sim.time_step);
  EXPECT_EQ(w["Configuration"]["numberOfSteps"], d.steps);
  EXPECT_FALSE(w["Configuration"].contains("stopAt"));
  EXPECT_EQ(w["Fluid"]["stiffness"], sim.fluid.stiffness);
  EXPECT_EQ(w["Fluid"]["viscosity"], sim.fluid.viscosity);
  EXPECT_EQ(w["Container"]["wallStiffness"], sim.walls.stiffness);
  EXPECT_EQ(w["Container"]["wallDamping"], sim.walls.damping);
  const sph::SceneDesc again = parse(w);
  EXPECT_TRUE(again == d);
  EXPECT_EQ(d.steps, static_cast<std::int64_t>(std::ceil(0.05 / sim.time_step)));
}

TEST(SceneDefaults, WarnsAboutAWallTooSoftForTheHeadOrTheImpact) {
  json j = tank_2d();
  j["Container"]["wallStiffness"] = 9000;  // below 9810 (see TankAtRest2d)
  const sph::SceneDesc d = parse(j);
  ASSERT_EQ(d.warnings.size(), 1u);
  EXPECT_CONTAINS(d.warnings[0], "Container.wallStiffness = 9000 is too low");
  EXPECT_CONTAINS(d.warnings[0], "wallStiffness = 8.83e+04 would hold");
  j["Container"]["wallStiffness"] = 9900;
  EXPECT_TRUE(parse(j).warnings.empty());
  // A fast block needs a stiffer wall: 10 m/s within 2 radii is (10 / 0.02)^2 = 2.5e5.
  j["FluidBlocks"][0]["velocity"] = {10, 0};
  j["Fluid"]["stiffness"] = 1e4;
  j["Configuration"]["timeStepSize"] = 1e-4;
  j["Container"]["wallStiffness"] = 2e5;
  ASSERT_EQ(parse(j).warnings.size(), 1u);
  EXPECT_CONTAINS(parse(j).warnings[0], "a particle arriving at 10.2 m/s");
}

TEST(SceneDefaults, WarnsAboutAnExplicitZeroViscosity) {
  json j = tank_2d();
  j["Fluid"]["viscosity"] = 0;
  const sph::SceneDesc d = parse(j);
  ASSERT_EQ(d.warnings.size(), 1u);
  EXPECT_CONTAINS(d.warnings[0], "Fluid.viscosity = 0: nothing damps");
  EXPECT_CONTAINS(d.warnings[0], "viscosity = 14.9 ");
}

}  // namespace

namespace {

TEST(SceneDefaults, AFlagGivingTheStepsOverridesStopAt) {
  json j = tank_2d();
  j["Configuration"].erase("numberOfSteps");
  j["Configuration"]["timeStepSize"] = 1e-4;
  j["Configuration"]["stopAt"] = 0.5;
  // `sph run --steps 7` is --set Configuration.numberOfSteps=7.
  EXPECT_EQ(parse(j, {"Configuration.numberOfSteps=7"}).steps, 7);
  // The stopAt it overrides is still checked.
  j["Configuration"]["stopAt"] = -1;
  EXPECT_THROW(parse(j, {"Configuration.numberOfSteps=7"}), sph::Error);
  // And the other way round.
  json k = tank_2d();
  k["Configuration"]["timeStepSize"] = 1e-4;
  EXPECT_EQ(parse(k, {"Configuration.stopAt=0.01"}).steps, 100);
  EXPECT_THROW(parse(k, {"Configuration.stopAt=0.01", "Configuration.numberOfSteps=5"}), sph::Error);
}

}  // namespace
