// The health monitor: what the integrate pass measures (containment, Mach, density ratio,
// energy), the same for any thread count; each threshold of kHealthWatches warns once or fails
// the step with a message naming the step, the particle, the value and the advice; its state
// survives save/load.

#include <cmath>
#include <sstream>

#include <gtest/gtest.h>

#include <sph/core/error.h>
#include <sph/core/parallel.h>
#include <sph/core/state_stream.h>
#include <sph/solver/simulation.h>
#include <sph/solver/wcsph.h>

#include "support/thread_count.h"

namespace sph {
namespace {

using test::ThreadCount;

/// A 2D tank, 0.4 m x 0.4 m, with an nx x ny block of water at rest in its corner (spacing 0.02 m).
SimulationParams<2> tank_params() {
  SimulationParams<2> p;
  p.particle_radius = 0.01;
  p.kernel_radius = 0.04;
  p.time_step = 2e-4;
  p.fluid.stiffness = 1000;
  p.fluid.viscosity = 2.0;
  p.particle_mass = lattice_mass<2>(1000, 0.02, 0.04);
  p.walls.stiffness = 1e6;
  p.walls.damping = 2000;
  p.gravity[1] = -9.81;
  p.container.lo = {{0, 0}};
  p.container.hi = {{0.4, 0.4}};
  return p;
}

ParticleSet<2, double> block(int nx, int ny, double x0 = 0.01, double y0 = 0.01, Vec<2, double> v = {}) {
  ParticleSet<2, double> ps;
  ps.mass = lattice_mass<2>(1000, 0.02, 0.04);
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j) ps.add(Vec<2, double>{x0 + 0.02 * i, y0 + 0.02 * j}, v);
  return ps;
}

/// The message of the sph::Error that `f` throws ("" if none).
template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return {};
}

TEST(Health, ATankAtRestIsContainedSubsonicAndLosesEnergy) {
  Simulation<2, double> sim(tank_params(), block(10, 10));
  const double e0 = sim.health().initial_energy();
  // Potential energy from the container's floor: sum m g y over the lattice.
  double expected = 0;
  for (std::size_t i = 0; i < sim.particles().size(); ++i)
    expected += sim.particles().mass * 9.81 * sim.particles().position[i][1];
  EXPECT_NEAR(e0, expected, 1e-9 * expected) << "at rest, clear of the walls' contact zones";
  for (int s = 0; s < 500; ++s) {
    const StepInfo& info = sim.step();
    ASSERT_EQ(info.health.outside, 0u);
    ASSERT_EQ(info.health.new_warnings, 0u) << sim.health().warnings().at(0);
    ASSERT_LT(info.health.max_mach, 0.1);
    ASSERT_GE(info.health.rho_max, 1.0);
    ASSERT_LT(info.health.rho_max, 1.1);
    ASSERT_LT(info.health.energy, e0 * (1 + 1e-3));
  }
  EXPECT_LT(sim.last_step().health.energy, e0) << "viscosity and damped walls dissipate";
  EXPECT_TRUE(sim.health().warnings().empty());
}

TEST(Health, StatisticsAreTheSameForAnyThreadCount) {
  ThreadCount restore;
  const auto run = [](int threads) {
    set_num_threads(threads);
    // 2,100 particles (three chunks), thrown at the right wall: contacts, compression, a spread of speeds.
    SimulationParams<2> p = tank_params();
    p.container.hi = {{1.3, 0.8}};
    Simulation<2, double> sim(p, block(60, 35, 0.01, 0.01, {{3.0, 0.0}}));
    for (int s = 0; s < 40; ++s) sim.step();
    return sim.last_step().health;
  };
  const HealthStats a = run(1), b = run(2);
  EXPECT_EQ(a.energy, b.energy);
  EXPECT_EQ(a.max_mach, b.max_mach);
  EXPECT_EQ(a.mach_id, b.mach_id);
  EXPECT_EQ(a.rho_min, b.rho_min);
  EXPECT_EQ(a.rho_max, b.rho_max);
  EXPECT_EQ(a.rho_max_id, b.rho_max_id);
  EXPECT_EQ(a.outside_depth, b.outside_depth);
}

