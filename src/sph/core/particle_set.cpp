#include <sph/core/particle_set.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include <sph/core/error.h>
#include <sph/core/state_stream.h>

namespace sph {

template <int D, std::floating_point R>
std::size_t ParticleSet<D, R>::add_field(FieldSpec spec) {
  if (!valid_field_name(spec.name))
    throw Error("\"" + spec.name +
                    "\" is not a valid particle field name; expected 1 to 64 of a-z, 0-9 and _, starting with a letter",
                "particle field");
  if (find_particle_field(spec.name) || added_field_index(spec.name) >= 0)
    throw Error("a particle field named \"" + spec.name + "\" exists already", "particle field");
  if (spec.kind == FieldKind::Id) throw Error("added particle fields hold reals or vectors, not ids", spec.name);
  AddedField a;
  a.ply = added_field_ply_names(spec);
  a.spec = std::move(spec);
  if (a.spec.kind == FieldKind::Vector)
    a.vectors.assign(size(), V{});
  else
    a.reals.assign(size(), R(0));
  if (a.spec.kind == FieldKind::Vector)
    a.vectors.reserve(position.capacity());
  else
    a.reals.reserve(position.capacity());
  added_.push_back(std::move(a));
  return added_.size() - 1;
}

template <int D, std::floating_point R>
std::ptrdiff_t ParticleSet<D, R>::added_field_index(std::string_view name) const {
  for (std::size_t k = 0; k < added_.size(); ++k)
    if (added_[k].spec.name == name) return static_cast<std::ptrdiff_t>(k);
  return -1;
}

template <int D, std::floating_point R>
std::vector<R>& ParticleSet<D, R>::real_field(std::size_t k) {
  SPH_CHECK(k < added_.size() && added_[k].spec.kind == FieldKind::Real, "real_field: no such real field");
  return added_[k].reals;
}
template <int D, std::floating_point R>
const std::vector<R>& ParticleSet<D, R>::real_field(std::size_t k) const {
  SPH_CHECK(k < added_.size() && added_[k].spec.kind == FieldKind::Real, "real_field: no such real field");
  return added_[k].reals;
}
template <int D, std::floating_point R>
std::vector<Vec<D, R>>& ParticleSet<D, R>::vector_field(std::size_t k) {
  SPH_CHECK(k < added_.size() && added_[k].spec.kind == FieldKind::Vector, "vector_field: no such vector field");
  return added_[k].vectors;
}
template <int D, std::floating_point R>
const std::vector<Vec<D, R>>& ParticleSet<D, R>::vector_field(std::size_t k) const {
  SPH_CHECK(k < added_.size() && added_[k].spec.kind == FieldKind::Vector, "vector_field: no such vector field");
  return added_[k].vectors;
}

template <int D, std::floating_point R>
void ParticleSet<D, R>::keep_initial_positions(bool keep) {
  SPH_CHECK(empty(), "keep_initial_positions: the set already holds particles");
  keep_initial_ = keep;
  if (!keep) std::vector<V>().swap(initial_position);  // (its memory too)
}

template <int D, std::floating_point R>
void ParticleSet<D, R>::reserve(std::size_t n) {
  for_each_field([n](const FieldDesc&, auto& column) { column.reserve(n); });
}

template <int D, std::floating_point R>
std::uint64_t ParticleSet<D, R>::add(V x, V v) {
  SPH_CHECK(next_id_ <= std::numeric_limits<std::uint32_t>::max(), "more particles than 32-bit ids number");
  for_each_field([](const FieldDesc&, auto& column) { column.emplace_back(); });  // zeros
  position.back() = x;
  velocity.back() = v;
  if (keep_initial_) initial_position.back() = x;
  id.back() = static_cast<std::uint32_t>(next_id_);
  return next_id_++;
}

template <int D, std::floating_point R>
void ParticleSet<D, R>::permute(std::span<const std::uint32_t> perm) {
  const std::size_t n = size();
  SPH_CHECK(perm.size() == n, "permutation size differs from particle count");
  // Check it is a permutation (a repeated index would lose a particle), using the bits.
  placed_.assign((n + 63) / 64, 0);
  for (std::uint32_t p : perm) {
    SPH_CHECK(p < n && !((placed_[p / 64] >> (p % 64)) & 1u), "not a permutation");
    placed_[p / 64] |= std::uint64_t{1} << (p % 64);
  }
  // Each field in turn: each cycle k -> perm[k] -> perm[perm[k]] ... is rotated through one
  // saved value.
  for_each_field([&](const FieldDesc&, auto& column) {
    std::fill(placed_.begin(), placed_.end(), 0);
    const auto placed = [&](std::size_t k) { return (placed_[k / 64] >> (k % 64)) & 1u; };
    for (std::size_t start = 0; start < n; ++start) {
      if (placed(start) || perm[start] == start) continue;
      const auto saved = column[start];
      std::size_t k = start;
      for (;;) {
        placed_[k / 64] |= std::uint64_t{1} << (k % 64);
        const std::size_t src = perm[k];
        if (src == start) break;
        column[k] = column[src];
        k = src;
      }
      column[k] = saved;
    }
  });
}

template <int D, std::floating_point R>
void ParticleSet<D, R>::save(StateWriter& out) const {
  out.put(next_id_);
  out.put(mass);
  out.put(static_cast<std::uint64_t>(field_count()));
  for_each_field([&](const FieldDesc& f, const auto& column) {
    out.put(std::string(f.name));
    out.put(static_cast<std::uint8_t>(f.kind));
    out.put(column);
  });
}

template <int D, std::floating_point R>
void ParticleSet<D, R>::load(StateReader& in) {
  in.get(next_id_);
  in.get(mass);
  in.expect(std::isfinite(mass) && mass >= R(0), "a particle mass that is not a finite number at least 0");
  const auto fields = in.get<std::uint64_t>();
  in.expect(fields == field_count(),
            "it holds " + std::to_string(fields) + " particle fields; this run has " + std::to_string(field_count()));
  std::size_t n = 0;
  bool first = true;
  for_each_field([&](const FieldDesc& f, auto& column) {
    std::string name;
    in.get(name);
    const auto kind = in.get<std::uint8_t>();
    in.expect(name == f.name && kind == static_cast<std::uint8_t>(f.kind),
              "it holds the particle field \"" + name + "\" where this run has \"" + std::string(f.name) + "\"");
    in.get(column);
    if (first) n = column.size(), first = false;
    in.expect(column.size() == n, "particle fields of different lengths");
  });
  for (std::uint64_t i : id) in.expect(i < next_id_, "a particle id at or above the next id");
}

template class ParticleSet<2, float>;
template class ParticleSet<2, double>;
template class ParticleSet<3, float>;
template class ParticleSet<3, double>;

}  // namespace sph
