#pragma once
/// \file Names of the frame formats and fields (scene keys, --format, --fields, file extensions)
/// and the field selection the frame writers take.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <sph/scene/scene_desc.h>

namespace sph {

/// "vtu", "vtk" or "ply": the scene's name of the format, which is also its file extension.
const char* frame_format_name(FrameFormat f);
/// The format named `name` ("vtu", "vtk", "ply"), or nullopt.
std::optional<FrameFormat> parse_frame_format(std::string_view name);

/// Which of kFrameFieldNames a frame holds: bit i for kFrameFieldNames[i].
using FrameFieldMask = unsigned;
inline constexpr FrameFieldMask kFieldVelocity = 1u << 0, kFieldDensity = 1u << 1, kFieldPressure = 1u << 2,
                                kFieldId = 1u << 3, kFieldInitialPosition = 1u << 4;
inline constexpr FrameFieldMask kAllFrameFields = 0x1Fu;
/// The mask of `names` (each one of kFrameFieldNames; SPH_CHECK: the scene reader checked them).
FrameFieldMask frame_field_mask(const std::vector<std::string>& names);

}  // namespace sph