TEST(Health, StatisticsMeasuredInBatchesAreThoseOfOneParticleAtATime) {
  // The integrate pass measures the particles of a scene without obstacles in batches (a register
  // of particles at once, then recorded in order) and those of a scene with obstacles one at a
  // time. An obstacle that no particle comes near changes nothing else: the statistics of every
  // step must be the same bits either way, in both precisions.
  const auto run = [](auto real, bool obstacle) {
    using R = decltype(real);
    SimulationParams<2> p = tank_params();
    p.container.hi = {{1.21, 1.2}};  // (the block's right column at r from the wall)
    p.walls.stiffness = 1e5;         // (the thrown block presses into the wall: its springs in the energy)
    p.walls.damping = 600;
    if (obstacle) p.obstacles.push_back({{{1.1, 1.0}}, {{1.2, 1.1}}});  // (0.3 m above the fluid)
    // 2,102 particles (eight full chunks and 54: whole batches and a remainder), thrown at the right
    // wall, and one 1.5 cm past the left wall and one past the right (outside, under 1 % of them
    // and within h).
    ParticleSet<2, double> d = block(60, 35, 0.01, 0.01, {{3.0, 0.0}});
    d.add(Vec<2, double>{-0.015, 0.3}, {});
    d.add(Vec<2, double>{1.225, 0.9}, {});
    ParticleSet<2, R> ps;
    ps.mass = static_cast<R>(d.mass);
    for (std::size_t i = 0; i < d.size(); ++i) ps.add(vec_cast<R>(d.position[i]), vec_cast<R>(d.velocity[i]));
    Simulation<2, R> sim(p, std::move(ps));
    std::vector<HealthStats> steps;
    for (int s = 0; s < 60; ++s) steps.push_back(sim.step().health);
    return std::pair(steps, sim.particles().position);
  };
  const auto compare = [&run](auto real) {
    const auto [batched, x_batched] = run(real, false);
    const auto [single, x_single] = run(real, true);
    ASSERT_EQ(x_batched, x_single) << "the far obstacle changed the flow: the comparison would mean nothing";
    std::uint64_t outside = 0;
    double compressed = 0;
    for (std::size_t s = 0; s < batched.size(); ++s) {
      const HealthStats& a = batched[s];
      const HealthStats& b = single[s];
      EXPECT_EQ(a.energy, b.energy) << "step " << s;
      EXPECT_EQ(a.max_mach, b.max_mach) << "step " << s;
      EXPECT_EQ(a.mach_id, b.mach_id) << "step " << s;
      EXPECT_EQ(a.rho_min, b.rho_min) << "step " << s;
      EXPECT_EQ(a.rho_max, b.rho_max) << "step " << s;
      EXPECT_EQ(a.rho_max_id, b.rho_max_id) << "step " << s;
      EXPECT_EQ(a.outside, b.outside) << "step " << s;
      EXPECT_EQ(a.outside_depth, b.outside_depth) << "step " << s;
      EXPECT_EQ(a.outside_id, b.outside_id) << "step " << s;
      EXPECT_EQ(b.inside_solid, 0u);
      outside += a.outside;
      compressed = std::max(compressed, a.rho_max);
    }
    EXPECT_GT(outside, 0u) << "a particle was outside: the count and depth were compared";
    EXPECT_GT(compressed, 1.0) << "the block was compressed against the wall";
  };
  compare(0.0);
  compare(0.0f);
}

