// Surface images: a block of fluid reads as shaded water where it is and leaves the background
// elsewhere, and the image is the same on every run.

#include <algorithm>
#include <array>
#include <vector>

#include <gtest/gtest.h>

#include <sph/render/particles.h>
#include <sph/surface/surface.h>

namespace sph {
namespace {

using A3 = std::array<double, 3>;

/// A 12 x 8 x 6 lattice of particles with spacing 0.1 in the corner of a 2 x 1.5 x 1 box.
SurfaceMesh block_mesh() {
  std::vector<double> xyz;
  for (int i = 0; i < 12; ++i)
    for (int j = 0; j < 8; ++j)
      for (int k = 0; k < 6; ++k) {
        xyz.push_back(0.05 + 0.1 * i);
        xyz.push_back(0.05 + 0.1 * j);
        xyz.push_back(0.05 + 0.1 * k);
      }
  SurfaceSettings s;
  s.spacing = 0.1;
  return extract_surface(xyz, 3, s);
}

const A3 kLo{0, 0, 0}, kHi{2, 1.5, 1};

TEST(RenderSurface, BlockIsBlueWhereItIsAndBackgroundElsewhere) {
  const SurfaceMesh mesh = block_mesh();
  ASSERT_FALSE(mesh.triangles.empty());
  const ParticleView view = default_particle_view(3, 400, 300);
  const Image img = render_surface(mesh, 0.05, kLo, kHi, view);
  const ParticleCamera cam(3, kLo, kHi, 0.05, view);
  const A3 center = cam.project({0.6, 0.4, 0.3});
  const Rgb c = img.at(static_cast<int>(center[0]), static_cast<int>(center[1]));
  EXPECT_GT(c.b, c.r);
  EXPECT_NE(c, view.background);
  // High in the empty part of the box: above the floor's projection, away from the block.
  for (const A3& p : {A3{1.5, 1.2, 0.5}, A3{1.7, 1.0, 0.8}}) {
    const A3 s = cam.project(p);
    EXPECT_EQ(img.at(static_cast<int>(s[0]), static_cast<int>(s[1])), view.background);
  }
}

TEST(RenderSurface, Deterministic) {
  const SurfaceMesh mesh = block_mesh();
  const ParticleView view = default_particle_view(3, 320, 240);
  const std::vector<SolidBox> solids{{{1.4, 0, 0.2}, {1.7, 0.5, 0.6}}};
  const Image a = render_surface(mesh, 0.05, kLo, kHi, view, solids);
  const Image b = render_surface(mesh, 0.05, kLo, kHi, view, solids);
  ASSERT_EQ(a.pixels().size(), b.pixels().size());
  EXPECT_TRUE(std::equal(a.pixels().begin(), a.pixels().end(), b.pixels().begin()));
}

}  // namespace
}  // namespace sph
