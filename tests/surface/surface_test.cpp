#include <sph/surface/surface.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <map>
#include <numbers>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include <sph/core/error.h>
#include <sph/core/parallel.h>

namespace sph {
namespace {

constexpr double kS = 0.1;  // particle spacing

/// A lattice block of nx x ny x nz particles (nz = 1 in 2D, z = 0), cell-centered from `lo`.
std::vector<double> block(int nx, int ny, int nz, double lo = 0.0) {
  std::vector<double> p;
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x) {
        p.push_back(lo + (x + 0.5) * kS);
        p.push_back(lo + (y + 0.5) * kS);
        p.push_back(nz == 1 ? 0.0 : lo + (z + 0.5) * kS);
      }
  return p;
}

SurfaceSettings settings() {
  SurfaceSettings s;
  s.spacing = kS;
  return s;
}

/// Every undirected edge is shared by exactly two triangles, and each directed edge occurs once
/// (the two triangles run along it in opposite directions: consistent orientation).
void expect_closed_and_oriented(const SurfaceMesh& m) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  for (const auto& t : m.triangles) {
    ASSERT_TRUE(t[0] != t[1] && t[1] != t[2] && t[0] != t[2]);
    for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
  }
  std::size_t open = 0, doubled = 0;
  for (const auto& [e, n] : directed) {
    if (n != 1) ++doubled;
    if (!directed.count({e.second, e.first})) ++open;
  }
  EXPECT_EQ(open, 0u) << "edges with one face";
  EXPECT_EQ(doubled, 0u) << "directed edges used twice (inconsistent orientation or non-manifold)";
}

/// The triangles (2D: segments) with no area (length), two of their vertices at one point, and
/// the vertices no face uses.
std::pair<std::size_t, std::size_t> degenerate(const SurfaceMesh& m) {
  std::size_t flat = 0;
  std::vector<bool> used(m.vertices.size(), false);
  for (const auto& t : m.triangles) {
    flat += m.vertices[t[0]] == m.vertices[t[1]] || m.vertices[t[1]] == m.vertices[t[2]] ||
            m.vertices[t[0]] == m.vertices[t[2]];
    for (const auto v : t) used[v] = true;
  }
  for (const auto& s : m.segments) {
    flat += m.vertices[s[0]] == m.vertices[s[1]];
    for (const auto v : s) used[v] = true;
  }
  return {flat, static_cast<std::size_t>(std::count(used.begin(), used.end(), false))};
}

/// The vertices of the face on the wall x = 0 of block(20, 16, 12) (or its 2D slice), away from
/// the face's edges (within half a spacing of the wall): {those exactly on it, the others}.
std::pair<std::size_t, std::size_t> wall_face_vertices(const SurfaceMesh& m, int dim) {
  std::size_t on = 0, off = 0;
  for (const auto& v : m.vertices) {
    if (!(v[0] < 0.5 * kS && v[1] > 0.3 && v[1] < 1.3 && (dim == 2 || (v[2] > 0.3 && v[2] < 0.9)))) continue;
    (v[0] == 0.0f ? on : off) += 1;
  }
  return {on, off};
}

TEST(Surface, RestingBlockIsClosedAndEnclosesItsVolume) {
  // A resting tank's water: its edges and corners are rounded by about a spacing, so smaller
  // blocks lose more (a 10^3 block encloses 0.97 of its volume).
  const auto p = block(20, 16, 12);
  const SurfaceMesh m = extract_surface(p, 3, settings());
  ASSERT_GT(m.triangles.size(), 100u);
  expect_closed_and_oriented(m);
  const double fluid = 20 * 16 * 12 * std::pow(kS, 3);
  EXPECT_NEAR(enclosed_measure(m) / fluid, 1.0, 0.03);
  ASSERT_EQ(m.normals.size(), m.vertices.size());
}

