#pragma once
// A block of fluid for the pass tests: a jittered lattice of spacing dx (h = 2 spacings) with
// random velocities, its density a few % off rest when summed (pressures of both signs), and
// boundary samples on a wall plane below it; and walls far from it, with gravity.

#include <cmath>
#include <random>
#include <vector>

#include <sph/core/particle_set.h>
#include <sph/solver/wcsph.h>

namespace sph::test {

/// side^D particles (jitter 0.2 dx, velocities in [-1, 1]) and (2 side)^(D-1) samples at dx / 2
/// on the plane one spacing below the block, each with psi 0.3 of the particle mass.
template <int D, class R>
struct Blob {
  ParticleSet<D, R> ps;
  std::vector<Vec<D, R>> samples;
  std::vector<R> psi;
  double dx = 0.02, h = 0.04;

  explicit Blob(int side, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> jit(-0.2 * dx, 0.2 * dx), vel(-1, 1);
    const int nz = D == 3 ? side : 1;
    const double m = 1000 * std::pow(dx, D);
    ps.mass = static_cast<R>(m);
    for (int k = 0; k < nz; ++k)
      for (int j = 0; j < side; ++j)
        for (int i = 0; i < side; ++i) {
          Vec<D, R> x, v;
          const int c[3] = {i, j, k};
          for (int d = 0; d < D; ++d) x[d] = static_cast<R>(c[d] * dx + jit(rng)), v[d] = static_cast<R>(vel(rng));
          ps.add(x, v);
        }
    // Samples on the plane below the block (last axis at -dx), spacing dx / 2.
    const int ns = 2 * side;
    for (int b = 0; b < ns; ++b)
      for (int a = 0; a < (D == 3 ? ns : 1); ++a) {
        Vec<D, R> x;
        x[0] = static_cast<R>(b * dx / 2);
        if constexpr (D == 3) x[1] = static_cast<R>(a * dx / 2);
        x[D - 1] = static_cast<R>(-dx);
        samples.push_back(x);
        psi.push_back(static_cast<R>(0.3 * m));
      }
  }
};

/// Walls 10 m away on every side (no contact with a blob) and gravity along the last axis: what the
/// force-pass tests pass to compute_accelerations.
template <int D, class R>
struct FarWalls {
  FarWalls() = default;
  FarWalls(const FarWalls&) = delete;  // (walls refers to the members)
  FarWalls& operator=(const FarWalls&) = delete;

  std::vector<Box<D>> no_obstacles;
  Box<D> box = far_box();
  WallContact<D, R> walls{box, no_obstacles, R(0), WallParams{}};
  Vec<D, R> gravity = down();

  static Box<D> far_box() {
    Box<D> b;
    for (int d = 0; d < D; ++d) b.lo[d] = -10, b.hi[d] = 10;
    return b;
  }
  static Vec<D, R> down() {
    Vec<D, R> g{};
    g[D - 1] = R(-9.81);
    return g;
  }
};

}  // namespace sph::test
