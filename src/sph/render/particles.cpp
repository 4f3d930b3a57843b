#include <sph/render/particles.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include <fmt/format.h>

#include <sph/core/error.h>

namespace sph {

namespace {

using Vec3 = std::array<double, 3>;

constexpr Rgb kBoxColor{150, 150, 150};
constexpr Rgb kDefaultParticle{0, 114, 178};

double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/// Unit vector towards the light in camera space (x right, y up, z towards the viewer):
/// from the upper left, somewhat in front.
const Vec3 kLight = [] {
  const Vec3 l{-1.0, 1.0, 1.4};
  const double n = std::sqrt(dot(l, l));
  return Vec3{l[0] / n, l[1] / n, l[2] / n};
}();
constexpr double kAmbient = 0.32;
constexpr double kDiffuse = 0.78;

std::uint8_t channel(float v) { return static_cast<std::uint8_t>(std::min(v + 0.5f, 255.0f)); }

/// A sphere-shaded disc: per pixel the sphere normal under the pixel center gives a Lambert term;
/// the rim is anti-aliased by coverage. This is the hot loop of render_particles.
void shaded_disc(Image& img, double cx, double cy, double r, Rgb c) {
  const double reach = r + 0.5;
  const int ya = detail::floor_clamped(cy - reach, 0, img.height());
  const int yb = detail::ceil_clamped(cy + reach, -1, img.height() - 1);
  const float inv_r = static_cast<float>(1.0 / r);
  const float inner2 = static_cast<float>(std::max(0.0, r - 0.5) * std::max(0.0, r - 0.5));  // full coverage
  const float lx = static_cast<float>(kLight[0]), ly = static_cast<float>(kLight[1]),
              lz = static_cast<float>(kLight[2]);
  const float cr = c.r, cg = c.g, cb = c.b;
  for (int y = ya; y <= yb; ++y) {
    const double ey = y + 0.5 - cy;
    if (std::abs(ey) >= reach) continue;
    const double w = std::sqrt(reach * reach - ey * ey);
    const int xa = detail::floor_clamped(cx - w, 0, img.width());
    const int xb = detail::ceil_clamped(cx + w, -1, img.width() - 1);
    const std::span<Rgb> row = img.row(y);
    const float fy = static_cast<float>(ey);
    const float ny = -fy * inv_r;
    for (int x = xa; x <= xb; ++x) {
      const float fx = static_cast<float>(x + 0.5 - cx);
      const float d2 = fx * fx + fy * fy;
      float nx = fx * inv_r, nyy = ny;
      const float rho2 = nx * nx + nyy * nyy;
      float nz = 0.0f;
      if (rho2 < 1.0f) {
        nz = std::sqrt(1.0f - rho2);
      } else {
        const float k = 1.0f / std::sqrt(rho2);
        nx *= k;
        nyy *= k;
      }
      const float shade =
          static_cast<float>(kAmbient) + static_cast<float>(kDiffuse) * std::max(0.0f, nx * lx + nyy * ly + nz * lz);
      const Rgb s{channel(cr * shade), channel(cg * shade), channel(cb * shade)};
      if (d2 <= inner2) {
        row[x] = s;
      } else {
        const double coverage = reach - std::sqrt(static_cast<double>(d2));
        if (coverage > 0.0) row[x] = mix(row[x], s, coverage);
      }
    }
  }
}

struct Drawn {
  double x, y, depth;
  std::size_t index;
};

/// Unit vector towards the light that shades the faces of solids, in camera space: mostly from
/// above, so that a box's top, its side turned to the light and its other side come out in three
/// distinct tones at the usual cameras (the particles' light would give the top and the front
/// nearly the same tone).
const Vec3 kFaceLight = [] {
  const Vec3 l{-0.35, 0.85, 0.4};
  const double n = std::sqrt(dot(l, l));
  return Vec3{l[0] / n, l[1] / n, l[2] / n};
}();
constexpr double kFaceAmbient = 0.55;  // kSolidColor * 0.55 is still lighter than kSolidEdgeColor
constexpr double kFaceDiffuse = 0.45;

/// A face of a solid in pixel coordinates: a convex quadrilateral (corners in order around it)
/// with its depth, affine over the face: depth(x, y) = w0 + gx (x - q[0].x) + gy (y - q[0].y).
struct Face {
  std::array<std::array<double, 2>, 4> q{};
  int n = 4;            // corners: 4, or 3 (a mesh's triangle)
  bool outline = true;  // the outline along its sides (a box's faces; not a mesh's triangles)
  double w0 = 0, gx = 0, gy = 0;
  Rgb color;
};

/// Pixel bounds of what fill_face painted: [x0, x1] x [y0, y1] (empty while x0 > x1).
struct PixelBounds {
  int x0 = 1 << 30, y0 = 1 << 30, x1 = -1, y1 = -1;
};

/// Paints the pixels whose centers lie inside the face: kSolidEdgeColor within `edge` pixels of
/// its sides (the outline stays inside the face, so it is hidden exactly as the face is),
/// f.color elsewhere. With `depth` (3D, one value per pixel, larger nearer): only where the face
/// is nearer than `depth` holds, which it then updates. A face of no area paints nothing.
void fill_face(Image& img, const Face& f, double edge, std::vector<float>* depth, PixelBounds& painted) {
  double area2 = 0;  // twice the signed area: its sign tells which side of each edge is inside
  for (int k = 0; k < f.n; ++k) {
    const auto& a = f.q[k];
    const auto& b = f.q[(k + 1) % f.n];
    area2 += a[0] * b[1] - a[1] * b[0];
  }
  if (!(std::abs(area2) > 1e-9)) return;
  // Inward unit normals of the sides (nx, ny) and offsets: distance = nx x + ny y - off.
  std::array<std::array<double, 3>, 4> side{};
  for (int k = 0; k < f.n; ++k) {
    const auto& a = f.q[k];
    const auto& b = f.q[(k + 1) % f.n];
    const double ex = b[0] - a[0], ey = b[1] - a[1], len = std::hypot(ex, ey);
    if (!(len > 0)) return;
    const double sign = area2 > 0 ? 1.0 : -1.0;
    const double nx = -ey * sign / len, ny = ex * sign / len;
    side[k] = {nx, ny, nx * a[0] + ny * a[1]};
  }
  double lo_x = f.q[0][0], hi_x = lo_x, lo_y = f.q[0][1], hi_y = lo_y;
  for (int k = 0; k < f.n; ++k) {
    const auto& c = f.q[k];
    lo_x = std::min(lo_x, c[0]);
    hi_x = std::max(hi_x, c[0]);
    lo_y = std::min(lo_y, c[1]);
    hi_y = std::max(hi_y, c[1]);
  }
  const int xa = detail::floor_clamped(lo_x, 0, img.width()), xb = detail::ceil_clamped(hi_x, -1, img.width() - 1);
  const int ya = detail::floor_clamped(lo_y, 0, img.height()), yb = detail::ceil_clamped(hi_y, -1, img.height() - 1);
  for (int y = ya; y <= yb; ++y) {
    const double py = y + 0.5;
    const std::span<Rgb> row = img.row(y);
    for (int x = xa; x <= xb; ++x) {
      const double px = x + 0.5;
      double inside = HUGE_VAL;  // distance to the nearest side, negative outside
      for (int k = 0; k < f.n; ++k) inside = std::min(inside, side[k][0] * px + side[k][1] * py - side[k][2]);
      if (inside < 0.0) continue;
      if (depth != nullptr) {
        const float w = static_cast<float>(f.w0 + f.gx * (px - f.q[0][0]) + f.gy * (py - f.q[0][1]));
        float& held = (*depth)[static_cast<std::size_t>(y) * img.width() + x];
        if (!(w > held)) continue;
        held = w;
      }
      row[x] = f.outline && inside < edge ? kSolidEdgeColor : f.color;
      painted.x0 = std::min(painted.x0, x);
      painted.x1 = std::max(painted.x1, x);
      painted.y0 = std::min(painted.y0, y);
      painted.y1 = std::max(painted.y1, y);
    }
  }
}

/// Sets the face's depth plane (w0, gx, gy) from the depths `w` of its corners 0, 1 and `other`
/// (the sides q0 -> q1 and q0 -> q_other); false, leaving it, if those sides are parallel.
bool set_depth_plane(Face& f, const std::array<double, 4>& w, int other) {
  const double ax = f.q[1][0] - f.q[0][0], ay = f.q[1][1] - f.q[0][1];
  const double bx = f.q[other][0] - f.q[0][0], by = f.q[other][1] - f.q[0][1];
  const double det = ax * by - ay * bx;
  if (!(std::abs(det) > 1e-12)) return false;
  f.w0 = w[0];
  f.gx = ((w[1] - w[0]) * by - (w[other] - w[0]) * ay) / det;
  f.gy = ((w[other] - w[0]) * ax - (w[1] - w[0]) * bx) / det;
  return true;
}

/// The outline width of solids, in pixels: about 1.5 at 800 x 600, wider in larger images.
double solid_edge_width(const Image& img) { return 0.75 + std::min(img.width(), img.height()) / 800.0; }

/// The faces of a solid box turned to the camera, flat-shaded by facing: one quadrilateral in 2D
/// (the placed rectangle), up to three faces in 3D. Corners are placed by the box's pose, and a
/// face is turned to the camera by its rotated normal R e_a.
std::vector<Face> solid_faces(const SolidBox& box, int dim, const ParticleCamera& cam) {
  std::vector<Face> faces;
  if (dim == 3 && !box.vertices.empty()) {
    // A mesh: its triangles turned to the camera (away from it when inverted), flat-shaded.
    const auto& axes = cam.axes();
    for (const auto& t : box.triangles) {
      Vec3 p[3];
      for (int k = 0; k < 3; ++k) p[k] = box.place(box.vertices[t[static_cast<std::size_t>(k)]], 3);
      const Vec3 u{p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]};
      const Vec3 v{p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
      Vec3 normal{u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
      const double length = std::sqrt(dot(normal, normal));
      if (!(length > 0)) continue;
      const double sign = box.inverted ? -1.0 : 1.0;
      for (double& c : normal) c *= sign / length;
      const Vec3 n_cam{dot(normal, axes[0]), dot(normal, axes[1]), dot(normal, axes[2])};
      if (!(n_cam[2] > 1e-9)) continue;
      Face f;
      f.n = 3;
      f.outline = false;
      std::array<double, 4> w{};
      for (int k = 0; k < 3; ++k) {
        const Vec3 s = cam.project(p[k]);
        f.q[k] = {s[0], s[1]};
        w[k] = s[2];
      }
      if (!set_depth_plane(f, w, 2)) continue;
      f.color = scaled(kSolidColor, kFaceAmbient + kFaceDiffuse * std::max(0.0, dot(n_cam, kFaceLight)));
      faces.push_back(f);
    }
    return faces;
  }
  if (dim == 2) {
    Face f;
    const Vec3 corners[4] = {
        {box.lo[0], box.lo[1], 0}, {box.hi[0], box.lo[1], 0}, {box.hi[0], box.hi[1], 0}, {box.lo[0], box.hi[1], 0}};
    for (int k = 0; k < 4; ++k) {
      const Vec3 s = cam.project(box.place(corners[k], 2));
      f.q[k] = {s[0], s[1]};
    }
    f.color = kSolidColor;
    faces.push_back(f);
    return faces;
  }
  const auto& axes = cam.axes();
  for (int a = 0; a < 3; ++a) {
    const Vec3 normal = box.axis(a, 3);  // of the face on the hi side; the lo side's is its opposite
    const Vec3 n_cam{dot(normal, axes[0]), dot(normal, axes[1]), dot(normal, axes[2])};
    for (int side = 0; side < 2; ++side) {
      const double sign = side ? 1.0 : -1.0;
      if (!(sign * n_cam[2] > 1e-9)) continue;  // turned away from the camera, or edge-on
      const int b = (a + 1) % 3, c = (a + 2) % 3;
      Face f;
      std::array<double, 4> w{};
      for (int k = 0; k < 4; ++k) {
        Vec3 p{};
        p[a] = side ? box.hi[a] : box.lo[a];
        p[b] = k == 1 || k == 2 ? box.hi[b] : box.lo[b];
        p[c] = k >= 2 ? box.hi[c] : box.lo[c];
        const Vec3 s = cam.project(box.place(p, 3));
        f.q[k] = {s[0], s[1]};
        w[k] = s[2];
      }
      // Depth gradient from the sides q0 -> q1 and q0 -> q3 (a parallelogram: orthographic).
      if (!set_depth_plane(f, w, 3)) continue;
      const Vec3 face_n{sign * n_cam[0], sign * n_cam[1], sign * n_cam[2]};
      f.color = scaled(kSolidColor, kFaceAmbient + kFaceDiffuse * std::max(0.0, dot(face_n, kFaceLight)));
      faces.push_back(f);
    }
  }
  return faces;
}

/// The placed polygon `s` (2D) cut to the container [lo, hi] (Sutherland-Hodgman against its four
/// sides): the simulation drops the part past the walls, and so does the picture.
std::vector<Vec3> polygon_in_box(const SolidBox& s, const Vec3& lo, const Vec3& hi) {
  std::vector<Vec3> poly;
  for (const auto& v : s.vertices) poly.push_back(s.place(v, 2));
  for (int side = 0; side < 4 && !poly.empty(); ++side) {
    const int a = side / 2;
    const bool upper = side % 2 == 1;
    const double bound = upper ? hi[a] : lo[a];
    const auto inside = [&](const Vec3& p) { return upper ? p[a] <= bound : p[a] >= bound; };
    std::vector<Vec3> out;
    for (std::size_t k = 0; k < poly.size(); ++k) {
      const Vec3& p = poly[k];
      const Vec3& q = poly[(k + 1) % poly.size()];
      if (inside(p)) out.push_back(p);
      if (inside(p) != inside(q)) {
        const double t = (bound - p[a]) / (q[a] - p[a]);
        Vec3 x{};
        for (int b = 0; b < 3; ++b) x[b] = p[b] + t * (q[b] - p[b]);
        x[a] = bound;
        out.push_back(x);
      }
    }
    poly = std::move(out);
  }
  return poly;
}

/// A 2D polygon solid, cut to the container [lo, hi]: filled with kSolidColor (pixels whose
/// centers it holds, by the even-odd rule), unless it is inverted, and outlined in kSolidEdgeColor.
void draw_polygon(Image& img, const SolidBox& s, const ParticleCamera& cam, const Vec3& lo, const Vec3& hi) {
  std::vector<std::array<double, 2>> q;
  for (const Vec3& x : polygon_in_box(s, lo, hi)) {
    const Vec3 p = cam.project(x);
    q.push_back({p[0], p[1]});
  }
  const std::size_t n = q.size();
  if (n < 3) return;  // wholly past the walls
  if (!s.inverted) {
    double lo_y = q[0][1], hi_y = lo_y;
    for (const auto& c : q) lo_y = std::min(lo_y, c[1]), hi_y = std::max(hi_y, c[1]);
    const int ya = detail::floor_clamped(lo_y, 0, img.height()), yb = detail::ceil_clamped(hi_y, -1, img.height() - 1);
    std::vector<double> xs;
    for (int y = ya; y <= yb; ++y) {
      const double py = y + 0.5;
      xs.clear();
      for (std::size_t k = 0; k < n; ++k) {
        const auto& a = q[k];
        const auto& b = q[(k + 1) % n];
        if ((a[1] <= py) != (b[1] <= py)) xs.push_back(a[0] + (py - a[1]) / (b[1] - a[1]) * (b[0] - a[0]));
      }
      std::sort(xs.begin(), xs.end());
      for (std::size_t k = 0; k + 1 < xs.size(); k += 2) {
        const int xa = detail::floor_clamped(xs[k] - 0.5, -1, img.width() - 1) + 1;
        const int xb = detail::ceil_clamped(xs[k + 1] - 0.5, 0, img.width()) - 1;
        for (int x = std::max(xa, 0); x <= std::min(xb, img.width() - 1); ++x) img.set(x, y, kSolidColor);
      }
    }
  }
  for (std::size_t k = 0; k < n; ++k)
    img.draw_line(q[k][0], q[k][1], q[(k + 1) % n][0], q[(k + 1) % n][1], kSolidEdgeColor, solid_edge_width(img));
}

/// Throws sph::Error for a solid with non-finite corners or placement, or lo > hi.
void check_solids(std::span<const SolidBox> solids, int dim) {
  for (std::size_t k = 0; k < solids.size(); ++k) {
    const SolidBox& s = solids[k];
    for (int a = 0; a < dim; ++a)
      if (!std::isfinite(s.lo[a]) || !std::isfinite(s.hi[a]) || s.lo[a] > s.hi[a])
        throw Error(fmt::format("obstacle {} must have finite corners with lo <= hi (axis {}: {} .. {})", k + 1,
                                "xyz"[a], s.lo[a], s.hi[a]));
    const auto finite = [](double v) { return std::isfinite(v); };
    if (!std::all_of(s.rotation.begin(), s.rotation.end(), finite) ||
        !std::all_of(s.center.begin(), s.center.end(), finite) ||
        !std::all_of(s.translation.begin(), s.translation.end(), finite))
      throw Error(fmt::format("obstacle {} must have a finite placement (rotation, center and translation)", k + 1));
  }
}

/// A projected edge of the container box; `front` if it bounds a face turned to the camera (always in 2D).
struct BoxEdge {
  std::array<double, 3> p0, p1;
  bool front;
};

/// The container box's edges: corners k and k ^ (1 << a) differ along axis a.
std::vector<BoxEdge> box_edges(const ParticleCamera& cam, int dim, const Vec3& box_lo, const Vec3& box_hi) {
  std::vector<BoxEdge> edges;
  const int corners = dim == 3 ? 8 : 4;
  auto corner = [&](int k) {
    Vec3 p{};
    for (int a = 0; a < dim; ++a) p[a] = (k >> a) & 1 ? box_hi[a] : box_lo[a];
    return p;
  };
  for (int k = 0; k < corners; ++k)
    for (int a = 0; a < dim; ++a) {
      const int j = k ^ (1 << a);
      if (j < k) continue;
      bool front = true;  // 2D: the outline goes over the particles
      if (dim == 3) {
        // The edge bounds the two faces normal to the other two axes, on the corner's sides;
        // it is in front if either face turns towards the camera.
        front = false;
        for (int b = 0; b < 3; ++b) {
          if (b == a) continue;
          const double sign = (k >> b) & 1 ? 1.0 : -1.0;
          if (sign * cam.axes()[2][b] > 1e-9) front = true;
        }
      }
      edges.push_back({cam.project(corner(k)), cam.project(corner(j)), front});
    }
  return edges;
}

}  // namespace

bool SolidBox::axis_aligned() const {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      if (rotation[static_cast<std::size_t>(3 * r + c)] != (r == c ? 1.0 : 0.0)) return false;
  return true;
}

Vec3 SolidBox::place(const Vec3& p, int dim) const {
  Vec3 x = p;
  if (axis_aligned()) {  // p + t exactly: an obstacle at rest is drawn as it was before poses existed
    for (int a = 0; a < dim; ++a) x[a] = p[a] + translation[a];
    return x;
  }
  for (int a = 0; a < dim; ++a) {
    double r = 0;
    for (int b = 0; b < dim; ++b) r += rotation[static_cast<std::size_t>(3 * a + b)] * (p[b] - center[b]);
    x[a] = center[a] + translation[a] + r;
  }
  return x;
}

Vec3 SolidBox::axis(int a, int dim) const {
  Vec3 v{};
  for (int r = 0; r < dim; ++r) v[r] = rotation[static_cast<std::size_t>(3 * r + a)];
  return v;
}

ParticleView default_particle_view(int dim, int width, int height) {
  ParticleView v;
  v.width = width;
  v.height = height;
  if (dim == 3) {
    v.azimuth_deg = 30.0;
    v.elevation_deg = 20.0;
  }
  return v;
}

ParticleCamera::ParticleCamera(int dim, const Vec3& box_lo, const Vec3& box_hi, double radius, const ParticleView& view)
    : dim_(dim) {
  SPH_CHECK(dim == 2 || dim == 3, "dimension must be 2 or 3");
  if (view.width < 1 || view.height < 1 || view.width > 16384 || view.height > 16384)
    throw Error(fmt::format("image size {} x {} is out of range (1 to 16384 pixels a side)", view.width, view.height));
  if (!std::isfinite(view.azimuth_deg) || !std::isfinite(view.elevation_deg))
    throw Error("camera angles must be finite numbers");
  if (!std::isfinite(radius) || radius < 0.0)
    throw Error(fmt::format("particle radius must be a finite number >= 0 (got {})", radius));
  for (int a = 0; a < dim; ++a)
    if (!std::isfinite(box_lo[a]) || !std::isfinite(box_hi[a]) || box_lo[a] > box_hi[a])
      throw Error(fmt::format("the box must have finite corners with lo <= hi (axis {}: {} .. {})", "xyz"[a], box_lo[a],
                              box_hi[a]));

  if (dim == 3) {
    const double az = view.azimuth_deg * std::numbers::pi / 180.0;
    const double el = view.elevation_deg * std::numbers::pi / 180.0;
    axes_[0] = {std::cos(az), 0.0, -std::sin(az)};                                          // right
    axes_[1] = {-std::sin(az) * std::sin(el), std::cos(el), -std::cos(az) * std::sin(el)};  // up
    axes_[2] = {std::sin(az) * std::cos(el), std::sin(el), std::cos(az) * std::cos(el)};    // to viewer
  } else {
    axes_ = {{{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}}};
  }
  for (int a = 0; a < 3; ++a) center_[a] = a < dim ? 0.5 * (box_lo[a] + box_hi[a]) : 0.0;

  // Screen-space extent of the box corners, grown by the radius.
  double ux = 0.0, uy = 0.0;  // half extents
  const int corners = dim == 3 ? 8 : 4;
  for (int k = 0; k < corners; ++k) {
    Vec3 p{};
    for (int a = 0; a < dim; ++a) p[a] = ((k >> a) & 1 ? box_hi[a] : box_lo[a]) - center_[a];
    ux = std::max(ux, std::abs(dot(p, axes_[0])));
    uy = std::max(uy, std::abs(dot(p, axes_[1])));
  }
  ux += radius;
  uy += radius;
  if (ux <= 0.0 && uy <= 0.0) ux = uy = 1.0;  // a point: any scale will do
  const double margin = std::max(2.0, 0.04 * std::min(view.width, view.height));
  const double avail_x = std::max(1.0, view.width - 2.0 * margin), avail_y = std::max(1.0, view.height - 2.0 * margin);
  scale_ = std::min(ux > 0.0 ? avail_x / (2.0 * ux) : HUGE_VAL, uy > 0.0 ? avail_y / (2.0 * uy) : HUGE_VAL);
  cx_ = 0.5 * view.width;
  cy_ = 0.5 * view.height;
}

std::array<double, 3> ParticleCamera::project(const Vec3& p) const {
  Vec3 q{p[0] - center_[0], p[1] - center_[1], dim_ == 3 ? p[2] - center_[2] : 0.0};
  return {cx_ + dot(q, axes_[0]) * scale_, cy_ - dot(q, axes_[1]) * scale_, dim_ == 3 ? dot(q, axes_[2]) : 0.0};
}

Image render_particles(std::span<const double> xyz, int dim, std::span<const Rgb> colors, double radius,
                       const Vec3& box_lo, const Vec3& box_hi, const ParticleView& view,
                       std::span<const SolidBox> solids) {
  SPH_CHECK(dim == 2 || dim == 3, "dimension must be 2 or 3");
  SPH_CHECK(xyz.size() % static_cast<std::size_t>(dim) == 0, "xyz must hold dim coordinates per particle");
  const std::size_t n = xyz.size() / static_cast<std::size_t>(dim);
  SPH_CHECK(colors.size() <= 1 || colors.size() == n, "colors must hold 0, 1 or one color per particle");
  const ParticleCamera cam(dim, box_lo, box_hi, radius, view);
  check_solids(solids, dim);
  Image img(view.width, view.height, view.background);

  const std::vector<BoxEdge> edges = box_edges(cam, dim, box_lo, box_hi);
  auto draw_edges = [&](bool front) {
    for (const BoxEdge& e : edges)
      if (e.front == front) img.draw_line(e.p0[0], e.p0[1], e.p1[0], e.p1[1], kBoxColor, 1.0);
  };
  draw_edges(false);

  // 3D solids go under the particles, behind the nearer ones: their faces are painted now, per
  // pixel nearest first (solid_depth), and after each particle the pixels where a face is nearer
  // than the particle's center get the face back (`layer`). Painting far to near, every earlier
  // particle at such a pixel was behind the face too, so this is exact per pixel. The particle's
  // center depth suffices: a sphere touching a face from outside is in front of the face's plane
  // over its whole disc, so only particles that reach into a solid lose pixels.
  std::vector<float> solid_depth;
  Image layer;
  PixelBounds solid_pixels;
  if (dim == 3 && !solids.empty()) {
    solid_depth.assign(static_cast<std::size_t>(img.width()) * img.height(), -HUGE_VALF);
    for (const SolidBox& s : solids)
      for (const Face& f : solid_faces(s, dim, cam))
        fill_face(img, f, solid_edge_width(img), &solid_depth, solid_pixels);
    layer = img;
  }
  const auto hidden_by_solid = [&](int x, int y, double depth) {
    return solid_depth[static_cast<std::size_t>(y) * img.width() + x] > static_cast<float>(depth);
  };
  const auto restore_solids = [&](double cx, double cy, double r, double depth) {
    const double reach = r + 0.5;
    const int xa = std::max(detail::floor_clamped(cx - reach, 0, img.width()), solid_pixels.x0);
    const int xb = std::min(detail::ceil_clamped(cx + reach, -1, img.width() - 1), solid_pixels.x1);
    const int ya = std::max(detail::floor_clamped(cy - reach, 0, img.height()), solid_pixels.y0);
    const int yb = std::min(detail::ceil_clamped(cy + reach, -1, img.height() - 1), solid_pixels.y1);
    for (int y = ya; y <= yb; ++y)
      for (int x = xa; x <= xb; ++x)
        if (hidden_by_solid(x, y, depth)) img.set(x, y, layer.at(x, y));
  };

  // Project, skip non-finite positions, order far to near (3D).
  std::vector<Drawn> drawn;
  drawn.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    Vec3 p{};
    bool finite = true;
    for (int a = 0; a < dim; ++a) {
      p[a] = xyz[i * dim + a];
      finite = finite && std::isfinite(p[a]);
    }
    if (!finite) continue;
    const auto s = cam.project(p);
    drawn.push_back({s[0], s[1], s[2], i});
  }
  if (dim == 3)
    std::sort(drawn.begin(), drawn.end(), [](const Drawn& a, const Drawn& b) {
      return a.depth != b.depth ? a.depth < b.depth : a.index < b.index;
    });