TEST(Surface, CalmTopHasNoParticleSizedBumps) {
  // The top face, away from the edges: all vertices at one height within 2 % of a spacing.
  const int n = 16;
  const auto p = block(n, n, 6);
  const SurfaceMesh m = extract_surface(p, 3, settings());
  float lo = 1e9f, hi = -1e9f;
  const double top = 6 * kS;
  for (const auto& v : m.vertices)
    if (v[2] > top - 0.25 * kS && v[0] > 4 * kS && v[0] < (n - 4) * kS && v[1] > 4 * kS && v[1] < (n - 4) * kS)
      lo = std::min(lo, v[2]), hi = std::max(hi, v[2]);
  ASSERT_LT(lo, hi + 1);  // found some
  EXPECT_LT(hi - lo, 0.02 * kS);
  EXPECT_NEAR(0.5 * (hi + lo), top, 0.1 * kS);  // half a spacing above the top particles' centers
}

TEST(Surface, SphereOfParticlesLiesWithinHalfASpacing) {
  std::vector<double> p;
  const double r = 8 * kS;
  std::size_t n = 0;
  for (int z = -10; z <= 10; ++z)
    for (int y = -10; y <= 10; ++y)
      for (int x = -10; x <= 10; ++x) {
        const double px = x * kS, py = y * kS, pz = z * kS;
        if (px * px + py * py + pz * pz <= r * r) p.insert(p.end(), {px, py, pz}), ++n;
      }
  const SurfaceMesh m = extract_surface(p, 3, settings());
  expect_closed_and_oriented(m);
  // The sphere the particles fill: volume N s^3.
  const double radius = std::cbrt(3.0 * static_cast<double>(n) * std::pow(kS, 3) / (4 * std::numbers::pi));
  double worst = 0;
  for (const auto& v : m.vertices) worst = std::max(worst, std::abs(std::hypot(v[0], v[1], v[2]) - radius));
  EXPECT_LT(worst, 0.5 * kS);
  // Normals point outwards (within the lattice sphere's own facets).
  for (std::size_t i = 0; i < m.vertices.size(); i += 97) {
    const auto& v = m.vertices[i];
    const auto& nn = m.normals[i];
    EXPECT_GT(v[0] * nn[0] + v[1] * nn[1] + v[2] * nn[2], 0.7 * std::hypot(v[0], v[1], v[2]));
  }
}

TEST(Surface, LoneDropKeepsAClosedSphereOfItsRadius) {
  auto p = block(6, 6, 6);
  p.insert(p.end(), {2.0, 2.0, 2.0});  // far from the block
  const SurfaceMesh m = extract_surface(p, 3, settings());
  expect_closed_and_oriented(m);
  double worst = 0;
  std::size_t near = 0;
  for (const auto& v : m.vertices) {
    const double d = std::hypot(v[0] - 2.0, v[1] - 2.0, v[2] - 2.0);
    if (d < kS) worst = std::max(worst, std::abs(d - 0.4 * kS)), ++near;
  }
  EXPECT_GT(near, 10u);
  EXPECT_LT(worst, 0.1 * kS);
}

TEST(Surface, TwoDimensionalBlockGivesOneCounterClockwiseLoop) {
  const auto p = block(20, 12, 1);
  const SurfaceMesh m = extract_surface(p, 2, settings());
  EXPECT_TRUE(m.triangles.empty());
  std::vector<int> in(m.vertices.size(), 0), out(m.vertices.size(), 0);
  for (const auto& s : m.segments) ++out[s[0]], ++in[s[1]];
  for (std::size_t v = 0; v < m.vertices.size(); ++v) EXPECT_TRUE(in[v] == 1 && out[v] == 1) << v;
  EXPECT_NEAR(enclosed_measure(m) / (20 * 12 * kS * kS), 1.0, 0.03);
  const auto lines = surface_polylines(m);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(lines[0].front(), lines[0].back());
  EXPECT_EQ(lines[0].size(), m.segments.size() + 1);
}

