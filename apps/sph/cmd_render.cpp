// `sph render DIR`: PNG images (and an MP4) of a run's frames, or of a compare directory's runs
// side by side.

#include <algorithm>
#include <exception>
#include <filesystem>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include <fmt/format.h>

#include <sph/core/error.h>
#include <sph/core/parallel.h>
#include <sph/core/spelling.h>
#include <sph/core/timer.h>
#include <sph/io/atomic_file.h>
#include <sph/io/frame_format.h>
#include <sph/io/frames.h>
#include <sph/io/run_directory.h>
#include <sph/render/frame_image.h>
#include <sph/render/png.h>
#include <sph/render/video.h>

#include "cli_checks.h"
#include "commands.h"
#include "progress.h"

namespace sph::app {

namespace {

namespace fs = std::filesystem;

struct RenderCliOptions {
  std::string dir;
  std::optional<std::string> output;  // -o DIR (given empty: refused)
  std::string color_by;               // empty: speed, or what the frames hold (below)
  std::string colormap;
  std::string range;
  std::string frames = "all";
  std::string size;
  std::string format;
  double azimuth = 30, elevation = 20;
  bool mp4 = false, no_png = false, flat = false, surface = false, no_progress = false;
  double video_fps = 30;
  int threads = 0;
};

/// "W x H" in pixels, e.g. 1280x720.
std::pair<int, int> parse_size(const std::string& s) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  std::istringstream in(s);
  if (!(in >> w >> x >> h) || (x != 'x' && x != 'X') || (in >> extra) || w < 16 || h < 16 || w > 8192 || h > 8192)
    throw Error(fmt::format("\"{}\" is not an image size; expected WIDTHxHEIGHT in pixels, 16 to 8192 a side, "
                            "e.g. 1280x720",
                            s),
                "--size");
  return {w, h};
}

/// "LO,HI" with LO < HI.
std::pair<double, double> parse_range(const std::string& s) {
  double lo = 0, hi = 0;
  char comma = 0, extra = 0;
  std::istringstream in(s);
  if (!(in >> lo >> comma >> hi) || comma != ',' || (in >> extra) || !std::isfinite(lo) || !std::isfinite(hi) ||
      !(lo < hi))
    throw Error(fmt::format("\"{}\" is not a color range; expected LO,HI with LO < HI, e.g. 0,2.5", s), "--range");
  return {lo, hi};
}

int render(const RenderCliOptions& opt) {
  // Everything that can be refused is checked before anything is written.
  std::optional<ColorBy> by;
  if (!opt.color_by.empty() && !(by = color_by_from_name(opt.color_by)))
    throw Error(fmt::format("unknown quantity \"{}\"{}; expected one of: {}, or none", opt.color_by,
                            did_you_mean(opt.color_by, color_by_list()), color_by_names()),
                "--color-by");
  std::optional<Colormap> map;
  if (!opt.colormap.empty() && !(map = colormap_from_name(opt.colormap)))
    throw Error(fmt::format("unknown color map \"{}\"{}; expected viridis, coolwarm or turbo", opt.colormap,
                            did_you_mean(opt.colormap, kColormapNames)),
                "--colormap");
  std::optional<FrameFormat> format;
  if (!opt.format.empty() && !(format = parse_frame_format(opt.format)))
    throw Error(fmt::format("unknown frame format \"{}\"; expected {}", opt.format, frame_format_list("", " or ")),
                "--format");
  if (opt.no_png && !opt.mp4) throw Error("--no-png leaves nothing to write; give --mp4 with it", "--no-png");
  if (opt.output) check_output_path(*opt.output, "-o/--output");
  if (opt.mp4 && !video_encoder_available()) throw Error(kVideoEncoderMissing, "--mp4");
  if (opt.threads > 0) set_num_threads(opt.threads);

  std::vector<RunDirectory> runs;
  for (const fs::path& d : run_directories(opt.dir)) runs.push_back(open_run_directory(d, format));
  std::size_t count = runs[0].frames.size();
  for (const RunDirectory& r : runs) count = std::min(count, r.frames.size());
  for (const RunDirectory& r : runs)
    if (r.frames.size() != count)
      fmt::print(stderr, "sph: warning: {} has {} frames, fewer than the others; rendering the first {} of each\n",
                 r.dir.string(), r.frames.size(), count);
  const std::vector<std::size_t> frames = parse_frames(opt.frames, count);
  // The first run's first frame, read once for what needs it before rendering.
  std::optional<FrameData> first_frame;
  const auto first_of_first_run = [&]() -> const FrameData& {
    if (!first_frame) first_frame = read_frame(runs[0].frames[frames.front()]);
    return *first_frame;
  };
  if (!by) {
    // Speed, unless the run left the velocities out (--fields): then the first quantity the
    // frames hold, or one color when they hold positions only.
    const FrameData& first = first_of_first_run();
    by = ColorBy::None;
    for (const ColorBy q : kColorByAll)
      if (first.field(color_by_field(q))) {
        by = q;
        break;
      }
    if (by != ColorBy::Speed)
      fmt::print(stderr, "sph: the frames hold no velocities (the run left them out with --fields): {}\n",
                 by == ColorBy::None ? std::string("every particle in one color")
                                     : fmt::format("colored by {}", color_by_name(*by)));
  }
  const std::string coloring =
      *by == ColorBy::None ? std::string("in one color") : fmt::format("colored by {}", color_by_name(*by));
  if (!color_by_is_scalar(*by))
    for (const auto& [flag, given] : {std::pair{"--range", !opt.range.empty()}, {"--colormap", !opt.colormap.empty()}})
      if (given)
        fmt::print(stderr, "sph: warning: {}: particles {} take no color map: it is ignored\n", flag, coloring);

  FrameStyle style;
  const bool several = runs.size() > 1;
  const auto [w, h] = opt.size.empty() ? (several ? std::pair{640, 480} : std::pair{1280, 720}) : parse_size(opt.size);
  style.view = default_particle_view(runs[0].dimension, w, h);
  if (runs[0].dimension == 3) style.view.azimuth_deg = opt.azimuth, style.view.elevation_deg = opt.elevation;
  style.view.shaded = !opt.flat;
  style.surface = opt.surface;
  style.color.by = *by;
  style.color.map = map.value_or(default_colormap(*by));
  if (!opt.range.empty()) {
    std::tie(style.color.lo, style.color.hi) = parse_range(opt.range);
  } else if (color_by_is_scalar(*by)) {
    std::tie(style.color.lo, style.color.hi) = run_color_range(runs, *by);
  }

  // A field the frames lack is refused before anything is written (the range above found it
  // for scalars; initial position needs the first frame read).
  if (!color_by_is_scalar(*by))
    for (const RunDirectory& r : runs) {
      if (&r == &runs[0])
        particle_colors(first_of_first_run(), style.color, r);
      else
        particle_colors(read_frame(r.frames[frames.front()]), style.color, r);
    }

  const fs::path out = opt.output ? fs::path(*opt.output) : fs::path(opt.dir) / "render";
  // The images and movie replace an earlier render's (only the files a render makes:
  // is_render_output) when they are all written, so that two renders are never mixed, a render
  // that fails leaves the earlier one whole, and a user's other files there are kept.
  StagedFiles staged(out, is_render_output, "the images");
  std::unique_ptr<VideoWriter> video;
  Stopwatch wall;
  fmt::print(stderr, "sph: render {} frame{} of {} ({}, {}) -> {}\n", frames.size(), frames.size() == 1 ? "" : "s",
             opt.dir,
             several ? fmt::format("{} runs side by side", runs.size()) : fmt::format("{}D", runs[0].dimension),
             opt.surface && runs[0].dimension == 3 ? std::string("the shaded free surface")
             : opt.surface                         ? coloring + ", with the free surface"
                                                   : coloring,
             out.string());
  Progress progress(
      static_cast<std::int64_t>(frames.size()),
      opt.no_progress ? Progress::Mode::Off : (::isatty(STDERR_FILENO) ? Progress::Mode::Bar : Progress::Mode::Lines),
      stderr, "frame");

  // Frames are rendered in parallel, a batch at a time, and handed to the movie in order.
  const std::size_t batch = 2 * static_cast<std::size_t>(num_threads());
  std::vector<Image> images(batch);
  std::vector<std::string> errors(batch);
  for (std::size_t first = 0; first < frames.size(); first += batch) {
    const std::size_t n = std::min(batch, frames.size() - first);
    parallel_for(n, [&](std::size_t k) {
      try {
        const std::size_t index = frames[first + k];
        std::vector<FrameData> data;
        for (const RunDirectory& r : runs) data.push_back(read_frame(r.frames[index]));
        images[k] = render_frame(runs, data, style);
        if (!opt.no_png) write_png(staged.path() / fmt::format("frame_{:06d}.png", index), images[k]);
      } catch (const std::exception& e) {
        errors[k] = e.what();
      }
    });
    for (std::size_t k = 0; k < n; ++k)
      if (!errors[k].empty()) throw Error(errors[k]);
    if (opt.mp4) {
      if (!video)
        video = std::make_unique<VideoWriter>(staged.path() / "movie.mp4", images[0].width(), images[0].height(),
                                              opt.video_fps);
      for (std::size_t k = 0; k < n; ++k) video->add(images[k]);
    }
    progress.update(static_cast<std::int64_t>(first + n), 0);
  }
  if (video) video->finish();
  staged.commit();
  progress.finish();
  const double seconds = wall.elapsed();
  fmt::print(stderr, "sph: done: {} frame{} in {:.2f} s ({:.1f} ms per frame).\n", frames.size(),
             frames.size() == 1 ? "" : "s", seconds, 1e3 * seconds / static_cast<double>(frames.size()));
  if (!opt.no_png) {
    // The pictures written: all of them when few, first ... last when they run on without a gap.
    const auto name = [](std::size_t f) { return fmt::format("frame_{:06d}.png", f); };
    std::string pictures = name(frames.front());
    if (frames.size() <= 3) {
      for (std::size_t k = 1; k < frames.size(); ++k) pictures += ", " + name(frames[k]);
    } else if (frames.back() - frames.front() + 1 == frames.size()) {
      pictures += " ... " + name(frames.back());
    } else {
      pictures += fmt::format(", {}, ... {} ({} pictures)", name(frames[1]), name(frames.back()), frames.size());
    }
    fmt::print(stderr, "  {}/{}\n", out.string(), pictures);
  }
  if (video)
    fmt::print(stderr, "  {}/movie.mp4 ({} frames at {} per second)\n", out.string(), video->frames(), opt.video_fps);
  return kOk;
}

}  // namespace

