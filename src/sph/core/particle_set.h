#pragma once
/// \file ParticleSet: every per-particle field, stored as one array per field.

#include <cstdint>
#include <span>
#include <vector>

#include <sph/core/vec.h>

namespace sph {

class StateWriter;
class StateReader;

/// Structure of arrays holding all per-particle state. This is the only place that resizes,
/// appends and permutes particle data: a field added here is carried through every operation.
///
/// Units: position and initial position in m, velocity in m/s, acceleration in m/s^2,
/// density in kg/m^D (kg/m^3 in 3D, kg/m^2 in 2D), pressure in Pa (N/m in 2D), mass in kg.
template <int D, std::floating_point R>
class ParticleSet {
 public:
  using V = Vec<D, R>;

  std::vector<V> position;
  std::vector<V> velocity;
  std::vector<V> acceleration;
  std::vector<V> initial_position;
  std::vector<R> density;
  std::vector<R> pressure;
  std::vector<R> mass;
  /// Stable id: assigned once when a particle is added, never reused, survives permutation.
  std::vector<std::uint64_t> id;

  std::size_t size() const { return position.size(); }
  bool empty() const { return position.empty(); }

  /// Reserves room for n particles in every field.
  void reserve(std::size_t n);

  /// Appends one particle at rest state (zero acceleration, density and pressure) and returns
  /// its stable id. Its initial position is x.
  std::uint64_t add(const V& x, const V& v, R m);

  /// The id the next added particle will get.
  std::uint64_t next_id() const { return next_id_; }

  /// Reorders every field so that new index k holds the particle previously at perm[k].
  /// perm must be a permutation of [0, size()). Works in place, following the permutation's
  /// cycles: no copy of the fields, and no allocation once it has run at this size.
  void permute(std::span<const std::uint32_t> perm);

  /// Writes every field and the next id (checkpoints).
  void save(StateWriter& out) const;
  /// Replaces every field and the next id with what save() wrote. Throws sph::Error if the
  /// data is inconsistent (fields of different lengths, an id not below the next id).
  void load(StateReader& in);

 private:
  std::uint64_t next_id_ = 0;
  std::vector<std::uint64_t> placed_;  // permute(): one bit per particle
};

extern template class ParticleSet<2, float>;
extern template class ParticleSet<2, double>;
extern template class ParticleSet<3, float>;
extern template class ParticleSet<3, double>;

}  // namespace sph
