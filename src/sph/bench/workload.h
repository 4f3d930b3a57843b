#pragma once
/// \file The benchmark workloads' data: a small deterministic random generator, the jittered
/// 3D lattice of the neighbors suite, its moved copy and a shuffling permutation, and the
/// scenes of the steps suite (a 3D dam break built in code). Everything here depends only on
/// the seeds, never on the standard library's distributions, so results compare across
/// versions, compilers and machines.

#include <concepts>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <sph/core/vec.h>
#include <sph/neighbors/strategy.h>
#include <sph/scene/scene_desc.h>

namespace sph {

/// SplitMix64 (Steele, Lea and Flood, 2014): a 64-bit counter passed through a mixing function.
/// Tiny, fast, and the same sequence everywhere.
class SplitMix64 {
 public:
  explicit SplitMix64(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  /// Uniform in [0, 1), 53 random bits.
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  /// Uniform in [-a, a).
  double symmetric(double a) { return (2.0 * uniform() - 1.0) * a; }
  /// Integer in [0, n), n > 0, by remainder (the bias, at most n / 2^64, is irrelevant here).
  std::uint64_t below(std::uint64_t n) { return next() % n; }

 private:
  std::uint64_t state_;
};

/// Fixed seeds of the neighbors workload (changing them changes every published figure).
inline constexpr std::uint64_t kLatticeSeed = 0x5eed0001;
inline constexpr std::uint64_t kMoveSeed = 0x5eed0002;
inline constexpr std::uint64_t kShuffleSeed = 0x5eed0003;

/// The neighbors workload's geometry.
struct LatticeSpec {
  int side = 20;           ///< points per axis: side^3 points
  double spacing = 0.025;  ///< dx, m
  double jitter = 0.1;     ///< each coordinate moves uniformly by up to +-jitter * dx
  std::uint64_t seed = kLatticeSeed;

  std::size_t count() const { return static_cast<std::size_t>(side) * side * side; }
};

/// Points of a cubic lattice: point x + side (y + side z) starts at dx (x, y, z) and each of
/// its coordinates is shifted by a uniform value in [-jitter dx, jitter dx) (drawn in double,
/// x then y then z, point after point, then rounded to R). Same spec, same points.
template <std::floating_point R>
std::vector<Vec<3, R>> lattice_points(const LatticeSpec& spec);

/// A copy of `points` with every coordinate moved by a uniform value in [-amplitude, amplitude)
/// (drawn in double from `seed`, then rounded to R).
template <std::floating_point R>
std::vector<Vec<3, R>> moved_points(std::span<const Vec<3, R>> points, double amplitude, std::uint64_t seed);

/// A uniformly random permutation of [0, n) (Fisher-Yates driven by SplitMix64(seed)).
std::vector<std::uint32_t> shuffle_permutation(std::size_t n, std::uint64_t seed);

/// out[k] = in[perm[k]]; out is resized to perm.size(). perm must index into in.
template <class T>
void gather(std::span<const T> in, std::span<const std::uint32_t> perm, std::vector<T>& out) {
  out.resize(perm.size());
  for (std::size_t k = 0; k < perm.size(); ++k) out[k] = in[perm[k]];
}

/// The steps suite's scene: a 3D dam break of side^3 particles (spacing 0.02 m, particle radius
/// 0.01 m, h = 0.04 m, the fluid and walls of scenes/paper/block_3d.json, dt = 4e-4 s): a cubic
/// block of width L = 0.02 side against the left wall (x = 0) and the floor of a box
/// 2.5 L x 1.5 L x L. Returns the scene's JSON text.
std::string dam_break_scene_json(int side, Precision precision, NeighborMode mode, std::int64_t steps);

/// "float" or "double".
const char* precision_name(Precision precision);

}  // namespace sph
