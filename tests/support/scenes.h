#pragma once
// The repository's paper scenes by path (SPH_SOURCE_DIR: tests/CMakeLists.txt defines it).

#include <string>

namespace sph::test {

/// scenes/paper/NAME.json of the source tree.
inline std::string paper_scene(const std::string& name) { return SPH_SOURCE_DIR "/scenes/paper/" + name + ".json"; }

inline const std::string kDamBreak = paper_scene("dam_break_2d");
inline const std::string kBlock = paper_scene("block_3d");
inline const std::string kTank = paper_scene("tank_fill_3d");

}  // namespace sph::test