// Water crowded against the container's walls (its outer particles 0.2 spacings from them, as
// penalty walls let them come) reaches through the walls by about 0.3 spacings unless the
// surface is cut by the container (SurfaceSettings::clip, which sph surface, sph render and sph
// run --surface set): then no vertex lies outside, the mesh stays closed and oriented, and the
// water against the walls ends on them, so the volume is the box's part of the fluid.
TEST(Surface, ClippedToTheContainerNoVertexLiesOutsideIt) {
  const auto p = block(20, 16, 12);  // [0, 2] x [0, 1.6] x [0, 1.2]
  SurfaceSettings s = settings();
  s.clip_lo = {0.03, 0.03, 0.03};  // the walls at x, y, z = 0.03; the fluid's far sides are free
  s.clip_hi = {10, 10, 10};
  const auto outside = [&](const SurfaceMesh& m, int dim) {
    double deepest = 0;
    for (const auto& v : m.vertices)
      for (int a = 0; a < dim; ++a) deepest = std::max(deepest, s.clip_lo[a] - v[a]);
    return deepest;
  };
  for (const int dim : {2, 3}) {
    SCOPED_TRACE(dim);
    const auto q = dim == 3 ? p : block(20, 16, 1);
    const SurfaceMesh free = extract_surface(q, dim, s);
    EXPECT_GT(outside(free, dim), 0.02) << "without the cut the surface reaches through the walls";
    s.clip = true;
    const SurfaceMesh cut = extract_surface(q, dim, s);
    s.clip = false;
    EXPECT_LE(outside(cut, dim), 0.0);  // exactly: the vertices are held to the floats within the walls
    if (dim == 3) expect_closed_and_oriented(cut);
    // Walls wherever they fall: not one vertex a float's width beyond them (the interpolation's
    // round-off put some there, 1.8e-10 below a wall at 0 in the paper's block).
    for (const double wall : {0.0, 0.01, 0.02, 0.03, 0.047}) {
      SurfaceSettings w = s;
      w.clip = true;
      w.clip_lo = {wall, wall, wall};
      const SurfaceMesh m = extract_surface(q, dim, w);
      std::size_t beyond = 0;
      for (const auto& v : m.vertices)
        for (int a = 0; a < dim; ++a) beyond += static_cast<double>(v[a]) < wall ? 1 : 0;
      EXPECT_EQ(beyond, 0u) << "walls at " << wall;
    }
    const double box = (2.0 - 0.03) * (1.6 - 0.03) * (dim == 3 ? 1.2 - 0.03 : 1.0);
    EXPECT_NEAR(enclosed_measure(cut) / box, 0.995, 0.01);  // (0.998 in 2D, 0.993 in 3D: the free edges rounded)
  }
}

TEST(Surface, WaterAgainstAWallEndsInAFlatFaceOnIt) {
  // A block whose outer particles sit half a spacing off the walls at x, y, z = 0 (as the
  // boundary particles keep them): the wall face is flat on the wall, its vertices exactly on it
  // (the field reaches about 1 there, with the particles' images beyond the wall), where the
  // field alone falls to about iso and ripples with the lattice.
  for (const int dim : {2, 3}) {
    SCOPED_TRACE(dim);
    const auto p = dim == 3 ? block(20, 16, 12) : block(20, 16, 1);
    SurfaceSettings s = settings();
    s.clip = true;
    s.clip_lo = {0, 0, 0};
    s.clip_hi = {10, 10, 10};
    const SurfaceMesh m = extract_surface(p, dim, s);
    // The field is exactly iso on the walls, whose planes here hold voxels: each such voxel is
    // one vertex, not one per edge that ends there (which gave 16,710 of the 52,976 triangles no
    // area in 3D, and 70 of the 350 segments no length in 2D).
    const auto [flat, unused] = degenerate(m);
    EXPECT_EQ(flat, 0u) << "triangles with two vertices at one point";
    EXPECT_EQ(unused, 0u);
    // The face on x = 0, away from its edges: every vertex within half a spacing of the wall is on it.
    const auto [on, off] = wall_face_vertices(m, dim);
    EXPECT_GT(on, 0u);
    EXPECT_EQ(off, 0u) << "vertices of the wall face off the wall: a face bumpy at the particles' scale";
    if (dim == 3) expect_closed_and_oriented(m);
    // The images add nothing beyond the walls: the volume is the water's, the far sides rounded.
    const double box = 2.0 * 1.6 * (dim == 3 ? 1.2 : 1.0);
    EXPECT_LE(enclosed_measure(m), box);
    EXPECT_GT(enclosed_measure(m) / box, 0.98);
  }
}

