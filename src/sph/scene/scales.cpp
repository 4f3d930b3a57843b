#include <sph/scene/scales.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include <sph/solver/motion.h>

namespace sph {

namespace {

/// The height of x above the container floor along unit gravity direction `down`: the container's
/// lowest point along `down` minus x's.
template <int D>
double height_above_floor(const Vec<D, double>& x, const Box<D>& container, const Vec<D, double>& down) {
  double floor = 0, at = 0;
  for (int d = 0; d < D; ++d) {
    floor += down[d] * (down[d] > 0 ? container.hi[d] : container.lo[d]);
    at += down[d] * x[d];
  }
  return std::max(0.0, floor - at);
}

/// The highest point of box b along `down` (its corner least far down).
template <int D>
Vec<D, double> top_of(const Box<D>& b, const Vec<D, double>& down) {
  Vec<D, double> x;
  for (int d = 0; d < D; ++d) x[d] = down[d] > 0 ? b.lo[d] : b.hi[d];
  return x;
}

/// The largest speed obstacle k's surface reaches: a prescribed motion's over its ramp and a
/// period after it (an oscillation's), over its keys (keyframes', at their intervals' middles
/// too); a floating body's at its start (its speed plus its spin times its half diagonal).
template <int D>
double obstacle_peak_speed(const SimulationParams<D>& sim, std::size_t k) {
  const Vec<D, double>& lo = sim.obstacles[k].lo;
  const Vec<D, double>& hi = sim.obstacles[k].hi;
  const BodyParams<D>& body = obstacle_body(sim, k);
  if (body.dynamic)
    return std::sqrt(norm2(body.velocity)) + std::sqrt(norm2(body.angular_velocity)) * 0.5 * norm(hi - lo);
  const ObstacleMotion<D>& m = obstacle_motion(sim, k);
  if (!m.moves()) return 0;
  std::vector<double> times;
  const double span = m.ramp_time + (m.type == MotionType::Oscillation ? m.period : 0);
  constexpr int kSamples = 256;
  for (int j = 0; j <= kSamples; ++j) times.push_back(span * j / kSamples);
  for (std::size_t j = 0; j < m.keys.size(); ++j) {
    times.push_back(m.keys[j].time);
    if (j > 0) times.push_back(0.5 * (m.keys[j - 1].time + m.keys[j].time));
  }
  double fastest = 0;
  for (const double t : times) fastest = std::max(fastest, max_surface_speed(m, lo, hi, t));
  return std::isfinite(fastest) ? fastest : 0;  // (an overflowing motion is refused by the preflight)
}

}  // namespace

template <int D>
SceneScales scene_scales(const SceneBody<D>& body) {
  const SimulationParams<D>& sim = body.sim;
  SceneScales s;
  s.gravity = norm(sim.gravity);
  Vec<D, double> down{};
  if (s.gravity > 0) down = sim.gravity * (1.0 / s.gravity);
  const double dx = 2.0 * sim.particle_radius;
  double volume = 0;  // of all the fluid, blocks and emitters' budgets, m^D
  double fastest2 = 0;
  for (const FluidBlockDesc<D>& b : body.blocks) {
    double v = 1;
    for (int d = 0; d < D; ++d) v *= b.box.hi[d] - b.box.lo[d];
    volume += v;
    const double top = height_above_floor<D>(top_of<D>(b.box, down), sim.container, down);
    s.fall_height = std::max(s.fall_height, top);
    s.head = std::max(s.head, top);
    fastest2 = std::max(fastest2, norm2(b.velocity) + 2 * s.gravity * top);
  }
  for (const EmitterParams<D>& e : sim.emitters) {
    volume += static_cast<double>(e.max_particles) * std::pow(dx, D);
    const double top = height_above_floor<D>(e.origin, sim.container, down);
    s.fall_height = std::max(s.fall_height, top);
    fastest2 = std::max(fastest2, e.speed * e.speed + 2 * s.gravity * top);
  }
  // A moving obstacle drives the fluid at its surface's speed; a floating body starts at its own.
  for (std::size_t k = 0; k < sim.obstacles.size(); ++k)
    fastest2 = std::max(fastest2, std::pow(obstacle_peak_speed(sim, k), 2));
  if (s.gravity > 0) {
    // The depth the fluid fills: its volume over the container's section across g (the
    // container's volume over its extent along g), at most that extent.
    double extent = 0, container_volume = 1;
    for (int d = 0; d < D; ++d) {
      const double side = sim.container.hi[d] - sim.container.lo[d];
      extent += std::abs(down[d]) * side;
      container_volume *= side;
    }
    s.head = std::max(s.head, std::min(extent, volume * extent / container_volume));
  }
  s.max_speed = std::sqrt(fastest2);
  return s;
}

double stiffness_for_speed(double speed) {
  const double c0 = kSoundSpeedPerSpeed * speed;
  return c0 * c0;
}

double default_stiffness(const SceneScales& s) { return stiffness_for_speed(kDesignSpeedFactor * s.max_speed); }

double wall_impact_speed(const SceneScales& s, double stiffness) {
  return s.max_speed > 0 ? s.max_speed : std::sqrt(stiffness) / kSoundSpeedPerSpeed;
}

double wall_stiffness_for_head(const SceneScales& s, double particle_radius, double fraction) {
  return s.gravity * s.head / (2.0 * particle_radius * fraction * particle_radius);
}

double wall_stiffness_for_impact(double speed, double distance) { return (speed / distance) * (speed / distance); }

double default_wall_stiffness(const SceneScales& s, double particle_radius, double stiffness) {
  return std::max(wall_stiffness_for_head(s, particle_radius, kHeadPenetrationFraction),
                  wall_stiffness_for_impact(kDesignSpeedFactor * wall_impact_speed(s, stiffness), particle_radius));
}

double least_holding_wall_stiffness(const SceneScales& s, double particle_radius, double stiffness) {
  return std::max(wall_stiffness_for_head(s, particle_radius, 1.0),
                  wall_stiffness_for_impact(wall_impact_speed(s, stiffness), 2.0 * particle_radius));
}

double critical_wall_damping(double wall_stiffness) { return 2.0 * std::sqrt(wall_stiffness); }

template SceneScales scene_scales<2>(const SceneBody<2>&);
template SceneScales scene_scales<3>(const SceneBody<3>&);

}  // namespace sph
