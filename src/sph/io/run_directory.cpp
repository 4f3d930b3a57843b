#include <sph/io/run_directory.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <map>
#include <random>
#include <sstream>

#include <unistd.h>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include <sph/core/error.h>
#include <sph/io/atomic_file.h>
#include <sph/io/checkpoint.h>
#include <sph/io/frame_source.h>
#include <sph/neighbors/strategy.h>
#include <sph/scene/scene_reader.h>

namespace sph {

namespace fs = std::filesystem;

namespace {

/// "PREFIXNNNNNN.EXT" -> NNNNNN (6 to 12 digits), or nullopt.
std::optional<std::uint64_t> numbered_file(const std::string& name, const std::string& prefix, const std::string& ext) {
  if (name.rfind(prefix, 0) != 0 || name.size() < prefix.size() + 6 + 1 + ext.size()) return std::nullopt;
  const std::string tail = "." + ext;
  if (name.compare(name.size() - tail.size(), tail.size(), tail) != 0) return std::nullopt;
  const std::string digits = name.substr(prefix.size(), name.size() - prefix.size() - tail.size());
  if (digits.size() < 6 || digits.size() > 12) return std::nullopt;
  return detail::parse_count(digits);
}

/// "frame_NNNNNN.EXT" -> NNNNNN (6 digits or more), or nullopt.
std::optional<std::uint64_t> frame_number(const std::string& name, const std::string& ext) {
  return numbered_file(name, "frame_", ext);
}

}  // namespace

void check_output_path(const std::string& path, const std::string& option) {
  if (path.empty()) throw Error("an empty directory name; expected the directory to write to, e.g. out/my_run", option);
  std::error_code ec;
  const fs::path p = fs::absolute(path, ec).lexically_normal();
  if (!ec && p.relative_path().empty())
    throw Error("\"" + path + "\" is the root of the file system; expected a directory of its own, e.g. out/my_run",
                option);
}

bool is_render_output(const std::string& file_name) {
  return file_name == "movie.mp4" || frame_number(file_name, "png").has_value();
}

bool is_surface_output(const std::string& file_name) {
  for (const char* ext : {"ply", "obj", "vdb"})
    if (numbered_file(file_name, "surface_", ext)) return true;
  return false;
}

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

std::vector<BodyPoseRow> read_body_rows(const fs::path& file) {
  std::ifstream in(file);
  if (!in) throw Error("cannot be read", file.string());
  std::string line;
  const std::string header = fmt::format("{}", fmt::join(kBodyColumns, ","));
  if (!std::getline(in, line) || line != header)
    throw Error(fmt::format("line 1 is not the header of a bodies table; expected \"{}\"", header), file.string());
  std::vector<BodyPoseRow> rows;
  for (int number = 2; std::getline(in, line); ++number) {
    std::vector<double> v;
    std::stringstream ss(line);
    for (std::string cell; std::getline(ss, cell, ',');) {
      char* end = nullptr;
      const double x = std::strtod(cell.c_str(), &end);
      if (cell.empty() || *end != '\0' || !std::isfinite(x)) {
        v.clear();
        break;
      }
      v.push_back(x);
    }
    const auto index = [](double x) { return x >= 0 && x < 0x1p53 && x == std::floor(x); };
    if (v.size() != std::size(kBodyColumns) || !index(v[0]) || !index(v[2]))
      throw Error(fmt::format("line {} is not a row of {} finite numbers (frame and obstacle whole numbers >= 0, "
                              "then time, position, orientation, ...)",
                              number, std::size(kBodyColumns)),
                  file.string());
    const double q2 = v[6] * v[6] + v[7] * v[7] + v[8] * v[8] + v[9] * v[9];
    if (std::abs(q2 - 1) > 1e-6)
      throw Error(fmt::format("line {}: the orientation ({}, {}, {}, {}) is not a unit quaternion", number, v[6], v[7],
                              v[8], v[9]),
                  file.string());
    BodyPoseRow r;
    r.frame = static_cast<std::size_t>(v[0]);
    r.time = v[1];
    r.obstacle = static_cast<std::size_t>(v[2]);
    r.position = {v[3], v[4], v[5]};
    r.orientation = {v[6], v[7], v[8], v[9]};
    rows.push_back(r);
  }
  return rows;
}

RunDirectory open_run_directory(const fs::path& dir, std::optional<FrameFormat> format) {
  std::error_code ec;
  require_directory(dir, "a run directory (sph run -o DIR)");
  const fs::path scene_file = dir / "scene.json";
  if (!fs::is_regular_file(scene_file, ec))
    throw Error("is not a run directory: it has no scene.json (expected the output directory of sph run)",
                dir.string());
  RunDirectory run;
  run.dir = dir;
  run.scene = read_scene_file(scene_file.string());
  run.dimension = run.scene.dimension;
  // (a scene with floating bodies only: a stray table beside any other run is not read)
  const bool floating = run.scene.visit_body([](const auto& body) { return any_dynamic_body(body.sim); });
  if (floating && !fs::is_regular_file(dir / "bodies.csv", ec) && fs::exists(dir / "frames.pvd", ec))
    throw Error(
        "is missing: it holds where the scene's floating bodies were at each frame, and without it their "
        "pictures would show them where they started; expected the file sph run wrote with the frames (the "
        "run directory is incomplete)",
        (dir / "bodies.csv").string());
  if (floating && fs::is_regular_file(dir / "bodies.csv", ec)) {
    run.bodies = read_body_rows(dir / "bodies.csv");
    const std::size_t obstacles = run.scene.visit_body([](const auto& body) { return body.sim.obstacles.size(); });
    for (const BodyPoseRow& r : run.bodies)
      if (r.obstacle >= obstacles)
        throw Error(fmt::format("a row names obstacle {}, but the scene has {} obstacles", r.obstacle, obstacles),
                    (dir / "bodies.csv").string());
  }
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
  } else {
    for (const FrameFormatDesc& f : kFrameFormats) {
      run.frames = list_frames(dir, f.format);
      if (!run.frames.empty()) {
        run.format = f.format;
        break;
      }
    }
    if (run.frames.empty())
      throw Error("holds no frames (frames/frame_000000.vtu, .vtk or .ply); was it run with outputEveryNSteps = 0?",
                  dir.string());
  }
  // Each floating body at every frame: a table that lost rows would draw it where it was not.
  if (floating)
    run.scene.visit_body([&]<int D>(const SceneBody<D>& body) {
      for (std::size_t k = 0; k < body.sim.obstacles.size(); ++k) {
        if (!obstacle_body(body.sim, k).dynamic) continue;
        std::vector<bool> seen(run.frames.size(), false);
        for (const BodyPoseRow& r : run.bodies)
          if (r.obstacle == k && r.frame < seen.size()) seen[r.frame] = true;
        const auto missing = std::find(seen.begin(), seen.end(), false);
        if (missing != seen.end())
          throw Error(fmt::format("has no row of obstacle {} (a floating body) at frame {} of the {}; expected the "
                                  "table sph run wrote with the frames (the run directory is incomplete)",
                                  k, missing - seen.begin(), run.frames.size()),
                      (dir / "bodies.csv").string());
      }
    });
  return run;
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
  require_directory(dir, "a run directory (sph run -o DIR) or a compare directory (sph compare -o DIR)");
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

// --- Run identity --------------------------------------------------------------------------

std::string new_run_id() {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm utc{};
  gmtime_r(&now, &utc);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y%m%dT%H%M%SZ", &utc);
  static std::mt19937 rng{std::random_device{}()};
  static std::uint32_t counter = 0;  // two ids of one process in one second still differ
  return fmt::format("{}-{}-{:08x}", stamp, ::getpid(), static_cast<std::uint32_t>(rng()) ^ counter++);
}

std::string scene_fingerprint(const std::string& scene_json) {
  nlohmann::json doc = nlohmann::json::parse(scene_json);  // keys sorted: one text per scene
  if (doc.is_object() && doc.contains("Configuration") && doc["Configuration"].is_object())
    doc["Configuration"].erase("numberOfSteps");
  std::uint64_t h = 14695981039346656037ull;  // FNV-1a 64
  const auto add = [&h](const std::string& bytes) {
    for (const char c : bytes) h = (h ^ static_cast<unsigned char>(c)) * 1099511628211ull;
  };
  add(doc.dump());
  // The mesh files the scene names (the effective scene names them by absolute path): a run
  // resumed after one changed would go on with another obstacle.
  if (doc.is_object() && doc.contains("Obstacles") && doc["Obstacles"].is_array())
    for (const nlohmann::json& o : doc["Obstacles"]) {
      if (!o.is_object() || !o.contains("geometryFile") || !o["geometryFile"].is_string()) continue;
      std::ifstream in(o["geometryFile"].get<std::string>(), std::ios::binary);
      std::stringstream bytes;
      bytes << in.rdbuf();
      add(in ? "\n" + bytes.str() : std::string("\nunreadable"));
    }
  return fmt::format("{:016x}", h);
}

void write_run_identity(const fs::path& dir, const RunIdentity& id) {
  nlohmann::ordered_json j;
  j["run_id"] = id.run_id;
  j["scene_fingerprint"] = id.scene_fingerprint;
  write_file_atomic(dir / kRunIdentityFile, j.dump(2) + "\n");
}

namespace {

/// DIR/NAME parsed as a JSON object, or nullopt if the file is not there. Throws sph::Error
/// naming the file if it is not a JSON object.
std::optional<nlohmann::json> read_json_object(const fs::path& file) {
  std::error_code ec;
  if (!fs::exists(file, ec)) return std::nullopt;
  std::ifstream in(file, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  nlohmann::json j = nlohmann::json::parse(text.str(), nullptr, /*allow_exceptions=*/false);
  if (!in || !j.is_object())
    throw Error("cannot be read as a JSON object; expected the file sph run wrote", file.string());
  return j;
}

/// The string at `key` of `j`, or "" if it is not there or not a string.
std::string string_at(const nlohmann::json& j, const char* key) {
  const auto it = j.find(key);
  return it != j.end() && it->is_string() ? it->get<std::string>() : std::string();
}

}  // namespace

void check_run_identity(const fs::path& dir, const RunIdentity& checkpoint) {
  const auto refuse = [&](const fs::path& file, const std::string& what) {
    throw Error(fmt::format("{}; the checkpoint belongs to run {}: it was copied from another run's directory, or "
                            "this directory was reused. Resume it in its own directory, or start a new run with "
                            "sph run SCENE -o DIR",
                            what, checkpoint.run_id),
                file.string());
  };
  const fs::path run_file = dir / kRunIdentityFile;
  const std::optional<nlohmann::json> run = read_json_object(run_file);
  if (!run) refuse(run_file, "missing: nothing says which run this directory holds");
  if (const std::string id = string_at(*run, "run_id"); id != checkpoint.run_id)
    refuse(run_file, fmt::format("names run {}", id.empty() ? "(none)" : id));
  const fs::path summary_file = dir / "summary.json";
  if (const std::optional<nlohmann::json> summary = read_json_object(summary_file)) {
    if (const std::string id = string_at(*summary, "run_id"); id != checkpoint.run_id)
      refuse(summary_file, fmt::format("is the summary of run {}", id.empty() ? "(none: an older sph's run)" : id));
  }
  const fs::path scene_file = dir / "scene.json";
  std::error_code ec;
  if (fs::is_regular_file(scene_file, ec)) {
    std::string fingerprint;
    try {
      fingerprint = scene_fingerprint(read_scene_text(scene_file.string()));
    } catch (const std::exception&) {
      refuse(scene_file, "is not a scene this sph wrote");
    }
    if (fingerprint != checkpoint.scene_fingerprint)
      throw Error(fmt::format("holds another scene, or a mesh file it names (geometryFile) changed since the run "
                              "started (fingerprint {}, the checkpoint's is {}); resume with the scene and meshes the "
                              "run started with, or start a new run with sph run SCENE -o DIR",
                              fingerprint, checkpoint.scene_fingerprint),
                  scene_file.string());
  }
}

std::optional<RunEnd> read_run_end(const fs::path& dir) {
  const fs::path file = dir / "summary.json";
  const std::optional<nlohmann::json> j = read_json_object(file);
  if (!j) return std::nullopt;
  const auto steps = j->find("steps");
  if (string_at(*j, "status").empty() || steps == j->end() || !steps->is_number_integer())
    throw Error("has no status or steps; expected the summary sph run wrote", file.string());
  return RunEnd{string_at(*j, "status"), steps->get<std::int64_t>()};
}

std::optional<std::string> unfinished_run(const fs::path& dir) {
  std::error_code ec;
  if (!fs::exists(dir / kCheckpointFile, ec)) return std::nullopt;
  std::optional<RunEnd> end;
  try {
    end = read_run_end(dir);
  } catch (const Error&) {
    return "the checkpoint of a run whose summary.json is unreadable";
  }
  if (!end) return "the checkpoint of a run that did not finish (no summary.json: it was killed, or is still running)";
  if (end->finished()) return std::nullopt;
  return fmt::format("the checkpoint of a run that did not finish (summary.json: {})", end->status);
}

}  // namespace sph