std::function<int()> add_render_command(CLI::App& app) {
  auto opt = std::make_shared<RenderCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "render", "Render a run's frames to PNG images (and an MP4 movie); a compare directory's runs side by side");
  cmd->add_option("dir", opt->dir, "A run's output directory (sph run -o DIR) or a comparison's (sph compare -o DIR)")
      ->required();
  cmd->add_option("-o,--output", opt->output,
                  "Directory for the images and movie (default: DIR/render); the images and movie of an earlier "
                  "render there (frame_NNNNNN.png, movie.mp4) are replaced, other files are kept");
  cmd->add_option("--color-by", opt->color_by,
                  "Color particles by speed, kinetic_energy, density, pressure or initial_position, or none (one "
                  "color) (default: speed, or the first of these the frames hold; none if they hold positions only)")
      ->check(not_empty("a quantity: " + color_by_names() + ", or none"));
  cmd->add_option("--colormap", opt->colormap, "Color map: turbo, viridis or coolwarm (default: by quantity)")
      ->check(not_empty("a color map: turbo, viridis or coolwarm"));
  cmd->add_option("--range", opt->range,
                  "Color range LO,HI (default: over the whole run, 0 or the 0.5th to the 99.5th percentile)")
      ->check(not_empty("LO,HI with LO < HI, e.g. 0,2.5"))
      ->type_name("LO,HI");
  cmd->add_option("--frames", opt->frames,
                  "Frames to render: all, first, last, or numbers separated by commas (-1 is the last)")
      ->default_str("all");
  cmd->add_option("--size", opt->size,
                  "Size of each panel, WIDTHxHEIGHT pixels (default: 1280x720, 640x480 side by side); the image adds a "
                  "caption row above and the color bar to the right")
      ->check(not_empty("WIDTHxHEIGHT in pixels, e.g. 1280x720"))
      ->type_name("WxH");
  cmd->add_option("--azimuth", opt->azimuth, "3D camera: turn about the vertical axis, degrees")
      ->check(in_range(-360.0, 360.0))
      ->default_str("30");
  cmd->add_option("--elevation", opt->elevation, "3D camera: look down from this angle, degrees")
      ->check(in_range(-90.0, 90.0))
      ->default_str("20");
  cmd->add_flag("--flat", opt->flat, "Flat discs instead of shaded spheres");
  cmd->add_flag("--surface", opt->surface,
                "Draw the fluid's free surface (sph surface's mesh, shaded) instead of particles; 2D: the surface "
                "lines over the particles");
  cmd->add_option("--format", opt->format,
                  "Which frames to read when the run wrote several formats: " + frame_format_list())
      ->check(not_empty("a frame format: " + frame_format_list("", " or ")));
  cmd->add_flag("--mp4", opt->mp4, "Also encode the images as movie.mp4 in the output directory (needs ffmpeg)");
  cmd->add_option("--video-fps", opt->video_fps, "Frames per second of the movie")
      ->check(in_range(1.0, 240.0))
      ->default_str("30");
  cmd->add_flag("--no-png", opt->no_png, "Write only the movie, no PNG images");
  cmd->add_option("--threads", opt->threads, "Worker threads (default: all cores)")->check(in_range(1, 4096));
  cmd->add_flag("--no-progress", opt->no_progress, "No progress output");
  return [opt, cmd]() -> int {
    if (!cmd->parsed()) return kBadInput;
    return render(*opt);
  };
}

}  // namespace sph::app
