// The benchmark's fixed workloads: the generator, the jittered lattice, the moved copy, the
// shuffle, and the dam break scene. These must not change silently: every published figure
// depends on them.

#include <algorithm>
#include <cmath>
#include <numeric>

#include <gtest/gtest.h>

#include <sph/bench/workload.h>
#include <sph/scene/builders.h>
#include <sph/scene/scene_reader.h>

namespace sph {
namespace {

TEST(SplitMix64, MatchesTheReferenceSequence) {
  // First outputs of the reference implementation (Vigna's splitmix64.c) seeded with 0.
  SplitMix64 rng(0);
  EXPECT_EQ(rng.next(), 0xe220a8397b1dcdafull);
  EXPECT_EQ(rng.next(), 0x6e789e6aa1b965f4ull);
  EXPECT_EQ(rng.next(), 0x06c45d188009454full);
}

TEST(SplitMix64, UniformAndBelowStayInRange) {
  SplitMix64 rng(42);
  double lo = 1, hi = 0, sum = 0;
  for (int k = 0; k < 100000; ++k) {
    const double u = rng.uniform();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    lo = std::min(lo, u), hi = std::max(hi, u), sum += u;
    const double s = rng.symmetric(0.5);
    ASSERT_GE(s, -0.5);
    ASSERT_LT(s, 0.5);
    ASSERT_LT(rng.below(7), 7u);
  }
  EXPECT_LT(lo, 1e-3);
  EXPECT_GT(hi, 1 - 1e-3);
  EXPECT_NEAR(sum / 100000, 0.5, 0.01);
}

template <class R>
class Lattice : public ::testing::Test {};
using Precisions = ::testing::Types<float, double>;
TYPED_TEST_SUITE(Lattice, Precisions);

TYPED_TEST(Lattice, CountSpacingAndJitterBounds) {
  using R = TypeParam;
  LatticeSpec spec;
  spec.side = 12;
  const auto x = lattice_points<R>(spec);
  ASSERT_EQ(x.size(), 12u * 12u * 12u);
  ASSERT_EQ(spec.count(), x.size());
  const double bound = spec.jitter * spec.spacing;
  // R rounding of a coordinate up to 0.3 m: a few ulps.
  const double slack = std::is_same_v<R, float> ? 1e-7 : 1e-15;
  double max_dev = 0, sum_dev = 0;
  for (int z = 0; z < spec.side; ++z)
    for (int y = 0; y < spec.side; ++y)
      for (int xi = 0; xi < spec.side; ++xi) {
        const auto& p = x[static_cast<std::size_t>(xi + spec.side * (y + spec.side * z))];
        const int c[3] = {xi, y, z};
        for (int d = 0; d < 3; ++d) {
          const double dev = static_cast<double>(p[d]) - spec.spacing * c[d];
          ASSERT_LE(std::abs(dev), bound + slack) << "point " << xi << "," << y << "," << z;
          max_dev = std::max(max_dev, std::abs(dev));
          sum_dev += dev;
        }
      }
  // The jitter is really there, fills its range, and is centered.
  EXPECT_GT(max_dev, 0.95 * bound);
  EXPECT_NEAR(sum_dev / (3.0 * static_cast<double>(x.size())), 0.0, 0.05 * bound);
}

TYPED_TEST(Lattice, SameSeedSamePointsOtherSeedOtherPoints) {
  using R = TypeParam;
  LatticeSpec spec;
  spec.side = 10;
  const auto a = lattice_points<R>(spec);
  const auto b = lattice_points<R>(spec);
  EXPECT_EQ(a, b);
  spec.seed += 1;
  const auto c = lattice_points<R>(spec);
  EXPECT_NE(a, c);
}

TEST(Lattice, FloatPointsAreTheDoublePointsRounded) {
  LatticeSpec spec;
  spec.side = 8;
  const auto f = lattice_points<float>(spec);
  const auto d = lattice_points<double>(spec);
  ASSERT_EQ(f.size(), d.size());
  for (std::size_t i = 0; i < f.size(); ++i)
    for (int k = 0; k < 3; ++k) ASSERT_EQ(f[i][k], static_cast<float>(d[i][k])) << i;
}

TYPED_TEST(Lattice, MovedPointsStayWithinTheAmplitudeAndAreDeterministic) {
  using R = TypeParam;
  LatticeSpec spec;
  spec.side = 10;
  const auto x = lattice_points<R>(spec);
  const double a = 0.05 * spec.spacing;
  const auto m = moved_points<R>(x, a, kMoveSeed);
  ASSERT_EQ(m.size(), x.size());
  const double slack = std::is_same_v<R, float> ? 1e-7 : 1e-15;
  double max_move = 0;
  for (std::size_t i = 0; i < x.size(); ++i)
    for (int d = 0; d < 3; ++d) {
      const double mv = std::abs(static_cast<double>(m[i][d]) - static_cast<double>(x[i][d]));
      ASSERT_LE(mv, a + slack);
      max_move = std::max(max_move, mv);
    }
  EXPECT_GT(max_move, 0.9 * a);
  EXPECT_EQ(m, (moved_points<R>(x, a, kMoveSeed)));
}

TEST(Shuffle, IsADeterministicPermutationThatMovesMostPoints) {
  const std::size_t n = 10000;
  const auto p = shuffle_permutation(n, kShuffleSeed);
  ASSERT_EQ(p.size(), n);
  std::vector<std::uint32_t> sorted = p;
  std::sort(sorted.begin(), sorted.end());
  for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(sorted[i], i);
  std::size_t fixed = 0;
  for (std::size_t i = 0; i < n; ++i) fixed += p[i] == i;
  EXPECT_LT(fixed, 20u);  // a uniform permutation fixes about one point
  EXPECT_EQ(p, shuffle_permutation(n, kShuffleSeed));
  EXPECT_NE(p, shuffle_permutation(n, kShuffleSeed + 1));
  EXPECT_TRUE(shuffle_permutation(0, 1).empty());
  EXPECT_EQ(shuffle_permutation(1, 1), std::vector<std::uint32_t>{0});
}

TEST(Gather, PutsTheKthChosenElementKth) {
  const std::vector<int> in{10, 11, 12, 13};
  const std::vector<std::uint32_t> perm{2, 0, 3, 1};
  std::vector<int> out;
  gather<int>(in, perm, out);
  EXPECT_EQ(out, (std::vector<int>{12, 10, 13, 11}));
}

TEST(DamBreakScene, IsAValidSceneWithSideCubedParticlesInTheDocumentedBox) {
  for (int side : {5, 20}) {
    const SceneDesc desc = parse_scene(dam_break_scene_json(side, Precision::Float, NeighborMode::Verlet, 7), "test");
    EXPECT_EQ(desc.dimension, 3);
    EXPECT_EQ(desc.precision, Precision::Float);
    EXPECT_EQ(desc.steps, 7);
    const auto& body = desc.body<3>();
    EXPECT_EQ(body.sim.neighbors, NeighborMode::Verlet);
    EXPECT_EQ(count_block_particles<3>(body), static_cast<std::size_t>(side * side * side));
    const double w = 0.02 * side;
    EXPECT_NEAR(body.sim.container.hi[0] - body.sim.container.lo[0], 2.5 * w, 1e-12);
    EXPECT_NEAR(body.sim.container.hi[1] - body.sim.container.lo[1], 1.5 * w, 1e-12);
    EXPECT_NEAR(body.sim.container.hi[2] - body.sim.container.lo[2], w, 1e-12);
    EXPECT_DOUBLE_EQ(body.sim.kernel_radius, 0.04);
    EXPECT_DOUBLE_EQ(body.sim.particle_radius, 0.01);
    EXPECT_DOUBLE_EQ(body.sim.time_step, 4e-4);
  }
}

}  // namespace
}  // namespace sph