// Penalty walls let particles a little past the wall at an impact (the paper's dam break's reach
// 0.27 spacings). Such particles keep no images, but the face on the wall stays flat on it: the
// layers behind them and their images hold the field above iso there. A particle beyond the
// kernel's reach gives no water inside either.
TEST(Surface, ParticlesPastAWallLeaveItsFaceFlat) {
  for (const int dim : {2, 3}) {
    SCOPED_TRACE(dim);
    auto p = dim == 3 ? block(20, 16, 12) : block(20, 16, 1);
    // The layer next to x = 0 pressed 0.3 spacings past the wall.
    for (std::size_t i = 0; i < p.size(); i += 3)
      if (p[i] < kS) p[i] = -0.3 * kS;
    SurfaceSettings s = settings();
    s.clip = true;
    s.clip_lo = {0, 0, 0};
    s.clip_hi = {10, 10, 10};
    const SurfaceMesh m = extract_surface(p, dim, s);
    const auto [on, off] = wall_face_vertices(m, dim);
    EXPECT_GT(on, 0u);
    EXPECT_EQ(off, 0u) << "the wall face dips where particles crossed the wall";
    if (dim == 3) expect_closed_and_oriented(m);
    // One particle far beyond the wall (past the kernel's reach): no water inside from it.
    std::vector<double> far = {-5 * kS, 0.5, dim == 3 ? 0.5 : 0.0};
    EXPECT_TRUE(extract_surface(far, dim, s).vertices.empty());
  }
}

TEST(Surface, CutByTheSolidsNoVertexLiesInsideOne) {
  // Fluid around a ball (radius 0.35 about c), its nearest particles crowding it: 0.2 spacings
  // from its surface where the solver keeps them half a spacing off. The colour field reaches
  // into the ball there; the cut puts the surface on the ball's.
  const std::array<double, 3> c{1.0, 0.8, 0.6};
  const double radius = 0.35;
  const auto ball_distance = [&](const std::array<double, 3>& x, int dim) {
    double r2 = 0;
    for (int a = 0; a < dim; ++a) r2 += (x[a] - c[a]) * (x[a] - c[a]);
    return std::sqrt(r2) - radius;
  };
  for (const int dim : {2, 3}) {
    SCOPED_TRACE(dim);
    std::vector<double> p;
    const auto all = dim == 3 ? block(20, 16, 12) : block(20, 16, 1);
    for (std::size_t i = 0; i < all.size(); i += 3) {
      const std::array<double, 3> x{all[i], all[i + 1], all[i + 2]};
      if (ball_distance(x, dim) > 0.2 * kS) p.insert(p.end(), {x[0], x[1], x[2]});
    }
    SurfaceSettings s = settings();
    const auto deepest = [&](const SurfaceMesh& m) {
      double d = 0;
      for (const auto& v : m.vertices) d = std::max(d, -ball_distance({v[0], v[1], v[2]}, dim));
      return d;
    };
    const SurfaceMesh free = extract_surface(p, dim, s);
    EXPECT_GT(deepest(free), 0.1 * kS) << "without the cut the surface closes inside the ball";
    std::atomic<std::size_t> calls{0};
    s.solids = [&](const std::array<double, 3>& x, double reach) {
      ++calls;
      return std::min(ball_distance(x, dim), 2 * reach);  // (beyond reach: any value above it)
    };
    const SurfaceMesh cut = extract_surface(p, dim, s);
    EXPECT_LT(deepest(cut), 0.02 * kS) << "the cut puts the surface on the ball's";
    if (dim == 3) expect_closed_and_oriented(cut);
    // What the cut surface leaves out of the whole block's holds the ball (and the lattice's
    // jagged shell around it: 1.07 of it in 3D, 1.10 in 2D); the uncut one's did not.
    const double ball =
        dim == 3 ? 4.0 / 3.0 * std::numbers::pi * std::pow(radius, 3) : std::numbers::pi * radius * radius;
    EXPECT_LT(enclosed_measure(cut), enclosed_measure(free));
    const double whole = enclosed_measure(extract_surface(all, dim, settings()));
    EXPECT_GT((whole - enclosed_measure(cut)) / ball, 1.0);
    EXPECT_LT((whole - enclosed_measure(cut)) / ball, 1.15);
    // Blocks far from the ball are passed over after one call: most of the calls are the
    // voxels of the blocks that hold part of the cut.
    const std::size_t voxels = cut.blocks * (dim == 3 ? 512u : 64u);
    EXPECT_LT(calls.load(), voxels / 2) << "blocks far from the solids are not sampled voxel by voxel";
    // The same bits for any thread count, the cut included.
    for (const int t : {2, 3}) {
      set_num_threads(t);
      const SurfaceMesh again = extract_surface(p, dim, s);
      EXPECT_EQ(again.vertices, cut.vertices);
      EXPECT_EQ(again.triangles, cut.triangles);
      EXPECT_EQ(again.segments, cut.segments);
    }
    set_num_threads(1);
  }
}

