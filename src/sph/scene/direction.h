#pragma once
/// \file An emitter's direction: the unit vector the reader makes of a scene's direction, and
/// the direction the writer gives for a unit vector so that reading it gives that vector back.

#include <cmath>
#include <limits>
#include <optional>

#include <sph/core/error.h>
#include <sph/core/vec.h>

namespace sph::detail {

/// `dir` scaled to unit length, or nullopt if it is zero. Scaled by its largest component first:
/// the squared length of [1e200, 1e200, 0] overflows (1 / inf = 0 made it a zero direction:
/// particles emitted at rest, all on the nozzle) and that of [1e-200, 0, 0] underflows to 0 (a
/// non-zero direction refused as zero).
template <int D>
std::optional<Vec<D, double>> unit_direction(Vec<D, double> dir) {
  double largest = 0;
  for (int d = 0; d < D; ++d) largest = std::max(largest, std::abs(dir[d]));
  if (!(largest > 0)) return std::nullopt;
  for (int d = 0; d < D; ++d) dir[d] /= largest;  // divided, not multiplied by 1 / largest (1 / 1e-310 = inf)
  return dir * (1.0 / norm(dir));
}

/// A direction that unit_direction() maps to `unit` bit for bit (rounding makes unit_direction
/// of a unit vector differ from it in the last bits for some 5 % of directions). `unit` itself
/// when that holds, else the vector unit_direction() scaled before normalizing: `unit` over its
/// largest component, found within 4 units in the last place of each other component.
/// SPH_CHECK: `unit` is a result of unit_direction() (then there is such a vector).
template <int D>
Vec<D, double> direction_giving(const Vec<D, double>& unit) {
  if (unit_direction<D>(unit) == unit) return unit;
  int k = 0;
  for (int d = 1; d < D; ++d)
    if (std::abs(unit[d]) > std::abs(unit[k])) k = d;
  Vec<D, double> scaled;
  for (int d = 0; d < D; ++d) scaled[d] = unit[d] / std::abs(unit[k]);
  scaled[k] = unit[k] > 0 ? 1 : -1;
  // Offsets of the other components, in ulps: -4 .. 4 each (one loop over all combinations).
  constexpr int kUlps = 4, kSpan = 2 * kUlps + 1;
  const int combinations = D == 2 ? kSpan : kSpan * kSpan;
  for (int c = 0; c < combinations; ++c) {
    Vec<D, double> v = scaled;
    int code = c;
    for (int d = 0; d < D; ++d) {
      if (d == k) continue;
      const int offset = code % kSpan - kUlps;
      code /= kSpan;
      const double toward =
          offset > 0 ? std::numeric_limits<double>::infinity() : -std::numeric_limits<double>::infinity();
      for (int s = 0; s < std::abs(offset); ++s) v[d] = std::nextafter(v[d], toward);
    }
    if (unit_direction<D>(v) == unit) return v;
  }
  SPH_CHECK(false, "direction_giving: no direction normalizes to this vector");
  return unit;
}

}  // namespace sph::detail
