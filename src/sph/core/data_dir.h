#pragma once
/// \file Where the program's data files are: the scenes that `sph validate` and `sph bench` run
/// by default (scenes/validation, scenes/paper), found from the running program's own location,
/// so that an installed program needs no source tree.

#include <filesystem>
#include <string_view>

namespace sph {

/// The data directory: the directory that holds scenes/ (scenes/paper, scenes/validation).
/// The first of these that holds a scenes/ directory:
///   1. $SPH_DATA_DIR when set (then it must hold scenes/, or this throws);
///   2. the install's: <program's directory>/../share/sph (<prefix>/bin/sph ->
///      <prefix>/share/sph; the relative path follows CMake's install directories);
///   3. the build tree's: the directory named in <program's directory>/sph-data-dir.txt, a file
///      CMake writes next to the programs it builds (build/, build/tests/) naming the source
///      tree; it is not installed.
/// The program is /proc/self/exe. Throws sph::Error naming the places looked at when none holds
/// scenes/.
std::filesystem::path data_dir();

/// data_dir() / "scenes" / set, e.g. scene_dir("validation"); throws sph::Error when that
/// directory does not exist.
std::filesystem::path scene_dir(std::string_view set);

namespace detail {
/// data_dir()'s search for a given program path and $SPH_DATA_DIR value (null: unset).
std::filesystem::path find_data_dir(const std::filesystem::path& program, const char* env_data_dir);
}  // namespace detail

}  // namespace sph
