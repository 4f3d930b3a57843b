#pragma once
/// \file The particle-field vocabulary: one descriptor per per-particle field (name, kind, units,
/// what it holds, how frames store it). ParticleSet stores the fields and visits them in this
/// order (ParticleSet::for_each_field); reserve, append, permute, checkpoints, every frame
/// writer and reader, the scene's outputFields, `--fields`, color-by and the viewer all derive
/// from this table. Adding a field: a descriptor here and a member in ParticleSet's field list;
/// or, at run time, ParticleSet::add_field (a solver's own per-particle state).

#include <algorithm>
#include <array>
#include <cstddef>
#include <string>
#include <string_view>

namespace sph {

/// What a field holds for each particle.
enum class FieldKind {
  Vector,  ///< D reals (frames hold 3 components, z = 0 in 2D)
  Real,    ///< one real
  Id,      ///< one unsigned 32-bit integer (VTU frames write it as UInt64)
};

/// A per-particle field. Views into static text (the built-in table) or into a ParticleSet's
/// own storage (fields added at run time), valid as long as that set.
struct FieldDesc {
  std::string_view name;  ///< in scenes (outputFields), --fields, frames and color-by
  FieldKind kind = FieldKind::Real;
  std::string_view unit2, unit3;  ///< SI unit in 2D and in 3D ("" for ids)
  std::string_view what;          ///< one line for documentation and --help
  /// Frames may hold it as a point field (position is always the points themselves).
  bool in_frames = false;
  /// The field a frame's viewer shows first: VTK XML's PointData Scalars= / Vectors= attribute.
  bool vtk_active = false;
  /// PLY vertex property names, one per component (only the first for Real and Id).
  std::array<std::string_view, 3> ply{};

  /// Components per particle in a frame: 3 for vectors (padded with z = 0 in 2D), else 1.
  constexpr int components() const { return kind == FieldKind::Vector ? 3 : 1; }
  constexpr std::string_view unit(int dimension) const { return dimension == 2 ? unit2 : unit3; }
};

/// The built-in fields, in the order ParticleSet stores, checkpoints and writes them. Frames hold
/// the `in_frames` ones in this order (velocity, density, pressure, id, initial_position).
inline constexpr FieldDesc kParticleFields[] = {
    {"position", FieldKind::Vector, "m", "m", "position", false, false, {"x", "y", "z"}},
    {"velocity", FieldKind::Vector, "m/s", "m/s", "velocity", true, true, {"vx", "vy", "vz"}},
    {"density",
     FieldKind::Real,
     "kg/m^2",
     "kg/m^3",
     "density (the kernel sum: paper Eq. 4 with the paper's poly6)",
     true,
     true,
     {"density"}},
    {"pressure",
     FieldKind::Real,
     "N/m",
     "Pa",
     "pressure (WCSPH: the EOS p = k (rho - rho0); DFSPH: the solver's)",
     true,
     false,
     {"pressure"}},
    {"id", FieldKind::Id, "", "", "stable particle id (kept through reordering)", true, false, {"id"}},
    {"initial_position",
     FieldKind::Vector,
     "m",
     "m",
     "position when the particle was added",
     true,
     false,
     {"x0", "y0", "z0"}},
    {"acceleration", FieldKind::Vector, "m/s^2", "m/s^2", "acceleration of the last step", false, false, {}},
};

/// Indices into kParticleFields (ParticleSet's members, in that order).
namespace field {
inline constexpr std::size_t kPosition = 0, kVelocity = 1, kDensity = 2, kPressure = 3, kId = 4, kInitialPosition = 5,
                             kAcceleration = 6;
}  // namespace field

namespace detail {
constexpr std::size_t count_frame_fields() {
  std::size_t n = 0;
  for (const FieldDesc& f : kParticleFields) n += f.in_frames ? 1 : 0;
  return n;
}
}  // namespace detail

/// The names of the built-in fields frames may hold, in table order: the default of
/// Configuration.outputFields and `--fields`.
inline constexpr auto kFrameFieldNames = [] {
  std::array<std::string_view, detail::count_frame_fields()> names{};
  std::size_t k = 0;
  for (const FieldDesc& f : kParticleFields)
    if (f.in_frames) names[k++] = f.name;
  return names;
}();

/// The built-in field of this name, or nullptr.
constexpr const FieldDesc* find_particle_field(std::string_view name) {
  for (const FieldDesc& f : kParticleFields)
    if (f.name == name) return &f;
  return nullptr;
}

/// "velocity, density, pressure, id and initial_position" (for messages and --help).
inline std::string frame_field_list(std::string_view last_joint = " and ") {
  std::string s;
  for (std::size_t k = 0; k < kFrameFieldNames.size(); ++k) {
    if (k > 0) s += k + 1 == kFrameFieldNames.size() ? last_joint : std::string_view(", ");
    s += kFrameFieldNames[k];
  }
  return s;
}

/// Whether `name` may name a field added at run time: 1 to 64 of [a-z0-9_], starting with a
/// letter (it becomes a VTK array name, a PLY property prefix and a scene key value).
constexpr bool valid_field_name(std::string_view name) {
  if (name.empty() || name.size() > 64 || !(name[0] >= 'a' && name[0] <= 'z')) return false;
  return std::all_of(name.begin(), name.end(),
                     [](char c) { return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_'; });
}

}  // namespace sph
