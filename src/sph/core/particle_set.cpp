#include <sph/core/error.h>
#include <sph/core/particle_set.h>

namespace sph {

namespace {
template <class T>
void apply_permutation(std::vector<T>& field, std::span<const std::uint32_t> perm) {
  std::vector<T> out(field.size());
  for (std::size_t k = 0; k < perm.size(); ++k) out[k] = field[perm[k]];
  field.swap(out);
}
}  // namespace

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
  SPH_CHECK(perm.size() == size(), "permutation size differs from particle count");
  apply_permutation(position, perm);
  apply_permutation(velocity, perm);
  apply_permutation(acceleration, perm);
  apply_permutation(initial_position, perm);
  apply_permutation(density, perm);
  apply_permutation(pressure, perm);
  apply_permutation(mass, perm);
  apply_permutation(id, perm);
}

template class ParticleSet<2, float>;
template class ParticleSet<2, double>;
template class ParticleSet<3, float>;
template class ParticleSet<3, double>;

}  // namespace sph
