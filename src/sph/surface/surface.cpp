#include <sph/surface/surface.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <string>
#include <utility>

#include <fmt/format.h>

#include <sph/core/error.h>
#include <sph/core/parallel.h>

namespace sph {

namespace {

constexpr int kBlock = 8;            // voxels per block edge
constexpr float kSnap = 1e-4f;       // a vertex closer to a voxel than this (in voxels) is put on it
constexpr int kPadded = kBlock + 1;  // a block's values and its upper neighbors' first layer
// Dense per-block arrays cost 8 bytes a block of the bounding grid; the values 4 bytes a voxel
// of the blocks near particles.
constexpr std::size_t kMaxGridBlocks = std::size_t{1} << 24;
// The radius of the sphere each particle keeps, in spacings (surface.h).
constexpr double kDropRadius = 0.4;
constexpr std::size_t kMaxActiveBlocks = std::size_t{1} << 22;  // 8 GiB of values in 3D
// The obstacles' cut reaches the voxels whose field could exceed iso + d / (2 v): those within
// 2 v (kCutCeiling - iso). c is 1 inside a body of fluid, a little more where it is compressed
// (1.3 at 30 %), and a drop's sphere at most 2 iso.
constexpr double kCutCeiling = 2;

// The Kuhn split of a cube into 6 tetrahedra around its diagonal 0 -> 7 (corner bits x = 1,
// y = 2, z = 4): each runs 0 -> one axis -> two axes -> 7, so along every tetrahedron edge the
// corner set grows, and neighboring cubes split their shared faces the same way.
constexpr int kTets[6][4] = {{0, 1, 3, 7}, {0, 3, 2, 7}, {0, 2, 6, 7}, {0, 6, 4, 7}, {0, 4, 5, 7}, {0, 5, 1, 7}};
// The square's split into two triangles around its diagonal 0 -> 3 (x = 1, y = 2).
constexpr int kTris[2][3] = {{0, 1, 3}, {0, 2, 3}};

template <int D>
constexpr int kBlockVoxels = D == 3 ? kBlock* kBlock* kBlock : kBlock* kBlock;
template <int D>
constexpr int kPaddedVoxels = D == 3 ? kPadded* kPadded* kPadded : kPadded* kPadded;

/// The grid: voxel i (per axis) sits at origin + i v; block b holds voxels [8 b, 8 b + 8).
struct Grid {
  std::array<double, 3> origin{};
  double v = 0;
  std::array<std::int64_t, 3> blocks{1, 1, 1};
  std::size_t count() const { return static_cast<std::size_t>(blocks[0] * blocks[1] * blocks[2]); }
  std::int64_t id(std::int64_t x, std::int64_t y, std::int64_t z) const { return (z * blocks[1] + y) * blocks[0] + x; }
};

/// Local voxel index within a block (coordinates 0..7) and within the padded copy (0..8).
template <int D>
int local_index(int x, int y, int z) {
  return D == 3 ? (z * kBlock + y) * kBlock + x : y * kBlock + x;
}
template <int D>
int padded_index(int x, int y, int z) {
  return D == 3 ? (z * kPadded + y) * kPadded + x : y * kPadded + x;
}

struct BlockOut {
  std::vector<std::uint16_t> keys;  // local_index(a) * 8 + direction, ascending
  std::vector<std::array<float, 3>> vertices;
  // The vertices put on a voxel (within kSnap of it): {the voxel's global index, the vertex's index
  // in `vertices`}. Several edges end there; weld() makes them one vertex.
  std::vector<std::pair<std::uint64_t, std::uint32_t>> on_voxel;
  std::vector<std::array<float, 3>> normals;  // 3D
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::vector<std::array<std::uint32_t, 2>> segments;
};

template <int D>
class Extractor {
 public:
  Extractor(std::span<const double> positions, const SurfaceSettings& s) : s_(s) {
    n_ = positions.size() / 3;
    const double spacing = s.spacing;
    grid_.v = spacing / s.resolution;
    const double radius = s.smoothing * spacing;
    rv_ = radius / grid_.v;  // support in voxels
    std::array<double, 3> lo{}, hi{};
    lo.fill(std::numeric_limits<double>::infinity());
    hi.fill(-std::numeric_limits<double>::infinity());
    for (std::size_t i = 0; i < n_; ++i)
      for (int a = 0; a < D; ++a) {
        const double x = positions[3 * i + a];
        if (!std::isfinite(x)) throw Error(fmt::format("particle {} has a non-finite position", i), "surface");
        lo[a] = std::min(lo[a], x), hi[a] = std::max(hi[a], x);
      }
    const double pad = radius + 2 * grid_.v;
    for (int a = 0; a < D; ++a) {
      grid_.origin[a] = lo[a] - pad;
      const double voxels = std::ceil((hi[a] - lo[a] + 2 * pad) / grid_.v) + 1;
      const double blocks = std::ceil(voxels / kBlock);
      if (!(blocks < 1e7))
        throw Error(fmt::format("the particles span {:.4g} spacings along {}, too far to mesh; lower --resolution or "
                                "leave out the particles that flew away",
                                (hi[a] - lo[a]) / spacing, "xyz"[a]),
                    "surface");
      grid_.blocks[a] = static_cast<std::int64_t>(blocks);
    }
    if (static_cast<double>(grid_.blocks[0]) * static_cast<double>(grid_.blocks[1]) *
            static_cast<double>(grid_.blocks[2]) >
        static_cast<double>(kMaxGridBlocks))
      throw Error(
          fmt::format("the particles span {:.4g} x {:.4g}{} spacings: a grid of {} x {}{} blocks of {} voxels, "
                      "more than the {} blocks a surface may span; lower --resolution or leave out the "
                      "particles that flew away",
                      (hi[0] - lo[0]) / spacing, (hi[1] - lo[1]) / spacing,
                      D == 3 ? fmt::format(" x {:.4g}", (hi[2] - lo[2]) / spacing) : "", grid_.blocks[0],
                      grid_.blocks[1], D == 3 ? fmt::format(" x {}", grid_.blocks[2]) : "", kBlock, kMaxGridBlocks),
          "surface");
    // Particles in voxel units, sorted by block (counting sort: within a block in index order).
    const std::size_t nb = grid_.count();
    start_.assign(nb + 1, 0);
    std::vector<std::uint32_t> cell(n_);
    for (std::size_t i = 0; i < n_; ++i) {
      std::array<std::int64_t, 3> c{0, 0, 0};
      for (int a = 0; a < D; ++a) {
        const double u = (positions[3 * i + a] - grid_.origin[a]) / grid_.v;
        c[a] = std::clamp(static_cast<std::int64_t>(u / kBlock), std::int64_t{0}, grid_.blocks[a] - 1);
      }
      cell[i] = static_cast<std::uint32_t>(grid_.id(c[0], c[1], c[2]));
      ++start_[cell[i] + 1];
    }
    for (std::size_t b = 0; b < nb; ++b) start_[b + 1] += start_[b];
    std::vector<std::uint32_t> fill(start_.begin(), start_.end() - 1);
    for (int a = 0; a < 3; ++a) u_[a].resize(n_);
    for (std::size_t i = 0; i < n_; ++i) {
      const std::uint32_t p = fill[cell[i]]++;
      for (int a = 0; a < 3; ++a)
        u_[a][p] = a < D ? static_cast<float>((positions[3 * i + a] - grid_.origin[a]) / grid_.v) : 0.0f;
    }
    // Blocks near particles: a particle reaches the voxels within R of it, and a block also needs
    // its values for the cubes it shares with its upper neighbors, so it holds values if a
    // particle lies within R of its voxels [8 b, 8 b + 8]: in a block at most ring_ away.
    ring_ = static_cast<int>(std::floor(rv_ / kBlock)) + 1;
    std::vector<std::uint8_t> near(nb, 0);
    const std::int64_t rz = D == 3 ? ring_ : 0;
    for (std::int64_t z = 0; z < grid_.blocks[2]; ++z)
      for (std::int64_t y = 0; y < grid_.blocks[1]; ++y)
        for (std::int64_t x = 0; x < grid_.blocks[0]; ++x) {
          const auto b = static_cast<std::size_t>(grid_.id(x, y, z));
          if (start_[b] == start_[b + 1]) continue;
          for (std::int64_t cz = std::max<std::int64_t>(0, z - rz); cz <= std::min(grid_.blocks[2] - 1, z + rz); ++cz)
            for (std::int64_t cy = std::max<std::int64_t>(0, y - ring_); cy <= std::min(grid_.blocks[1] - 1, y + ring_);
                 ++cy)
              for (std::int64_t cx = std::max<std::int64_t>(0, x - ring_);
                   cx <= std::min(grid_.blocks[0] - 1, x + ring_); ++cx)
                near[static_cast<std::size_t>(grid_.id(cx, cy, cz))] = 1;
        }
    slot_.assign(nb, -1);
    for (std::size_t b = 0; b < nb; ++b)
      if (near[b]) {
        slot_[b] = static_cast<std::int32_t>(active_.size());
        active_.push_back(static_cast<std::uint32_t>(b));
      }
    if (active_.size() > kMaxActiveBlocks)
      throw Error(fmt::format("the particles need {} blocks of {} voxels, more than the {} a surface may hold; lower "
                              "--resolution",
                              active_.size(), kBlock, kMaxActiveBlocks),
                  "surface");
  }

