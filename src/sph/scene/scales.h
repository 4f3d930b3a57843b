#pragma once
/// \file Scene scale estimates: the heights, speeds and stiffnesses a scene's own geometry
/// implies, and the defaults derived from them (docs/reliability.md, "Defaults"). One place for
/// the formulas: the scene reader fills absent keys with them and warns about explicit values
/// they show cannot hold; the time-step limits themselves are in solver/time_step.h.

#include <sph/scene/scene_desc.h>

namespace sph {

/// The sound speed a default stiffness gives, in units of the expected largest speed: 10, a
/// Mach number of 0.1 and about 1 % density variation (Monaghan 1992, 2005).
inline constexpr double kSoundSpeedPerSpeed = 10;
/// The largest penetration into a wall a resting bottom particle may need to carry the
/// hydrostatic head, as a fraction of the particle radius (the springs act within one radius).
inline constexpr double kHeadPenetrationFraction = 0.5;
/// The speed the defaults are designed for (the sound speed 10 times it, the walls stopping it
/// within one radius), in units of the expected largest speed: splashes and jets off an impact
/// (and a dam break's surge front, 2 sqrt(g H) by Ritter's solution) run faster than the free
/// fall that starts them.
inline constexpr double kDesignSpeedFactor = 1.5;

/// What a scene's geometry implies, from its parameters, blocks and emitters (SI units).
struct SceneScales {
  double gravity = 0;      ///< |g|, m/s^2
  double fall_height = 0;  ///< height of the highest fluid (block top, nozzle) above the container floor along g, m
  /// The hydrostatic head: the deepest column at rest, the larger of the highest block top above
  /// the floor and the depth all the fluid (blocks and emitters' budgets) would fill, m.
  double head = 0;
  /// The expected largest speed: free fall from the highest fluid to the floor, sqrt(2 g H),
  /// added (in energy) to a block's initial speed or an emitter's speed, or a moving obstacle's
  /// surface speed (a prescribed motion's peak, a floating body's initial one) if larger, m/s.
  double max_speed = 0;
};

/// The scales of `body` (its sim: container, gravity, particleRadius and emitters; its blocks).
template <int D>
SceneScales scene_scales(const SceneBody<D>& body);

/// The EOS stiffness giving a sound speed kSoundSpeedPerSpeed times `speed`: k = (10 v)^2, m^2/s^2.
double stiffness_for_speed(double speed);
/// The default stiffness: stiffness_for_speed(kDesignSpeedFactor * s.max_speed).
double default_stiffness(const SceneScales& s);

/// The speed a wall must stop: the expected largest speed, or, when the scene has no gravity
/// and nothing in it moves, a tenth of the sound speed sqrt(stiffness) (the weakly
/// compressible model's own bound on speeds), m/s.
double wall_impact_speed(const SceneScales& s, double stiffness);

/// The wall stiffness (1/s^2) that carries the head at rest: a bottom particle carries g H / dx
/// per unit mass (the column above it, dx = 2 r), taken by a penetration of at most `fraction`
/// of the particle radius r: k_w = g H / (dx fraction r).
double wall_stiffness_for_head(const SceneScales& s, double particle_radius, double fraction);
/// The wall stiffness that stops speed v within `distance` (spring energy 1/2 k_w d^2 = 1/2 v^2):
/// k_w = (v / distance)^2.
double wall_stiffness_for_impact(double speed, double distance);
/// The default wall stiffness: the larger of the head at kHeadPenetrationFraction of the radius
/// and kDesignSpeedFactor times the impact speed stopped within one radius.
double default_wall_stiffness(const SceneScales& s, double particle_radius, double stiffness);
/// The stiffness below which an explicit wall cannot hold (a read-time warning): the head with
/// the bottom particles' centres reaching the wall (penetration r), or the impact speed not
/// stopped within two radii (the centre a radius past the wall).
double least_holding_wall_stiffness(const SceneScales& s, double particle_radius, double stiffness);

/// Critical damping of a unit-mass spring of stiffness k_w: 2 sqrt(k_w), 1/s.
double critical_wall_damping(double wall_stiffness);

}  // namespace sph
