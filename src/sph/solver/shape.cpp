#include <sph/solver/shape.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <unordered_map>

#include <fmt/format.h>

#include <sph/core/error.h>
#include <sph/core/parallel.h>
#include <sph/solver/params.h>

namespace sph {

namespace {

using V2 = Vec<2, double>;
using V3 = Vec<3, double>;

double cross2(const V2& a, const V2& b) { return a[0] * b[1] - a[1] * b[0]; }

template <int D>
Vec<D, double> unit_or_zero(const Vec<D, double>& v) {
  const double n = std::sqrt(norm2(v));
  return n > 0 ? v * (1.0 / n) : Vec<D, double>{};
}

/// Faces in a leaf of the hierarchy.
constexpr std::uint32_t kLeafFaces = 4;
/// Cells of the coarse grid along the shape's longest side.
constexpr double kGridCells = 40;

}  // namespace

template <int D>
ShapeField<D>::ShapeField(std::vector<Vec<D, double>> vertices, std::vector<std::array<std::uint32_t, D>> faces)
    : vertices_(std::move(vertices)), faces_(std::move(faces)) {
  SPH_CHECK(!vertices_.empty() && !faces_.empty(), "ShapeField: an empty surface");
  lo_ = hi_ = vertices_[0];
  for (const auto& v : vertices_)
    for (int d = 0; d < D; ++d) lo_[d] = std::min(lo_[d], v[d]), hi_[d] = std::max(hi_[d], v[d]);
  // Normals: per face, per edge (3D: the sum of its two faces'), per vertex (angle-weighted).
  face_normal_.resize(faces_.size());
  vertex_normal_.assign(vertices_.size(), Vec<D, double>{});
  if constexpr (D == 2) {
    for (std::size_t f = 0; f < faces_.size(); ++f) {
      const V2 e = vertices_[faces_[f][1]] - vertices_[faces_[f][0]];
      face_normal_[f] = unit_or_zero<2>(V2{{e[1], -e[0]}});  // outwards for a counter-clockwise polygon
      volume_ += 0.5 * cross2(vertices_[faces_[f][0]], vertices_[faces_[f][1]]);
      for (const std::uint32_t v : faces_[f]) vertex_normal_[v] += face_normal_[f];
    }
  } else {
    std::map<std::pair<std::uint32_t, std::uint32_t>, V3> edge_sum;
    for (std::size_t f = 0; f < faces_.size(); ++f) {
      const auto& t = faces_[f];
      const V3 &a = vertices_[t[0]], &b = vertices_[t[1]], &c = vertices_[t[2]];
      face_normal_[f] = unit_or_zero<3>(cross(b - a, c - a));
      volume_ += dot(a, cross(b, c)) / 6.0;
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t v = t[static_cast<std::size_t>(k)], u = t[static_cast<std::size_t>((k + 1) % 3)],
                            w = t[static_cast<std::size_t>((k + 2) % 3)];
        const V3 e1 = unit_or_zero<3>(vertices_[u] - vertices_[v]), e2 = unit_or_zero<3>(vertices_[w] - vertices_[v]);
        const double angle = std::acos(std::clamp(dot(e1, e2), -1.0, 1.0));
        vertex_normal_[v] += face_normal_[f] * angle;
        edge_sum[{std::min(v, u), std::max(v, u)}] += face_normal_[f];
      }
    }
    edge_normal_.resize(faces_.size());
    for (std::size_t f = 0; f < faces_.size(); ++f)
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t v = faces_[f][static_cast<std::size_t>(k)],
                            u = faces_[f][static_cast<std::size_t>((k + 1) % 3)];
        edge_normal_[f][static_cast<std::size_t>(k)] = edge_sum[{std::min(v, u), std::max(v, u)}];
      }
  }
  // The hierarchy: faces split at the median of their centroids along the longest side.
  order_.resize(faces_.size());
  std::iota(order_.begin(), order_.end(), 0u);
  std::vector<Vec<D, double>> centroids(faces_.size());
  for (std::size_t f = 0; f < faces_.size(); ++f) {
    Vec<D, double> c{};
    for (const std::uint32_t v : faces_[f]) c += vertices_[v];
    centroids[f] = c * (1.0 / D);
  }
  nodes_.reserve(2 * faces_.size() / kLeafFaces + 2);
  build(0, static_cast<std::uint32_t>(faces_.size()), centroids);
  // The coarse grid, two cells beyond the bounds on every side.
  double longest = 0;
  for (int d = 0; d < D; ++d) longest = std::max(longest, hi_[d] - lo_[d]);
  cell_ = longest / kGridCells;
  std::size_t cells = 1;
  for (int d = 0; d < D; ++d) {
    grid_lo_[d] = lo_[d] - 2 * cell_;
    n_[static_cast<std::size_t>(d)] = static_cast<std::int64_t>(std::ceil((hi_[d] - lo_[d]) / cell_)) + 4;
    cells *= static_cast<std::size_t>(n_[static_cast<std::size_t>(d)]);
  }
  bound_.resize(cells);
  side_.resize(cells);
  const double half_diagonal = 0.5 * cell_ * std::sqrt(static_cast<double>(D));
  parallel_for(cells, [&](std::size_t i) {
    Vec<D, double> x;
    std::size_t rest = i;
    for (int d = 0; d < D; ++d) {
      const auto n = static_cast<std::size_t>(n_[static_cast<std::size_t>(d)]);
      x[d] = grid_lo_[d] + (static_cast<double>(rest % n) + 0.5) * cell_;
      rest /= n;
    }
    const double s = distance(x).distance;
    bound_[i] = static_cast<float>(std::max(0.0, std::abs(s) - half_diagonal) * (1 - 1e-6));
    side_[i] = s < 0 ? 1 : 0;
  });
}

