#include <sph/io/run_directory.h>

#include <algorithm>
#include <fstream>
#include <map>

#include <fmt/format.h>

#include <sph/core/error.h>
#include <sph/io/atomic_file.h>
#include <sph/io/frame_source.h>
#include <sph/neighbors/strategy.h>
#include <sph/scene/scene_reader.h>

namespace sph {

namespace fs = std::filesystem;

namespace {

/// "frame_NNNNNN.EXT" -> NNNNNN (6 digits or more), or nullopt.
std::optional<std::uint64_t> frame_number(const std::string& name, const std::string& ext) {
  if (name.rfind("frame_", 0) != 0 || name.size() < 6 + 6 + 1 + ext.size()) return std::nullopt;
  const std::string tail = "." + ext;
  if (name.compare(name.size() - tail.size(), tail.size(), tail) != 0) return std::nullopt;
  const std::string digits = name.substr(6, name.size() - 6 - tail.size());
  if (digits.size() < 6 || digits.size() > 12) return std::nullopt;
  return detail::parse_count(digits);
}

}  // namespace

std::vector<fs::path> list_frames(const fs::path& dir, FrameFormat format) {
  const std::string ext = frame_format_name(format);
  std::map<std::uint64_t, fs::path> found;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir / "frames", ec)) {
    const auto k = frame_number(entry.path().filename().string(), ext);
    if (!k) continue;  // other files (temporaries of a killed run, notes) are not frames
    if (!found.emplace(*k, entry.path()).second)
      throw Error("two files hold frame " + std::to_string(*k), (dir / "frames").string());
  }
  std::vector<fs::path> frames;
  for (const auto& [k, path] : found) {
    if (k != frames.size())
      throw Error(fmt::format("frame {} is missing (frames/frame_{:06d}.{} not found, frame {} is there): the run "
                              "directory is incomplete",
                              frames.size(), frames.size(), ext, k),
                  dir.string());
    frames.push_back(path);
  }
  return frames;
}

RunDirectory open_run_directory(const fs::path& dir, std::optional<FrameFormat> format) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw Error("no such directory; expected a run directory (sph run -o DIR)", dir.string());
  const fs::path scene_file = dir / "scene.json";
  if (!fs::is_regular_file(scene_file, ec))
    throw Error("is not a run directory: it has no scene.json (expected the output directory of sph run)",
                dir.string());
  RunDirectory run;
  run.dir = dir;
  run.scene = read_scene_file(scene_file.string());
  run.dimension = run.scene.dimension;
  run.scene.visit_body([&]<int D>(const SceneBody<D>& body) {
    const SimulationParams<D>& sim = body.sim;
    run.particle_radius = sim.particle_radius;
    run.kernel_radius = sim.kernel_radius;
    run.particle_mass = sim.particle_mass;
    run.rest_density = sim.fluid.rest_density;
    for (int d = 0; d < D; ++d)
      run.box_lo[static_cast<std::size_t>(d)] = sim.container.lo[d],
      run.box_hi[static_cast<std::size_t>(d)] = sim.container.hi[d];
    run.label = run.scene.name;
    // A run of a compare directory is named by its neighbor mode.
    fs::path full = fs::absolute(dir, ec).lexically_normal();
    if (!full.has_filename()) full = full.parent_path();  // "DIR/" -> "DIR"
    if (fs::is_regular_file(full.parent_path() / kRunListFile, ec)) run.label = std::string(to_string(sim.neighbors));
  });

  if (format) {
    run.format = *format;
    run.frames = list_frames(dir, *format);
    if (run.frames.empty())
      throw Error(std::string("holds no .") + frame_format_name(*format) + " frames (frames/frame_000000." +
                      frame_format_name(*format) + " ...)",
                  dir.string());
    return run;
  }
  for (const FrameFormatDesc& f : kFrameFormats) {
    run.frames = list_frames(dir, f.format);
    if (!run.frames.empty()) {
      run.format = f.format;
      return run;
    }
  }
  throw Error("holds no frames (frames/frame_000000.vtu, .vtk or .ply); was it run with outputEveryNSteps = 0?",
              dir.string());
}

namespace {

std::vector<std::string> read_run_list(const fs::path& dir) {
  const fs::path file = dir / kRunListFile;
  std::ifstream in(file);
  if (!in) throw Error("cannot read the list of runs", file.string());
  std::vector<std::string> names;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '\t')) line.pop_back();
    if (line.empty()) continue;
    if (line.find('/') != std::string::npos || line == "." || line == ".." ||
        std::find(names.begin(), names.end(), line) != names.end())
      throw Error(
          fmt::format("line {}: \"{}\" is not a new subdirectory name; expected one run directory name per line",
                      number, line),
          file.string());
    names.push_back(line);
  }
  if (names.empty()) throw Error("lists no runs; expected one run directory name per line", file.string());
  return names;
}

}  // namespace

void write_run_list(const fs::path& dir, const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) {
    SPH_CHECK(!name.empty() && name.find_first_of("/\n\r") == std::string::npos, "bad run directory name " + name);
    text += name + "\n";
  }
  write_file_atomic(dir / kRunListFile, text);
}

std::vector<fs::path> run_directories(const fs::path& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw Error(
        "no such directory; expected a run directory (sph run -o DIR) or a compare directory (sph compare -o DIR)",
        dir.string());
  if (fs::is_regular_file(dir / "scene.json", ec)) return {dir};
  if (!fs::is_regular_file(dir / kRunListFile, ec))
    throw Error(
        std::string("is neither a run directory (no scene.json) nor a compare directory (no ") + kRunListFile + ")",
        dir.string());
  std::vector<fs::path> runs;
  for (const std::string& name : read_run_list(dir)) {
    if (!fs::is_regular_file(dir / name / "scene.json", ec))
      throw Error("lists \"" + name + "\", which is not a run directory here (no " + name + "/scene.json)",
                  (dir / kRunListFile).string());
    runs.push_back(dir / name);
  }
  return runs;
}

}  // namespace sph
