#pragma once
/// \file The field selection the frame writers take, and the one dispatch from a frame format to
/// its writer. Format names are in scene/frame_formats.h, field names in core/particle_fields.h.

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <sph/core/error.h>
#include <sph/core/particle_set.h>
#include <sph/scene/frame_formats.h>

namespace sph {

/// Which point fields a frame holds besides the positions: every field that frames may hold
/// (the default), or those named.
class FrameFields {
 public:
  /// Every field whose descriptor is `in_frames`, built-in or added (ParticleSet::add_field).
  FrameFields() = default;
  /// Exactly the fields named (none for an empty list); written in the set's field order.
  static FrameFields only(std::vector<std::string> names) {
    FrameFields f;
    f.all_ = false;
    f.names_ = std::move(names);
    return f;
  }
  bool has(std::string_view name) const { return all_ || names(name); }
  /// Whether the field is named (not only taken as one of all).
  bool names(std::string_view name) const {
    for (const std::string& n : names_)
      if (n == name) return true;
    return false;
  }

 private:
  bool all_ = true;
  std::vector<std::string> names_;
};

/// Calls f(desc, column) for each field of `ps` that a frame with `fields` holds, in the set's
/// field order (ParticleSet::for_each_field). SPH_CHECK: a set that does not keep its initial
/// positions is not asked for them by name (RunSettings::every_field).
template <int D, std::floating_point R, class F>
void for_each_frame_field(const ParticleSet<D, R>& ps, const FrameFields& fields, F&& f) {
  SPH_CHECK(ps.keeps_initial_positions() || !fields.names(kParticleFields[field::kInitialPosition].name),
            "a frame names the initial positions, which these particles do not keep");
  ps.for_each_field([&](const FieldDesc& desc, const auto& column) {
    if (desc.in_frames && fields.has(desc.name)) f(desc, column);
  });
}

/// Writes one frame file of `format` (write_vtu, write_legacy_vtk or write_ply), atomically.
template <int D, std::floating_point R>
void write_frame(FrameFormat format, const std::filesystem::path& path, const ParticleSet<D, R>& particles, double time,
                 const FrameFields& fields = {});

}  // namespace sph