template <int D>
std::uint32_t ShapeField<D>::build(std::uint32_t first, std::uint32_t count, std::vector<Vec<D, double>>& centroids) {
  const auto index = static_cast<std::uint32_t>(nodes_.size());
  nodes_.push_back({});
  Node n;
  n.lo = n.hi = vertices_[faces_[order_[first]][0]];
  for (std::uint32_t k = first; k < first + count; ++k)
    for (const std::uint32_t v : faces_[order_[k]])
      for (int d = 0; d < D; ++d)
        n.lo[d] = std::min(n.lo[d], vertices_[v][d]), n.hi[d] = std::max(n.hi[d], vertices_[v][d]);
  if (count <= kLeafFaces) {
    n.first = first;
    n.count = count;
    nodes_[index] = n;
    return index;
  }
  int axis = 0;
  for (int d = 1; d < D; ++d)
    if (n.hi[d] - n.lo[d] > n.hi[axis] - n.lo[axis]) axis = d;
  const std::uint32_t half = count / 2;
  std::nth_element(order_.begin() + first, order_.begin() + first + half, order_.begin() + first + count,
                   [&](std::uint32_t a, std::uint32_t b) {
                     return centroids[a][axis] != centroids[b][axis] ? centroids[a][axis] < centroids[b][axis] : a < b;
                   });
  n.left = build(first, half, centroids);
  n.right = build(first + half, count - half, centroids);
  nodes_[index] = n;
  return index;
}

template <int D>
double ShapeField<D>::box_distance2(const Node& n, const Vec<D, double>& X) const {
  double s = 0;
  for (int d = 0; d < D; ++d) {
    const double o = std::max({n.lo[d] - X[d], 0.0, X[d] - n.hi[d]});
    s += o * o;
  }
  return s;
}

template <int D>
void ShapeField<D>::nearest_on_face(std::uint32_t f, const Vec<D, double>& X, Vec<D, double>& P,
                                    Vec<D, double>& pn) const {
  const auto& t = faces_[f];
  if constexpr (D == 2) {
    const V2 &a = vertices_[t[0]], &b = vertices_[t[1]];
    const V2 e = b - a;
    const double s = dot(X - a, e) / norm2(e);
    if (s <= 0) {
      P = a, pn = vertex_normal_[t[0]];
    } else if (s >= 1) {
      P = b, pn = vertex_normal_[t[1]];
    } else {
      P = a + e * s, pn = face_normal_[f];
    }
  } else {
    // Ericson, Real-Time Collision Detection, 5.1.5: the Voronoi regions of the triangle's
    // vertices, edges and face, in turn.
    const V3 &a = vertices_[t[0]], &b = vertices_[t[1]], &c = vertices_[t[2]];
    const V3 ab = b - a, ac = c - a, ap = X - a;
    const double d1 = dot(ab, ap), d2 = dot(ac, ap);
    if (d1 <= 0 && d2 <= 0) {
      P = a, pn = vertex_normal_[t[0]];
      return;
    }
    const V3 bp = X - b;
    const double d3 = dot(ab, bp), d4 = dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) {
      P = b, pn = vertex_normal_[t[1]];
      return;
    }
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
      P = a + ab * (d1 / (d1 - d3)), pn = edge_normal_[f][0];
      return;
    }
    const V3 cp = X - c;
    const double d5 = dot(ab, cp), d6 = dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) {
      P = c, pn = vertex_normal_[t[2]];
      return;
    }
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
      P = a + ac * (d2 / (d2 - d6)), pn = edge_normal_[f][2];
      return;
    }
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
      P = b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))), pn = edge_normal_[f][1];
      return;
    }
    const double denom = 1.0 / (va + vb + vc);
    P = a + ab * (vb * denom) + ac * (vc * denom), pn = face_normal_[f];
  }
}

