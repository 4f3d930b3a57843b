// Scenes that give only the required keys (dimension, particleRadius, the container's corners,
// the fluid, the run's length) settle and stay settled on the defaults derived from their scales
// (scene/scales.h, docs/reliability.md "Defaults"): in 2D and 3D, at rest and in a dam break, at
// several particle radii, over thousands of steps. Every step: no particle outside the container,
// the largest speed below a third of the sound speed; at the end: near rest, densities near rho0.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <sph/scene/builders.h>
#include <sph/scene/scales.h>
#include <sph/scene/scene_reader.h>

namespace {

/// What a run did, over all its steps and at its end.
struct Settling {
  std::int64_t steps = 0;
  std::size_t particles = 0;
  std::size_t most_outside = 0;  ///< the most particles outside the container in any step
  double peak_mach = 0;          ///< the largest max|v| / c0 of any step
  double peak_speed = 0;         ///< m/s
  double end_speed = 0;          ///< the largest speed over the last tenth of the steps, m/s
  double end_bulk_speed = 0;     ///< the largest 95th-percentile speed over the last tenth, m/s
  double free_fall = 0;          ///< sqrt(2 g H) of the scene's scales, m/s
  double peak_kinetic = 0;
  double peak_density = 0;      ///< the largest rho / rho0 of any particle in any step
  double end_kinetic = 0;       ///< at the last step
  double end_max_density = 0;   ///< the largest rho / rho0 at the end
  double end_mean_density = 0;  ///< the mean rho / rho0 at the end
};

template <int D>
Settling run_scene(const std::string& json) {
  const sph::SceneDesc desc = sph::parse_scene(json, "settling.json");
  EXPECT_TRUE(desc.warnings.empty()) << desc.warnings.front();
  auto sim = sph::make_simulation<D, double>(desc);
  const auto& p = sim.params();
  const double c0 = std::sqrt(p.fluid.stiffness), rho0 = p.fluid.rest_density;
  Settling s;
  s.steps = desc.steps;
  s.free_fall = sph::scene_scales<D>(desc.body<D>()).max_speed;
  for (std::int64_t n = 0; n < desc.steps; ++n) {
    sim.step();
    const auto& ps = sim.particles();
    std::size_t outside = 0;
    for (std::size_t i = 0; i < ps.size(); ++i) s.peak_density = std::max(s.peak_density, ps.density[i] / rho0);
    for (std::size_t i = 0; i < ps.size(); ++i)
      for (int d = 0; d < D; ++d)
        if (ps.position[i][d] < p.container.lo[d] || ps.position[i][d] > p.container.hi[d]) {
          ++outside;
          break;
        }
    s.most_outside = std::max(s.most_outside, outside);
    const double v = sim.max_speed(), ke = sim.kinetic_energy();
    s.peak_speed = std::max(s.peak_speed, v);
    s.peak_mach = std::max(s.peak_mach, v / c0);
    s.peak_kinetic = std::max(s.peak_kinetic, ke);
    if (10 * n >= 9 * desc.steps) {
      s.end_speed = std::max(s.end_speed, v);
      std::vector<double> speeds(ps.size());
      for (std::size_t i = 0; i < ps.size(); ++i) speeds[i] = sph::norm(ps.velocity[i]);
      const auto at = speeds.begin() + static_cast<std::ptrdiff_t>(speeds.size() * 95 / 100);
      std::nth_element(speeds.begin(), at, speeds.end());
      s.end_bulk_speed = std::max(s.end_bulk_speed, *at);
    }
    s.end_kinetic = ke;
  }
  const auto& ps = sim.particles();
  s.particles = ps.size();
  double sum = 0;
  for (std::size_t i = 0; i < ps.size(); ++i) {
    s.end_max_density = std::max(s.end_max_density, ps.density[i] / rho0);
    sum += ps.density[i] / rho0;
  }
  s.end_mean_density = sum / static_cast<double>(ps.size());
  std::printf(
      "  %lld steps of %.3g s, %zu particles: outside %zu, peak Mach %.3f, speed peak %.3g end %.3g (free fall "
      "%.3g, 95 %% end %.3g) m/s, kinetic peak %.3g end %.3g, density peak %.4f end max %.4f mean %.4f\n",
      static_cast<long long>(s.steps), p.time_step, s.particles, s.most_outside, s.peak_mach, s.peak_speed, s.end_speed,
      s.free_fall, s.end_bulk_speed, s.peak_kinetic, s.end_kinetic, s.peak_density, s.end_max_density,
      s.end_mean_density);
  return s;
}

/// A tank at rest: contained, subsonic, at rest at the end (95 % of the particles slower than
/// 2 % of the free-fall speed sqrt(2 g H) over the last tenth of the run; a particle at the free
/// surface may still hop, the clamped equation of state's surface noise, at under a third of
/// it), densities within a few percent.
void expect_settled_at_rest(const Settling& s) {
  EXPECT_EQ(s.most_outside, 0u);
  EXPECT_LT(s.peak_mach, 0.1);
  EXPECT_LT(s.end_bulk_speed, 0.02 * s.free_fall) << "not at rest at the end";
  EXPECT_LT(s.end_speed, 0.3 * s.free_fall) << "a particle still runs at the end";
  EXPECT_LT(s.end_max_density, 1.03);
  EXPECT_GT(s.end_mean_density, 0.9);
}

/// A dam break: contained and subsonic throughout, its motion decaying.
void expect_settling_dam_break(const Settling& s) {
  EXPECT_EQ(s.most_outside, 0u);
  EXPECT_LT(s.peak_mach, 0.3);
  EXPECT_LT(s.end_kinetic, 0.25 * s.peak_kinetic) << "the motion does not decay";
  EXPECT_LT(s.end_max_density, 1.1);
  EXPECT_GT(s.end_mean_density, 0.85);
}

std::string tank_2d(double r, double width, double depth, double stop) {
  return fmt::format(R"({{ "version": 1, "dimension": 2,
    "Configuration": {{ "particleRadius": {}, "stopAt": {} }},
    "Container": {{ "start": [0, 0], "end": [{}, {}] }},
    "FluidBlocks": [ {{ "start": [0, 0], "end": [{}, {}] }} ] }})",
                     r, stop, width, 1.5 * depth, width, depth);
}