TEST(Health, BoundaryParticleScenesGetStepAndModeAdviceNotWallSprings) {
  // A particle beyond h outside a container of boundary particles, in the adaptive mode: the advice
  // names the step and the exact modes (the wall springs do not exist).
  SimulationParams<2> p = tank_params();
  p.boundary.handling = BoundaryHandling::Particles;
  p.neighbors = NeighborMode::Adaptive;
  ParticleSet<2, double> far = block(10, 10, 0.1, 0.1);
  far.add(Vec<2, double>{0.45, 0.2}, Vec<2, double>{2.0, 0.0});
  Simulation<2, double> lost(p, std::move(far));
  const std::string e = error_of([&] { lost.step(); });
  EXPECT_NE(e.find("simulation lost its fluid at step 1"), std::string::npos) << e;
  EXPECT_NE(e.find("boundary particles hold a particle that sees them within h"), std::string::npos) << e;
  EXPECT_NE(e.find("adaptive_exact"), std::string::npos) << e;
  EXPECT_EQ(e.find("wallStiffness"), std::string::npos) << e;
}

TEST(Health, AParticleOutsideTheContainerWarnsOnceAndOneBeyondHFails) {
  // 100 particles and one 1.5 cm past the right wall (tolerance r = 1 cm): under 1 % of them.
  ParticleSet<2, double> ps = block(10, 10, 0.1, 0.1);
  ps.add(Vec<2, double>{0.415, 0.2}, {});
  Simulation<2, double> sim(tank_params(), std::move(ps));
  const StepInfo& first = sim.step();
  EXPECT_EQ(first.health.outside, 1u);
  EXPECT_NEAR(first.health.outside_depth, 0.015, 2e-3);  // after one step of the wall's push
  EXPECT_EQ(first.health.outside_id, 100u);
  EXPECT_EQ(first.health.new_warnings, 1u << static_cast<int>(HealthKind::Outside));
  const std::string w = sim.health().warning(HealthKind::Outside);
  EXPECT_NE(w.find("1 particle outside the container at step 1"), std::string::npos) << w;
  EXPECT_NE(w.find("particle id 100"), std::string::npos) << w;
  EXPECT_NE(w.find("Container.wallStiffness >= (v / r)^2"), std::string::npos) << w;
  const StepInfo& second = sim.step();  // the wall pushes it back in over a few steps
  EXPECT_EQ(second.health.new_warnings, 0u) << "a warning is given once";
  EXPECT_EQ(sim.health().counts()[static_cast<int>(HealthKind::Outside)], 2);

  ParticleSet<2, double> far = block(10, 10, 0.1, 0.1);
  far.add(Vec<2, double>{0.45, 0.2}, {});  // 5 cm past the wall: beyond h = 4 cm
  Simulation<2, double> lost(tank_params(), std::move(far));
  const std::string e = error_of([&] { lost.step(); });
  EXPECT_NE(e.find("simulation lost its fluid at step 1"), std::string::npos) << e;
  EXPECT_NE(e.find("particle id 100"), std::string::npos) << e;
  EXPECT_EQ(lost.steps_done(), 1);

  ParticleSet<2, double> many = block(10, 10, 0.1, 0.1);
  for (int k = 0; k < 2; ++k) many.add(Vec<2, double>{0.415, 0.1 + 0.05 * k}, {});
  Simulation<2, double> leak(tank_params(), std::move(many));
  const std::string e2 = error_of([&] { leak.step(); });
  EXPECT_NE(e2.find("2 of 102 particles are outside the container (more than 1 % of them"), std::string::npos) << e2;
}

TEST(Health, AParticleInsideAnObstacleIsCounted) {
  SimulationParams<2> p = tank_params();
  p.obstacles.push_back({{{0.2, 0.0}}, {{0.3, 0.1}}});
  ParticleSet<2, double> ps = block(10, 10, 0.01, 0.15);
  ps.add(Vec<2, double>{0.25, 0.07}, {});  // 3 cm inside the obstacle's top (tolerance 1 cm)
  Simulation<2, double> sim(p, std::move(ps));
  const StepInfo& info = sim.step();
  EXPECT_EQ(info.health.inside_solid, 1u);
  EXPECT_NEAR(info.health.inside_depth, 0.03, 3e-3);  // after one step of the obstacle's push
  EXPECT_EQ(info.health.inside_id, 100u);
  EXPECT_NE(sim.health().warning(HealthKind::InsideSolid).find("inside an obstacle"), std::string::npos);
}

