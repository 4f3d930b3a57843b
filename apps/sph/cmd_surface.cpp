// `sph surface DIR`: the free surface of a run's frames as triangle meshes (PLY, OBJ) and
// OpenVDB level sets, or as polylines in 2D (docs/visualization.md, "Surfaces").

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <unistd.h>

#include <fmt/format.h>

#include <sph/core/error.h>
#include <sph/core/parallel.h>
#include <sph/core/timer.h>
#include <sph/io/atomic_file.h>
#include <sph/io/frame_format.h>
#include <sph/io/frames.h>
#include <sph/io/run_directory.h>
#include <sph/surface/mesh_files.h>
#include <sph/surface/solid_cut.h>
#include <sph/surface/surface.h>

#include "cli_checks.h"
#include "commands.h"
#include "progress.h"

namespace sph::app {

namespace {

namespace fs = std::filesystem;

struct SurfaceCliOptions {
  std::string dir;
  std::optional<std::string> output;
  std::string frames = "all";
  std::string format = "all";
  std::string frame_format;
  SurfaceSettings settings;
  int threads = 0;
  bool no_progress = false;
};

int surface(SurfaceCliOptions opt) {
  // Everything that can be refused is checked before anything is written.
  const SurfaceFormats formats = parse_surface_formats(opt.format, "--format");
  std::optional<FrameFormat> frame_format;
  if (!opt.frame_format.empty() && !(frame_format = parse_frame_format(opt.frame_format)))
    throw Error(
        fmt::format("unknown frame format \"{}\"; expected {}", opt.frame_format, frame_format_list("", " or ")),
        "--frame-format");
  if (opt.output) check_output_path(*opt.output, "-o/--output");
  if (opt.threads > 0) set_num_threads(opt.threads);
  const RunDirectory run = open_run_directory(opt.dir, frame_format);
  fit_to_run(opt.settings, run.particle_radius, run.box_lo, run.box_hi);
  if (const std::string e = surface_settings_error(opt.settings); !e.empty()) {
    const bool res = e.rfind("resolution", 0) == 0, smooth = e.rfind("smoothing", 0) == 0;
    throw Error(e, res ? "--resolution" : smooth ? "--smoothing" : e.rfind("iso", 0) == 0 ? "--iso" : opt.dir);
  }
  // ("all" means the formats that apply: a 2D run's are ply and obj)
  if (run.dimension == 2 && formats.vdb && opt.format != "all")
    throw Error("a 2D run's surfaces are polylines, which have no level set: vdb is for 3D runs; choose ply or obj",
                "--format");
  const std::vector<std::size_t> frames = parse_frames(opt.frames, run.frames.size());

  const fs::path out = opt.output ? fs::path(*opt.output) : fs::path(opt.dir) / "surface";
  // The meshes replace an earlier surface's (only the files sph surface makes) when they are all
  // written: a command that fails half-way leaves the earlier ones whole.
  StagedFiles staged(out, is_surface_output, "the surfaces");

  fmt::print(
      stderr, "sph: surface of {} frame{} of {} ({}D, voxel {:.3g} m = spacing / {}, smoothing {} spacings) -> {}\n",
      frames.size(), frames.size() == 1 ? "" : "s", opt.dir, run.dimension,
      opt.settings.spacing / opt.settings.resolution, opt.settings.resolution, opt.settings.smoothing, out.string());
  Progress progress(
      static_cast<std::int64_t>(frames.size()),
      opt.no_progress ? Progress::Mode::Off : (::isatty(STDERR_FILENO) ? Progress::Mode::Bar : Progress::Mode::Lines),
      stderr, "frame");
  Stopwatch wall;
  double mesh_seconds = 0;
  std::size_t particles = 0, faces = 0;
  std::vector<fs::path> written;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const FrameData data = read_frame(run.frames[frames[k]]);
    Stopwatch mesh_wall;
    opt.settings.solids = run_obstacles_distance(run, data.time);  // (where the obstacles are then)
    const SurfaceMesh mesh = extract_surface(data.position, run.dimension, opt.settings);
    mesh_seconds += mesh_wall.elapsed();
    particles += data.size;
    faces += run.dimension == 3 ? mesh.triangles.size() : mesh.segments.size();
    written = write_surface_frame(staged.path(), frames[k], mesh, data.time, formats);
    progress.update(static_cast<std::int64_t>(k + 1), 0);
  }
  staged.commit();
  progress.finish();
  const double seconds = wall.elapsed();
  fmt::print(stderr,
             "sph: done: {} frame{} in {:.2f} s; meshing {:.2f} s for {} particles ({:.2f} M particles/s), {} {} in "
             "all.\n",
             frames.size(), frames.size() == 1 ? "" : "s", seconds, mesh_seconds, particles,
             mesh_seconds > 0 ? 1e-6 * static_cast<double>(particles) / mesh_seconds : 0.0, faces,
             run.dimension == 3 ? "triangles" : "segments");
  for (const fs::path& p : written)
    fmt::print(stderr, "  {}{}\n", frames.size() > 1 ? "... " : "", (out / p.filename()).string());
  return kOk;
}

}  // namespace

std::function<int()> add_surface_command(CLI::App& app) {
  auto opt = std::make_shared<SurfaceCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "surface", "Mesh the free surface of a run's frames: PLY and OBJ meshes and OpenVDB level sets (2D: polylines)");
  cmd->add_option("dir", opt->dir, "A run's output directory (sph run -o DIR)")->required();
  cmd->add_option("-o,--output", opt->output,
                  "Directory for the surfaces (default: DIR/surface); surfaces of an earlier call there "
                  "(surface_NNNNNN.ply/.obj/.vdb) are replaced, other files are kept");
  cmd->add_option("--frames", opt->frames,
                  "Frames to mesh: all, first, last, or numbers separated by commas (-1 is the last)")
      ->default_str("all");
  cmd->add_option("--format", opt->format, "Files per frame: all, or a comma list of ply, obj and vdb (3D only)")
      ->default_str("all");
  cmd->add_option("--resolution", opt->settings.resolution,
                  "Voxels per particle spacing, 0.5 to 8 (finer: smoother and slower)")
      ->default_str("2")
      ->check(in_range(0.5, 8.0));
  cmd->add_option("--smoothing", opt->settings.smoothing,
                  "Kernel radius in particle spacings, 1 to 4 (larger: flatter surfaces, rounder edges)")
      ->default_str("2")
      ->check(in_range(1.0, 4.0));
  cmd->add_option("--iso", opt->settings.iso,
                  "Iso-value of the color field, 0.05 to 0.95 (0.5 puts a flat surface half a spacing beyond the "
                  "outer particles)")
      ->default_str("0.5")
      ->check(in_range(0.05, 0.95));
  cmd->add_option("--frame-format", opt->frame_format,
                  "Which frames to read when the run wrote several formats: " + frame_format_list())
      ->check(not_empty("a frame format: " + frame_format_list("", " or ")));
  cmd->add_option("--threads", opt->threads, "Worker threads (default: all cores)")->check(in_range(1, 4096));
  cmd->add_flag("--no-progress", opt->no_progress, "No progress output");
  return [opt, cmd]() -> int {
    if (!cmd->parsed()) return kBadInput;
    return surface(*opt);
  };
}

}  // namespace sph::app
