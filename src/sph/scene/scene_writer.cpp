#include <sph/scene/scene_writer.h>

#include <algorithm>
#include <cmath>
#include <string_view>

#include <sph/core/error.h>
#include <sph/scene/direction.h>
#include <sph/scene/scene_keys.h>

namespace sph {

namespace {

using OrderedJson = nlohmann::ordered_json;

/// Builds one object of the scene from the keys declared for it (scene_keys.h), which the
/// reader also goes through: a key the reader would refuse is a bug found here.
class ObjectWriter {
 public:
  explicit ObjectWriter(const std::vector<std::string>& keys) : keys_(keys) {}

  template <class T>
  ObjectWriter& put(const std::string& key, T&& value) {
    SPH_CHECK(std::find(keys_.begin(), keys_.end(), key) != keys_.end(),
              "scene writer: key \"" + key + "\" is not declared for its object");
    j_[key] = std::forward<T>(value);
    return *this;
  }
  OrderedJson take() { return std::move(j_); }

 private:
  const std::vector<std::string>& keys_;
  OrderedJson j_ = OrderedJson::object();
};

template <int D>
OrderedJson vec_json(const Vec<D, double>& v) {
  OrderedJson a = OrderedJson::array();
  for (int d = 0; d < D; ++d) a.push_back(v[d]);
  return a;
}

template <int D>
OrderedJson configuration_json(const SceneDesc& desc, const SimulationParams<D>& sim) {
  const OutputDesc& out = desc.output;
  OrderedJson formats = OrderedJson::array();
  for (FrameFormat f : out.formats) formats.push_back(frame_format_name(f));
  ObjectWriter w(detail::kConfigurationKeys);
  w.put("precision", detail::name_of(detail::kPrecisionNames, desc.precision)).put("timeStepSize", sim.time_step);
  if (desc.end_time > 0)
    w.put("stopAt", desc.end_time);
  else
    w.put("numberOfSteps", desc.steps);
  w.put("particleRadius", sim.particle_radius)
      .put("kernelRadius", sim.kernel_radius)
      .put("gravitation", vec_json<D>(sim.gravity))
      .put("neighbors", std::string(to_string(sim.neighbors)))
      .put("fullRebuildPeriod", sim.full_rebuild_period)
      .put("flagNearMovingBodies", sim.flag_near_moving)
      .put("verletSkin", sim.verlet_skin)
      .put("trackedSkin", sim.tracked_skin)
      .put("reorderPeriod", sim.reorder_period)
      .put("boundaryHandling", detail::name_of(detail::kBoundaryHandlingNames, sim.boundary.handling))
      .put("boundaryVolume", detail::name_of(detail::kBoundaryVolumeNames, sim.boundary.volume))
      .put("boundaryPressure", detail::name_of(detail::kBoundaryPressureNames, sim.boundary.pressure))
      .put("boundaryFriction", sim.boundary.friction)
      .put("kernel", detail::name_of(detail::kKernelNames, sim.fluid.kernel))
      .put("outputEveryNSteps", out.every_steps)
      .put("outputFps", out.fps)
      .put("outputFormats", std::move(formats))
      .put("outputFields", out.fields)
      .put("outputBoundary", out.boundary)
      .put("simulationMethod", detail::name_of(detail::kSimulationMethodNames, sim.method))
      .put("minIterations", sim.dfsph.min_iterations)
      .put("maxIterations", sim.dfsph.max_iterations)
      .put("maxError", sim.dfsph.max_error)
      .put("enableDivergenceSolver", sim.dfsph.divergence_solver)
      .put("maxIterationsV", sim.dfsph.max_iterations_v)
      .put("maxErrorV", sim.dfsph.max_error_v)
      .put("cflMethod", detail::name_of(detail::kCflMethodNames, sim.time_stepping))
      .put("cflFactor", sim.cfl.factor)
      .put("cflMinTimeStepSize", sim.cfl.min_dt)
      .put("cflMaxTimeStepSize", sim.cfl.max_dt);
  return w.take();
}

template <int D>
OrderedJson fluid_json(const SimulationParams<D>& sim) {
  const FluidParams& f = sim.fluid;
  ObjectWriter w(detail::kFluidKeys);
  w.put("density0", f.rest_density)
      .put("stiffness", f.stiffness)
      .put("viscosity", f.viscosity)
      .put("viscosityModel", detail::name_of(detail::kViscosityModelNames, f.viscosity_model))
      .put("artificialViscosityAlpha", f.alpha)
      .put("viscositySolver", detail::name_of(detail::kViscositySolverNames, f.viscosity_solve))
      .put("viscosityMaxIterations", f.viscosity_max_iterations)
      .put("viscosityMaxError", f.viscosity_max_error)
      .put("negativePressure", detail::name_of(detail::kNegativePressureNames, f.negative_pressure))
      .put("pressureForce", detail::name_of(detail::kPressureForceNames, f.pressure_force))
      .put("gradientCorrection", detail::name_of(detail::kGradientCorrectionNames, f.gradient_correction))
      .put("particleMass", sim.particle_mass);
  return w.take();
}

template <int D>
OrderedJson emitter_json(const EmitterParams<D>& e) {
  const std::vector<std::string> keys = detail::emitter_keys(D);
  ObjectWriter w(keys);
  w.put("translation", vec_json<D>(e.origin))
      .put("direction", vec_json<D>(detail::direction_giving<D>(e.direction)))
      .put("velocity", e.speed)
      .put("width", e.width);
  if constexpr (D == 3) w.put("height", e.height);
  w.put("emitEveryNSteps", e.every_steps).put("maxParticles", e.max_particles).put("emitStartTime", e.start_time);
  if (std::isfinite(e.end_time)) w.put("emitEndTime", e.end_time);  // JSON has no infinity: absent is never
  return w.take();
}

template <int D>
OrderedJson motion_json(const ObstacleMotion<D>& m) {
  const std::vector<std::string> keys = detail::motion_keys(m.type, D);  // (the writer keeps a reference)
  ObjectWriter w(keys);
  w.put("type", detail::name_of(detail::kMotionTypeNames, m.type));
  switch (m.type) {
    case MotionType::None:
      break;
    case MotionType::Oscillation:
      w.put("direction", vec_json<D>(detail::direction_giving<D>(m.direction)))
          .put("amplitude", m.amplitude)
          .put("period", m.period)
          .put("phase", m.phase)
          .put("rampTime", m.ramp_time);
      break;
    case MotionType::Rotation:
    case MotionType::Keyframes:
      if constexpr (D == 3) w.put("axis", vec_json<3>(detail::direction_giving<3>(m.axis)));
      w.put("center", vec_json<D>(m.center));
      if (m.type == MotionType::Rotation) {
        w.put("angularVelocity", m.angular_velocity).put("rampTime", m.ramp_time);
      } else {
        OrderedJson keys = OrderedJson::array();
        for (const MotionKey<D>& k : m.keys)
          keys.push_back(ObjectWriter(detail::kMotionKeyKeys)
                             .put("time", k.time)
                             .put("translation", vec_json<D>(k.translation))
                             .put("rotation", k.rotation)
                             .take());
        w.put("keys", std::move(keys));
      }
      break;
  }
  return w.take();
}

template <int D>
void write_body(const SceneDesc& desc, const SceneBody<D>& body, ObjectWriter& root) {
  const SimulationParams<D>& sim = body.sim;
  OrderedJson blocks = OrderedJson::array(), obstacles = OrderedJson::array(), emitters = OrderedJson::array();
  for (const FluidBlockDesc<D>& b : body.blocks)
    blocks.push_back(ObjectWriter(detail::kFluidBlockKeys)
                         .put("start", vec_json<D>(b.box.lo))
                         .put("end", vec_json<D>(b.box.hi))
                         .put("velocity", vec_json<D>(b.velocity))
                         .take());
  for (std::size_t k = 0; k < sim.obstacles.size(); ++k) {
    ObjectWriter o(detail::kObstacleKeys);
    if (const ObstacleShape<D>* shape = obstacle_shape(sim, k)) {
      if constexpr (D == 2) {
        OrderedJson polygon = OrderedJson::array();
        for (const Vec<2, double>& v : shape->vertices) polygon.push_back(vec_json<2>(v));
        o.put("polygon", std::move(polygon));
      } else {
        const MeshSource& m = shape->source;
        o.put("geometryFile", m.file)
            .put("translation", vec_json<3>(m.translation))
            .put("rotationAxis", vec_json<3>(detail::direction_giving<3>(m.rotation_axis)))
            .put("rotationAngle", m.rotation_angle)
            .put("scale", vec_json<3>(m.scale));
      }
      o.put("inverted", shape->inverted);
    } else {
      o.put("start", vec_json<D>(sim.obstacles[k].lo)).put("end", vec_json<D>(sim.obstacles[k].hi));
    }
    o.put("motion", motion_json<D>(obstacle_motion(sim, k)));
    const BodyParams<D>& b = obstacle_body(sim, k);
    o.put("dynamic", b.dynamic);
    if (b.dynamic) {  // (the body's keys only with it: the reader refuses them on a fixed obstacle)
      o.put("density", b.density).put("velocity", vec_json<D>(b.velocity));
      if constexpr (D == 2)
        o.put("angularVelocity", b.angular_velocity[2]);
      else
        o.put("angularVelocity", vec_json<3>(b.angular_velocity));
    }
    obstacles.push_back(o.take());
  }
  for (const EmitterParams<D>& e : sim.emitters) emitters.push_back(emitter_json<D>(e));
  root.put("Configuration", configuration_json<D>(desc, sim))
      .put("Fluid", fluid_json<D>(sim))
      .put("Container", ObjectWriter(detail::kContainerKeys)
                            .put("start", vec_json<D>(sim.container.lo))
                            .put("end", vec_json<D>(sim.container.hi))
                            .put("wallStiffness", sim.walls.stiffness)
                            .put("wallDamping", sim.walls.damping)
                            .take())
      .put("FluidBlocks", std::move(blocks))
      .put("Obstacles", std::move(obstacles))
      .put("Emitters", std::move(emitters));
}

}  // namespace

OrderedJson scene_to_json(const SceneDesc& desc) {
  ObjectWriter root(detail::kRootKeys);
  root.put("version", desc.version)
      .put("name", desc.name)
      .put("description", desc.description)
      .put("units", "SI")
      .put("dimension", desc.dimension);
  desc.visit_body([&]<int D>(const SceneBody<D>& body) { write_body<D>(desc, body, root); });
  return root.take();
}

std::string scene_text(const SceneDesc& desc) { return scene_to_json(desc).dump(2); }

}  // namespace sph