TEST(Health, ASupersonicParticleFailsTheStepWithTheStiffnessItNeeds) {
  ParticleSet<2, double> ps = block(5, 5, 0.1, 0.1);
  ps.velocity[7] = {{40.0, 0.0}};  // c0 = sqrt(1000) = 31.6 m/s
  Simulation<2, double> sim(tank_params(), std::move(ps));
  const std::string e = error_of([&] { sim.step(); });
  EXPECT_NE(e.find("simulation went supersonic at step 1"), std::string::npos) << e;
  EXPECT_NE(e.find("particle id 7"), std::string::npos) << e;
  EXPECT_NE(e.find("Mach 1.26"), std::string::npos) << e;
  EXPECT_NE(e.find("Fluid.stiffness >= (10 v)^2 = 1.59e+05"), std::string::npos) << e;
}

TEST(Health, MachAboveAThirdWarns) {
  ParticleSet<2, double> ps = block(5, 5, 0.1, 0.1);
  ps.velocity[3] = {{0.0, 15.0}};  // Mach 0.47
  Simulation<2, double> sim(tank_params(), std::move(ps));
  const StepInfo& info = sim.step();
  EXPECT_EQ(info.health.mach_id, 3u);
  EXPECT_NEAR(info.health.max_mach, 15.0 / std::sqrt(1000.0), 0.01);
  EXPECT_TRUE(info.health.new_warnings & (1u << static_cast<int>(HealthKind::Mach)));
  EXPECT_NE(sim.health().warning(HealthKind::Mach).find("Mach 0.473"), std::string::npos)
      << sim.health().warning(HealthKind::Mach);
}

TEST(Health, ANonFiniteVelocityStillBlowsUp) {
  ParticleSet<2, double> ps = block(3, 3, 0.1, 0.1);
  ps.velocity[4] = {{std::nan(""), 0.0}};
  Simulation<2, double> sim(tank_params(), std::move(ps));
  const std::string e = error_of([&] { sim.step(); });
  EXPECT_NE(e.find("simulation blew up at step 1"), std::string::npos) << e;
  EXPECT_NE(e.find("is not finite"), std::string::npos) << e;
}

TEST(Health, AVeryViscousFluidGainingEnergyIsToldOfTheImplicitViscosityNotToRaiseIt) {
  HealthScene scene;
  scene.sound_speed = 10, scene.kernel_radius = 0.04, scene.time_step = 1e-3;
  scene.viscosity = 100;  // Monaghan's alpha = 0.1 is 2.5 Pa s here
  HealthMonitor monitor(scene);
  monitor.set_initial(100.0, 1.0);
  HealthStats s;
  s.energy = 250.0;
  const std::string e = error_of([&] { monitor.check(s, 2, 3e-3, 10); });
  EXPECT_NE(e.find("Fluid.viscositySolver \"implicit\""), std::string::npos) << e;
  EXPECT_EQ(e.find("raise Fluid.viscosity"), std::string::npos) << e;
  scene.implicit_viscosity = true;  // (already implicit: the usual advice)
  HealthMonitor implicit(scene);
  implicit.set_initial(100.0, 1.0);
  const std::string f = error_of([&] { implicit.check(s, 2, 3e-3, 10); });
  EXPECT_EQ(f.find("viscositySolver"), std::string::npos) << f;
}

