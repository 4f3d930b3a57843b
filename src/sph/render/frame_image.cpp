#include <sph/render/frame_image.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include <fmt/format.h>

#include <sph/core/error.h>
#include <sph/render/compose.h>
#include <sph/render/font.h>
#include <sph/surface/solid_cut.h>
#include <sph/surface/surface.h>

namespace sph {

namespace {

/// The 2D surface lines: dark blue, apart from every colormap's particles.
constexpr Rgb kSurfaceLine{20, 40, 120};

/// `t = 0.125 s` with enough digits to tell frames apart at usual frame rates.
std::string time_label(double t) { return fmt::format("t = {:.3f} s", t); }

/// The x, y of each particle of a 2D frame, as render_particles takes them (a 3D frame's
/// positions are passed as they are).
std::vector<double> xy_of(const FrameData& frame) {
  std::vector<double> xy(2 * frame.size);
  for (std::size_t i = 0; i < frame.size; ++i) {
    xy[2 * i] = frame.position[3 * i];
    xy[2 * i + 1] = frame.position[3 * i + 1];
  }
  return xy;
}

/// The box of obstacle k of `sim` placed by `pose`, as render_particles draws it.
template <int D>
SolidBox placed_box(const SimulationParams<D>& sim, std::size_t k, const RigidPose<D>& pose) {
  SPH_CHECK(k < sim.obstacles.size(), "no such obstacle");
  const Box<D>& box = sim.obstacles[k];
  SolidBox s;
  for (int a = 0; a < D; ++a) {
    s.lo[a] = box.lo[a];
    s.hi[a] = box.hi[a];
  }
  // A 2D pose turns about z: its upper-left 2 x 2 is all that matters, and z stays.
  for (std::size_t r = 0; r < D; ++r)
    for (std::size_t c = 0; c < D; ++c) s.rotation[3 * r + c] = pose.rotation[3 * r + c];
  for (int a = 0; a < D; ++a) {
    s.center[a] = pose.center[a];
    s.translation[a] = pose.translation[a];
  }
  if (const ObstacleShape<D>* shape = obstacle_shape(sim, k)) {
    for (const auto& v : shape->vertices) {
      std::array<double, 3> x{};
      for (int a = 0; a < D; ++a) x[static_cast<std::size_t>(a)] = v[a];
      s.vertices.push_back(x);
    }
    if constexpr (D == 3)
      for (const auto& t : shape->faces) s.triangles.push_back(t);
    s.inverted = shape->inverted;
  }
  return s;
}

}  // namespace

SolidBox obstacle_solid(const SimulationParams<2>& sim, std::size_t k, double time,
                        std::span<const BodyPoseRow> bodies) {
  return placed_box(sim, k, obstacle_pose_at(sim, k, time, bodies));
}

SolidBox obstacle_solid(const SimulationParams<3>& sim, std::size_t k, double time,
                        std::span<const BodyPoseRow> bodies) {
  return placed_box(sim, k, obstacle_pose_at(sim, k, time, bodies));
}

std::vector<SolidBox> run_obstacles(const RunDirectory& run, double time) {
  return run.scene.visit_body([&](const auto& body) {
    std::vector<SolidBox> out;
    for (std::size_t k = 0; k < body.sim.obstacles.size(); ++k)
      out.push_back(obstacle_solid(body.sim, k, time, run.bodies));
    return out;
  });
}

std::pair<double, double> run_color_range(std::span<const RunDirectory> runs, ColorBy by, std::size_t max_frames,
                                          std::size_t max_values) {
  SPH_CHECK(max_frames >= 2 && max_values >= 1, "sample sizes");
  std::vector<std::vector<double>> sampled;
  for (const RunDirectory& run : runs) {
    const std::size_t n = run.frames.size();
    const std::size_t take = std::min(n, max_frames);
    for (std::size_t k = 0; k < take; ++k) {
      const std::size_t index = take == 1 ? 0 : k * (n - 1) / (take - 1);
      FrameData frame;
      try {
        frame = read_frame(run.frames[index]);
      } catch (const Error& e) {
        // (the frames asked for may be fine: say how to render them without this one)
        throw Error(e.message() +
                        " (the color range samples the run's frames, this one among them; give --range "
                        "LO,HI to render other frames without it)",
                    e.where());
      }
      const std::vector<double> values = color_values(frame, by, run);
      const std::size_t stride = std::max<std::size_t>(1, values.size() / max_values);
      std::vector<double>& out = sampled.emplace_back();
      for (std::size_t i = 0; i < values.size(); i += stride) out.push_back(values[i]);
    }
  }
  return color_range(by, sampled);
}

Image render_frame(std::span<const RunDirectory> runs, std::span<const FrameData> frames, const FrameStyle& style) {
  SPH_CHECK(!runs.empty() && runs.size() == frames.size(), "one frame per run");
  std::vector<Image> panels;
  std::vector<std::string> captions;
  for (std::size_t k = 0; k < runs.size(); ++k) {
    const RunDirectory& run = runs[k];
    const FrameData& frame = frames[k];
    SPH_CHECK(frame.position.size() == 3 * frame.size, "3 coordinates per particle");
    const std::vector<SolidBox> obstacles = run_obstacles(run, frame.time);  // where they are now
    SurfaceMesh mesh;
    if (style.surface) {
      SurfaceSettings settings = style.surface_settings;
      fit_to_run(settings, run.particle_radius, run.box_lo, run.box_hi);
      settings.solids = run_obstacles_distance(run, frame.time);
      mesh = extract_surface(frame.position, run.dimension, settings);
    }
    if (style.surface && run.dimension == 3) {
      panels.push_back(render_surface(mesh, run.particle_radius, run.box_lo, run.box_hi, style.view, obstacles));
    } else {
      const std::vector<Rgb> colors = particle_colors(frame, style.color, run);
      const std::vector<double> xy = run.dimension == 2 ? xy_of(frame) : std::vector<double>();
      const std::span<const double> xyz = run.dimension == 2 ? std::span<const double>(xy) : frame.position;
      Image panel = render_particles(xyz, run.dimension, colors, run.particle_radius, run.box_lo, run.box_hi,
                                     style.view, obstacles);
      if (style.surface) {  // 2D: the surface lines over the particles, in the same camera
        const ParticleCamera cam(2, run.box_lo, run.box_hi, run.particle_radius, style.view);
        for (const auto& seg : mesh.segments) {
          const auto& u = mesh.vertices[seg[0]];
          const auto& v = mesh.vertices[seg[1]];
          const auto p = cam.project({u[0], u[1], 0.0});
          const auto q = cam.project({v[0], v[1], 0.0});
          panel.draw_line(p[0], p[1], q[0], q[1], kSurfaceLine, 2.0);
        }
      }
      panels.push_back(std::move(panel));
    }
    // The time in a caption row above the panel, where it never covers particles or the box.
    captions.push_back(runs.size() > 1 ? fmt::format("{}, {}", run.label, time_label(frame.time))
                                       : time_label(frame.time));
  }
  Image img = hstack(panels, captions, style.view.background);
  const int dim = runs[0].dimension;
  // A 3D surface shows no particle colors, so a color bar or key would describe nothing.
  if (!style.legend || (style.surface && dim == 3)) return img;
  if (color_by_is_scalar(style.color.by))
    return add_colorbar(img, style.color.map, style.color.lo, style.color.hi, color_by_label(style.color.by, dim),
                        style.view.background);
  if (style.color.by == ColorBy::None) return img;     // one color: nothing to explain
  const int scale = style.view.height >= 380 ? 2 : 1;  // as add_colorbar chooses for its labels
  const std::string key = dim == 3 ? "color: initial x red, y green, z blue" : "color: initial x red, y green";
  draw_text(img, 8 * scale, img.height() - text_height(scale) - 6 * scale, key, kInk, scale);
  return img;
}

}  // namespace sph