  SurfaceMesh run() {
    SurfaceMesh mesh;
    mesh.dimension = D;
    mesh.voxel_size = grid_.v;
    mesh.blocks = active_.size();
    const std::size_t na = active_.size();
    values_.assign(na * kBlockVoxels<D>, 0.0f);
    parallel_for(na, [&](std::size_t k) { sample_block(k); });
    std::vector<BlockOut> out(na);
    std::vector<std::uint8_t> surface(na, 0);
    parallel_for(na, [&](std::size_t k) { surface[k] = find_vertices(k, out[k]); });
    std::vector<std::uint32_t> base(na + 1, 0);
    for (std::size_t k = 0; k < na; ++k) {
      base[k + 1] = base[k] + static_cast<std::uint32_t>(out[k].keys.size());
      mesh.surface_blocks += surface[k];
    }
    parallel_for(na, [&](std::size_t k) {
      if (surface[k]) make_faces(k, out, base, out[k]);
    });
    mesh.vertices.reserve(base[na]);
    for (const BlockOut& b : out) mesh.vertices.insert(mesh.vertices.end(), b.vertices.begin(), b.vertices.end());
    if (s_.clip) clamp_to_container(mesh);
    if constexpr (D == 3) {
      mesh.normals.reserve(base[na]);
      for (const BlockOut& b : out) mesh.normals.insert(mesh.normals.end(), b.normals.begin(), b.normals.end());
    }
    for (const BlockOut& b : out) {
      mesh.triangles.insert(mesh.triangles.end(), b.triangles.begin(), b.triangles.end());
      mesh.segments.insert(mesh.segments.end(), b.segments.begin(), b.segments.end());
    }
    weld(out, base, mesh);
    return mesh;
  }