TEST(Health, EnergyGrowthInAClosedSceneWarns) {
  HealthScene scene;
  scene.sound_speed = 10, scene.kernel_radius = 0.04, scene.time_step = 1e-3;
  HealthMonitor monitor(scene);
  monitor.set_initial(100.0, 1.0);  // scale 100 + 1 * 100 / 2e4
  HealthStats s;
  s.energy = 104.0;
  monitor.check(s, 0, 1e-3, 10);
  EXPECT_EQ(s.new_warnings, 0u) << "4 % is within the margin";
  s.energy = 106.0;
  monitor.check(s, 1, 2e-3, 10);
  EXPECT_EQ(s.new_warnings, 1u << static_cast<int>(HealthKind::Energy));
  EXPECT_NE(monitor.warning(HealthKind::Energy).find("lower Configuration.timeStepSize"), std::string::npos);
  EXPECT_NE(monitor.warning(HealthKind::Energy).find("raise Fluid.viscosity"), std::string::npos);
  s.new_warnings = 0, s.energy = 250.0;
  const std::string e = error_of([&] { monitor.check(s, 2, 3e-3, 10); });
  EXPECT_NE(e.find("simulation gained energy at step 2"), std::string::npos) << e;
  EXPECT_NE(e.find("total energy 250 J is 150 % of its scale above the initial 100 J"), std::string::npos) << e;
  scene.closed = false;  // an emitter adds energy: not judged
  HealthMonitor open(scene);
  open.set_initial(100.0, 1.0);
  open.check(s, 0, 1e-3, 10);
  EXPECT_EQ(s.new_warnings, 0u);
}

TEST(Health, UnderCflStepsTheAdviceNamesTheCflSettings) {
  // With CFL steps Configuration.timeStepSize only starts the run: the advice names cflFactor and
  // cflMaxTimeStepSize, with their values (it named timeStepSize with the largest step's value).
  HealthScene scene;
  scene.sound_speed = 10, scene.kernel_radius = 0.04, scene.time_step = 5e-3;
  scene.cfl = true, scene.cfl_factor = 0.4;
  HealthStats s;
  s.energy = 250.0;
  HealthMonitor monitor(scene);
  monitor.set_initial(100.0, 1.0);
  const std::string e = error_of([&] { monitor.check(s, 2, 3e-3, 10); });
  EXPECT_NE(e.find("lower Configuration.cflFactor (now 0.4, e.g. to 0.2) or cflMaxTimeStepSize (now 0.005 s)"),
            std::string::npos)
      << e;
  EXPECT_EQ(e.find("timeStepSize ("), std::string::npos) << e;
  s.energy = 0, s.rho_max = 1.5;  // WCSPH's compression advice
  HealthMonitor squeezed(scene);
  squeezed.set_initial(0.0, 1.0);
  squeezed.check(s, 2, 3e-3, 10);
  const std::string c = squeezed.warning(HealthKind::Compression);
  EXPECT_NE(c.find("or lower Configuration.cflFactor (now 0.4) or cflMaxTimeStepSize"), std::string::npos) << c;
}

TEST(Health, TheMonitorsStateSurvivesSaveAndLoad) {
  HealthScene scene;
  scene.sound_speed = 10, scene.kernel_radius = 0.04;
  HealthMonitor a(scene);
  a.set_initial(5.0, 2.0);
  HealthStats s;
  s.max_mach = 0.5, s.energy = 4.0, s.outside = 1, s.outside_depth = 1e-3;
  a.check(s, 3, 0.1, 100);
  std::stringstream buf;
  StateWriter w(buf);
  a.save_state(w);
  StateReader r(buf, w.written(), "test");
  HealthMonitor b(scene);
  b.load_state(r);
  EXPECT_EQ(b.warnings(), a.warnings());
  EXPECT_EQ(b.counts(), a.counts());
  EXPECT_EQ(b.initial_energy(), 5.0);
  EXPECT_EQ(b.max_mach(), 0.5);
  HealthStats again = s;
  again.new_warnings = 0;
  b.check(again, 4, 0.2, 100);
  EXPECT_EQ(again.new_warnings, 0u) << "warnings given before the checkpoint are not given again";
}

}  // namespace
}  // namespace sph