template <int D>
SurfaceDistance<D> ShapeField<D>::distance(const Vec<D, double>& X) const {
  double best = std::numeric_limits<double>::infinity();
  Vec<D, double> best_p{}, best_pn{};
  std::uint32_t best_face = std::numeric_limits<std::uint32_t>::max();
  std::uint32_t stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[stack[--top]];
    if (box_distance2(n, X) > best) continue;
    if (n.count > 0) {
      for (std::uint32_t k = n.first; k < n.first + n.count; ++k) {
        Vec<D, double> P, pn;
        nearest_on_face(order_[k], X, P, pn);
        const double d2 = norm2(X - P);
        // (ties go to the lower face index: the same answer however the tree is walked)
        if (d2 < best || (d2 == best && order_[k] < best_face))
          best = d2, best_p = P, best_pn = pn, best_face = order_[k];
      }
      continue;
    }
    // The nearer child is searched first (pushed last).
    const double dl = box_distance2(nodes_[n.left], X), dr = box_distance2(nodes_[n.right], X);
    SPH_CHECK(top + 2 <= 64, "ShapeField: hierarchy too deep");
    if (dl <= dr) {
      stack[top++] = n.right;
      stack[top++] = n.left;
    } else {
      stack[top++] = n.left;
      stack[top++] = n.right;
    }
  }
  SurfaceDistance<D> out;
  const Vec<D, double> off = X - best_p;
  const double dist = std::sqrt(best);
  const bool in = dot(off, best_pn) < 0;
  out.distance = in ? -dist : dist;
  out.normal = dist > 0 ? off * ((in ? -1.0 : 1.0) / dist) : unit_or_zero<D>(best_pn);
  return out;
}

template <int D>
SurfaceDistance<D> ShapeField<D>::distance_within(const Vec<D, double>& X, double reach, bool solid_inside) const {
  std::size_t cell = 0, stride = 1;
  for (int d = 0; d < D; ++d) {
    const double u = (X[d] - grid_lo_[d]) / cell_;
    const auto n = n_[static_cast<std::size_t>(d)];
    if (!(u >= 0 && u < static_cast<double>(n))) {
      // Outside the grid: farther from the bounds than two cells, and outside the surface.
      double o2 = 0;
      for (int e = 0; e < D; ++e) {
        const double o = std::max({lo_[e] - X[e], 0.0, X[e] - hi_[e]});
        o2 += o * o;
      }
      const double o = std::sqrt(o2);
      if (solid_inside && o > reach) return {o, {}};
      return distance(X);
    }
    cell += static_cast<std::size_t>(u) * stride;
    stride *= static_cast<std::size_t>(n);
  }
  // (the cell lies wholly on the side away from the solid, farther than `reach`)
  if (side_[cell] == (solid_inside ? 0 : 1) && static_cast<double>(bound_[cell]) > reach)
    return {solid_inside ? static_cast<double>(bound_[cell]) : -static_cast<double>(bound_[cell]), {}};
  return distance(X);
}

template <int D>
SurfaceDistance<D> ObstacleShape<D>::solid_distance(const Vec<D, double>& X, double reach) const {
  SPH_CHECK(field != nullptr, "ObstacleShape: made without make_shape");
  if (!inverted) return field->distance_within(X, reach);
  // Inverted: the solid is outside the surface; a point far inside the surface is far outside
  // the solid, and any point outside the surface needs its exact depth.
  SurfaceDistance<D> s = field->distance_within(X, reach, false);
  s.distance = -s.distance;
  s.normal = -s.normal;
  return s;
}

template <int D>
Box<D> shape_bounds(const ObstacleShape<D>& shape) {
  Box<D> b;
  SPH_CHECK(!shape.vertices.empty(), "shape_bounds: no vertices");
  b.lo = b.hi = shape.vertices[0];
  for (const auto& v : shape.vertices)
    for (int d = 0; d < D; ++d) b.lo[d] = std::min(b.lo[d], v[d]), b.hi[d] = std::max(b.hi[d], v[d]);
  return b;
}

