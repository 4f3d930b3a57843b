#include <sph/core/data_dir.h>

#include <cstdlib>
#include <fstream>
#include <string>
#include <system_error>
#include <vector>

#include <sph/core/error.h>

#ifndef SPH_DATA_FROM_BIN
#define SPH_DATA_FROM_BIN "../share/sph"
#endif

namespace sph {

namespace fs = std::filesystem;

namespace {

bool holds_scenes(const fs::path& dir) {
  std::error_code ec;
  return fs::is_directory(dir / "scenes", ec);
}

/// The directory named on the first line of `file`, empty when the file cannot be read.
fs::path read_path_file(const fs::path& file) {
  std::ifstream in(file);
  std::string line;
  if (!in || !std::getline(in, line)) return {};
  while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
  return line;
}

}  // namespace

namespace detail {

fs::path find_data_dir(const fs::path& program, const char* env_data_dir) {
  if (env_data_dir != nullptr && *env_data_dir != '\0') {
    const fs::path dir(env_data_dir);
    if (!holds_scenes(dir))
      throw Error("no scenes/ directory in \"" + dir.string() +
                      "\"; expected sph's data directory (an install's <prefix>/share/sph, or the source tree)",
                  "SPH_DATA_DIR");
    return dir;
  }
  std::vector<fs::path> looked;
  if (!program.empty()) {
    const fs::path bin = program.parent_path();
    const fs::path installed = (bin / SPH_DATA_FROM_BIN).lexically_normal();
    if (holds_scenes(installed)) return installed;
    looked.push_back(installed);
    const fs::path marker = bin / "sph-data-dir.txt";
    const fs::path named = read_path_file(marker);
    if (!named.empty() && holds_scenes(named)) return named;
    looked.push_back(named.empty() ? marker : named);
  }
  std::string places;
  for (const fs::path& p : looked) places += (places.empty() ? "" : ", ") + p.string();
  if (places.empty()) places = "nowhere: the program's own path is unknown";
  throw Error("cannot find sph's data (a directory holding scenes/); looked in " + places +
              "; install sph (cmake --install), or set SPH_DATA_DIR to its share/sph directory or to the source tree");
}

}  // namespace detail

fs::path data_dir() {
  std::error_code ec;
  fs::path program = fs::read_symlink("/proc/self/exe", ec);
  if (ec) program.clear();
  return detail::find_data_dir(program, std::getenv("SPH_DATA_DIR"));
}

fs::path scene_dir(std::string_view set) {
  const fs::path dir = data_dir() / "scenes" / set;
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw Error("no such directory; expected the " + std::string(set) + " scenes in sph's data directory",
                dir.string());
  return dir;
}

}  // namespace sph
