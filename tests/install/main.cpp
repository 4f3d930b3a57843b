// A user's program of the installed library (tests/install/CMakeLists.txt): a small 2D block of
// water falls in a box for 50 steps; prints the version and the particle count, and checks that the
// fluid fell (downward momentum) at a sane speed. Exits 1 if not.

#include <cstdio>

#include <sph/core/particle_set.h>
#include <sph/core/version.h>
#include <sph/solver/simulation.h>
#include <sph/solver/time_step.h>

int main() {
  sph::SimulationParams<2> p;
  p.time_step = 1e-4;
  p.particle_radius = 0.01;
  p.kernel_radius = 0.04;
  p.particle_mass = 0.4;  // rho0 (2 r)^2 in 2D
  p.gravity = {0.0, -9.81};
  p.container = {{0.0, 0.0}, {0.5, 0.5}};
  sph::ParticleSet<2, double> particles;
  particles.mass = p.particle_mass;
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j) particles.add({0.05 + 0.02 * i, 0.05 + 0.02 * j}, {0.0, 0.0});
  for (const std::string& w : sph::check_time_step(p)) std::printf("warning: %s\n", w.c_str());
  sph::Simulation<2, double> sim(p, std::move(particles));
  for (int s = 0; s < 50; ++s) sim.step();
  const bool fell = sim.momentum()[1] < 0;
  const bool sane = sim.max_speed() < 10;
  std::printf("sph %s: %zu particles, %lld steps, momentum y %.3g kg m/s, max speed %.3g m/s\n", sph::kVersion,
              sim.particles().size(), static_cast<long long>(sim.steps_done()), sim.momentum()[1], sim.max_speed());
  return fell && sane ? 0 : 1;
}