template <int D>
ObstacleShape<D> make_shape(std::vector<Vec<D, double>> vertices, std::vector<std::array<std::uint32_t, D>> faces,
                            bool inverted, MeshSource source) {
  const char* face_word = D == 2 ? "edge" : "triangle";
  if (faces.size() < (D == 2 ? 3u : 4u))
    throw Error(fmt::format("has {} {}s; a closed surface needs at least {}", faces.size(), face_word, D == 2 ? 3 : 4));
  if (faces.size() > kMaxShapeFaces)
    throw Error(fmt::format("has {} {}s, more than the {} supported; simplify (decimate) it first", faces.size(),
                            face_word, kMaxShapeFaces));
  for (const auto& v : vertices)
    for (int d = 0; d < D; ++d)
      if (!std::isfinite(v[d])) throw Error("has a vertex that is not a finite number");
  for (std::size_t f = 0; f < faces.size(); ++f)
    for (const std::uint32_t v : faces[f])
      if (v >= vertices.size())
        throw Error(fmt::format("{} {} uses vertex {}, but there are {} vertices", face_word, f, v, vertices.size()));
  // Sizes relative to the whole: a face smaller than 1e-12 of the bounds is degenerate.
  Vec<D, double> lo = vertices[faces[0][0]], hi = lo;
  for (const auto& t : faces)
    for (const std::uint32_t v : t)
      for (int d = 0; d < D; ++d) lo[d] = std::min(lo[d], vertices[v][d]), hi[d] = std::max(hi[d], vertices[v][d]);
  const double size = std::sqrt(norm2(hi - lo));
  std::size_t degenerate = 0, first_degenerate = 0;
  for (std::size_t f = 0; f < faces.size(); ++f) {
    double measure;
    if constexpr (D == 2)
      measure = std::sqrt(norm2(vertices[faces[f][1]] - vertices[faces[f][0]]));
    else
      measure = std::sqrt(
          norm2(cross(vertices[faces[f][1]] - vertices[faces[f][0]], vertices[faces[f][2]] - vertices[faces[f][0]])));
    if (!(measure > 1e-12 * (D == 2 ? size : size * size))) {
      if (degenerate++ == 0) first_degenerate = f;
    }
  }
  if (degenerate > 0)
    throw Error(
        fmt::format("has {} degenerate {}s (of zero {}; the first is {} {}); remove them (most mesh tools "
                    "have a clean-up for degenerate faces)",
                    degenerate, face_word, D == 2 ? "length" : "area", face_word, first_degenerate));
  // Closed and consistently oriented. 2D: each vertex used starts one edge and ends one.
  if constexpr (D == 2) {
    std::vector<int> starts(vertices.size()), ends(vertices.size());
    for (const auto& e : faces) ++starts[e[0]], ++ends[e[1]];
    for (std::size_t v = 0; v < vertices.size(); ++v)
      if (starts[v] != ends[v] || starts[v] > 1)
        throw Error(
            fmt::format("is not a closed, consistently oriented outline: vertex {} starts {} edges and ends {} "
                        "(each vertex must join one edge in and one edge out)",
                        v, starts[v], ends[v]));
  } else {  // 3D: each directed edge once, and its reverse once.
    std::vector<std::pair<std::uint32_t, std::uint32_t>> directed;
    directed.reserve(faces.size() * D);
    for (const auto& t : faces)
      for (int k = 0; k < 3; ++k)
        directed.emplace_back(t[static_cast<std::size_t>(k)], t[static_cast<std::size_t>((k + 1) % D)]);
    std::sort(directed.begin(), directed.end());
    for (std::size_t i = 1; i < directed.size(); ++i)
      if (directed[i] == directed[i - 1])
        throw Error(
            fmt::format("is not a closed, consistently oriented surface: the edge between vertices {} and {} "
                        "is used twice in the same direction (faces turned inconsistently, or more than two "
                        "faces meet at it)",
                        directed[i].first, directed[i].second));
    std::size_t open = 0;
    std::pair<std::uint32_t, std::uint32_t> first_open{};
    for (const auto& e : directed)
      if (!std::binary_search(directed.begin(), directed.end(), std::make_pair(e.second, e.first))) {
        if (open++ == 0) first_open = e;
      }
    if (open > 0)
      throw Error(
          fmt::format("is not closed: {} {} belong to one {} only (the first joins vertices {} and {}); "
                      "a solid needs a closed, watertight surface",
                      open, "edges", face_word, first_open.first, first_open.second));
  }
  // Outwards: a positive enclosed volume.
  double volume = 0;
  for (const auto& t : faces) {
    if constexpr (D == 2)
      volume += 0.5 * cross2(vertices[t[0]], vertices[t[1]]);
    else
      volume += dot(vertices[t[0]], cross(vertices[t[1]], vertices[t[2]])) / 6.0;
  }
  const double scale = D == 2 ? size * size : size * size * size;
  if (!(std::abs(volume) > 1e-12 * scale)) throw Error("encloses no volume (its faces cancel out)");
  if (volume < 0)
    for (auto& t : faces) std::swap(t[0], t[1]);
  ObstacleShape<D> s;
  s.field = std::make_shared<const ShapeField<D>>(vertices, faces);
  s.vertices = std::move(vertices);
  s.faces = std::move(faces);
  s.inverted = inverted;
  s.source = std::move(source);
  return s;
}