TEST(Settling, TankAtRest2dAtSeveralRadii) {
  for (double r : {0.005, 0.0035, 0.0025}) {
    SCOPED_TRACE(fmt::format("particleRadius {}", r));
    expect_settled_at_rest(run_scene<2>(tank_2d(r, 30 * r, 30 * r, 2.0)));
  }
}

TEST(Settling, DamBreak2d) {
  for (double r : {0.01, 0.0075}) {
    SCOPED_TRACE(fmt::format("particleRadius {}", r));
    const std::string scene = fmt::format(R"({{ "version": 1, "dimension": 2,
      "Configuration": {{ "particleRadius": {}, "stopAt": 1.5 }},
      "Container": {{ "start": [0, 0], "end": [0.8, 0.5] }},
      "FluidBlocks": [ {{ "start": [0, 0], "end": [0.2, 0.4] }} ] }})",
                                          r);
    expect_settling_dam_break(run_scene<2>(scene));
  }
}

TEST(Settling, TankAtRest3d) {
  for (double r : {0.01, 0.0075}) {
    SCOPED_TRACE(fmt::format("particleRadius {}", r));
    const std::string scene = fmt::format(R"({{ "version": 1, "dimension": 3,
      "Configuration": {{ "particleRadius": {}, "stopAt": 2.0 }},
      "Container": {{ "start": [0, 0, 0], "end": [0.12, 0.15, 0.12] }},
      "FluidBlocks": [ {{ "start": [0, 0, 0], "end": [0.12, 0.09, 0.12] }} ] }})",
                                          r);
    expect_settled_at_rest(run_scene<3>(scene));
  }
}

TEST(Settling, DamBreak3d) {
  const std::string scene = R"({ "version": 1, "dimension": 3,
    "Configuration": { "particleRadius": 0.01, "stopAt": 1.5 },
    "Container": { "start": [0, 0, 0], "end": [0.4, 0.3, 0.1] },
    "FluidBlocks": [ { "start": [0, 0, 0], "end": [0.1, 0.2, 0.1] } ] })";
  expect_settling_dam_break(run_scene<3>(scene));
}

}  // namespace