 private:
  /// Where the field is iso at a voxel, or within a float's rounding of iso (the walls' cut makes
  /// it so at every voxel on a wall, when the grid's planes fall on it), every edge from that
  /// voxel ends in a vertex on it or a hair from it: several vertices at one point once rounded
  /// to floats, and faces of no area between them. find_vertices puts each vertex within kSnap
  /// of a voxel on it; here those of one voxel become the first of them (in vertex order, the
  /// same for any thread count), the faces left with a repeated vertex go (a face (a, a, b) runs
  /// along (a, b) both ways, so the mesh stays closed), and so do the vertices merged away.
  /// Their normals are all the voxel's gradient.
  static void weld(const std::vector<BlockOut>& out, const std::vector<std::uint32_t>& base, SurfaceMesh& mesh) {
    std::vector<std::pair<std::uint64_t, std::uint32_t>> on;
    for (std::size_t k = 0; k < out.size(); ++k)
      for (const auto& [voxel, v] : out[k].on_voxel) on.emplace_back(voxel, base[k] + v);
    if (on.empty()) return;
    std::sort(on.begin(), on.end());
    std::vector<std::uint32_t> to(mesh.vertices.size());
    std::iota(to.begin(), to.end(), 0u);
    bool merged = false;
    for (std::size_t i = 1; i < on.size(); ++i)
      if (on[i].first == on[i - 1].first) to[on[i].second] = to[on[i - 1].second], merged = true;
    if (!merged) return;
    // New indices: the vertices that stay, in their order.
    std::vector<std::uint32_t> index(mesh.vertices.size());
    std::uint32_t kept = 0;
    for (std::size_t v = 0; v < mesh.vertices.size(); ++v)
      if (to[v] == v) {
        index[v] = kept;
        mesh.vertices[kept] = mesh.vertices[v];
        if (!mesh.normals.empty()) mesh.normals[kept] = mesh.normals[v];
        ++kept;
      }
    mesh.vertices.resize(kept);
    if (!mesh.normals.empty()) mesh.normals.resize(kept);
    const auto remap = [&](auto& faces) {
      std::size_t n = 0;
      for (auto f : faces) {
        for (auto& v : f) v = index[to[v]];
        bool repeated = false;
        for (std::size_t a = 0; a < f.size(); ++a)
          for (std::size_t b = a + 1; b < f.size(); ++b) repeated = repeated || f[a] == f[b];
        if (!repeated) faces[n++] = f;
      }
      faces.resize(n);
    };
    remap(mesh.triangles);
    remap(mesh.segments);
  }

  std::array<std::int64_t, 3> block_coords(std::uint32_t b) const {
    const auto id = static_cast<std::int64_t>(b);
    return {id % grid_.blocks[0], (id / grid_.blocks[0]) % grid_.blocks[1], id / (grid_.blocks[0] * grid_.blocks[1])};
  }

  /// The color field (with the drop spheres) at the voxels of active block k.
  void sample_block(std::size_t k) {
    const auto bc = block_coords(active_[k]);
    std::array<float, kBlockVoxels<D>> drop{};
    float* acc = values_.data() + k * kBlockVoxels<D>;
    const float r2max = static_cast<float>(rv_ * rv_);
    const float inv_r2 = 1.0f / r2max;
    const double norm = D == 3 ? 315.0 / (64.0 * std::numbers::pi) : 4.0 / std::numbers::pi;
    const auto scale = static_cast<float>(norm / std::pow(s_.smoothing, D));
    const float rd = static_cast<float>(kDropRadius * s_.resolution);  // in voxels
    const float inv_rd2 = 1.0f / (rd * rd);
    const auto iso = static_cast<float>(s_.iso);
    std::array<int, 3> lo{}, hi{};
    for (int a = 0; a < 3; ++a) lo[a] = static_cast<int>(bc[a] * kBlock), hi[a] = lo[a] + kBlock - 1;
    if constexpr (D == 2) hi[2] = lo[2] = 0;
    const std::int64_t rz = D == 3 ? ring_ : 0;
    for (std::int64_t cz = std::max<std::int64_t>(0, bc[2] - rz); cz <= std::min(grid_.blocks[2] - 1, bc[2] + rz); ++cz)
      for (std::int64_t cy = std::max<std::int64_t>(0, bc[1] - ring_);
           cy <= std::min(grid_.blocks[1] - 1, bc[1] + ring_); ++cy)
        for (std::int64_t cx = std::max<std::int64_t>(0, bc[0] - ring_);
             cx <= std::min(grid_.blocks[0] - 1, bc[0] + ring_); ++cx) {
          const auto cell = static_cast<std::size_t>(grid_.id(cx, cy, cz));
          for (std::uint32_t p = start_[cell]; p < start_[cell + 1]; ++p) {
            const float px = u_[0][p], py = u_[1][p], pz = u_[2][p];
            const float rr = static_cast<float>(rv_);
            const int z0 = D == 3 ? std::max(lo[2], static_cast<int>(std::ceil(pz - rr))) : 0;
            const int z1 = D == 3 ? std::min(hi[2], static_cast<int>(std::floor(pz + rr))) : 0;
            const int y0 = std::max(lo[1], static_cast<int>(std::ceil(py - rr)));
            const int y1 = std::min(hi[1], static_cast<int>(std::floor(py + rr)));
            for (int z = z0; z <= z1; ++z) {
              const float dz = D == 3 ? static_cast<float>(z) - pz : 0.0f;
              for (int y = y0; y <= y1; ++y) {
                const float dy = static_cast<float>(y) - py;
                const float d2 = dz * dz + dy * dy;
                if (d2 >= r2max) continue;
                const float chord = std::sqrt(r2max - d2);
                const int x0 = std::max(lo[0], static_cast<int>(std::ceil(px - chord)));
                const int x1 = std::min(hi[0], static_cast<int>(std::floor(px + chord)));
                const int row = local_index<D>(0, y - lo[1], z - lo[2]) - lo[0];
                for (int x = x0; x <= x1; ++x) {
                  const float dx = static_cast<float>(x) - px;
                  const float r2 = dx * dx + d2;
                  const float w = std::max(0.0f, 1.0f - r2 * inv_r2);
                  acc[row + x] += scale * (w * w * w);
                  drop[static_cast<std::size_t>(row + x)] =
                      std::max(drop[static_cast<std::size_t>(row + x)], iso * (2.0f - r2 * inv_rd2));
                }
              }
            }
          }
        }
    for (int i = 0; i < kBlockVoxels<D>; ++i) acc[i] = std::max(acc[i], drop[static_cast<std::size_t>(i)]);
    if (s_.clip) clip_block(lo, acc);
    if (s_.solids) cut_solids(lo, acc);
  }

