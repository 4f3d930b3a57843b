#pragma once
/// \file The preflight: checks of a whole scene, after every key was read and checked on its own,
/// that refuse what cannot work and warn about what probably will not, each with advice computed
/// from the scene (docs/reliability.md, "Preflight"). parse_scene runs it once, at the end of
/// reading, so `sph run`, the library and the fuzzer all get it.

#include <cstdint>

#include <sph/scene/object_reader.h>
#include <sph/scene/scene_desc.h>

namespace sph {

/// Two fluid blocks whose particles come closer than this many spacings are refused (blocks
/// sharing a face are a whole spacing apart).
inline constexpr double kMinBlockGapSpacings = 0.5;
/// How far in front of a nozzle, in spacings, an obstacle or fluid block draws a warning.
inline constexpr double kNozzlePathSpacings = 4;
/// The float (or double) spacing of the largest coordinate, |x| * epsilon, as a fraction of the
/// particle spacing: above the first a warning, above the second a refusal (initial densities
/// measured off rho0 by about 0.05 % and 0.5 %).
inline constexpr double kCoordinateWarnFraction = 1e-3;
inline constexpr double kCoordinateRefuseFraction = 1e-2;
/// Fluid.particleMass against the lattice mass (the default, which gives density0 on the
/// initial lattice): beyond the first factor either way a warning, beyond the second a refusal.
inline constexpr double kMassWarnFactor = 1.1;
inline constexpr double kMassRefuseFactor = 10;

/// Checks the D-dimensional scene just read into `desc` as a whole: obstacles inside the
/// container and leaving room for the fluid, coordinates not too far from the origin for the
/// precision, no overlapping fluid blocks, no block in an obstacle, every nozzle particle inside
/// the container and clear of obstacles and blocks, emitter windows, the particle mass, and
/// negativePressure "allow" with a free surface. Throws sph::Error through ctx.fail (naming
/// the key path) for a refusal; appends warnings to desc.warnings.
template <int D>
void preflight(SceneDesc& desc, const detail::ReadContext& ctx);

namespace detail {

/// The shortest distance between a particle of a block filling box `a` and one of a block
/// filling box `b`, both filled as build_particles does at spacing dx.
template <int D>
double lattice_gap(const Box<D>& a, const Box<D>& b, double dx);

/// How many particles e emits in a run of `steps` steps of dt from step 0, on the schedule of
/// Simulation::emit (the first batch at the first step whose time reaches emitStartTime less
/// half a step, then one every emitEveryNSteps steps while the time is not past emitEndTime).
template <int D>
std::int64_t emitted_in_run(const EmitterParams<D>& e, std::int64_t steps, double dt);

}  // namespace detail

}  // namespace sph
