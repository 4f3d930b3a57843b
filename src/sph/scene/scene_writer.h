#pragma once
/// \file Writer of scene files: a SceneDesc as the JSON the reader reads (docs/scene-format.md).

#include <string>

#include <nlohmann/json.hpp>

#include <sph/scene/scene_desc.h>

namespace sph {

/// The scene as a JSON object with every key of the format, the defaults the reader filled in
/// written out (emitEndTime only for an emitter that stops), in the order of
/// docs/scene-format.md. parse_scene(scene_to_json(d).dump(), d.source) gives back a SceneDesc
/// equal to d, every floating value bit for bit, when d was read by parse_scene (a scene's
/// `source` and the `audit` flag are not part of the file; `warnings` come back as the reader
/// finds them). This is what a run writes to DIR/scene.json and stores in its checkpoints.
nlohmann::ordered_json scene_to_json(const SceneDesc& desc);

/// scene_to_json(desc) as text, indented by 2 spaces, without a final newline.
std::string scene_text(const SceneDesc& desc);

}  // namespace sph
