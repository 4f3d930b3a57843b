#pragma once
/// \file SceneDesc: a scene file's content as plain structs (no JSON types), SI units.

#include <algorithm>
#include <cstdint>
#include <iterator>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include <sph/core/error.h>
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
  std::vector<std::string> fields{std::begin(kFrameFieldNames),
                                  std::end(kFrameFieldNames)};  ///< in kFrameFieldNames order
  /// Write the boundary particles (their positions and psi) once, as boundary.vtu in the run
  /// directory (Configuration.outputBoundary).
  bool boundary = false;

  /// Whether the run writes frames at all (a schedule: every_steps or fps).
  bool writes_frames() const { return every_steps > 0 || fps > 0; }
  /// Whether its frames hold the field `name`.
  bool frames_hold(std::string_view name) const {
    return writes_frames() && std::find(fields.begin(), fields.end(), name) != fields.end();
  }

  friend bool operator==(const OutputDesc&, const OutputDesc&) = default;
};

/// A box of fluid filled with particles on a lattice of spacing 2 * particleRadius.
template <int D>
struct FluidBlockDesc {
  Box<D> box;
  Vec<D, double> velocity{};  ///< initial velocity, m/s

  friend bool operator==(const FluidBlockDesc&, const FluidBlockDesc&) = default;
};

/// The dimension-specific part of a scene.
template <int D>
struct SceneBody {
  SimulationParams<D> sim;
  std::vector<FluidBlockDesc<D>> blocks;

  friend bool operator==(const SceneBody&, const SceneBody&) = default;
};

/// A scene: the settings of any dimension, and one body of the scene's dimension.
///
/// Written out with scene_to_json (scene_writer.h), which parse_scene reads back to an equal
/// SceneDesc.
struct SceneDesc {
  int version = 1;
  std::string name;  ///< short name, used for the default output directory
  std::string description;
  std::string source;  ///< file the scene was read from (or "<string>")
  /// 2 or 3: the dimension of the body; set together with it by set_body().
  int dimension = 3;
  Precision precision = Precision::Double;
  std::int64_t steps = 0;  ///< number of time steps to run (with end_time: the most it may take)
  /// A run of CFL steps (TimeStepping::Cfl) given by Configuration.stopAt ends at this simulated
  /// time, s; 0: the run ends after `steps` steps.
  double end_time = 0;
  OutputDesc output;                  ///< frame formats, fields and schedule
  std::vector<std::string> warnings;  ///< non-fatal problems found while reading (e.g. dt close to a limit)

  /// The body; SPH_CHECK: D is the scene's dimension.
  template <int D>
  SceneBody<D>& body() {
    check_dimension(D);
    return std::get<SceneBody<D>>(body_);
  }
  template <int D>
  const SceneBody<D>& body() const {
    check_dimension(D);
    return std::get<SceneBody<D>>(body_);
  }

  /// Makes the scene D-dimensional with body `b` (dimension becomes D).
  template <int D>
  SceneBody<D>& set_body(SceneBody<D> b = {}) {
    dimension = D;
    return body_.template emplace<SceneBody<D>>(std::move(b));
  }

  /// Calls f(body) with the body of the scene's dimension (a SceneBody<2> or <3>), for code that
  /// does the same in either dimension; returns what f returns.
  template <class F>
  decltype(auto) visit_body(F&& f) {
    check_dimension(dimension);
    return std::visit(std::forward<F>(f), body_);
  }
  template <class F>
  decltype(auto) visit_body(F&& f) const {
    check_dimension(dimension);
    return std::visit(std::forward<F>(f), body_);
  }

  /// The simulation settings callers choose whatever the dimension (the --audit and --neighbors flags).
  void set_audit(bool on) {
    visit_body([&](auto& b) { b.sim.audit = on; });
  }
  void set_neighbors(NeighborMode mode) {
    visit_body([&](auto& b) { b.sim.neighbors = mode; });
  }

  friend bool operator==(const SceneDesc&, const SceneDesc&) = default;

 private:
  void check_dimension(int d) const {
    SPH_CHECK(d == dimension && static_cast<int>(body_.index()) + 2 == d,
              "SceneDesc: body of a dimension other than the scene's");
  }

  std::variant<SceneBody<2>, SceneBody<3>> body_{SceneBody<3>{}};
};

}  // namespace sph
