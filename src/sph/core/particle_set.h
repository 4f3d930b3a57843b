#pragma once
/// \file ParticleSet: every per-particle field, stored as one array per field.

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <sph/core/particle_fields.h>
#include <sph/core/vec.h>

namespace sph {

class StateWriter;
class StateReader;

/// A field added to a ParticleSet at run time (ParticleSet::add_field).
struct FieldSpec {
  std::string name;                  ///< valid_field_name(), not a built-in field's
  FieldKind kind = FieldKind::Real;  ///< Real or Vector
  std::string unit2, unit3;          ///< SI unit in 2D and 3D
  std::string what;                  ///< one line for documentation
};

/// The PLY vertex property names of an added field: NAME for a real, NAME_x, NAME_y, NAME_z for
/// a vector (the writer and the reader both go through this).
inline std::array<std::string, 3> added_field_ply_names(const FieldSpec& spec) {
  if (spec.kind == FieldKind::Vector) return {spec.name + "_x", spec.name + "_y", spec.name + "_z"};
  return {spec.name, "", ""};
}

/// Structure of arrays holding all per-particle state. This is the only place that resizes,
/// appends and permutes particle data: every operation goes through for_each_field, so a field
/// added to the list there (with its descriptor in kParticleFields) or at run time (add_field)
/// is carried through all of them, and through checkpoints and frames.
///
/// Units: position and initial position in m, velocity in m/s, acceleration in m/s^2,
/// density in kg/m^D (kg/m^3 in 3D, kg/m^2 in 2D), pressure in Pa (N/m in 2D), mass in kg
/// (kg/m in 2D).
///
/// Every particle of a set has one mass (`mass`, docs/physics.md "Particle mass"): it is not a
/// per-particle field, so the pair loops broadcast it instead of gathering it per neighbour.
///
/// The initial positions are only ever written out (frames, Python's views): a set made with
/// keep_initial_positions(false) has no such field (12 bytes a particle less in float 3D), and
/// every operation (for_each_field and all that goes through it) leaves it out.
template <int D, std::floating_point R>
class ParticleSet {
 public:
  using V = Vec<D, R>;

  std::vector<V> position;
  std::vector<V> velocity;
  std::vector<R> density;
  std::vector<R> pressure;
  /// Stable id: assigned once when a particle is added, never reused, survives permutation.
  /// 32 bits: a scene holds at most 2e9 particles over its whole run (blocks and emitter budgets,
  /// scene_reader), and frames write ids in 32 bits but VTU's UInt64.
  std::vector<std::uint32_t> id;
  std::vector<V> initial_position;
  std::vector<V> acceleration;
  /// Every particle's mass (kg; kg/m in 2D): one value for the set, saved with it.
  R mass = R(0);

  std::size_t size() const { return position.size(); }
  bool empty() const { return position.empty(); }

  /// Whether the set keeps each particle's initial position (the default). Changed only while the
  /// set is empty (SPH_CHECK): the positions a particle was added at are not known afterwards.
  bool keeps_initial_positions() const { return keep_initial_; }
  void keep_initial_positions(bool keep);

  /// Calls f(const FieldDesc&, column) for every field in kParticleFields order, then for the
  /// fields added with add_field in the order they were added; `column` is the field's
  /// std::vector<V> (FieldKind::Vector), std::vector<R> (Real) or std::vector<std::uint32_t> (Id).
  template <class F>
  void for_each_field(F&& f) {
    visit_fields(*this, f);
  }
  template <class F>
  void for_each_field(F&& f) const {
    visit_fields(*this, f);
  }

  /// Adds a per-particle field of kind Real or Vector, zero for the particles already in the set
  /// and for each one added later, and carried like the built-in fields (reserve, add, permute,
  /// checkpoints, frames that select it by name). Returns its index for real_field() or
  /// vector_field(). Throws sph::Error if the name is not valid_field_name(), is a built-in
  /// field's or was added before, or the kind is Id.
  std::size_t add_field(FieldSpec spec);
  /// The index of the added field named `name`, or -1.
  std::ptrdiff_t added_field_index(std::string_view name) const;
  std::vector<R>& real_field(std::size_t k);
  const std::vector<R>& real_field(std::size_t k) const;
  std::vector<V>& vector_field(std::size_t k);
  const std::vector<V>& vector_field(std::size_t k) const;
  std::size_t added_fields() const { return added_.size(); }
  /// The specs of the added fields, in order (what read_frame needs to read them back).
  std::vector<FieldSpec> added_field_specs() const {
    std::vector<FieldSpec> specs;
    for (const AddedField& a : added_) specs.push_back(a.spec);
    return specs;
  }

  /// Reserves room for n particles in every field.
  void reserve(std::size_t n);

  /// Appends one particle (of the set's `mass`) at rest state (zero acceleration, density,
  /// pressure and added fields) and returns its stable id. Its initial position is x (where the
  /// set keeps initial positions). x and v are taken by value: one of the set's own positions may
  /// be passed, though adding moves the arrays.
  std::uint64_t add(V x, V v);

  /// The id the next added particle will get.
  std::uint64_t next_id() const { return next_id_; }

  /// Reorders every field so that new index k holds the particle previously at perm[k].
  /// perm must be a permutation of [0, size()). Works in place, following the permutation's
  /// cycles: no copy of the fields, and no allocation once it has run at this size.
  void permute(std::span<const std::uint32_t> perm);

  /// Writes every field (name, kind and values), the next id and the mass (checkpoints).
  void save(StateWriter& out) const;
  /// Replaces every field, the next id and the mass with what save() wrote. Throws sph::Error if
  /// the data is inconsistent (fields of different lengths, an id not below the next id) or holds
  /// other fields than this set (a checkpoint of a build or solver with other fields, or of a set
  /// that kept its initial positions where this one does not, or the reverse).
  void load(StateReader& in);

 private:
  struct AddedField {
    FieldSpec spec;
    std::array<std::string, 3> ply;  // PLY property names: NAME, or NAME_x NAME_y NAME_z
    std::vector<R> reals;
    std::vector<V> vectors;
    FieldDesc desc() const {
      return {spec.name, spec.kind, spec.unit2, spec.unit3, spec.what, true, false, {ply[0], ply[1], ply[2]}};
    }
  };

  template <class Self, class F>
  static void visit_fields(Self& s, F& f) {
    f(kParticleFields[field::kPosition], s.position);
    f(kParticleFields[field::kVelocity], s.velocity);
    f(kParticleFields[field::kDensity], s.density);
    f(kParticleFields[field::kPressure], s.pressure);
    f(kParticleFields[field::kId], s.id);
    if (s.keep_initial_) f(kParticleFields[field::kInitialPosition], s.initial_position);
    f(kParticleFields[field::kAcceleration], s.acceleration);
    static_assert(std::size(kParticleFields) == 7, "every built-in field is visited above");
    for (auto& a : s.added_) {
      const FieldDesc d = a.desc();
      if (a.spec.kind == FieldKind::Vector)
        f(d, a.vectors);
      else
        f(d, a.reals);
    }
  }

  std::size_t field_count() const { return std::size(kParticleFields) - (keep_initial_ ? 0 : 1) + added_.size(); }

  std::uint64_t next_id_ = 0;
  bool keep_initial_ = true;
  std::vector<AddedField> added_;
  std::vector<std::uint64_t> placed_;  // permute(): one bit per particle
};

extern template class ParticleSet<2, float>;
extern template class ParticleSet<2, double>;
extern template class ParticleSet<3, float>;
extern template class ParticleSet<3, double>;

}  // namespace sph
