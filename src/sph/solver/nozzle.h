#pragma once
/// \file An emitter's nozzle: the axes across it and where each of its particles is placed.
/// Shared by Simulation::emit, which places the particles, and the scene preflight, which checks
/// every one of them before step 0.

#include <cmath>
#include <utility>

#include <sph/core/vec.h>
#include <sph/solver/params.h>

namespace sph {

/// Two unit vectors orthogonal to dir (and to each other); in 2D only the first is used.
template <int D>
std::pair<Vec<D, double>, Vec<D, double>> nozzle_axes(const Vec<D, double>& dir) {
  Vec<D, double> u{}, w{};
  if constexpr (D == 2) {
    u[0] = -dir[1];
    u[1] = dir[0];
  } else {
    // Pick the coordinate axis least aligned with dir, then Gram-Schmidt.
    int k = 0;
    for (int d = 1; d < 3; ++d)
      if (std::abs(dir[d]) < std::abs(dir[k])) k = d;
    Vec<D, double> e{};
    e[k] = 1;
    u = e - dir * dot(e, dir);
    u *= 1.0 / norm(u);
    w[0] = dir[1] * u[2] - dir[2] * u[1];
    w[1] = dir[2] * u[0] - dir[0] * u[2];
    w[2] = dir[0] * u[1] - dir[1] * u[0];
  }
  return {u, w};
}

/// Where particle (a, b) of e's nozzle is placed: a in [0, width) across u, b in [0, height)
/// across w (b ignored in 2D), with (u, w) = nozzle_axes(e.direction); the nozzle is centered on
/// e.origin.
template <int D>
Vec<D, double> nozzle_position(const EmitterParams<D>& e, const Vec<D, double>& u, const Vec<D, double>& w, int a,
                               int b) {
  Vec<D, double> x = e.origin + u * ((a - 0.5 * (e.width - 1)) * e.spacing);
  if constexpr (D == 3) x += w * ((b - 0.5 * (e.height - 1)) * e.spacing);
  return x;
}

}  // namespace sph
