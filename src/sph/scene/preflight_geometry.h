#pragma once
/// \file Internals of the scene checks (preflight.cpp, preflight_emitters.cpp, scene_reader.cpp): boxes as text, their
/// volumes and intersections, the room obstacles leave, and the emitters' checks.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include <fmt/format.h>

#include <sph/scene/object_reader.h>
#include <sph/scene/scene_desc.h>

namespace sph::detail {

inline constexpr const char* kAxisNames[3] = {"x", "y", "z"};

template <int D>
std::string point_text(const Vec<D, double>& v) {
  std::string s = "[";
  for (int d = 0; d < D; ++d) s += fmt::format("{}{:.6g}", d ? ", " : "", v[d]);
  return s + "]";
}

template <int D>
std::string box_text(const Box<D>& b) {
  return point_text<D>(b.lo) + " .. " + point_text<D>(b.hi);
}

/// The number of particles build_particles puts along [lo, hi] at spacing dx.
inline double lattice_count(double lo, double hi, double dx) { return std::floor((hi - lo) / dx + 1e-9); }

/// The volume (area in 2D) of b; 0 if b is empty.
template <int D>
double volume(const Box<D>& b) {
  double v = 1;
  for (int d = 0; d < D; ++d) v *= std::max(0.0, b.hi[d] - b.lo[d]);
  return v;
}

template <int D>
Box<D> intersection(const Box<D>& a, const Box<D>& b) {
  Box<D> r;
  for (int d = 0; d < D; ++d) {
    r.lo[d] = std::max(a.lo[d], b.lo[d]);
    r.hi[d] = std::min(a.hi[d], b.hi[d]);
  }
  return r;
}

/// The obstacles that are boxes: the room checks leave the shapes (shape.h) out, whose bounds
/// are all they know of them as boxes.
template <int D>
std::vector<Box<D>> box_obstacles(const SimulationParams<D>& sim) {
  std::vector<Box<D>> boxes;
  for (std::size_t k = 0; k < sim.obstacles.size(); ++k)
    if (!obstacle_shape(sim, k)) boxes.push_back(sim.obstacles[k]);
  return boxes;
}

/// The volume of the container not covered by any obstacle: exact (the cells between the
/// obstacles' coordinates) while that grid has at most ~1e7 cells x obstacles; beyond it the
/// container's volume less the largest obstacle's (an upper bound, so that a refusal on it is
/// never wrong).
template <int D>
double free_volume(const Box<D>& container, const std::vector<Box<D>>& obstacles) {
  std::vector<Box<D>> inside;
  double largest = 0;
  for (const Box<D>& o : obstacles) {
    const Box<D> c = intersection<D>(o, container);
    if (volume<D>(c) > 0) inside.push_back(c), largest = std::max(largest, volume<D>(c));
  }
  const double total = volume<D>(container);
  const double n = static_cast<double>(inside.size());
  if (inside.empty()) return total;
  if (std::pow(2 * n + 1, D) * n > 1e7) return std::max(0.0, total - largest);
  std::vector<double> cuts[D];
  for (int d = 0; d < D; ++d) {
    cuts[d] = {container.lo[d], container.hi[d]};
    for (const Box<D>& o : inside) cuts[d].insert(cuts[d].end(), {o.lo[d], o.hi[d]});
    std::sort(cuts[d].begin(), cuts[d].end());
    cuts[d].erase(std::unique(cuts[d].begin(), cuts[d].end()), cuts[d].end());
  }
  double covered = 0;
  std::size_t idx[3] = {0, 0, 0};
  const std::size_t nz = D == 3 ? cuts[D - 1].size() - 1 : 1;
  for (idx[2] = 0; idx[2] < nz; ++idx[2])
    for (idx[1] = 0; idx[1] + 1 < cuts[1].size(); ++idx[1])
      for (idx[0] = 0; idx[0] + 1 < cuts[0].size(); ++idx[0]) {
        Box<D> cell;
        for (int d = 0; d < D; ++d) cell.lo[d] = cuts[d][idx[d]], cell.hi[d] = cuts[d][idx[d] + 1];
        Vec<D, double> mid = (cell.lo + cell.hi) * 0.5;
        const bool in = std::any_of(inside.begin(), inside.end(), [&](const Box<D>& o) {
          for (int d = 0; d < D; ++d)
            if (!(mid[d] > o.lo[d] && mid[d] < o.hi[d])) return false;
          return true;
        });
        if (in) covered += volume<D>(cell);
      }
  return std::max(0.0, total - covered);
}

/// The emitters' part of the preflight (preflight_emitters.cpp): every nozzle particle inside
/// the container and clear of obstacles and blocks, the path in front of it, the emission
/// window, and room in the container for what the emitters add.
template <int D>
void check_emitters(const ReadContext& ctx, SceneDesc& desc, const SceneBody<D>& body);

}  // namespace sph::detail
