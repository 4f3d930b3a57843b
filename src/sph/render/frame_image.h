#pragma once
/// \file Pictures of a run's frames for `sph render`: the particles colored by a quantity, the
/// scene's obstacles as solid boxes, the simulated time, a color bar, and for a compare directory every mode side by
/// side.

#include <span>
#include <string>
#include <vector>

#include <sph/io/frames.h>
#include <sph/render/color_by.h>
#include <sph/render/image.h>
#include <sph/render/particles.h>

namespace sph {

/// How frames look.
struct FrameStyle {
  ParticleView view;  ///< size and camera of each panel
  ColorSpec color;
  bool legend = true;  ///< a color bar for scalar quantities, a key for initial position
  /// Draw the fluid's free surface (extract_surface, spacing 2 particleRadius of each run): in 3D
  /// the shaded mesh instead of the particles (render_surface; no legend), in 2D the surface
  /// lines over the particles.
  bool surface = false;
  SurfaceSettings surface_settings;  ///< for `surface`; its spacing is set per run
};

/// Obstacle k of `sim` (its box at rest) placed where its motion (obstacle_motion) puts it at
/// `time` (s), or a floating body where `bodies` (its run's bodies.csv) has it at the frame
/// nearest `time` (where it started if the table has no row of it), as render_particles draws it;
/// z is 0 in 2D. Precondition: k < sim.obstacles.size().
SolidBox obstacle_solid(const SimulationParams<2>& sim, std::size_t k, double time,
                        std::span<const BodyPoseRow> bodies = {});
SolidBox obstacle_solid(const SimulationParams<3>& sim, std::size_t k, double time,
                        std::span<const BodyPoseRow> bodies = {});

/// The scene's obstacles (its Obstacles) as render_particles draws them at `time` (s, a frame's
/// simulated time), in the scene's order: each moving one where its motion puts it then, each
/// floating one where the run's bodies.csv has it, the others at rest (obstacle_solid).
std::vector<SolidBox> run_obstacles(const RunDirectory& run, double time);

/// The color range for `by` over whole runs (color_range of every run's values together), from
/// at most `max_frames` evenly spaced frames of each run (first and last included) and at most
/// `max_values` evenly spaced particles of each frame: enough for percentiles, cheap for large
/// runs. Throws sph::Error as read_frame and color_values do.
std::pair<double, double> run_color_range(std::span<const RunDirectory> runs, ColorBy by, std::size_t max_frames = 60,
                                          std::size_t max_values = 50000);

/// One panel per run, side by side, each under a caption with its frame's simulated time (and
/// its run's label when there are several); `frames[k]` is a frame of `runs[k]`. Throws sph::Error as particle_colors
/// and ParticleCamera do. Precondition: runs.size() == frames.size() >= 1.
Image render_frame(std::span<const RunDirectory> runs, std::span<const FrameData> frames, const FrameStyle& style);

}  // namespace sph
