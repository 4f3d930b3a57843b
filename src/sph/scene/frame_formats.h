#pragma once
/// \file The frame-format vocabulary: one descriptor per file format a run can write its frames
/// in. The scene's outputFormats, `--format`, the run directory's readers, file extensions and
/// what `sph run` prints derive from this table; the writers and readers of each format are in
/// io/ (write_frame, read_frame).

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace sph {

/// File formats for particle frames.
enum class FrameFormat { Vtu, Vtk, Ply };

struct FrameFormatDesc {
  FrameFormat format;
  std::string_view name;     ///< in scenes and flags; also the file extension
  std::string_view what;     ///< a few words for --help: what it is or what reads it
  std::string_view look_at;  ///< what a finished run points the user to, in its directory
  std::string_view hint;     ///< ... and how to open it
};

/// Every format, in the order frames are looked for in a run directory (vtu, vtk, ply).
inline constexpr FrameFormatDesc kFrameFormats[] = {
    {FrameFormat::Vtu, "vtu", "ParaView", "frames.pvd  ",
     "open in ParaView (Representation: Point Gaussian to see particles)"},
    {FrameFormat::Vtk, "vtk", "legacy VTK", "frames/*.vtk", "legacy VTK frames (ParaView, VisIt, meshio)"},
    {FrameFormat::Ply, "ply", "Blender, Houdini", "frames/*.ply",
     "point clouds (Blender: File > Import > Stanford PLY; Houdini: File node)"},
};

constexpr const FrameFormatDesc& frame_format_desc(FrameFormat f) {
  for (const FrameFormatDesc& d : kFrameFormats)
    if (d.format == f) return d;
  return kFrameFormats[0];  // (every enumerator is in the table)
}

/// "vtu", "vtk" or "ply": the scene's name of the format, which is also its file extension.
constexpr const char* frame_format_name(FrameFormat f) { return frame_format_desc(f).name.data(); }

/// The format named `name` ("vtu", "vtk", "ply"), or nullopt.
constexpr std::optional<FrameFormat> parse_frame_format(std::string_view name) {
  for (const FrameFormatDesc& d : kFrameFormats)
    if (d.name == name) return d.format;
  return std::nullopt;
}

/// The format names with `quote` around each, ", " between and `last_joint` before the last:
/// `vtu, vtk or ply`, `"vtu", "vtk", "ply"` (for messages). With `what`, each name is followed by
/// its description in parentheses (for --help); `prefix` goes before each name (".": `.vtu`).
inline std::string frame_format_list(std::string_view quote = "", std::string_view last_joint = ", ", bool what = false,
                                     std::string_view prefix = "") {
  std::string s;
  for (std::size_t k = 0; k < std::size(kFrameFormats); ++k) {
    if (k > 0) s += k + 1 == std::size(kFrameFormats) ? last_joint : std::string_view(", ");
    s += quote;
    s += prefix;
    s += kFrameFormats[k].name;
    s += quote;
    if (what) (s += " (") += std::string(kFrameFormats[k].what) + ")";
  }
  return s;
}

/// The names of every format, in table order (for flags' accepted values).
inline std::vector<std::string> frame_format_names() {
  std::vector<std::string> names;
  for (const FrameFormatDesc& d : kFrameFormats) names.emplace_back(d.name);
  return names;
}

}  // namespace sph
