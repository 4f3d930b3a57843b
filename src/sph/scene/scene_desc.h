#pragma once
/// \file SceneDesc: a scene file's content as plain structs (no JSON types), SI units.

#include <cstdint>
#include <iterator>
#include <string>
#include <vector>

#include <sph/core/particle_fields.h>
#include <sph/scene/frame_formats.h>
#include <sph/solver/params.h>

namespace sph {

enum class Precision { Float, Double };

/// What a run writes as frames and when (Configuration.outputEveryNSteps, outputFps,
/// outputFormats, outputFields).
struct OutputDesc {
  std::int64_t every_steps = 0;  ///< a frame every this many steps (0: none, unless fps > 0)
  /// Frames per simulated second (0: use every_steps): frame k is written at the first step
  /// whose time reaches k / fps.
  double fps = 0;
  std::vector<FrameFormat> formats{FrameFormat::Vtu};  ///< each frame in each of these formats
  std::vector<std::string> fields{std::begin(kFrameFieldNames), std::end(kFrameFieldNames)};  ///< in kFrameFieldNames order
};

/// A box of fluid filled with particles on a lattice of spacing 2 * particleRadius.
template <int D>
struct FluidBlockDesc {
  Box<D> box;
  Vec<D, double> velocity{};  ///< initial velocity, m/s
};

/// The dimension-specific part of a scene.
template <int D>
struct SceneBody {
  SimulationParams<D> sim;
  std::vector<FluidBlockDesc<D>> blocks;
};

struct SceneDesc {
  int version = 1;
  std::string name;         ///< short name, used for the default output directory
  std::string description;
  std::string source;       ///< file the scene was read from (or "<string>")
  int dimension = 3;
  Precision precision = Precision::Double;
  std::int64_t steps = 0;               ///< number of time steps to run
  OutputDesc output;                    ///< frame formats, fields and schedule
  SceneBody<2> body2;  ///< filled when dimension == 2
  SceneBody<3> body3;  ///< filled when dimension == 3
  std::string effective_json;           ///< the scene as read, after --set overrides (pretty JSON)
  std::vector<std::string> warnings;    ///< non-fatal problems found while reading (e.g. dt close to a limit)

  template <int D>
  SceneBody<D>& body() {
    if constexpr (D == 2) return body2; else return body3;
  }
  template <int D>
  const SceneBody<D>& body() const {
    if constexpr (D == 2) return body2; else return body3;
  }
};

}  // namespace sph