  /// The cut's faces lie on the walls up to round-off (the interpolation, then the float a
  /// vertex is stored in): each coordinate is held to the floats within the container.
  void clamp_to_container(SurfaceMesh& mesh) const {
    for (int a = 0; a < D; ++a) {
      float lo = static_cast<float>(s_.clip_lo[a]), hi = static_cast<float>(s_.clip_hi[a]);
      if (static_cast<double>(lo) < s_.clip_lo[a]) lo = std::nextafter(lo, std::numeric_limits<float>::infinity());
      if (static_cast<double>(hi) > s_.clip_hi[a]) hi = std::nextafter(hi, -std::numeric_limits<float>::infinity());
      for (auto& v : mesh.vertices) v[static_cast<std::size_t>(a)] = std::clamp(v[static_cast<std::size_t>(a)], lo, hi);
    }
  }

  /// The container's cut (SurfaceSettings::clip): each value at most iso + d / (2 v), d the
  /// voxel's distance inside the box (negative outside): iso on the walls, and above the fluid's
  /// own values a voxel inside them.
  void clip_block(const std::array<int, 3>& lo, float* acc) const {
    const int nz = D == 3 ? kBlock : 1;
    for (int z = 0; z < nz; ++z)
      for (int y = 0; y < kBlock; ++y)
        for (int x = 0; x < kBlock; ++x) {
          const std::array<int, 3> i{lo[0] + x, lo[1] + y, lo[2] + z};
          double d = std::numeric_limits<double>::infinity();
          for (int a = 0; a < D; ++a) {
            const double w = grid_.origin[a] + i[a] * grid_.v;
            d = std::min({d, w - s_.clip_lo[a], s_.clip_hi[a] - w});
          }
          float& value = acc[local_index<D>(x, y, z)];
          value = std::min(value, static_cast<float>(s_.iso + 0.5 * d / grid_.v));
        }
  }

  /// The obstacles' cut (SurfaceSettings::solids), as the container's: each value at most
  /// iso + d / (2 v), d the voxel's distance outside the solids, for the voxels within the cut's
  /// reach; a block whose centre is farther than that and its half-diagonal is left as it is.
  void cut_solids(const std::array<int, 3>& lo, float* acc) const {
    const double reach = 2 * grid_.v * (kCutCeiling - s_.iso);
    std::array<double, 3> centre{};
    double half = 0;
    for (int a = 0; a < D; ++a) {
      centre[a] = grid_.origin[a] + (lo[a] + 0.5 * (kBlock - 1)) * grid_.v;
      half += 0.25 * (kBlock - 1) * (kBlock - 1) * grid_.v * grid_.v;
    }
    half = std::sqrt(half);
    const double from_centre = s_.solids(centre, reach + half);  // (exact below reach + half)
    if (from_centre >= reach + half) return;
    const int nz = D == 3 ? kBlock : 1;
    for (int z = 0; z < nz; ++z)
      for (int y = 0; y < kBlock; ++y)
        for (int x = 0; x < kBlock; ++x) {
          const std::array<int, 3> i{lo[0] + x, lo[1] + y, lo[2] + z};
          std::array<double, 3> w{};
          double r2 = 0;
          for (int a = 0; a < D; ++a) {
            w[a] = grid_.origin[a] + i[a] * grid_.v;
            r2 += (w[a] - centre[a]) * (w[a] - centre[a]);
          }
          if (from_centre - std::sqrt(r2) >= reach) continue;  // (the distance is 1-Lipschitz)
          const double d = s_.solids(w, reach);
          if (!(d < reach)) continue;
          float& value = acc[local_index<D>(x, y, z)];
          value = std::min(value, static_cast<float>(s_.iso + 0.5 * d / grid_.v));
        }
  }

