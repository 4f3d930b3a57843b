#include <sph/bench/workload.h>

#include <fmt/format.h>

#include <sph/core/error.h>

namespace sph {

template <std::floating_point R>
std::vector<Vec<3, R>> lattice_points(const LatticeSpec& spec) {
  SPH_CHECK(spec.side > 0 && spec.spacing > 0 && spec.jitter >= 0, "bad lattice spec");
  SplitMix64 rng(spec.seed);
  const double a = spec.jitter * spec.spacing;
  std::vector<Vec<3, R>> points;
  points.reserve(spec.count());
  for (int z = 0; z < spec.side; ++z)
    for (int y = 0; y < spec.side; ++y)
      for (int x = 0; x < spec.side; ++x) {
        const int c[3] = {x, y, z};
        Vec<3, R> p;
        for (int d = 0; d < 3; ++d) p[d] = static_cast<R>(spec.spacing * c[d] + rng.symmetric(a));
        points.push_back(p);
      }
  return points;
}

template <std::floating_point R>
std::vector<Vec<3, R>> moved_points(std::span<const Vec<3, R>> points, double amplitude, std::uint64_t seed) {
  SplitMix64 rng(seed);
  std::vector<Vec<3, R>> out(points.begin(), points.end());
  for (auto& p : out)
    for (int d = 0; d < 3; ++d) p[d] = static_cast<R>(static_cast<double>(p[d]) + rng.symmetric(amplitude));
  return out;
}

std::vector<std::uint32_t> shuffle_permutation(std::size_t n, std::uint64_t seed) {
  SPH_CHECK(n < (std::size_t{1} << 32), "too many points for 32-bit indices");
  std::vector<std::uint32_t> perm(n);
  for (std::size_t i = 0; i < n; ++i) perm[i] = static_cast<std::uint32_t>(i);
  SplitMix64 rng(seed);
  for (std::size_t i = n; i > 1; --i) {
    const std::size_t j = static_cast<std::size_t>(rng.below(i));  // j in [0, i)
    std::swap(perm[i - 1], perm[j]);
  }
  return perm;
}

const char* precision_name(Precision precision) { return precision == Precision::Float ? "float" : "double"; }

std::string dam_break_scene_json(int side, Precision precision, NeighborMode mode, std::int64_t steps) {
  SPH_CHECK(side > 0 && steps > 0, "bad dam break size");
  constexpr double kSpacing = 0.02;
  const double width = kSpacing * side;
  return fmt::format(
      R"({{
  "version": 1,
  "name": "bench_dam_break_{side}",
  "description": "sph bench steps workload: a {side}^3 block against the left wall of a 2.5 x 1.5 x 1 box",
  "units": "SI",
  "dimension": 3,
  "Configuration": {{
    "precision": "{precision}",
    "timeStepSize": 4e-4,
    "numberOfSteps": {steps},
    "particleRadius": 0.01,
    "kernelRadius": 0.04,
    "gravitation": [0, -9.81, 0],
    "neighbors": "{mode}",
    "fullRebuildPeriod": 200,
    "outputEveryNSteps": 0
  }},
  "Fluid": {{ "density0": 1000, "stiffness": 900, "viscosity": 3.0, "negativePressure": "clamp" }},
  "Container": {{ "start": [0, 0, 0], "end": [{bx:.17g}, {by:.17g}, {bz:.17g}], "wallStiffness": 2e5, "wallDamping": 300 }},
  "FluidBlocks": [ {{ "start": [0, 0, 0], "end": [{w:.17g}, {w:.17g}, {w:.17g}] }} ]
}}
)",
      fmt::arg("side", side), fmt::arg("precision", precision_name(precision)), fmt::arg("steps", steps),
      fmt::arg("mode", to_string(mode)), fmt::arg("bx", 2.5 * width), fmt::arg("by", 1.5 * width),
      fmt::arg("bz", width), fmt::arg("w", width));
}

template std::vector<Vec<3, float>> lattice_points<float>(const LatticeSpec&);
template std::vector<Vec<3, double>> lattice_points<double>(const LatticeSpec&);
template std::vector<Vec<3, float>> moved_points<float>(std::span<const Vec<3, float>>, double, std::uint64_t);
template std::vector<Vec<3, double>> moved_points<double>(std::span<const Vec<3, double>>, double, std::uint64_t);

}  // namespace sph
