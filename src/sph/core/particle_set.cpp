#include <sph/core/error.h>
#include <sph/core/particle_set.h>
#include <algorithm>

#include <sph/core/state_stream.h>

namespace sph {

template <int D, std::floating_point R>
void ParticleSet<D, R>::reserve(std::size_t n) {
  position.reserve(n);
  velocity.reserve(n);
  acceleration.reserve(n);
  initial_position.reserve(n);
  density.reserve(n);
  pressure.reserve(n);
  mass.reserve(n);
  id.reserve(n);
}

template <int D, std::floating_point R>
std::uint64_t ParticleSet<D, R>::add(const V& x, const V& v, R m) {
  position.push_back(x);
  velocity.push_back(v);
  acceleration.push_back(V{});
  initial_position.push_back(x);
  density.push_back(R(0));
  pressure.push_back(R(0));
  mass.push_back(m);
  id.push_back(next_id_);
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
  std::fill(placed_.begin(), placed_.end(), 0);
  const auto placed = [&](std::size_t k) { return (placed_[k / 64] >> (k % 64)) & 1u; };
  const auto move_to = [&](std::size_t dst, std::size_t src) {
    position[dst] = position[src];
    velocity[dst] = velocity[src];
    acceleration[dst] = acceleration[src];
    initial_position[dst] = initial_position[src];
    density[dst] = density[src];
    pressure[dst] = pressure[src];
    mass[dst] = mass[src];
    id[dst] = id[src];
  };
  // Each cycle k -> perm[k] -> perm[perm[k]] ... is rotated through one saved particle.
  for (std::size_t start = 0; start < n; ++start) {
    if (placed(start) || perm[start] == start) continue;
    const V x = position[start], v = velocity[start], a = acceleration[start], x0 = initial_position[start];
    const R rho = density[start], p = pressure[start], m = mass[start];
    const std::uint64_t ident = id[start];
    std::size_t k = start;
    for (;;) {
      placed_[k / 64] |= std::uint64_t{1} << (k % 64);
      const std::size_t src = perm[k];
      if (src == start) break;
      move_to(k, src);
      k = src;
    }
    position[k] = x, velocity[k] = v, acceleration[k] = a, initial_position[k] = x0;
    density[k] = rho, pressure[k] = p, mass[k] = m, id[k] = ident;
  }
}

template <int D, std::floating_point R>
void ParticleSet<D, R>::save(StateWriter& out) const {
  out.put(next_id_);
  out.put(position);
  out.put(velocity);
  out.put(acceleration);
  out.put(initial_position);
  out.put(density);
  out.put(pressure);
  out.put(mass);
  out.put(id);
}

template <int D, std::floating_point R>
void ParticleSet<D, R>::load(StateReader& in) {
  in.get(next_id_);
  in.get(position);
  in.get(velocity);
  in.get(acceleration);
  in.get(initial_position);
  in.get(density);
  in.get(pressure);
  in.get(mass);
  in.get(id);
  const std::size_t n = position.size();
  in.expect(velocity.size() == n && acceleration.size() == n && initial_position.size() == n && density.size() == n &&
                pressure.size() == n && mass.size() == n && id.size() == n,
            "particle fields of different lengths");
  for (std::uint64_t i : id) in.expect(i < next_id_, "a particle id at or above the next id");
}

template class ParticleSet<2, float>;
template class ParticleSet<2, double>;
template class ParticleSet<3, float>;
template class ParticleSet<3, double>;

}  // namespace sph