  /// The values at voxels [8 b, 8 b + 8] of active block k (its upper neighbors' first layers;
  /// 0 where a neighbor holds no values).
  void padded(std::size_t k, std::array<float, kPaddedVoxels<D>>& p) const {
    const auto bc = block_coords(active_[k]);
    const int oz_max = D == 3 ? 1 : 0;
    for (int oz = 0; oz <= oz_max; ++oz)
      for (int oy = 0; oy <= 1; ++oy)
        for (int ox = 0; ox <= 1; ++ox) {
          const std::int64_t x = bc[0] + ox, y = bc[1] + oy, z = bc[2] + oz;
          const float* src = nullptr;
          if (x < grid_.blocks[0] && y < grid_.blocks[1] && z < grid_.blocks[2]) {
            const std::int32_t s = slot_[static_cast<std::size_t>(grid_.id(x, y, z))];
            if (s >= 0) src = values_.data() + static_cast<std::size_t>(s) * kBlockVoxels<D>;
          }
          const int zs = D == 3 ? (oz ? kBlock : 0) : 0, ze = D == 3 ? (oz ? kBlock : kBlock - 1) : 0;
          const int ys = oy ? kBlock : 0, ye = oy ? kBlock : kBlock - 1;
          const int xs = ox ? kBlock : 0, xe = ox ? kBlock : kBlock - 1;
          for (int lz = zs; lz <= ze; ++lz)
            for (int ly = ys; ly <= ye; ++ly)
              for (int lx = xs; lx <= xe; ++lx)
                p[static_cast<std::size_t>(padded_index<D>(lx, ly, lz))] =
                    src ? src[local_index<D>(lx - ox * kBlock, ly - oy * kBlock, lz - oz * kBlock)] : 0.0f;
        }
  }

  static std::array<int, 3> bits(int c) { return {c & 1, (c >> 1) & 1, (c >> 2) & 1}; }

  /// The surface's vertices on the grid edges that start in block k: edge (a, d) joins voxel a
  /// to a + bits(d) (d = 1..7 in 3D, 1..3 in 2D); these are all the edges of the cube split.
  /// Returns whether the surface passes through the block's cubes.
  bool find_vertices(std::size_t k, BlockOut& out) const {
    std::array<float, kPaddedVoxels<D>> p{};
    padded(k, p);
    const auto iso = static_cast<float>(s_.iso);
    int inside = 0;
    for (float x : p) inside += x > iso;
    if (inside == 0 || inside == kPaddedVoxels<D>) return false;
    const auto bc = block_coords(active_[k]);
    const int nz = D == 3 ? kBlock : 1, dirs = D == 3 ? 8 : 4;
    for (int z = 0; z < nz; ++z)
      for (int y = 0; y < kBlock; ++y)
        for (int x = 0; x < kBlock; ++x) {
          const float fa = p[static_cast<std::size_t>(padded_index<D>(x, y, z))];
          for (int d = 1; d < dirs; ++d) {
            const auto e = bits(d);
            const float fb = p[static_cast<std::size_t>(padded_index<D>(x + e[0], y + e[1], z + e[2]))];
            if ((fa > iso) == (fb > iso)) continue;
            float t = (iso - fa) / (fb - fa);
            // (a vertex within kSnap of a voxel is put on it: see weld())
            if (t < kSnap) t = 0.0f;
            if (t > 1.0f - kSnap) t = 1.0f;
            std::array<float, 3> v{0, 0, 0};
            const std::array<int, 3> a{x, y, z};
            if (t == 0.0f || t == 1.0f) {  // (on voxel a, or on a + e)
              std::uint64_t g = 0;
              for (int c = D - 1; c >= 0; --c)
                g = g * static_cast<std::uint64_t>(grid_.blocks[c] * kBlock) +
                    static_cast<std::uint64_t>(bc[c] * kBlock + a[c] + (t == 1.0f ? e[c] : 0));
              out.on_voxel.emplace_back(g, static_cast<std::uint32_t>(out.vertices.size()));
            }
            for (int c = 0; c < D; ++c)
              v[c] = static_cast<float>(grid_.origin[c] +
                                        grid_.v * (static_cast<double>(bc[c] * kBlock + a[c]) + t * e[c]));
            out.keys.push_back(static_cast<std::uint16_t>(local_index<D>(x, y, z) * 8 + d));
            out.vertices.push_back(v);
            if constexpr (D == 3) {
              // The normal: minus the field's gradient (differences on the grid), interpolated
              // along the edge like the position.
              const auto ga = gradient(p, x, y, z), gb = gradient(p, x + e[0], y + e[1], z + e[2]);
              std::array<float, 3> n{};
              for (int c = 0; c < 3; ++c) n[c] = -(ga[c] + t * (gb[c] - ga[c]));
              const float len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
              if (len > 0) {
                for (float& c : n) c /= len;
              } else {
                n = {static_cast<float>(e[0]), static_cast<float>(e[1]), static_cast<float>(e[2])};
                if (fa > iso) {
                  const float l = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
                  for (float& c : n) c /= l;
                } else {
                  const float l = -std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
                  for (float& c : n) c /= l;
                }
              }
              out.normals.push_back(n);
            }
          }
        }
    return true;
  }

