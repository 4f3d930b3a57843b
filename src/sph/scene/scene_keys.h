#pragma once
/// \file The scene format's vocabulary, shared by the reader and the writer: the keys each
/// object may have (docs/scene-format.md) and the names of the enumerated values.
///
/// A new key: add it to its object's list here, read it in scene_reader.cpp, write it in
/// scene_writer.cpp and document it in docs/scene-format.md. Reading or writing an undeclared key
/// is an SPH_CHECK failure, and tests/scene/scene_writer_test.cpp fails until the writer writes
/// every declared key and the reader reads it back to the same value.

#include <algorithm>
#include <string>
#include <vector>

#include <sph/core/error.h>
#include <sph/scene/scene_desc.h>
#include <sph/solver/params.h>

namespace sph::detail {

/// The keys of each object of a scene, in the order the writer writes them. The reader refuses
/// any other key; the writer writes every one (emitEndTime only when an emitter stops), except
/// Configuration.stopAt, the alternative to numberOfSteps: the writer writes the numberOfSteps it
/// gave (kWriterResolvedKeys), or, for a run of CFL steps that ends at a time, stopAt instead.
inline const std::vector<std::string> kRootKeys{"version",     "name",          "description", "units",
                                                "dimension",   "Configuration", "Fluid",       "Container",
                                                "FluidBlocks", "Obstacles",     "Emitters"};
inline const std::vector<std::string> kConfigurationKeys{"precision",          "timeStepSize",
                                                         "numberOfSteps",      "stopAt",
                                                         "particleRadius",     "kernelRadius",
                                                         "gravitation",        "neighbors",
                                                         "fullRebuildPeriod",  "flagNearMovingBodies",
                                                         "verletSkin",         "trackedSkin",
                                                         "reorderPeriod",      "boundaryHandling",
                                                         "boundaryVolume",     "boundaryPressure",
                                                         "boundaryFriction",   "kernel",
                                                         "outputEveryNSteps",  "outputFps",
                                                         "outputFormats",      "outputFields",
                                                         "outputBoundary",     "cflMethod",
                                                         "cflFactor",          "cflMinTimeStepSize",
                                                         "cflMaxTimeStepSize", "simulationMethod",
                                                         "minIterations",      "maxIterations",
                                                         "maxError",           "enableDivergenceSolver",
                                                         "maxIterationsV",     "maxErrorV"};
inline const std::vector<std::string> kFluidKeys{"density0",
                                                 "stiffness",
                                                 "viscosity",
                                                 "viscosityModel",
                                                 "artificialViscosityAlpha",
                                                 "viscositySolver",
                                                 "viscosityMaxIterations",
                                                 "viscosityMaxError",
                                                 "negativePressure",
                                                 "pressureForce",
                                                 "gradientCorrection",
                                                 "particleMass"};
inline const std::vector<std::string> kContainerKeys{"start", "end", "wallStiffness", "wallDamping"};
inline const std::vector<std::string> kFluidBlockKeys{"start", "end", "velocity"};
inline const std::vector<std::string> kObstacleKeys{
    "start",   "end",      "geometryFile", "translation", "rotationAxis", "rotationAngle", "scale",
    "polygon", "inverted", "motion",       "dynamic",     "density",      "velocity",      "angularVelocity"};
/// The keys of an obstacle's motion of each type (Obstacles[].motion; "type" first), in D
/// dimensions: a 2D rotation turns about the z axis, so it has no "axis".
inline std::vector<std::string> motion_keys(MotionType type, int dimension) {
  switch (type) {
    case MotionType::None:
      return {"type"};
    case MotionType::Oscillation:
      return {"type", "direction", "amplitude", "period", "phase", "rampTime"};
    case MotionType::Rotation:
      if (dimension == 2) return {"type", "center", "angularVelocity", "rampTime"};
      return {"type", "axis", "center", "angularVelocity", "rampTime"};
    case MotionType::Keyframes:
      if (dimension == 2) return {"type", "center", "keys"};
      return {"type", "axis", "center", "keys"};
  }
  return {"type"};
}
/// Every key a motion of any type may have (the reader checks each against the type's own).
inline const std::vector<std::string> kAnyMotionKeys{"type", "direction", "amplitude",       "period", "phase",
                                                     "axis", "center",    "angularVelocity", "keys",   "rampTime"};
/// The keys of one of a keyframes motion's keys.
inline const std::vector<std::string> kMotionKeyKeys{"time", "translation", "rotation"};
/// The keys the writer never writes because the reader resolves them into another key's value.
inline const std::vector<std::string> kWriterResolvedKeys{"stopAt"};
/// An emitter's keys in D dimensions: a 2D nozzle is a line of `width` particles (no height).
inline std::vector<std::string> emitter_keys(int dimension) {
  std::vector<std::string> keys{"translation",     "direction",    "velocity",      "width",      "height",
                                "emitEveryNSteps", "maxParticles", "emitStartTime", "emitEndTime"};
  if (dimension == 2) keys.erase(std::find(keys.begin(), keys.end(), "height"));
  return keys;
}

/// An enumerated value and its name in scene files.
template <class E>
struct Named {
  E value;
  const char* name;
};

inline constexpr Named<Precision> kPrecisionNames[] = {{Precision::Double, "double"}, {Precision::Float, "float"}};
inline constexpr Named<NegativePressure> kNegativePressureNames[] = {{NegativePressure::Clamp, "clamp"},
                                                                     {NegativePressure::Allow, "allow"}};
inline constexpr Named<PressureForce> kPressureForceNames[] = {{PressureForce::Paper, "paper"},
                                                               {PressureForce::Symmetric, "symmetric"},
                                                               {PressureForce::Variational, "variational"}};
inline constexpr Named<GradientCorrection> kGradientCorrectionNames[] = {
    {GradientCorrection::None, "none"}, {GradientCorrection::Renormalize, "renormalize"}};
inline constexpr Named<BoundaryHandling> kBoundaryHandlingNames[] = {{BoundaryHandling::Penalty, "penalty"},
                                                                     {BoundaryHandling::Particles, "particles"}};
inline constexpr Named<BoundaryVolume> kBoundaryVolumeNames[] = {{BoundaryVolume::RestFluid, "rest_fluid"},
                                                                 {BoundaryVolume::Akinci, "akinci"}};
inline constexpr Named<BoundaryPressure> kBoundaryPressureNames[] = {{BoundaryPressure::Extrapolate, "extrapolate"},
                                                                     {BoundaryPressure::Mirror, "mirror"},
                                                                     {BoundaryPressure::None, "none"}};
inline constexpr Named<KernelKind> kKernelNames[] = {
    {KernelKind::Paper, "paper"}, {KernelKind::Cubic, "cubic"}, {KernelKind::Wendland, "wendland"}};
inline constexpr Named<SimulationMethod> kSimulationMethodNames[] = {{SimulationMethod::Wcsph, "wcsph"},
                                                                     {SimulationMethod::Dfsph, "dfsph"}};
inline constexpr Named<TimeStepping> kCflMethodNames[] = {{TimeStepping::Fixed, "none"}, {TimeStepping::Cfl, "cfl"}};
inline constexpr Named<MotionType> kMotionTypeNames[] = {{MotionType::None, "none"},
                                                         {MotionType::Oscillation, "oscillation"},
                                                         {MotionType::Rotation, "rotation"},
                                                         {MotionType::Keyframes, "keyframes"}};
inline constexpr Named<ViscosityModel> kViscosityModelNames[] = {{ViscosityModel::Paper, "paper"},
                                                                 {ViscosityModel::Artificial, "artificial"}};
inline constexpr Named<ViscositySolve> kViscositySolverNames[] = {{ViscositySolve::Explicit, "explicit"},
                                                                  {ViscositySolve::Implicit, "implicit"}};

/// The names of a table, in its order (the order messages list them in).
template <class E, std::size_t N>
std::vector<std::string> names_of(const Named<E> (&table)[N]) {
  std::vector<std::string> out;
  for (const auto& n : table) out.emplace_back(n.name);
  return out;
}
/// The value named `name`; SPH_CHECK: the table has it (the reader checks names first).
template <class E, std::size_t N>
E value_named(const Named<E> (&table)[N], const std::string& name) {
  for (const auto& n : table)
    if (name == n.name) return n.value;
  SPH_CHECK(false, "scene value name \"" + name + "\" not in its table");
  return table[0].value;
}
/// The name of `value`; SPH_CHECK: the table has it.
template <class E, std::size_t N>
const char* name_of(const Named<E> (&table)[N], E value) {
  for (const auto& n : table)
    if (n.value == value) return n.name;
  SPH_CHECK(false, "scene value without a name in its table");
  return table[0].name;
}

}  // namespace sph::detail
