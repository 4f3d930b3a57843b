// `sph view DIR`: one self-contained HTML page that plays a run (or a comparison's runs side by
// side) in the browser, offline.

#include <filesystem>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include <sph/core/error.h>
#include <sph/core/spelling.h>
#include <sph/core/version.h>
#include <sph/io/atomic_file.h>
#include <sph/render/viewer.h>

#include "cli_checks.h"
#include "commands.h"

namespace sph::app {

namespace {

namespace fs = std::filesystem;

struct ViewCliOptions {
  std::string dir;
  std::optional<std::string> output;
  std::vector<std::string> color_by;
  bool no_progress = false;  // (accepted as by the other commands; the page is written at once)
  std::size_t max_frames = 300;
  double max_size_mb = 200;
};

/// "speed,density" (the option may also be given several times).
std::vector<ColorBy> parse_color_by(const std::vector<std::string>& items) {
  std::vector<ColorBy> out;
  for (const std::string& item : items) {
    std::stringstream ss(item);
    for (std::string name; std::getline(ss, name, ',');) {
      if (name.empty()) continue;
      const auto by = color_by_from_name(name);
      if (by == ColorBy::None)
        throw Error(fmt::format("none is sph render's; the page colors particles in one color when their frames hold "
                                "no quantity; expected one or more of: {}",
                                color_by_names()),
                    "--color-by");
      if (!by)
        throw Error(fmt::format("unknown quantity \"{}\"{}; expected one of: {}", name,
                                did_you_mean(name, color_by_list()), color_by_names()),
                    "--color-by");
      out.push_back(*by);
    }
  }
  if (!items.empty() && out.empty())
    throw Error(fmt::format("no quantity given; expected one or more of: {}", color_by_names()), "--color-by");
  return out;
}

/// Refuses an output path that cannot be written before any frame is read: its directory must
/// exist, and the path must not be a directory.
void check_output(const fs::path& out) {
  std::error_code ec;
  if (out.extension() != ".html" && out.extension() != ".htm")
    throw Error("expected a file name ending in .html", out.string());
  if (fs::is_directory(out, ec)) throw Error("is a directory; expected the path of an .html file", out.string());
  const fs::path parent = out.has_parent_path() ? out.parent_path() : fs::path(".");
  require_directory(parent, "an existing directory for the page");
  AtomicFile probe(out);  // throws naming the directory if it is not writable; removed unused
}

int view(const ViewCliOptions& opt) {
  const fs::path dir(opt.dir);
  if (opt.output && opt.output->empty())
    throw Error("an empty file name; expected the page to write, e.g. -o out/my_run/view.html", "-o/--output");
  const fs::path out = opt.output ? fs::path(*opt.output) : dir / "view.html";
  ViewOptions vo;
  vo.max_frames = opt.max_frames;
  vo.color_by = parse_color_by(opt.color_by);
  vo.max_bytes = static_cast<std::size_t>(opt.max_size_mb * 1e6);
  vo.generator = std::string("sph ") + kVersion;
  // The directory first (its error is the likelier one), then the output path.
  run_directories(dir);
  check_output(out);

  const ViewPage page = build_view_page(dir, vo);
  write_file_atomic(out, page.html);
  fmt::print(stderr, "sph: view {} -> {}\n", dir.string(), out.string());
  fmt::print(stderr, "  {} run{}, {} of {} frames, up to {} particles, {:.1f} MB\n", page.runs,
             page.runs == 1 ? "" : "s", page.frames_shown, page.frames_total, page.max_particles,
             static_cast<double>(page.html.size()) / 1e6);
  for (const std::string& note : page.notes) fmt::print(stderr, "  note: {}\n", note);
  fmt::print(stderr, "  open it in a browser: file://{}\n", fs::absolute(out).lexically_normal().string());
  return kOk;
}

}  // namespace

std::function<int()> add_view_command(CLI::App& app) {
  auto opt = std::make_shared<ViewCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "view",
      "Write a self-contained HTML page that plays a run in 3D in the browser (offline): orbit, play, scrub, "
      "color by a quantity; a comparison's runs side by side");
  cmd->add_option("dir", opt->dir, "A run's output directory (sph run -o DIR) or a comparison's (sph compare -o DIR)")
      ->required();
  cmd->add_option("-o,--output", opt->output, "The page to write (default: DIR/view.html)");
  cmd->add_option("--color-by", opt->color_by,
                  "Quantities the page offers, the first shown first (comma-separated or repeated): speed, "
                  "kinetic_energy, density, pressure, initial_position (default: all the frames hold)");
  cmd->add_option("--max-frames", opt->max_frames,
                  "Frames kept per run; a run with more is subsampled evenly, first and last kept")
      ->default_str("300")
      ->check(in_range(std::size_t{2}, std::size_t{1000000}));
  cmd->add_option("--max-size", opt->max_size_mb, "Refuse a page larger than this, in MB")
      ->default_str("200")
      ->check(in_range(1.0, 1e6));
  cmd->add_flag("--no-progress", opt->no_progress, "Accepted as by the other commands (view prints no progress)");
  return [opt, cmd]() -> int {
    if (!cmd->parsed()) return kBadInput;
    return view(*opt);
  };
}

}  // namespace sph::app
