#pragma once
/// \file Free surfaces of particle frames (docs/visualization.md, "Surfaces"): a smooth color
/// field sampled on a sparse grid near the particles, and its iso-surface by marching tetrahedra:
/// a closed, consistently oriented triangle mesh in 3D, oriented polylines in 2D.
///
/// The field is c(x) = sum_j V W(|x - x_j|, R) with V = s^dim (s the particle spacing,
/// 2 particleRadius), W the poly6 shape (1 - r^2/R^2)^3 normalized to integrate to 1 in 2D or 3D,
/// and R = smoothing * s. Inside a large body of fluid c is 1; at a flat free surface it falls
/// through 0.5 half a spacing beyond the outermost particle centers, where the particles' own
/// volume ends, so the iso-surface c = iso (0.5) encloses about N V. A particle far from the
/// others (a drop, the tip of a thin jet) would fade below iso (a lone particle's c peaks at 0.2);
/// each particle therefore also keeps a sphere of radius 0.4 s: the sampled value is max(c, g_j)
/// with g_j = iso (2 - |x - x_j|^2 / (0.4 s)^2) (iso on that sphere), which leaves a calm surface
/// unchanged (it lies 0.5 s beyond the outer particles, out of the spheres' reach) and keeps
/// every drop.
///
/// The grid has voxel size v = s / resolution, blocks of 8^dim voxels, and only the blocks
/// within R of a particle hold values. Each block sums its particles in a fixed order and the
/// outputs are joined in block order, so results are bitwise identical for any thread count.

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

namespace sph {

/// The signed distance from a point x (world units; z ignored in 2D) to the solids the fluid
/// cannot enter, negative inside them: exact where it is below `reach`, and any value above
/// `reach` elsewhere. It is called from several threads at once (solid_cut.h makes one for a
/// run's obstacles).
using SolidDistance = std::function<double(const std::array<double, 3>& x, double reach)>;

/// How a surface is made from particles.
struct SurfaceSettings {
  double spacing = 0;     ///< particle spacing s (2 Configuration.particleRadius), world units
  double resolution = 2;  ///< voxels per spacing (voxel size s / resolution); 0.5 to 8
  double smoothing = 2;   ///< kernel support R in spacings; 1 to 4
  double iso = 0.5;       ///< the iso-value of the color field; 0.05 to 0.95
  /// The container, when `clip`: the surface is kept inside it. Each particle within R of a
  /// wall is mirrored across it (and across each pair and the three of the walls it is near),
  /// so that the field goes on beyond a wall the water touches as the water would, and the
  /// field is cut by the box's walls (the sampled value is at most iso + d / (2 v), d the
  /// distance inside the box): water against a wall ends in a flat face on the wall, neither
  /// bulging through it (by up to half a spacing where the outer particles crowd the wall) nor
  /// rippling at the particles' scale where they keep half a spacing off it. z is ignored in 2D.
  bool clip = false;
  std::array<double, 3> clip_lo{}, clip_hi{};
  /// The obstacles, when set: the field is cut by them as by the container's walls (each value
  /// at most iso + d / (2 v), d the voxel's distance outside the solids), so that water against
  /// an obstacle ends on its surface instead of closing over it a particle radius inside it.
  SolidDistance solids;
};

/// Sets `s` for a run's particles: the spacing 2 `particle_radius`, and kept inside the container
/// [lo, hi] (clip). Every surface of a run's frames is made with it (sph surface, sph render
/// --surface, sph run --surface).
inline void fit_to_run(SurfaceSettings& s, double particle_radius, const std::array<double, 3>& lo,
                       const std::array<double, 3>& hi) {
  s.spacing = 2 * particle_radius;
  s.clip = true;
  s.clip_lo = lo;
  s.clip_hi = hi;
}

/// The reasons extract_surface refuses settings, as one message naming the flag's meaning
/// ("resolution must be ..."); empty if `s` is valid.
std::string surface_settings_error(const SurfaceSettings& s);

/// A surface: in 3D a closed triangle mesh whose triangles turn counter-clockwise when seen from
/// outside (normals point out of the fluid); in 2D oriented segments with the fluid on their left
/// (outer boundaries run counter-clockwise). Vertices are shared: every vertex lies on one grid
/// edge, and each grid edge the surface crosses has exactly one vertex.
struct SurfaceMesh {
  int dimension = 3;
  double voxel_size = 0;                                ///< v, world units
  std::vector<std::array<float, 3>> vertices;           ///< positions (z = 0 in 2D)
  std::vector<std::array<float, 3>> normals;            ///< unit, outward: minus the field's gradient (3D); empty in 2D
  std::vector<std::array<std::uint32_t, 3>> triangles;  ///< 3D
  std::vector<std::array<std::uint32_t, 2>> segments;   ///< 2D
  std::size_t blocks = 0;                               ///< blocks that hold values
  std::size_t surface_blocks = 0;                       ///< blocks the surface passes through
};

/// The surface of `count` particles at `positions` (3 coordinates each, z ignored in 2D), in
/// `dimension` 2 or 3. An empty mesh for no particles. Throws sph::Error for bad settings
/// (surface_settings_error), a non-finite position, or a frame so spread out that its grid would
/// exceed the memory bound (the message says how far it spans and what to change).
SurfaceMesh extract_surface(std::span<const double> positions, int dimension, const SurfaceSettings& settings);

/// The volume (3D) or area (2D) the surface encloses, by the divergence theorem; positive for
/// outward orientation.
double enclosed_measure(const SurfaceMesh& mesh);

/// The segments of a 2D surface joined into polylines, each in order along its direction; a
/// closed loop lists its first vertex again at its end.
std::vector<std::vector<std::uint32_t>> surface_polylines(const SurfaceMesh& mesh);

}  // namespace sph