ObstacleShape<2> polygon_shape(std::vector<Vec<2, double>> vertices, bool inverted) {
  const std::size_t n = vertices.size();
  if (n < 3) throw Error(fmt::format("has {} vertices; a polygon needs at least 3", n));
  if (n > 100'000) throw Error(fmt::format("has {} vertices; at most 100000 are supported", n));
  for (std::size_t i = 0; i < n; ++i)
    if (vertices[i] == vertices[(i + 1) % n])
      throw Error(fmt::format("vertices {} and {} are the same point; remove one", i, (i + 1) % n));
  // Edges that cross (each pair that does not share a vertex): a grid would be faster, but
  // polygons typed into a scene are small.
  const auto orient = [](const V2& a, const V2& b, const V2& c) { return cross2(b - a, c - a); };
  const auto on_segment = [](const V2& a, const V2& b, const V2& p) {
    return std::min(a[0], b[0]) <= p[0] && p[0] <= std::max(a[0], b[0]) && std::min(a[1], b[1]) <= p[1] &&
           p[1] <= std::max(a[1], b[1]);
  };
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j) {
      const V2 &a = vertices[i], &b = vertices[(i + 1) % n], &c = vertices[j], &d = vertices[(j + 1) % n];
      const bool adjacent = j == i + 1 || (i == 0 && j == n - 1);
      const double o1 = orient(a, b, c), o2 = orient(a, b, d), o3 = orient(c, d, a), o4 = orient(c, d, b);
      bool cross = ((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) && ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0));
      if (!adjacent)
        cross = cross || (o1 == 0 && on_segment(a, b, c)) || (o2 == 0 && on_segment(a, b, d)) ||
                (o3 == 0 && on_segment(c, d, a)) || (o4 == 0 && on_segment(c, d, b));
      else  // adjacent edges meet at their shared vertex only, unless they fold back on each other
        cross = o1 == 0 && o2 == 0 && o3 == 0 && o4 == 0 && dot(b - a, d - c) < 0;
      if (cross)
        throw Error(
            fmt::format("edges {} (vertices {} to {}) and {} (vertices {} to {}) cross; a polygon obstacle "
                        "must be simple (its edges meet only at shared vertices)",
                        i, i, (i + 1) % n, j, j, (j + 1) % n));
    }
  std::vector<std::array<std::uint32_t, 2>> edges(n);
  for (std::size_t i = 0; i < n; ++i)
    edges[i] = {static_cast<std::uint32_t>(i), static_cast<std::uint32_t>((i + 1) % n)};
  // make_shape turns the edges outwards by swapping each edge's ends; a polygon keeps its vertex
  // order instead (counter-clockwise), so that its edges stay in order around it.
  double area = 0;
  for (std::size_t i = 0; i < n; ++i) area += cross2(vertices[i], vertices[(i + 1) % n]);
  if (area < 0) std::reverse(vertices.begin(), vertices.end());
  return make_shape<2>(std::move(vertices), std::move(edges), inverted);
}

template class ShapeField<2>;
template class ShapeField<3>;
template struct ObstacleShape<2>;
template struct ObstacleShape<3>;
template Box<2> shape_bounds<2>(const ObstacleShape<2>&);
template Box<3> shape_bounds<3>(const ObstacleShape<3>&);
template ObstacleShape<2> make_shape<2>(std::vector<Vec<2, double>>, std::vector<std::array<std::uint32_t, 2>>, bool,
                                        MeshSource);
template ObstacleShape<3> make_shape<3>(std::vector<Vec<3, double>>, std::vector<std::array<std::uint32_t, 2 + 1>>,
                                        bool, MeshSource);

}  // namespace sph
