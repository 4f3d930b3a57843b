#pragma once
/// \file Strict reader of JSON scene files (format: docs/scene-format.md).

#include <cstddef>
#include <string>
#include <vector>

#include <sph/scene/overrides.h>
#include <sph/scene/scene_desc.h>

namespace sph {

/// Reads and validates a scene file. `overrides` are "KEY.PATH=VALUE" strings (the --set flag)
/// applied to the JSON before validation; VALUE is JSON if it parses as JSON, else a string.
/// Throws sph::Error naming the file, line and column (syntax errors) or the key path and what
/// is expected (unknown keys, wrong types, missing or impossible values).
/// `naming`: how messages name an override (OverrideNaming, overrides.h).
SceneDesc read_scene_file(const std::string& path, const std::vector<std::string>& overrides = {},
                          OverrideNaming naming = OverrideNaming::Flag);

/// The largest scene file read_scene_text reads (64 MiB; a scene is a few kB of JSON).
inline constexpr std::size_t kMaxSceneBytes = std::size_t{64} << 20;

/// Reads a scene file's text; throws sph::Error naming the path if it is missing, a directory,
/// not a regular file (a device such as /dev/zero, a FIFO, a socket), larger than
/// kMaxSceneBytes or unreadable.
std::string read_scene_text(const std::string& path);

/// Same as read_scene_file for scene text held in memory; `source` names it in messages.
SceneDesc parse_scene(const std::string& text, const std::string& source,
                      const std::vector<std::string>& overrides = {}, OverrideNaming naming = OverrideNaming::Flag);

}  // namespace sph
