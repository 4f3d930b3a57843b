#include <sph/scene/scene_reader.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include <sph/core/error.h>
#include <sph/neighbors/neighbor_mode.h>
#include <sph/scene/direction.h>
#include <sph/scene/json_source.h>
#include <sph/scene/mesh_reader.h>
#include <sph/scene/object_reader.h>
#include <sph/scene/overrides.h>
#include <sph/scene/preflight.h>
#include <sph/scene/preflight_geometry.h>
#include <sph/scene/scales.h>
#include <sph/scene/scene_keys.h>
#include <sph/solver/time_step.h>
#include <sph/solver/wcsph.h>

namespace sph {

namespace {

using json = nlohmann::json;
using detail::ObjectReader;
using detail::point_text;

/// The keys a scene left out (or set to "auto") whose values come from its scales (scales.h),
/// filled in by resolve_defaults once the whole body is read.
struct Derived {
  bool time_step = false;  ///< timeStepSize absent or "auto"
  bool stiffness = false;
  bool viscosity = false;
  bool wall_stiffness = false;
  bool wall_damping = false;
};

/// Configuration.boundaryHandling of a scene that does not say (docs/validation.md, "Boundaries").
constexpr const char* kDefaultBoundaryHandling = "penalty";

/// The largest kernel support h accepted, in particle spacings (2 * particleRadius).
constexpr double kMaxKernelSpacings = 10;

template <int D>
bool inside(const Vec<D, double>& x, const Box<D>& b) {
  for (int d = 0; d < D; ++d)
    if (x[d] < b.lo[d] || x[d] > b.hi[d]) return false;
  return true;
}

template <int D>
Box<D> read_box(ObjectReader& r, const char* what) {
  Box<D> b;
  b.lo = r.vec<D>("start", std::string("the lower corner of the ") + what + ", m");
  b.hi = r.vec<D>("end", std::string("the upper corner of the ") + what + ", m");
  for (int d = 0; d < D; ++d)
    if (!(b.hi[d] > b.lo[d]))
      r.ctx().fail(r.child("end"), fmt::format("must be greater than \"start\" in every coordinate; got start {} "
                                               "and end {}",
                                               point_text<D>(b.lo), point_text<D>(b.hi)));
  // Corners near +-1.8e308 would make the size itself infinite (and every count built on it).
  for (int d = 0; d < D; ++d)
    if (!std::isfinite(b.hi[d] - b.lo[d]))
      r.ctx().fail(r.child("end"), fmt::format("the {} from start {} to end {} is too large: its size overflows a "
                                               "double in some coordinate",
                                               what, point_text<D>(b.lo), point_text<D>(b.hi)));
  return b;
}

/// A unit vector from `key` (any non-zero length), m.
template <int D>
Vec<D, double> read_unit(ObjectReader& r, const std::string& key, const std::string& what,
                         std::optional<Vec<D, double>> def = {}) {
  const Vec<D, double> v = r.vec<D>(key, what, def);
  // (the emitters' normalization: the writer writes detail::direction_giving, which reads back to
  // the same unit vector bit for bit)
  const std::optional<Vec<D, double>> unit = detail::unit_direction<D>(v);
  if (!unit)
    r.ctx().fail(r.child(key), fmt::format("expected {}, got {} (it has no direction)", what, point_text<D>(v)));
  return *unit;
}

/// Obstacles[].motion of the obstacle `box` (docs/scene-format.md, "Obstacles").
template <int D>
ObstacleMotion<D> read_motion(ObjectReader& o, const Box<D>& box) {
  using detail::names_of, detail::value_named;
  ObstacleMotion<D> m;
  o.object("motion", detail::kAnyMotionKeys, [&](ObjectReader& r) {
    if (!o.find("motion")) return;
    const std::vector<std::string> types = names_of(detail::kMotionTypeNames);
    r.require("type", fmt::format("the kind of motion, one of \"{}\"", fmt::join(types, "\", \"")));
    m.type = value_named(detail::kMotionTypeNames, r.choice("type", types, "none"));
    // A key of another type's motion is refused, naming the keys this type takes.
    const std::vector<std::string> own = detail::motion_keys(m.type, D);
    for (const std::string& k : detail::kAnyMotionKeys)
      if (r.find(k) && std::find(own.begin(), own.end(), k) == own.end())
        r.ctx().fail(r.child(k), fmt::format("not a key of the motion type \"{}\"{}; it takes {}", r.string("type", ""),
                                             k == "axis" && D == 2 ? " in 2D (2D rotations turn about z)" : "",
                                             fmt::join(own, ", ")));
    Vec<D, double> middle = (box.lo + box.hi) * 0.5;
    switch (m.type) {
      case MotionType::None:
        break;
      case MotionType::Oscillation:
        m.direction = read_unit<D>(r, "direction", "the direction of the oscillation, a non-zero vector");
        m.amplitude = r.positive("amplitude", "the amplitude of the oscillation, m (> 0)");
        m.period = r.positive("period", "the period of the oscillation, s (> 0)");
        m.phase = r.find("phase") ? r.number(*r.find("phase"), "phase", "the phase at t = 0 in rad, a number") : 0.0;
        break;
      case MotionType::Rotation:
      case MotionType::Keyframes:
        if constexpr (D == 3)
          m.axis = read_unit<3>(r, "axis", "the rotation axis, a non-zero vector", Vec<3, double>{{0, 0, 1}});
        m.center = r.vec<D>("center", "the point the obstacle turns about, m", middle);
        break;
    }
    if (m.type == MotionType::Rotation)
      m.angular_velocity =
          r.number(r.require("angularVelocity", "the angular velocity in rad/s (counter-clockwise about the axis)"),
                   "angularVelocity", "the angular velocity in rad/s, a number");
    if (m.type == MotionType::Oscillation || m.type == MotionType::Rotation)
      m.ramp_time = r.positive("rampTime", "a time over which the motion starts up, s (>= 0)", 0.0, true);
    if (m.type == MotionType::Keyframes) {
      r.require("keys", "the keyframes, an array of {\"time\", \"translation\", \"rotation\"}");
      r.array_of_objects("keys", detail::kMotionKeyKeys, [&](ObjectReader& k, std::size_t i) {
        MotionKey<D> key;
        key.time = k.positive("time", "the key's time, s (>= 0)", std::nullopt, true);
        key.translation = k.vec<D>("translation", "the translation at the key's time, m", Vec<D, double>{});
        key.rotation = k.find("rotation") ? k.number(*k.find("rotation"), "rotation",
                                                     "the rotation at the key's time in rad, a number")
                                          : 0.0;
        if (i == 0 && (norm2(key.translation) != 0 || key.rotation != 0))
          k.ctx().fail(k.child(key.rotation != 0 ? "rotation" : "translation"),
                       "the first key must have no translation and no rotation: the obstacle is where \"start\" "
                       "and \"end\" put it until then; move the box there instead");
        if (i > 0 && !(key.time > m.keys.back().time))
          k.ctx().fail(k.child("time"),
                       fmt::format("the keys' times must increase: {} s follows {} s", key.time, m.keys.back().time));
        m.keys.push_back(key);
      });
      if (m.keys.empty()) r.ctx().fail(r.child("keys"), "expected at least one key {\"time\": ...}, got none");
    }
  });
  return m;
}

/// A path in a scene, relative to the scene file's directory (to the working directory for a
/// scene given as text), as an absolute path.
std::string scene_relative_path(const std::string& source, const std::string& file) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::path p(file);
  if (p.is_relative() && fs::is_regular_file(fs::path(source), ec)) p = fs::path(source).parent_path() / p;
  return fs::absolute(p, ec).lexically_normal().string();
}

/// The keys of a mesh obstacle's transform (3D).
constexpr std::array<const char*, 4> kMeshTransformKeys{"translation", "rotationAxis", "rotationAngle", "scale"};

/// An obstacle's solid: its box ("start", "end"), or its shape (3D: "geometryFile" and its
/// transform; 2D: "polygon"; either may be "inverted"), with `box` its bounds.
template <int D>
ObstacleShape<D> read_solid(ObjectReader& o, Box<D>& box) {
  const bool mesh = o.find("geometryFile") != nullptr, polygon = o.find("polygon") != nullptr;
  const char* shape_key = mesh ? "geometryFile" : "polygon";
  if (mesh && polygon)
    o.ctx().fail(o.child("polygon"),
                 "an obstacle is a box (\"start\", \"end\"), a mesh (\"geometryFile\", 3D) or a "
                 "polygon (\"polygon\", 2D); give one");
  if (!mesh && !polygon) {
    for (const char* key : kMeshTransformKeys)
      if (o.find(key))
        o.ctx().fail(o.child(key),
                     "only a mesh obstacle (\"geometryFile\") takes this key; a box is placed by "
                     "\"start\" and \"end\"");
    if (o.find("inverted"))
      o.ctx().fail(o.child("inverted"),
                   "only a mesh or polygon obstacle can be inverted (the fluid inside it); the "
                   "container box already holds the fluid inside a box");
    box = read_box<D>(o, "obstacle");
    return {};
  }
  for (const char* key : {"start", "end"})
    if (o.find(key))
      o.ctx().fail(o.child(key), fmt::format("an obstacle with \"{}\" takes its place from it; remove \"{}\" (its "
                                             "bounds are the shape's)",
                                             shape_key, key));
  const bool inverted = o.boolean(
      "inverted", "whether the solid is outside the closed surface (the fluid held inside it, as a container)", false);
  ObstacleShape<D> shape;
  if constexpr (D == 2) {
    if (mesh)
      o.ctx().fail(o.child("geometryFile"),
                   "mesh files are for 3D scenes; a 2D obstacle of any shape is a "
                   "\"polygon\": [[x, y], ...] (its vertices in order, m)");
    for (const char* key : kMeshTransformKeys)
      if (o.find(key))
        o.ctx().fail(o.child(key), "only a 3D mesh obstacle takes this key; give a polygon's vertices where they are");
    const json& v = o.require("polygon", "the polygon's vertices in order around it, [[x, y], ...], m");
    const std::string expect = "the polygon's vertices in order around it, an array of [x, y] pairs of numbers, m";
    if (!v.is_array()) o.ctx().fail(o.child("polygon"), "expected " + expect + ", got " + detail::describe(v));
    std::vector<Vec<2, double>> points;
    for (std::size_t i = 0; i < v.size(); ++i) {
      const json& e = v[i];
      if (!e.is_array() || e.size() != 2 || !e[0].is_number() || !e[1].is_number() ||
          !std::isfinite(e[0].get<double>()) || !std::isfinite(e[1].get<double>()))
        o.ctx().fail(fmt::format("{}[{}]", o.child("polygon"), i),
                     "expected " + expect + ", got " + detail::describe(e));
      points.push_back(Vec<2, double>{{e[0].get<double>(), e[1].get<double>()}});
    }
    try {
      shape = polygon_shape(std::move(points), inverted);
    } catch (const Error& e) {
      o.ctx().fail(o.child("polygon"), "the polygon " + e.message());
    }
  } else {
    if (polygon)
      o.ctx().fail(o.child("polygon"),
                   "polygons are for 2D scenes; a 3D obstacle of any shape is a mesh file, "
                   "\"geometryFile\" (OBJ, STL or PLY)");
    MeshSource src;
    const std::string given = o.string("geometryFile",
                                       "the path of a closed triangle mesh, .obj, .stl or .ply (relative "
                                       "to the scene file)");
    if (given.empty())
      o.ctx().fail(o.child("geometryFile"), "expected the path of a .obj, .stl or .ply file, got \"\"");
    src.file = scene_relative_path(o.ctx().source, given);
    src.translation = o.vec<3>("translation", "the mesh's translation, m", Vec<3, double>{});
    src.rotation_axis =
        read_unit<3>(o, "rotationAxis", "the axis the mesh turns about, a non-zero vector", Vec<3, double>{{0, 0, 1}});
    if (const json* a = o.find("rotationAngle"))
      src.rotation_angle = o.number(*a, "rotationAngle", "the mesh's rotation about rotationAxis, rad, a number");
    src.scale =
        o.vec<3>("scale", "the mesh's scale along x, y and z (applied first), each > 0", Vec<3, double>{{1, 1, 1}});
    for (int d = 0; d < 3; ++d)
      if (!(src.scale[d] > 0))
        o.ctx().fail(o.child("scale"), fmt::format("each factor must be > 0; got {}", point_text<3>(src.scale)));
    TriangleMesh m;
    try {
      m = read_mesh_file(src.file);
    } catch (const Error& e) {
      o.ctx().fail(o.child("geometryFile"), e.message());
    }
    // x = t + R (s * X): Rodrigues' rotation.
    const Vec<3, double>& k = src.rotation_axis;
    const double c = std::cos(src.rotation_angle), sn = std::sin(src.rotation_angle);
    for (Vec<3, double>& x : m.vertices) {
      Vec<3, double> v;
      for (int d = 0; d < 3; ++d) v[d] = x[d] * src.scale[d];
      const Vec<3, double> kxv{{k[1] * v[2] - k[2] * v[1], k[2] * v[0] - k[0] * v[2], k[0] * v[1] - k[1] * v[0]}};
      const double kv = dot(k, v);
      for (int d = 0; d < 3; ++d) x[d] = src.translation[d] + v[d] * c + kxv[d] * sn + k[d] * kv * (1 - c);
    }
    try {
      shape = make_shape<3>(std::move(m.vertices), std::move(m.triangles), inverted, src);
    } catch (const Error& e) {
      o.ctx().fail(o.child("geometryFile"), fmt::format("the mesh '{}' {}", src.file, e.message()));
    }
  }
  box = shape_bounds(shape);
  for (int d = 0; d < D; ++d)
    if (!(box.hi[d] > box.lo[d]))
      o.ctx().fail(o.child(shape_key), "the shape is flat: it has no extent along some axis");
  return shape;
}

/// Obstacles[].dynamic and its keys (docs/scene-format.md, "Floating bodies"), after the motion.
template <int D>
BodyParams<D> read_floating(ObjectReader& o, const ObstacleMotion<D>& motion) {
  BodyParams<D> b;
  b.dynamic = o.boolean("dynamic", "whether the obstacle floats, moved by the fluid, gravity and the container", false);
  if (!b.dynamic) {
    for (const char* key : {"density", "velocity", "angularVelocity"})
      if (o.find(key))
        o.ctx().fail(o.child(key),
                     "only a floating obstacle takes this key; add \"dynamic\": true to the "
                     "obstacle, or remove the key");
    return b;
  }
  if (motion.type != MotionType::None)
    o.ctx().fail(o.child("motion"),
                 "a floating obstacle (\"dynamic\": true) is moved by the fluid and cannot also follow a prescribed "
                 "motion; remove \"motion\" or \"dynamic\"");
  o.require("density", "the body's density, kg/m^3 (in 2D in Fluid.density0's units), > 0");
  b.density = o.positive("density", "the body's density, kg/m^3 (in 2D in Fluid.density0's units), > 0");
  b.velocity = o.vec<D>("velocity", "the body's velocity at t = 0, m/s", Vec<D, double>{});
  if constexpr (D == 2) {
    if (const json* w = o.find("angularVelocity"))
      b.angular_velocity[2] =
          o.number(*w, "angularVelocity", "the body's angular velocity at t = 0, rad/s (counter-clockwise), a number");
  } else {
    b.angular_velocity =
        o.vec<3>("angularVelocity", "the body's angular velocity at t = 0, rad/s (world axes)", Vec<3, double>{});
  }
  return b;
}

/// Configuration.outputEveryNSteps, outputFps, outputFormats, outputFields.
void read_output(ObjectReader& c, SceneDesc& desc) {
  OutputDesc& out = desc.output;
  // A run that ends at a time (CFL steps) writes 100 frames by default, on the fps schedule.
  const bool by_time = desc.end_time > 0 && !c.find("outputEveryNSteps");
  out.fps = c.positive("outputFps", "a frame rate >= 0 in frames per simulated second (0: frames by outputEveryNSteps)",
                       by_time ? 100.0 / desc.end_time : 0.0, true);
  // Frames by time replace the default frames by steps; both given is a contradiction.
  out.every_steps = c.integer("outputEveryNSteps", "a frame interval in steps (0: no frames)", 0, 1'000'000'000'000LL,
                              out.fps > 0 ? 0 : std::max<std::int64_t>(1, desc.steps / 100));
  if (out.fps > 0 && out.every_steps > 0)
    c.ctx().fail(c.child("outputFps"),
                 fmt::format("outputEveryNSteps = {} and outputFps = {:g} both choose when frames are written; give "
                             "one of them (or set the other to 0)",
                             out.every_steps, out.fps));
  if (auto formats = c.string_set("outputFormats", frame_format_names(), "the frame formats")) {
    if (formats->empty())
      c.ctx().fail(c.child("outputFormats"), "expected at least one frame format of " + frame_format_list("\""));
    out.formats.clear();
    for (const std::string& f : *formats) out.formats.push_back(*parse_frame_format(f));  // (checked by string_set)
  }
  const std::vector<std::string> all(std::begin(kFrameFieldNames), std::end(kFrameFieldNames));
  if (auto fields = c.string_set("outputFields", all, "the point fields of each frame (empty: positions only)")) {
    out.fields.clear();
    for (const std::string& name : all)  // in kFrameFieldNames order, whatever the file's
      if (std::find(fields->begin(), fields->end(), name) != fields->end()) out.fields.push_back(name);
  }
  out.boundary = c.boolean("outputBoundary", "whether to write the boundary particles as boundary.vtu", false);
}

/// Configuration.simulationMethod and DFSPH's solver settings (after boundaryHandling).
template <int D>
void read_solver(ObjectReader& c, SimulationParams<D>& sim) {
  using detail::names_of, detail::value_named;
  sim.method = value_named(detail::kSimulationMethodNames,
                           c.choice("simulationMethod", names_of(detail::kSimulationMethodNames), "wcsph"));
  if (sim.method == SimulationMethod::Dfsph && sim.boundary.handling != BoundaryHandling::Particles)
    c.ctx().fail(c.child("simulationMethod"),
                 fmt::format("{} (or use simulationMethod \"wcsph\")", kDfsphNeedsBoundaryParticles));
  DfsphParams& p = sim.dfsph;
  p.min_iterations = static_cast<int>(
      c.integer("minIterations", "DFSPH's least constant-density iterations, 0 to 10000", 0, 10000, p.min_iterations));
  p.max_iterations = static_cast<int>(
      c.integer("maxIterations", "DFSPH's most constant-density iterations, 1 to 10000", 1, 10000, p.max_iterations));
  // (blamed on the key the scene gave; when it gave both, on maxIterations)
  if (p.max_iterations < p.min_iterations) {
    if (c.find("maxIterations"))
      c.ctx().fail(c.child("maxIterations"),
                   fmt::format("maxIterations = {} is below minIterations = {}; expected at least minIterations",
                               p.max_iterations, p.min_iterations));
    c.ctx().fail(c.child("minIterations"),
                 fmt::format("minIterations = {} is above maxIterations = {} (its default); expected at most "
                             "maxIterations, or give a larger maxIterations too",
                             p.min_iterations, p.max_iterations));
  }
  p.max_error = c.positive("maxError", "DFSPH's tolerance on the average compression, a positive % of the rest density",
                           p.max_error);
  p.divergence_solver = c.boolean("enableDivergenceSolver", "whether DFSPH runs its divergence solve", true);
  p.max_iterations_v = static_cast<int>(
      c.integer("maxIterationsV", "DFSPH's most divergence iterations, 1 to 10000", 1, 10000, p.max_iterations_v));
  p.max_error_v = c.positive(
      "maxErrorV", "DFSPH's tolerance on the average divergence error, a positive % of the rest density per second",
      p.max_error_v);
}

/// The time stepping: Configuration.cflMethod and its settings (a DFSPH scene takes CFL steps
/// unless it says "none").
template <int D>
void read_time_stepping(ObjectReader& c, SimulationParams<D>& sim) {
  using detail::names_of, detail::value_named;
  const char* fallback = sim.method == SimulationMethod::Dfsph ? "cfl" : "none";
  sim.time_stepping =
      value_named(detail::kCflMethodNames, c.choice("cflMethod", names_of(detail::kCflMethodNames), fallback));
  CflParams& cfl = sim.cfl;
  cfl.factor = c.positive(
      "cflFactor", "a positive CFL factor (a step moves a particle at most 0.4 cflFactor diameters)", cfl.factor);
  if (cfl.factor > 1)
    c.ctx().fail(c.child("cflFactor"), fmt::format("a CFL factor of {:g} lets a particle cross {:g} diameters in a "
                                                   "step; expected at most 1 (typical: 0.5)",
                                                   cfl.factor, 0.4 * cfl.factor));
  cfl.min_dt = c.positive("cflMinTimeStepSize", "the smallest CFL step, a positive time in s", cfl.min_dt);
  cfl.max_dt = c.positive("cflMaxTimeStepSize", "the largest CFL step, a positive time in s", cfl.max_dt);
  if (cfl.max_dt < cfl.min_dt)
    c.ctx().fail(
        c.child("cflMaxTimeStepSize"),
        fmt::format("cflMaxTimeStepSize = {:g} s is below cflMinTimeStepSize = {:g} s", cfl.max_dt, cfl.min_dt));
}

/// The Configuration object: time step, steps, particle and kernel radii, gravity, the neighbor
/// strategy's settings and the output.
template <int D>
void read_configuration(ObjectReader& c, SceneDesc& desc, SimulationParams<D>& sim, Derived& derived) {
  Vec<D, double> default_g{};
  default_g[1] = -9.81;
  desc.precision = detail::value_named(detail::kPrecisionNames,
                                       c.choice("precision", detail::names_of(detail::kPrecisionNames), "double"));
  const json* dt = c.find("timeStepSize");
  derived.time_step = !dt || (dt->is_string() && dt->get<std::string>() == "auto");
  if (!derived.time_step) sim.time_step = c.positive("timeStepSize", "a positive time step in seconds or \"auto\"");
  sim.particle_radius = c.positive("particleRadius", "a positive particle radius in metres");
  sim.kernel_radius =
      c.positive("kernelRadius", "a positive kernel support radius h in metres", 4.0 * sim.particle_radius);
  if (sim.kernel_radius <= 2.0 * sim.particle_radius)
    c.ctx().fail(c.child("kernelRadius"),
                 fmt::format("h = {:g} m must exceed the particle spacing 2 * particleRadius = {:g} m (typical: "
                             "4 * particleRadius)",
                             sim.kernel_radius, 2 * sim.particle_radius));
  // Work per particle grows as (h / spacing)^D: the default particle mass sums the kernel over
  // that many lattice sites, and every list would hold that many neighbors.
  if (sim.kernel_radius > kMaxKernelSpacings * 2.0 * sim.particle_radius)
    c.ctx().fail(c.child("kernelRadius"),
                 fmt::format("h = {:g} m is more than {:g} particle spacings (2 * particleRadius = {:g} m): every "
                             "particle would have thousands of neighbors; expected at most {:g} m (typical: 4 * "
                             "particleRadius)",
                             sim.kernel_radius, kMaxKernelSpacings, 2 * sim.particle_radius,
                             kMaxKernelSpacings * 2.0 * sim.particle_radius));
  sim.gravity = c.vec<D>("gravitation", "the gravity acceleration in m/s^2", default_g);
  sim.neighbors = parse_neighbor_mode(c.choice("neighbors", neighbor_mode_names(), "standard"), c.child("neighbors"));
  sim.full_rebuild_period = static_cast<int>(
      c.integer("fullRebuildPeriod", "a full-rebuild period of at least 1 step", 1, 1'000'000'000, 200));
  sim.flag_near_moving = c.boolean(
      "flagNearMovingBodies", "whether the adaptive mode rebuilds the lists of particles near moving obstacles", true);
  sim.reorder_period = static_cast<int>(
      c.integer("reorderPeriod", "a whole number of steps, 0 or more (0: never reorder particles in memory)", 0,
                1'000'000'000, sim.full_rebuild_period));
  using detail::names_of, detail::value_named;
  sim.boundary.handling =
      value_named(detail::kBoundaryHandlingNames,
                  c.choice("boundaryHandling", names_of(detail::kBoundaryHandlingNames), kDefaultBoundaryHandling));
  sim.boundary.volume = value_named(detail::kBoundaryVolumeNames,
                                    c.choice("boundaryVolume", names_of(detail::kBoundaryVolumeNames), "rest_fluid"));
  sim.boundary.friction =
      c.positive("boundaryFriction", "a boundary friction sigma >= 0 (Akinci et al. 2012; 0: free slip)",
                 sim.boundary.friction, true);
  sim.fluid.kernel = value_named(detail::kKernelNames, c.choice("kernel", names_of(detail::kKernelNames), "paper"));
  read_solver<D>(c, sim);
  sim.boundary.pressure = value_named(detail::kBoundaryPressureNames,
                                      c.choice("boundaryPressure", names_of(detail::kBoundaryPressureNames),
                                               sim.method == SimulationMethod::Dfsph ? "none" : "extrapolate"));
  read_time_stepping<D>(c, sim);
  sim.verlet_skin = c.positive("verletSkin", "a positive verlet skin in metres (default 0.1 h)",
                               kDefaultSkinFraction * sim.kernel_radius);
  sim.tracked_skin = c.positive(
      "trackedSkin", "a tracked skin in metres, or 0 for the automatic one (the default, chosen at each full rebuild)",
      0.0, true);
  // Each skin is read (and checked for its sign) in every mode; its own modes also refuse a skin
  // over 2 h.
  const auto refuse_huge_skin = [&](const char* key, double skin, const char* expected, const char* typical) {
    if (skin > 2.0 * sim.kernel_radius)
      c.ctx().fail(c.child(key), fmt::format("a skin of {:g} m is more than twice h = {:g} m: lists would hold over 27 "
                                             "times the pairs needed in 3D; expected {} at most 2 h = {:g} m "
                                             "(typical: {})",
                                             skin, sim.kernel_radius, expected, 2.0 * sim.kernel_radius, typical));
  };
  if (neighbor_mode_info(sim.neighbors).tracked)
    refuse_huge_skin("trackedSkin", sim.tracked_skin, "0 (automatic) or a skin of", "0.02 h to 0.5 h");
  if (neighbor_mode_info(sim.neighbors).verlet)
    refuse_huge_skin("verletSkin", sim.verlet_skin, "a skin above 0 and", "0.05 h to 0.5 h");
}

/// Configuration.numberOfSteps or stopAt (an end time, turned into steps of dt), and the output
/// (whose default frame interval depends on the steps).
void read_run_length(ObjectReader& c, SceneDesc& desc, double dt, bool cfl, double min_dt) {
  constexpr std::int64_t kMaxSteps = 1'000'000'000'000LL;
  const char* what_steps = "a number of steps between 1 and 1e12 (or stopAt, an end time in s)";
  const char* what_stop = "a positive end time in seconds";
  // Both given: one from a flag (--steps, --set) overrides the other from the file, which is
  // still validated; both from the same place contradict each other.
  bool by_time = c.find("stopAt") != nullptr;
  if (by_time && c.find("numberOfSteps")) {
    const auto& set = c.ctx().overridden;
    const bool steps_set = set.count(c.child("numberOfSteps")) > 0, stop_set = set.count(c.child("stopAt")) > 0;
    if (steps_set == stop_set)
      c.ctx().fail(c.child("stopAt"), "numberOfSteps and stopAt both say when the run ends; give one of them");
    if (steps_set) c.positive("stopAt", what_stop);
    if (stop_set) c.integer("numberOfSteps", what_steps, 1, kMaxSteps);
    by_time = stop_set;
  }
  if (!by_time) {
    desc.steps = c.integer("numberOfSteps", what_steps, 1, kMaxSteps);
  } else {
    const double stop = c.positive("stopAt", what_stop);
    // The first step whose end reaches stopAt (an end time that is a whole number of steps,
    // up to rounding, is that number). CFL steps: the run ends at stopAt; the count (an
    // estimate, below) starts from the steps the smallest step needs.
    if (cfl) {
      desc.end_time = stop;
      dt = min_dt;
    }
    const double steps = std::max(1.0, std::ceil(stop / dt * (1 - 1e-12)));
    if (!(steps <= static_cast<double>(kMaxSteps)))
      c.ctx().fail(c.child("stopAt"), fmt::format("stopAt = {:g} s is {:.3g} steps of {:.4g} s; at most 1e12 steps are "
                                                  "supported",
                                                  stop, steps, dt));
    desc.steps = static_cast<std::int64_t>(steps);
  }
  read_output(c, desc);
  // CFL steps that end on a frame's time or on the end may be shorter than the smallest step:
  // each such barrier adds at most two steps (two equal steps rather than a step and a sliver).
  // The run ends at its end time (RunDriver::finished); the count is the estimate it shows.
  if (desc.end_time > 0 && desc.steps < kMaxSteps / 2)
    desc.steps += 2 * (1 + static_cast<std::int64_t>(std::min(1e11, std::ceil(desc.end_time * desc.output.fps))));
}

/// The Fluid object: rest density, equation of state, viscosity, the pressure force's form and
/// the particle mass.
template <int D>
void read_fluid(ObjectReader& f, SimulationParams<D>& sim, Derived& derived) {
  using detail::names_of, detail::value_named;
  sim.fluid.rest_density = f.positive("density0", "a positive rest density in kg/m^" + std::to_string(D), 1000.0);
  derived.stiffness = !f.find("stiffness");
  if (!derived.stiffness)
    sim.fluid.stiffness = f.positive("stiffness", "a positive EOS stiffness k in m^2/s^2 (p = k (rho - rho0))");
  derived.viscosity = !f.find("viscosity");
  if (!derived.viscosity) sim.fluid.viscosity = f.positive("viscosity", "a viscosity >= 0 in Pa s", 0.0, true);
  sim.fluid.viscosity_model = value_named(detail::kViscosityModelNames,
                                          f.choice("viscosityModel", names_of(detail::kViscosityModelNames), "paper"));
  sim.fluid.alpha = f.positive("artificialViscosityAlpha",
                               "Monaghan's artificial viscosity coefficient alpha >= 0 (typical: 0.01 to 0.1)",
                               kArtificialViscosityAlpha, true);
  sim.fluid.viscosity_solve = value_named(
      detail::kViscositySolverNames, f.choice("viscositySolver", names_of(detail::kViscositySolverNames), "explicit"));
  if (sim.fluid.viscosity_solve == ViscositySolve::Implicit && sim.fluid.viscosity_model != ViscosityModel::Paper)
    f.ctx().fail(f.child("viscositySolver"), kImplicitViscosityNeedsPaperModel);
  sim.fluid.viscosity_max_iterations = static_cast<int>(
      f.integer("viscosityMaxIterations", "the implicit viscosity solve's most iterations per step, 1 to 10000", 1,
                10000, sim.fluid.viscosity_max_iterations));
  sim.fluid.viscosity_max_error =
      f.positive("viscosityMaxError",
                 "the implicit viscosity solve's tolerance: a positive % (at most 100) of its starting residual",
                 sim.fluid.viscosity_max_error);
  if (sim.fluid.viscosity_max_error > 100)
    f.ctx().fail(f.child("viscosityMaxError"),
                 fmt::format("viscosityMaxError = {:g} % is above 100 %: the tolerance is a % of the solve's starting "
                             "residual, at most 100 (typical: 0.01 to 1)",
                             sim.fluid.viscosity_max_error));
  sim.fluid.negative_pressure = value_named(
      detail::kNegativePressureNames, f.choice("negativePressure", names_of(detail::kNegativePressureNames), "clamp"));
  sim.fluid.pressure_force = value_named(detail::kPressureForceNames,
                                         f.choice("pressureForce", names_of(detail::kPressureForceNames), "paper"));
  sim.fluid.gradient_correction =
      value_named(detail::kGradientCorrectionNames,
                  f.choice("gradientCorrection", names_of(detail::kGradientCorrectionNames), "none"));
  if (f.find("particleMass")) {
    sim.particle_mass = f.positive("particleMass", "a positive particle mass in kg");
    return;
  }
  // Extreme scales (h^9 in the kernel's normalization) can overflow to inf or NaN.
  sim.particle_mass =
      lattice_mass<D>(sim.fluid.rest_density, 2.0 * sim.particle_radius, sim.kernel_radius, sim.fluid.kernel);
  if (!(std::isfinite(sim.particle_mass) && sim.particle_mass > 0))
    f.ctx().fail(f.child("particleMass"),
                 fmt::format("the default particle mass computed from density0 = {:g}, particleRadius = {:g} and "
                             "kernelRadius = {:g} is {:g}; expected a positive finite mass: give particleMass or "
                             "use less extreme values",
                             sim.fluid.rest_density, sim.particle_radius, sim.kernel_radius, sim.particle_mass));
}

/// The Container object: the box and its walls' springs.
template <int D>
void read_container(ObjectReader& root, SimulationParams<D>& sim, Derived& derived) {
  const json& cj = root.require("Container", "an object with \"start\" and \"end\" corners");
  ObjectReader c(cj, root.child("Container"), root.ctx(), detail::kContainerKeys);
  sim.container = read_box<D>(c, "container");
  derived.wall_stiffness = !c.find("wallStiffness");
  if (!derived.wall_stiffness)
    sim.walls.stiffness = c.positive("wallStiffness", "a positive wall spring stiffness in 1/s^2");
  derived.wall_damping = !c.find("wallDamping");
  if (!derived.wall_damping) sim.walls.damping = c.positive("wallDamping", "a wall damping >= 0 in 1/s", 0.0, true);
  for (int d = 0; d < D; ++d)
    if (sim.container.hi[d] - sim.container.lo[d] < 4 * sim.particle_radius)
      c.ctx().fail(c.child("end"), "the container must be at least two particle diameters wide in every direction");
}

/// The FluidBlocks array; returns the number of particles they hold.
template <int D>
double read_blocks(ObjectReader& root, SceneBody<D>& body) {
  const SimulationParams<D>& sim = body.sim;
  const double dx = 2.0 * sim.particle_radius;
  double total = 0;
  root.array_of_objects("FluidBlocks", detail::kFluidBlockKeys, [&](ObjectReader& b, std::size_t) {
    FluidBlockDesc<D> blk;
    blk.box = read_box<D>(b, "fluid block");
    blk.velocity = b.vec<D>("velocity", "the initial velocity in m/s", Vec<D, double>{});
    if (!inside<D>(blk.box.lo, sim.container) || !inside<D>(blk.box.hi, sim.container))
      b.ctx().fail(b.child("start"), fmt::format("the block {} .. {} is not inside the container {} .. {}",
                                                 point_text<D>(blk.box.lo), point_text<D>(blk.box.hi),
                                                 point_text<D>(sim.container.lo), point_text<D>(sim.container.hi)));
    // Each axis on its own: a product taken first could be inf * 0 = NaN, which no comparison
    // refuses (a block far longer than 2e9 spacings one way and thinner than one the other).
    double count = 1;
    for (int d = 0; d < D; ++d) {
      const double along = std::floor((blk.box.hi[d] - blk.box.lo[d]) / dx + 1e-9);
      if (!(along >= 1))
        b.ctx().fail(b.child("end"), fmt::format("the block is thinner than one particle spacing ({:g} m) in some "
                                                 "direction, so it holds no particle",
                                                 dx));
      count *= along;
    }
    total += count;
    body.blocks.push_back(blk);
  });
  return total;
}

/// One Emitters entry.
template <int D>
EmitterParams<D> read_emitter(ObjectReader& e, const SimulationParams<D>& sim) {
  EmitterParams<D> em;
  em.origin = e.vec<D>("translation", "the center of the emitter nozzle in m");
  const auto unit = detail::unit_direction<D>(e.vec<D>("direction", "the emission direction (any non-zero length)"));
  if (!unit) e.ctx().fail(e.child("direction"), "expected a non-zero direction vector");
  em.direction = *unit;
  em.speed = e.positive("velocity", "a positive emission speed in m/s");
  em.width = static_cast<int>(e.integer("width", "a nozzle width of 1 to 10000 particles", 1, 10000));
  if constexpr (D == 2)
    if (e.find("height"))
      e.ctx().fail(e.child("height"),
                   "not a key of a 2D emitter: a 2D nozzle is a line of `width` particles; height is for 3D scenes");
  em.height = D == 3 ? static_cast<int>(e.integer("height", "a nozzle height of 1 to 10000 particles", 1, 10000)) : 1;
  em.spacing = 2.0 * sim.particle_radius;
  // Absent: 16, or the fewest steps a batch needs to clear the nozzle (check_emitter_travel).
  em.every_steps =
      e.find("emitEveryNSteps")
          ? static_cast<int>(e.integer("emitEveryNSteps", "an emission interval of at least 1 step", 1, 1'000'000'000))
          : 0;
  em.max_particles =
      e.integer("maxParticles", "a particle budget, a whole number from 1 to 4000000000", 1, 4'000'000'000LL);
  em.start_time = e.positive("emitStartTime", "a start time >= 0 in s", 0.0, true);
  em.end_time = e.positive("emitEndTime", "an end time > 0 in s", std::numeric_limits<double>::infinity());
  if (!inside<D>(em.origin, sim.container))
    e.ctx().fail(e.child("translation"),
                 fmt::format("the nozzle center {} is outside the container", point_text<D>(em.origin)));
  return em;
}

/// Each emitter's batch must have left the nozzle before the next one is placed there (checked
/// once the time step is known). An emitter without emitEveryNSteps (every_steps 0 here) emits
/// every 16 steps, or, when the time step is "auto", every as many steps as a batch needs to
/// move one spacing if 16 are too few. With CFL steps, whose batches come every emitEveryNSteps
/// timeStepSize seconds, it emits as soon as a batch has moved one spacing: a continuous jet
/// (with 16, DFSPH's long "auto" timeStepSize spread the layers many spacings apart).
template <int D>
void check_emitter_travel(const detail::ReadContext& ctx, SimulationParams<D>& sim, bool auto_time_step) {
  const double dx = 2.0 * sim.particle_radius;
  for (std::size_t i = 0; i < sim.emitters.size(); ++i) {
    EmitterParams<D>& em = sim.emitters[i];
    const bool cfl = sim.time_stepping == TimeStepping::Cfl;
    if (em.every_steps == 0 && !auto_time_step && !cfl) em.every_steps = 16;
    if (em.every_steps == 0) {
      double needed = std::ceil(dx / (em.speed * sim.time_step));
      if (em.speed * needed * sim.time_step < dx) needed += 1;  // (rounding)
      em.every_steps = static_cast<int>(std::clamp(needed, cfl ? 1.0 : 16.0, 1e9));
    }
    const double travel = em.speed * em.every_steps * sim.time_step;
    if (travel < dx)
      ctx.fail(fmt::format("Emitters[{}].velocity", i),
               fmt::format("a batch moves {:.3g} m in {} steps, less than the particle spacing {:.3g} m, so "
                           "batches would overlap; raise velocity to at least {:.3g} m/s or emitEveryNSteps",
                           travel, em.every_steps, dx, dx / (em.every_steps * sim.time_step)));
  }
}

/// A value derived from the scene's scales, checked positive and finite (extreme scenes can
/// overflow or vanish); the message names the key to give instead.
void check_derived(const detail::ReadContext& ctx, const std::string& key, double value, const std::string& from) {
  if (!(std::isfinite(value) && value > 0))
    ctx.fail(key, fmt::format("the default computed from {} is {:g}; expected a positive finite value: give {} in "
                              "the scene",
                              from, value, key));
}

/// Fills the keys the scene left out from its scales (scales.h, docs/reliability.md "Defaults"),
/// in dependency order: stiffness, viscosity, wall stiffness, wall damping, then the time step.
template <int D>
void resolve_defaults(const detail::ReadContext& ctx, SceneBody<D>& body, const Derived& derived,
                      const SceneScales& s) {
  SimulationParams<D>& sim = body.sim;
  if (derived.stiffness) {
    if (!(s.max_speed > 0))
      ctx.fail("Fluid.stiffness",
               "missing, and no default can be derived: the scene has no gravity, and neither its fluid nor an "
               "obstacle moves, so no speed sets the sound speed; give stiffness (typical: (10 v)^2 in m^2/s^2 for the "
               "largest speed v "
               "expected)");
    sim.fluid.stiffness = default_stiffness(s);
    check_derived(ctx, "Fluid.stiffness", sim.fluid.stiffness,
                  fmt::format("the expected largest speed {:g} m/s", s.max_speed));
  }
  const double c0 = std::sqrt(sim.fluid.stiffness);
  if (derived.viscosity) {
    sim.fluid.viscosity =
        viscosity_for_sound_speed(D, kArtificialViscosityAlpha, sim.kernel_radius, c0, sim.fluid.rest_density);
    check_derived(ctx, "Fluid.viscosity", sim.fluid.viscosity,
                  fmt::format("h = {:g} m and the sound speed {:g} m/s", sim.kernel_radius, c0));
  }
  if (derived.wall_stiffness) {
    sim.walls.stiffness = default_wall_stiffness(s, sim.particle_radius, sim.fluid.stiffness);
    check_derived(ctx, "Container.wallStiffness", sim.walls.stiffness,
                  fmt::format("the head {:g} m, the speed {:g} m/s and particleRadius {:g} m", s.head,
                              wall_impact_speed(s, sim.fluid.stiffness), sim.particle_radius));
  }
  if (derived.wall_damping) sim.walls.damping = critical_wall_damping(sim.walls.stiffness);
  if (derived.time_step) {
    sim.time_step = auto_time_step<D>(sim);
    check_derived(ctx, "Configuration.timeStepSize", sim.time_step, "the stability limits");
  }
}

/// Warnings about explicit values the scales show will probably not hold.
template <int D>
void warn_from_scales(SceneDesc& desc, const SimulationParams<D>& sim, const Derived& derived, const SceneScales& s) {
  const double r = sim.particle_radius, k = sim.fluid.stiffness, kw = sim.walls.stiffness;
  if (sim.boundary.handling == BoundaryHandling::Penalty && !derived.wall_stiffness &&
      kw < least_holding_wall_stiffness(s, r, k)) {
    const double v = wall_impact_speed(s, k);
    desc.warnings.push_back(fmt::format(
        "Container.wallStiffness = {:g} is too low for this scene: the {:.3g} m head of fluid pushes the bottom "
        "particles {:.2g} particle radii into the walls and a particle arriving at {:.3g} m/s stops only after {:.2g} "
        "radii (the wall springs act within one radius), so particles may leave the container; wallStiffness = "
        "{:.3g} would hold them (the default, docs/reliability.md \"Defaults\")",
        kw, s.head, s.gravity * s.head / (2 * r * kw) / r, v, v / std::sqrt(kw) / r, default_wall_stiffness(s, r, k)));
  }
  if (sim.fluid.viscosity_model == ViscosityModel::Paper && !derived.viscosity && sim.fluid.viscosity == 0)
    desc.warnings.push_back(fmt::format(
        "Fluid.viscosity = 0: nothing damps the pressure waves inside the fluid (wall damping acts only at the "
        "walls), so the run may heat up and blow up; viscosity = {:.3g} (the default: Monaghan's artificial "
        "viscosity alpha = {:g}, docs/reliability.md \"Defaults\") would damp them",
        viscosity_for_sound_speed(D, kArtificialViscosityAlpha, sim.kernel_radius, std::sqrt(k),
                                  sim.fluid.rest_density),
        kArtificialViscosityAlpha));
}

template <int D>
void read_body(ObjectReader& root, SceneDesc& desc) {
  SceneBody<D>& body = desc.set_body<D>();
  SimulationParams<D>& sim = body.sim;
  Derived derived;
  root.object("Configuration", detail::kConfigurationKeys,
              [&](ObjectReader& c) { read_configuration<D>(c, desc, sim, derived); });
  root.object("Fluid", detail::kFluidKeys, [&](ObjectReader& f) { read_fluid<D>(f, sim, derived); });
  read_container<D>(root, sim, derived);
  double total = read_blocks<D>(root, body);
  root.array_of_objects("Obstacles", detail::kObstacleKeys, [&](ObjectReader& o, std::size_t) {
    Box<D> box;
    sim.shapes.push_back(read_solid<D>(o, box));
    sim.obstacles.push_back(box);
    sim.motions.push_back(read_motion<D>(o, sim.obstacles.back()));
    sim.bodies.push_back(read_floating<D>(o, sim.motions.back()));
    if (sim.bodies.back().dynamic && sim.shapes.back().inverted)
      o.ctx().fail(o.child("dynamic"),
                   "an inverted shape (the fluid inside it) cannot float: its solid is "
                   "everything outside it; remove \"dynamic\" or \"inverted\"");
  });
  if (!any_shape(sim)) sim.shapes.clear();
  // (none moves, none floats: as a scene without motions or bodies)
  if (std::none_of(sim.motions.begin(), sim.motions.end(), [](const ObstacleMotion<D>& m) { return m.moves(); }))
    sim.motions.clear();
  if (!any_dynamic_body(sim)) sim.bodies.clear();
  // (every dimension's keys: read_emitter says why a 3D key is not one of a 2D scene)
  root.array_of_objects("Emitters", detail::emitter_keys(3), [&](ObjectReader& e, std::size_t) {
    sim.emitters.push_back(read_emitter<D>(e, sim));
    total += static_cast<double>(sim.emitters.back().max_particles);
  });

  if (total < 1)
    root.ctx().fail("FluidBlocks", "the scene has no particles: add a FluidBlocks entry or an Emitters entry");
  if (total > 2e9)
    root.ctx().fail("FluidBlocks",
                    fmt::format("the scene would hold {:.3g} particles; at most 2e9 are supported", total));

  const SceneScales scales = scene_scales<D>(body);
  resolve_defaults<D>(root.ctx(), body, derived, scales);
  root.object("Configuration", detail::kConfigurationKeys, [&](ObjectReader& c) {
    read_run_length(c, desc, sim.time_step, sim.time_stepping == TimeStepping::Cfl, sim.cfl.min_dt);
  });
  check_emitter_travel<D>(root.ctx(), sim, derived.time_step);
  warn_from_scales<D>(desc, sim, derived, scales);
  if (sim.method == SimulationMethod::Dfsph && sim.fluid.kernel == KernelKind::Paper)
    desc.warnings.push_back(
        "Configuration.kernel = \"paper\" with simulationMethod \"dfsph\": the paper's kernels take the density by "
        "poly6 and the gradient by spiky, which the divergence-free solve cannot reconcile (docs/physics.md, "
        "\"DFSPH\", \"Kernels\"); give kernel \"cubic\", as the DFSPH scenes do");
  try {
    for (const std::string& w : check_time_step<D>(sim)) desc.warnings.push_back(w);
  } catch (const Error& e) {
    root.ctx().fail(e.where(), e.message());
  }
  preflight<D>(desc, root.ctx());
}

}  // namespace

SceneDesc parse_scene(const std::string& text, const std::string& source, const std::vector<std::string>& overrides,
                      OverrideNaming naming) {
  json doc = detail::parse_json(text, source);
  if (!doc.is_object())
    throw Error("expected a JSON object { ... } at the top level, got " + detail::describe(doc), source);
  detail::ReadContext ctx;
  ctx.source = source;
  ctx.naming = naming;
  ctx.overridden = detail::apply_overrides(doc, overrides, &ctx.replaced, naming);
  SceneDesc desc;
  desc.source = source;
  ObjectReader root(doc, "", ctx, detail::kRootKeys);
  desc.version = static_cast<int>(root.integer("version", "the scene format version 1", 1, 1));
  desc.name = root.string("name", "a scene name (letters, digits, - and _)", "scene");
  if (desc.name.empty() || desc.name.find_first_not_of(
                               "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789-_") != std::string::npos)
    ctx.fail("name", "expected a non-empty name of letters, digits, - and _, got \"" + desc.name + "\"");
  desc.description = root.string("description", "a description", "");
  root.string("units", "\"SI\"", "SI");
  if (doc.contains("units") && doc["units"] != "SI") ctx.fail("units", "only \"SI\" units are supported");
  if (root.integer("dimension", "the dimension 2 or 3", 2, 3) == 2)
    read_body<2>(root, desc);
  else
    read_body<3>(root, desc);
  return desc;
}

std::string read_scene_text(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw Error("is a directory; expected a scene file (.json)", path);
  const fs::file_status st = fs::status(path, ec);
  if (!ec && fs::exists(st) && !fs::is_regular_file(st))
    throw Error("is not a regular file (a device, FIFO or socket); expected a scene file (.json)", path);
  const auto too_large = [&] {
    return Error(fmt::format("the scene file is larger than {} MiB; a scene is a few kB of JSON (is this the right "
                             "file?)",
                             kMaxSceneBytes >> 20),
                 path);
  };
  if (fs::is_regular_file(st) && fs::file_size(path, ec) > kMaxSceneBytes && !ec) throw too_large();
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("cannot open the scene file (does it exist and is it readable?)", path);
  // Read in blocks up to the limit: a file that grows while it is read is refused too.
  std::string text;
  std::vector<char> block(std::size_t{1} << 16);
  while (in.read(block.data(), static_cast<std::streamsize>(block.size())) || in.gcount() > 0) {
    text.append(block.data(), static_cast<std::size_t>(in.gcount()));
    if (text.size() > kMaxSceneBytes) throw too_large();
  }
  if (in.bad()) throw Error("cannot read the scene file", path);
  return text;
}

SceneDesc read_scene_file(const std::string& path, const std::vector<std::string>& overrides, OverrideNaming naming) {
  return parse_scene(read_scene_text(path), path, overrides, naming);
}

}  // namespace sph