  /// The field's gradient at padded voxel (x, y, z) in value per voxel: central differences,
  /// one-sided on the padded copy's faces.
  static std::array<float, 3> gradient(const std::array<float, kPaddedVoxels<D>>& p, int x, int y, int z) {
    const std::array<int, 3> a{x, y, z};
    std::array<float, 3> g{0, 0, 0};
    for (int c = 0; c < D; ++c) {
      std::array<int, 3> lo = a, hi = a;
      lo[c] = std::max(0, a[c] - 1), hi[c] = std::min(kBlock, a[c] + 1);
      g[c] = (p[static_cast<std::size_t>(padded_index<D>(hi[0], hi[1], hi[2]))] -
              p[static_cast<std::size_t>(padded_index<D>(lo[0], lo[1], lo[2]))]) /
             static_cast<float>(hi[c] - lo[c]);
    }
    return g;
  }

  /// The global id of the vertex on edge (lo corner, hi corner) of the cube at local voxel a.
  std::uint32_t vertex_id(const std::array<std::int64_t, 3>& bc, const std::array<int, 3>& a, int c_lo, int c_hi,
                          const std::vector<BlockOut>& out, const std::vector<std::uint32_t>& base) const {
    const auto e = bits(c_lo);
    std::array<int, 3> g{a[0] + e[0], a[1] + e[1], D == 3 ? a[2] + e[2] : 0};
    std::array<std::int64_t, 3> ob = bc;
    for (int c = 0; c < D; ++c)
      if (g[c] >= kBlock) g[c] -= kBlock, ++ob[c];
    const std::int32_t s = slot_[static_cast<std::size_t>(grid_.id(ob[0], ob[1], ob[2]))];
    SPH_CHECK(s >= 0, "a surface vertex lies in a block without values");
    const auto key = static_cast<std::uint16_t>(local_index<D>(g[0], g[1], g[2]) * 8 + (c_hi ^ c_lo));
    const std::vector<std::uint16_t>& keys = out[static_cast<std::size_t>(s)].keys;
    const auto it = std::lower_bound(keys.begin(), keys.end(), key);
    SPH_CHECK(it != keys.end() && *it == key, "a surface vertex is missing from its block");
    return base[static_cast<std::size_t>(s)] + static_cast<std::uint32_t>(it - keys.begin());
  }

  /// The triangles (3D) or segments (2D) of the cubes (squares) whose lowest corner is in block k.
  void make_faces(std::size_t k, const std::vector<BlockOut>& all, const std::vector<std::uint32_t>& base,
                  BlockOut& out) const {
    std::array<float, kPaddedVoxels<D>> p{};
    padded(k, p);
    const auto iso = static_cast<float>(s_.iso);
    const auto bc = block_coords(active_[k]);
    const int nz = D == 3 ? kBlock : 1, corners = D == 3 ? 8 : 4;
    for (int z = 0; z < nz; ++z)
      for (int y = 0; y < kBlock; ++y)
        for (int x = 0; x < kBlock; ++x) {
          int mask = 0;
          for (int c = 0; c < corners; ++c) {
            const auto e = bits(c);
            mask |= (p[static_cast<std::size_t>(padded_index<D>(x + e[0], y + e[1], z + e[2]))] > iso) << c;
          }
          if (mask == 0 || mask == (1 << corners) - 1) continue;
          const std::array<int, 3> a{x, y, z};
          auto id = [&](int c0, int c1) {
            // Along every edge of the split the corner set grows: the smaller set is the edge's start.
            return std::popcount(static_cast<unsigned>(c0)) < std::popcount(static_cast<unsigned>(c1))
                       ? vertex_id(bc, a, c0, c1, all, base)
                       : vertex_id(bc, a, c1, c0, all, base);
          };
          if constexpr (D == 3) {
            for (const auto& tet : kTets) tet_faces(tet, mask, id, out);
          } else {
            for (const auto& tri : kTris) tri_segments(tri, mask, id, out);
          }
        }
  }

  /// Midpoint of cube corners c0 and c1, in corner units (for orientation only).
  static std::array<float, 3> mid(int c0, int c1) {
    const auto a = bits(c0), b = bits(c1);
    return {0.5f * static_cast<float>(a[0] + b[0]), 0.5f * static_cast<float>(a[1] + b[1]),
            0.5f * static_cast<float>(a[2] + b[2])};
  }

