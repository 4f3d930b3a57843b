#pragma once
/// \file Obstacles of any shape (docs/scene-format.md "Obstacles", docs/physics.md "Mesh and polygon
/// obstacles"): a closed surface at rest, a polygon's edges in 2D (Obstacles[].polygon) or a
/// triangle mesh in 3D (Obstacles[].geometryFile), and its exact signed distance.
///
/// The surface is checked when it is made (make_shape): closed (every edge shared by exactly two
/// faces, in opposite directions), no face of zero size, a non-zero enclosed volume; its faces are
/// then turned outwards. Its signed distance (ShapeField) is exact: the nearest face is found
/// through a bounding-volume hierarchy over the faces, and the sign comes from the angle-weighted
/// pseudo-normal of the nearest feature (face, edge or vertex; Baerentzen and Aanaes 2005), which
/// is exact for a closed oriented surface. A coarse grid over the shape's bounds holds, per cell,
/// the side and a lower bound of the distance, so that points far from the surface (most of the
/// fluid) are answered without a search.
///
/// An `inverted` shape is the solid outside the closed surface: the fluid is held inside it (a
/// closed mesh or a polygon as the container).

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <sph/core/vec.h>

namespace sph {

template <int D>
struct Box;

/// Where a 3D mesh came from, as the scene says it (the scene writer writes it back): its file
/// and the transform x = translation + R(rotation_axis, rotation_angle) (scale * X) of its
/// vertices X (SPlisHSPlasH's names and order: scaled, turned, then moved).
struct MeshSource {
  std::string file;  ///< the path as resolved when read (absolute)
  Vec<3, double> translation{};
  Vec<3, double> rotation_axis{0, 0, 1};  ///< unit
  double rotation_angle = 0;              ///< rad
  Vec<3, double> scale{1, 1, 1};

  friend bool operator==(const MeshSource&, const MeshSource&) = default;
};

/// The nearest point of a shape's surface to a point: its signed distance (negative inside the
/// solid) and the solid's unit outward normal there.
template <int D>
struct SurfaceDistance {
  double distance = 0;
  Vec<D, double> normal{};
};

/// A closed surface's exact signed distance (see the file comment). Immutable once made.
template <int D>
class ShapeField {
 public:
  /// `faces` index `vertices` (2D: edges, 3D: triangles), closed and oriented outwards (make_shape
  /// checks both).
  ShapeField(std::vector<Vec<D, double>> vertices, std::vector<std::array<std::uint32_t, D>> faces);

  /// The signed distance of X to the surface (negative inside it) and the outward normal at the
  /// nearest point: (X - P) / |X - P| outside, (P - X) / |P - X| inside, the nearest feature's
  /// pseudo-normal on the surface.
  SurfaceDistance<D> distance(const Vec<D, double>& X) const;

  /// As distance() where X may be within `reach` of the surface or is on the solid's side of it
  /// (inside the surface when `solid_inside`, outside it otherwise); elsewhere (X on the other side,
  /// farther than `reach` for sure) a lower bound of |distance| above `reach`, with its sign, and
  /// no normal. Far points cost one grid lookup.
  SurfaceDistance<D> distance_within(const Vec<D, double>& X, double reach, bool solid_inside = true) const;

  /// Whether X is inside the surface (exact; a point on it counts as outside).
  bool inside(const Vec<D, double>& X) const { return distance_within(X, 0).distance < 0; }

  const Vec<D, double>& lo() const { return lo_; }  ///< the vertices' bounding box, m
  const Vec<D, double>& hi() const { return hi_; }
  /// The enclosed volume, m^3 (2D: area, m^2).
  double volume() const { return volume_; }

 private:
  struct Node {
    Vec<D, double> lo, hi;
    std::uint32_t first = 0, count = 0;  // a leaf: faces order_[first, first + count)
    std::uint32_t left = 0, right = 0;   // an inner node (count == 0): its children
  };
  std::uint32_t build(std::uint32_t first, std::uint32_t count, std::vector<Vec<D, double>>& centroids);
  double box_distance2(const Node& n, const Vec<D, double>& X) const;
  /// The nearest point of face f to X, and the pseudo-normal of its nearest feature.
  void nearest_on_face(std::uint32_t f, const Vec<D, double>& X, Vec<D, double>& P, Vec<D, double>& pn) const;

  std::vector<Vec<D, double>> vertices_;
  std::vector<std::array<std::uint32_t, D>> faces_;
  std::vector<Vec<D, double>> face_normal_;                 // unit (3D: a face's; 2D: an edge's)
  std::vector<std::array<Vec<D, double>, D>> edge_normal_;  // 3D: per face, edges ab, bc, ca
  std::vector<Vec<D, double>> vertex_normal_;               // angle-weighted (2D: the two edges')
  std::vector<std::uint32_t> order_;                        // faces in the hierarchy's leaf order
  std::vector<Node> nodes_;
  Vec<D, double> lo_{}, hi_{};
  double volume_ = 0;
  // The coarse grid: cells of size cell_ from grid_lo_, n_ per axis; per cell the side (1 inside)
  // and a lower bound of |distance| anywhere in it.
  Vec<D, double> grid_lo_{};
  double cell_ = 0;
  std::array<std::int64_t, D> n_{};
  std::vector<float> bound_;
  std::vector<std::uint8_t> side_;
};

/// An obstacle's shape (one that is not a box): its surface at rest, where the scene puts it.
template <int D>
struct ObstacleShape {
  std::vector<Vec<D, double>> vertices;             ///< m
  std::vector<std::array<std::uint32_t, D>> faces;  ///< 2D: edges in polygon order; 3D: triangles; outwards
  bool inverted = false;                            ///< the solid is outside the surface (the fluid inside)
  MeshSource source;                                ///< 3D: the file and transform it came from
  std::shared_ptr<const ShapeField<D>> field;       ///< made with the shape (make_shape)

  bool empty() const { return faces.empty(); }
  /// The signed distance to the solid (negative inside the solid, inverted or not) and the solid's
  /// outward normal, exact where the point may be within `reach` of the surface or inside the
  /// solid; elsewhere a lower bound > reach (ShapeField::distance_within).
  SurfaceDistance<D> solid_distance(const Vec<D, double>& X, double reach) const;

  friend bool operator==(const ObstacleShape& a, const ObstacleShape& b) {
    return a.vertices == b.vertices && a.faces == b.faces && a.inverted == b.inverted && a.source == b.source;
  }
};

/// Most faces a shape may have (a larger mesh is refused: decimate it first).
inline constexpr std::size_t kMaxShapeFaces = 4'000'000;

/// Makes a shape of a closed surface: checks it (throws sph::Error saying what is wrong: too few
/// or too many faces, an index out of range, a face of zero size, an edge that belongs to one face
/// only (not closed), to more than two, or twice in the same direction (not consistently
/// oriented), an enclosed volume of zero), turns its faces outwards and makes its field.
template <int D>
ObstacleShape<D> make_shape(std::vector<Vec<D, double>> vertices, std::vector<std::array<std::uint32_t, D>> faces,
                            bool inverted, MeshSource source = {});

/// The shape of a simple polygon (vertices in order around it, either way): throws sph::Error for
/// fewer than 3 vertices, two consecutive equal vertices, or edges that cross.
ObstacleShape<2> polygon_shape(std::vector<Vec<2, double>> vertices, bool inverted);

/// The bounding box of a shape's vertices.
template <int D>
Box<D> shape_bounds(const ObstacleShape<D>& shape);

extern template class ShapeField<2>;
extern template class ShapeField<3>;

}  // namespace sph