TEST(Surface, SameBitsForAnyThreadCount) {
  // A splashy frame: a block, a sheet and scattered drops.
  auto p = block(14, 9, 7);
  for (int k = 0; k < 300; ++k) {
    const double a = 0.37 * k, b = 0.11 * k;
    p.insert(p.end(), {2.2 + 0.6 * std::sin(a), 1.0 + 0.5 * std::cos(b), 0.4 + 0.3 * std::sin(a + b)});
  }
  for (int dim : {2, 3}) {
    std::vector<SurfaceMesh> runs;
    for (int t : {1, 2, 3}) {
      set_num_threads(t);
      runs.push_back(extract_surface(p, dim, settings()));
    }
    set_num_threads(1);
    for (const SurfaceMesh& r : runs) {
      EXPECT_EQ(r.vertices, runs[0].vertices);
      EXPECT_EQ(r.normals, runs[0].normals);
      EXPECT_EQ(r.triangles, runs[0].triangles);
      EXPECT_EQ(r.segments, runs[0].segments);
    }
  }
}

TEST(Surface, FinerResolutionConvergesOnTheSameVolume) {
  const auto p = block(16, 12, 10);
  SurfaceSettings s = settings();
  const double fluid = 16 * 12 * 10 * std::pow(kS, 3);
  for (double res : {2.0, 3.0, 4.0}) {
    s.resolution = res;
    const SurfaceMesh m = extract_surface(p, 3, s);
    expect_closed_and_oriented(m);
    EXPECT_NEAR(enclosed_measure(m) / fluid, 1.0, 0.03) << "resolution " << res;
  }
}

TEST(Surface, RefusesBadSettingsAndPositions) {
  const auto p = block(3, 3, 3);
  SurfaceSettings s = settings();
  s.resolution = 0.1;
  EXPECT_THROW(extract_surface(p, 3, s), Error);
  s = settings();
  s.smoothing = 9;
  EXPECT_THROW(extract_surface(p, 3, s), Error);
  s = settings();
  s.spacing = 0;
  EXPECT_THROW(extract_surface(p, 3, s), Error);
  auto bad = p;
  bad[4] = std::nan("");
  EXPECT_THROW(extract_surface(bad, 3, settings()), Error);
  auto far = p;
  far.insert(far.end(), {1e7, 0, 0});
  try {
    extract_surface(far, 3, settings());
    FAIL() << "a frame spanning 1e8 spacings was meshed";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("spacings"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(extract_surface(std::vector<double>{}, 3, settings()).triangles.empty());
}

}  // namespace
}  // namespace sph
