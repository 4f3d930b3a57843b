#pragma once
/// \file Images of particles: each particle a disc (optionally shaded as a sphere) seen by an
/// orthographic camera fitted to the container box, which is drawn as a thin outline, and the
/// scene's obstacles drawn as solid boxes.

#include <array>
#include <span>

#include <sph/render/image.h>
#include <sph/surface/surface.h>

namespace sph {

/// What the camera sees and how particles look.
struct ParticleView {
  int width = 800, height = 600;  ///< image size in pixels
  /// Orthographic camera for 3D (2D ignores them): the camera starts on the +z side looking
  /// towards -z (x right, y up), turns by `azimuth_deg` about the world y axis (positive shows
  /// more of the +x side), then rises by `elevation_deg` (positive looks down onto the top).
  double azimuth_deg = 0, elevation_deg = 0;
  Rgb background{255, 255, 255};
  bool shaded = true;  ///< sphere shading (Lambert, light from the upper left, plus ambient)
};

/// A solid box to draw (an obstacle of the scene): the box [lo, hi] at rest, in world units, and
/// the rigid placement that puts its point p at center + translation + R (p - center), R =
/// `rotation` (row-major 3 x 3), so that a moving obstacle is drawn where it is. The default
/// placement is the identity: `SolidBox{lo, hi}` is the axis-aligned box itself. In 2D, z is
/// ignored and only the upper-left 2 x 2 of R is used.
struct SolidBox {
  std::array<double, 3> lo{}, hi{};
  std::array<double, 9> rotation{1, 0, 0, 0, 1, 0, 0, 0, 1};  ///< R, a rotation
  std::array<double, 3> center{}, translation{};              ///< c and t, world units
  /// A solid of another shape (its surface at rest, placed as the box is; [lo, hi] its bounds):
  /// 2D, a polygon's vertices in order around it; 3D, a mesh's vertices and `triangles`, turned
  /// outwards. Empty: the box.
  std::vector<std::array<double, 3>> vertices{};
  std::vector<std::array<std::uint32_t, 3>> triangles{};
  /// The solid is outside the surface (the fluid inside it): in 2D only its outline is drawn, in
  /// 3D only the faces turned away from the camera (the far side of the vessel, cut open).
  bool inverted = false;

  /// Whether R is the identity (the box is axis-aligned, only translated if at all).
  bool axis_aligned() const;
  /// Where the point p of the box at rest is drawn: c + t + R (p - c) (2D: x, y only, z kept).
  /// Exactly p + t when R is the identity.
  std::array<double, 3> place(const std::array<double, 3>& p, int dim) const;
  /// The world direction of the box's axis a (0, 1, 2): R e_a, its face normals' direction.
  std::array<double, 3> axis(int a, int dim) const;
};

/// The fill of a solid box in 2D, and the base color of its faces in 3D (each face scaled by
/// its flat shading): a neutral gray between the white background and the container outline.
inline constexpr Rgb kSolidColor{196, 196, 196};
/// The outline of a solid box (its edges in 3D): darker than any shade of its faces.
inline constexpr Rgb kSolidEdgeColor{72, 72, 72};

/// A 3D camera that shows depth well (azimuth 30, elevation 20) for dim 3, the plain view for
/// dim 2; width x height pixels.
ParticleView default_particle_view(int dim, int width = 800, int height = 600);

/// The mapping from world coordinates to pixel coordinates used by render_particles: the box
/// (grown by the particle radius) fills the image with a small margin, aspect ratio preserved.
class ParticleCamera {
 public:
  /// Throws sph::Error for a bad view (size outside 1..16384, non-finite angles), a box with
  /// non-finite corners or lo > hi, or a negative or non-finite radius. Precondition: dim is 2 or 3.
  ParticleCamera(int dim, const std::array<double, 3>& box_lo, const std::array<double, 3>& box_hi, double radius,
                 const ParticleView& view);

  /// Pixel coordinates (x right, y down; pixel centers at +0.5) and depth (larger is nearer the
  /// camera; 0 in 2D) of a world point. In 2D, p[2] is ignored.
  std::array<double, 3> project(const std::array<double, 3>& p) const;
  /// Pixels per world unit.
  double pixels_per_unit() const { return scale_; }
  /// Camera-space unit vectors in world coordinates: right, up, towards the viewer.
  const std::array<std::array<double, 3>, 3>& axes() const { return axes_; }

 private:
  int dim_;
  std::array<std::array<double, 3>, 3> axes_{};
  std::array<double, 3> center_{};
  double scale_ = 1.0;
  double cx_ = 0.0, cy_ = 0.0;  ///< pixel position of the box center
};

/// Renders particles. `xyz` holds `dim` coordinates per particle (dim 2 or 3; y is up). `colors`
/// holds one color per particle, or a single color for all (an empty span draws them all blue).
/// `radius` is the particle radius in world units (drawn at least 1 pixel wide). The box
/// [box_lo, box_hi] (z ignored in 2D) fits the view and is drawn as a thin gray outline: a
/// rectangle in 2D, its 12 projected edges in 3D (edges of faces turned to the camera are drawn
/// over the particles, the others behind them). In 3D particles are drawn far to near (painter's
/// algorithm; equal depths in index order), in 2D in index order. Particles with a non-finite
/// coordinate are skipped.
///
/// Each of `solids` is drawn, where its placement puts it, as a solid box with a kSolidEdgeColor
/// outline: in 2D a rectangle (turned, if it is) filled with kSolidColor, drawn over the
/// particles and the container outline; in 3D its faces turned to the camera (by their rotated
/// normals), flat-shaded by facing, hidden per pixel behind nearer faces and by particles nearer
/// than the face (depth of the particle's center), and hiding the particles behind them. Either way a particle inside a
/// solid (a leak) is not seen: the solid always reads as the solid the fluid meets. Without solids the image is the
/// same as before they existed.
///
/// Throws sph::Error as ParticleCamera does, and for a solid with non-finite corners or
/// placement, or lo > hi.
/// Preconditions: dim is 2 or 3, xyz.size() is a multiple of dim, colors.size() is 0, 1 or the
/// particle count.
Image render_particles(std::span<const double> xyz, int dim, std::span<const Rgb> colors, double radius,
                       const std::array<double, 3>& box_lo, const std::array<double, 3>& box_hi,
                       const ParticleView& view, std::span<const SolidBox> solids = {});

/// Renders the free surface of a 3D fluid (extract_surface's mesh) seen by the same camera as
/// render_particles with this `radius`, box and view: triangles rasterized with a per-pixel depth
/// test, shaded per pixel from the interpolated vertex normals (Lambert, a key light from the
/// upper left and a weaker fill light fixed in camera space, ambient, a small highlight) in a
/// water blue. The container's bottom face is filled light gray as a floor, the box outline and
/// the `solids` are drawn as render_particles draws them in 3D, all depth-tested against the
/// fluid. Triangles with a non-finite vertex are skipped. Deterministic.
///
/// Throws sph::Error as render_particles does. Precondition: mesh.dimension is 3 and its
/// triangles index its vertices and normals.
Image render_surface(const SurfaceMesh& mesh, double radius, const std::array<double, 3>& box_lo,
                     const std::array<double, 3>& box_hi, const ParticleView& view,
                     std::span<const SolidBox> solids = {});

}  // namespace sph
