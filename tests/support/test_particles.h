#pragma once
// Particle sets for the writer and reader tests: every field distinct per particle, values that
// are not exact in float, positions moved away from the initial ones, ids out of index order.

#include <cstddef>
#include <cstdint>
#include <vector>

#include <sph/core/particle_set.h>

namespace sph::test {

template <int D, class R>
ParticleSet<D, R> make_test_particles(std::size_t n) {
  ParticleSet<D, R> ps;
  ps.mass = R(0.5);
  for (std::size_t i = 0; i < n; ++i) {
    Vec<D, R> x, vel;
    for (int d = 0; d < D; ++d) {
      x[d] = static_cast<R>(0.1 * static_cast<double>(i) + 0.01 * d + 1.0 / 3.0);  // not exact in float
      vel[d] = static_cast<R>(-1.0 * static_cast<double>(i) + 0.5 * d - 0.1);
    }
    ps.add(x, vel);
  }
  for (std::size_t i = 0; i < n; ++i) {
    ps.density[i] = static_cast<R>(1000.1 + static_cast<double>(i));
    ps.pressure[i] = static_cast<R>(-10.3 * static_cast<double>(i));
    ps.position[i][0] += R(1);  // moved: position != initial_position
  }
  // Permuted, so that ids differ from indices.
  std::vector<std::uint32_t> perm(n);
  for (std::size_t k = 0; k < n; ++k) perm[k] = static_cast<std::uint32_t>((k * 3 + 1) % n);
  if (n % 3 != 0) ps.permute(perm);
  return ps;
}

}  // namespace sph::test