  const double r = radius * cam.pixels_per_unit();
  for (const Drawn& d : drawn) {
    const Rgb c = colors.empty() ? kDefaultParticle : colors.size() == 1 ? colors[0] : colors[d.index];
    if (r < 1.0) {  // smaller than a pixel: still one whole pixel, shaded as a sphere's center
      const int px = detail::floor_clamped(d.x, -1, img.width()), py = detail::floor_clamped(d.y, -1, img.height());
      if (!solid_depth.empty() && img.contains(px, py) && hidden_by_solid(px, py, d.depth)) continue;
      img.set(px, py, view.shaded ? scaled(c, kAmbient + kDiffuse * kLight[2]) : c);
      continue;
    }
    if (view.shaded)
      shaded_disc(img, d.x, d.y, r, c);
    else
      img.fill_disc(d.x, d.y, r, c);
    if (!solid_depth.empty()) restore_solids(d.x, d.y, r, d.depth);
  }

  draw_edges(true);
  // 2D solids go over the particles and the container outline: in a healthy run no particle is
  // inside one, so this hides nothing but the rims of particles pressed into a soft wall, and the
  // obstacle keeps its true shape however the fluid leaks or penetrates (the run's health
  // monitor, not the picture, is what reports a leak).
  if (dim == 2) {
    PixelBounds painted;
    for (const SolidBox& s : solids) {
      if (!s.vertices.empty()) {
        draw_polygon(img, s, cam, box_lo, box_hi);
        continue;
      }
      for (const Face& f : solid_faces(s, dim, cam)) fill_face(img, f, solid_edge_width(img), nullptr, painted);
    }
  }
  return img;
}

namespace {

constexpr Rgb kWater{70, 130, 200};
constexpr Rgb kFloorColor{222, 222, 222};

Vec3 unit(const Vec3& v) {
  const double n = std::sqrt(dot(v, v));
  return {v[0] / n, v[1] / n, v[2] / n};
}

/// The surface's lights in camera space (x right, y up, z towards the viewer): a key light from
/// the upper left in front, and a weaker fill from the right so that the side turned away from
/// the key still shows its shape instead of a flat ambient tone.
const Vec3 kKeyLight = unit({-0.8, 1.0, 1.0});
const Vec3 kFillLight = unit({1.0, 0.2, 0.6});
/// Half vector of the key light and the viewing direction (+z), for the highlight.
const Vec3 kKeyHalf = unit({kKeyLight[0], kKeyLight[1], kKeyLight[2] + 1.0});
constexpr double kSurfaceAmbient = 0.30, kKeyDiffuse = 0.62, kFillDiffuse = 0.22, kSpecular = 0.35;

/// The shaded water color for a camera-space normal.
Rgb water_shade(Vec3 n) {
  const double len = std::sqrt(dot(n, n));
  if (!(len > 0)) return scaled(kWater, kSurfaceAmbient);
  n = {n[0] / len, n[1] / len, n[2] / len};
  const double diffuse = kSurfaceAmbient + kKeyDiffuse * std::max(0.0, dot(n, kKeyLight)) +
                         kFillDiffuse * std::max(0.0, dot(n, kFillLight));
  const double spec = kSpecular * std::pow(std::max(0.0, dot(n, kKeyHalf)), 48.0) * 255.0;
  auto ch = [&](std::uint8_t c) { return static_cast<std::uint8_t>(std::clamp(c * diffuse + spec + 0.5, 0.0, 255.0)); };
  return {ch(kWater.r), ch(kWater.g), ch(kWater.b)};
}

}  // namespace

Image render_surface(const SurfaceMesh& mesh, double radius, const Vec3& box_lo, const Vec3& box_hi,
                     const ParticleView& view, std::span<const SolidBox> solids) {
  SPH_CHECK(mesh.dimension == 3, "render_surface draws 3D surfaces");
  SPH_CHECK(mesh.normals.size() == mesh.vertices.size(), "one normal per vertex");
  const ParticleCamera cam(3, box_lo, box_hi, radius, view);
  check_solids(solids, 3);
  Image img(view.width, view.height, view.background);
  const std::vector<BoxEdge> edges = box_edges(cam, 3, box_lo, box_hi);
  for (const BoxEdge& e : edges)
    if (!e.front) img.draw_line(e.p0[0], e.p0[1], e.p1[0], e.p1[1], kBoxColor, 1.0);

  std::vector<float> depth(static_cast<std::size_t>(img.width()) * img.height(), -HUGE_VALF);
  PixelBounds painted;
  // The floor: the box's bottom face, depth-tested like a solid's face so that the fluid on it
  // (and the obstacles standing on it) cover it where they are nearer.
  {
    Face f;
    const Vec3 corners[4] = {{box_lo[0], box_lo[1], box_lo[2]},
                             {box_hi[0], box_lo[1], box_lo[2]},
                             {box_hi[0], box_lo[1], box_hi[2]},
                             {box_lo[0], box_lo[1], box_hi[2]}};
    std::array<double, 4> w{};
    for (int k = 0; k < 4; ++k) {
      const Vec3 s = cam.project(corners[k]);
      f.q[k] = {s[0], s[1]};
      w[k] = s[2];
    }
    const double ax = f.q[1][0] - f.q[0][0], ay = f.q[1][1] - f.q[0][1];
    const double bx = f.q[3][0] - f.q[0][0], by = f.q[3][1] - f.q[0][1];
    const double det = ax * by - ay * bx;
    if (std::abs(det) > 1e-12) {  // edge-on at elevation 0: nothing to fill
      f.w0 = w[0];
      f.gx = ((w[1] - w[0]) * by - (w[3] - w[0]) * ay) / det;
      f.gy = ((w[3] - w[0]) * ax - (w[1] - w[0]) * bx) / det;
      f.color = kFloorColor;
      fill_face(img, f, 0.0, &depth, painted);
    }
  }
  for (const SolidBox& s : solids)
    for (const Face& f : solid_faces(s, 3, cam)) fill_face(img, f, solid_edge_width(img), &depth, painted);

  // Vertices in pixel coordinates and normals in camera space, once each.
  const auto& axes = cam.axes();
  std::vector<Vec3> screen(mesh.vertices.size()), normal(mesh.vertices.size());
  std::vector<char> finite(mesh.vertices.size());
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const auto& v = mesh.vertices[i];
    const auto& nw = mesh.normals[i];
    finite[i] = std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
    if (!finite[i]) continue;
    screen[i] = cam.project({v[0], v[1], v[2]});
    const Vec3 n{nw[0], nw[1], nw[2]};
    normal[i] = {dot(n, axes[0]), dot(n, axes[1]), dot(n, axes[2])};
  }
  for (const auto& t : mesh.triangles) {
    if (!finite[t[0]] || !finite[t[1]] || !finite[t[2]]) continue;
    const Vec3 &a = screen[t[0]], &b = screen[t[1]], &c = screen[t[2]];
    const double area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    if (!(std::abs(area) > 1e-12)) continue;
    const int xa = detail::floor_clamped(std::min({a[0], b[0], c[0]}), 0, img.width());
    const int xb = detail::ceil_clamped(std::max({a[0], b[0], c[0]}), -1, img.width() - 1);
    const int ya = detail::floor_clamped(std::min({a[1], b[1], c[1]}), 0, img.height());
    const int yb = detail::ceil_clamped(std::max({a[1], b[1], c[1]}), -1, img.height() - 1);
    const double inv = 1.0 / area;
    for (int y = ya; y <= yb; ++y) {
      const double py = y + 0.5;
      const std::span<Rgb> row = img.row(y);
      for (int x = xa; x <= xb; ++x) {
        const double px = x + 0.5;
        // Barycentric weights of a, b, c; a pixel center on a shared edge belongs to both
        // triangles, which is harmless with the depth test (same depth, first one kept).
        const double wa = ((b[0] - px) * (c[1] - py) - (b[1] - py) * (c[0] - px)) * inv;
        const double wb = ((c[0] - px) * (a[1] - py) - (c[1] - py) * (a[0] - px)) * inv;
        const double wc = 1.0 - wa - wb;
        if (wa < 0.0 || wb < 0.0 || wc < 0.0) continue;
        const float w = static_cast<float>(wa * a[2] + wb * b[2] + wc * c[2]);
        float& held = depth[static_cast<std::size_t>(y) * img.width() + x];
        if (!(w > held)) continue;
        held = w;
        const Vec3 &na = normal[t[0]], &nb = normal[t[1]], &nc = normal[t[2]];
        row[x] = water_shade({wa * na[0] + wb * nb[0] + wc * nc[0], wa * na[1] + wb * nb[1] + wc * nc[1],
                              wa * na[2] + wb * nb[2] + wc * nc[2]});
      }
    }
  }
  for (const BoxEdge& e : edges)
    if (e.front) img.draw_line(e.p0[0], e.p0[1], e.p1[0], e.p1[1], kBoxColor, 1.0);
  return img;
}

}  // namespace sph