  /// Emits the triangle on edges (i0,o0), (i1,o1), (i2,o2), turned to face from the inside
  /// corners to the outside ones (`out_dir`). Orientation comes from the edges' midpoints,
  /// which the interpolated vertices keep (they lie on the same edges), so a vertex at a corner
  /// never flips a triangle.
  template <class Id>
  static void triangle(const std::array<std::array<int, 2>, 3>& e, const std::array<float, 3>& out_dir, Id& id,
                       BlockOut& out) {
    const auto m0 = mid(e[0][0], e[0][1]), m1 = mid(e[1][0], e[1][1]), m2 = mid(e[2][0], e[2][1]);
    const std::array<float, 3> u{m1[0] - m0[0], m1[1] - m0[1], m1[2] - m0[2]};
    const std::array<float, 3> w{m2[0] - m0[0], m2[1] - m0[1], m2[2] - m0[2]};
    const std::array<float, 3> n{u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
    const float dot = n[0] * out_dir[0] + n[1] * out_dir[1] + n[2] * out_dir[2];
    const std::uint32_t v0 = id(e[0][0], e[0][1]), v1 = id(e[1][0], e[1][1]), v2 = id(e[2][0], e[2][1]);
    out.triangles.push_back(dot >= 0 ? std::array{v0, v1, v2} : std::array{v0, v2, v1});
  }

  template <class Id>
  static void tet_faces(const int (&tet)[4], int mask, Id& id, BlockOut& out) {
    std::array<int, 4> in{}, ex{};
    int ni = 0, no = 0;
    for (int c : tet) ((mask >> c) & 1 ? in[static_cast<std::size_t>(ni++)] : ex[static_cast<std::size_t>(no++)]) = c;
    if (ni == 0 || no == 0) return;
    std::array<float, 3> dir{0, 0, 0};
    for (int j = 0; j < no; ++j) {
      const auto b = bits(ex[static_cast<std::size_t>(j)]);
      for (int c = 0; c < 3; ++c)
        dir[static_cast<std::size_t>(c)] += static_cast<float>(b[static_cast<std::size_t>(c)]) / static_cast<float>(no);
    }
    for (int j = 0; j < ni; ++j) {
      const auto b = bits(in[static_cast<std::size_t>(j)]);
      for (int c = 0; c < 3; ++c)
        dir[static_cast<std::size_t>(c)] -= static_cast<float>(b[static_cast<std::size_t>(c)]) / static_cast<float>(ni);
    }
    if (ni == 1) {
      triangle({{{in[0], ex[0]}, {in[0], ex[1]}, {in[0], ex[2]}}}, dir, id, out);
    } else if (no == 1) {
      triangle({{{in[0], ex[0]}, {in[1], ex[0]}, {in[2], ex[0]}}}, dir, id, out);
    } else {
      // A quad through edges (i0,o0), (i0,o1), (i1,o1), (i1,o0), in that order around it.
      triangle({{{in[0], ex[0]}, {in[0], ex[1]}, {in[1], ex[1]}}}, dir, id, out);
      triangle({{{in[0], ex[0]}, {in[1], ex[1]}, {in[1], ex[0]}}}, dir, id, out);
    }
  }

  template <class Id>
  static void tri_segments(const int (&tri)[3], int mask, Id& id, BlockOut& out) {
    std::array<int, 3> in{}, ex{};
    int ni = 0, no = 0;
    for (int c : tri) ((mask >> c) & 1 ? in[static_cast<std::size_t>(ni++)] : ex[static_cast<std::size_t>(no++)]) = c;
    if (ni == 0 || no == 0) return;
    std::array<std::array<int, 2>, 2> e{};
    e = ni == 1 ? std::array<std::array<int, 2>, 2>{{{in[0], ex[0]}, {in[0], ex[1]}}}
                : std::array<std::array<int, 2>, 2>{{{in[0], ex[0]}, {in[1], ex[0]}}};
    // The fluid on the left of p -> q: the left normal (-dy, dx) points from outside to inside.
    float ix = 0, iy = 0, ox = 0, oy = 0;
    for (int j = 0; j < ni; ++j)
      ix += static_cast<float>(in[static_cast<std::size_t>(j)] & 1) / static_cast<float>(ni),
          iy += static_cast<float>((in[static_cast<std::size_t>(j)] >> 1) & 1) / static_cast<float>(ni);
    for (int j = 0; j < no; ++j)
      ox += static_cast<float>(ex[static_cast<std::size_t>(j)] & 1) / static_cast<float>(no),
          oy += static_cast<float>((ex[static_cast<std::size_t>(j)] >> 1) & 1) / static_cast<float>(no);
    const auto m0 = mid(e[0][0], e[0][1]), m1 = mid(e[1][0], e[1][1]);
    const float dx = m1[0] - m0[0], dy = m1[1] - m0[1];
    const bool keep = (-dy) * (ix - ox) + dx * (iy - oy) > 0;
    const std::uint32_t v0 = id(e[0][0], e[0][1]), v1 = id(e[1][0], e[1][1]);
    out.segments.push_back(keep ? std::array{v0, v1} : std::array{v1, v0});
  }

  SurfaceSettings s_;
  std::size_t n_ = 0;
  Grid grid_;
  double rv_ = 0;
  int ring_ = 1;
  std::vector<std::uint32_t> start_;
  std::array<std::vector<float>, 3> u_;
  std::vector<std::int32_t> slot_;
  std::vector<std::uint32_t> active_;
  std::vector<float> values_;
};

}  // namespace

std::string surface_settings_error(const SurfaceSettings& s) {
  if (!(std::isfinite(s.spacing) && s.spacing > 0))
    return fmt::format("the particle spacing must be positive and finite (is {})", s.spacing);
  if (!(s.resolution >= 0.5 && s.resolution <= 8))
    return fmt::format("resolution must be 0.5 to 8 voxels per particle spacing (is {})", s.resolution);
  if (!(s.smoothing >= 1 && s.smoothing <= 4))
    return fmt::format("smoothing must be 1 to 4 particle spacings (is {})", s.smoothing);
  if (!(s.iso >= 0.05 && s.iso <= 0.95)) return fmt::format("iso must be 0.05 to 0.95 (is {})", s.iso);
  return {};
}

namespace {

/// The particles and, with the container's cut, each one's images across the walls within the
/// kernel's support R of it (across each wall, and across each pair and the three of the walls
/// it is near, for the edges and corners): the field then sees the water go on beyond a wall it
/// touches, as the solver's boundary does, and reaches about 1 on the wall, where the cut makes
/// the flat face, instead of about iso with the lattice's ripple (a surface bumpy at the
/// particles' scale along every wall). Particles outside the box keep no images.
std::vector<double> with_wall_images(std::span<const double> positions, int dim, const SurfaceSettings& s) {
  std::vector<double> out(positions.begin(), positions.end());
  const double reach = s.smoothing * s.spacing;
  const std::size_t n = positions.size() / 3;
  for (std::size_t i = 0; i < n; ++i) {
    const double* x = positions.data() + 3 * i;
    // Per axis: the particle's own coordinate, then its images across the walls within reach.
    std::array<std::array<double, 3>, 3> choices{};
    std::array<int, 3> count{1, 1, 1};
    bool inside = true;
    for (int a = 0; a < dim; ++a) {
      const double lo = s.clip_lo[a], hi = s.clip_hi[a];
      if (!(x[a] >= lo && x[a] <= hi)) inside = false;
      choices[a][0] = x[a];
      if (x[a] - lo < reach) choices[a][count[a]++] = 2 * lo - x[a];
      if (hi - x[a] < reach) choices[a][count[a]++] = 2 * hi - x[a];
    }
    if (!inside) continue;
    for (int cz = 0; cz < count[2]; ++cz)
      for (int cy = 0; cy < count[1]; ++cy)
        for (int cx = 0; cx < count[0]; ++cx) {
          if (cx == 0 && cy == 0 && cz == 0) continue;
          out.insert(out.end(), {choices[0][cx], choices[1][cy], dim == 3 ? choices[2][cz] : x[2]});
        }
  }
  return out;
}

}  // namespace

SurfaceMesh extract_surface(std::span<const double> positions, int dimension, const SurfaceSettings& settings) {
  if (const std::string e = surface_settings_error(settings); !e.empty()) throw Error(e, "surface");
  SPH_CHECK(dimension == 2 || dimension == 3, "extract_surface: dimension must be 2 or 3");
  SPH_CHECK(positions.size() % 3 == 0, "extract_surface: 3 coordinates per particle");
  // (the extractor counts particles in 32 bits: the frame's, and again with the walls' images)
  const std::size_t most = 3 * std::size_t{std::numeric_limits<std::uint32_t>::max() / 2};
  if (positions.size() > most) throw Error("more than 2^31 particles in one frame; mesh parts of it", "surface");
  if (positions.empty()) {
    SurfaceMesh m;
    m.dimension = dimension;
    m.voxel_size = settings.spacing / settings.resolution;
    return m;
  }
  std::vector<double> imaged;
  if (settings.clip) {
    // (a non-finite position has no images, and the originals come first: the refusal names it)
    imaged = with_wall_images(positions, dimension, settings);
    positions = imaged;
    if (positions.size() > most)
      throw Error("more than 2^31 particles in one frame with their images across the walls; mesh parts of it",
                  "surface");
  }
  if (dimension == 3) return Extractor<3>(positions, settings).run();
  return Extractor<2>(positions, settings).run();
}

double enclosed_measure(const SurfaceMesh& mesh) {
  if (mesh.vertices.empty()) return 0;
  const auto& o = mesh.vertices[0];
  auto rel = [&](std::uint32_t v) {
    const auto& p = mesh.vertices[v];
    return std::array<double, 3>{double(p[0]) - o[0], double(p[1]) - o[1], double(p[2]) - o[2]};
  };
  double sum = 0;
  if (mesh.dimension == 3) {
    for (const auto& t : mesh.triangles) {
      const auto a = rel(t[0]), b = rel(t[1]), c = rel(t[2]);
      sum +=
          a[0] * (b[1] * c[2] - b[2] * c[1]) + a[1] * (b[2] * c[0] - b[0] * c[2]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
    }
    return sum / 6;
  }
  for (const auto& s : mesh.segments) {
    const auto a = rel(s[0]), b = rel(s[1]);
    sum += a[0] * b[1] - a[1] * b[0];
  }
  return sum / 2;
}

std::vector<std::vector<std::uint32_t>> surface_polylines(const SurfaceMesh& mesh) {
  constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> next(mesh.vertices.size(), kNone);
  std::vector<std::uint8_t> has_prev(mesh.vertices.size(), 0), used(mesh.vertices.size(), 0);
  for (const auto& s : mesh.segments) next[s[0]] = s[1], has_prev[s[1]] = 1;
  std::vector<std::vector<std::uint32_t>> lines;
  auto walk = [&](std::uint32_t v) {
    std::vector<std::uint32_t> line{v};
    used[v] = 1;
    for (std::uint32_t w = next[v]; w != kNone; w = next[w]) {
      line.push_back(w);
      if (used[w]) break;  // back at the start: a closed loop
      used[w] = 1;
    }
    lines.push_back(std::move(line));
  };
  // Open lines (they end at the grid's edge only if the fluid does; normally all lines close).
  for (std::uint32_t v = 0; v < next.size(); ++v)
    if (next[v] != kNone && !has_prev[v] && !used[v]) walk(v);
  for (std::uint32_t v = 0; v < next.size(); ++v)
    if (next[v] != kNone && !used[v]) walk(v);
  return lines;
}

}  // namespace sph
