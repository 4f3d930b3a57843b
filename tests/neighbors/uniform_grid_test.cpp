// The grid-built lists equal brute force: random, clustered, on cell boundaries, negative
// coordinates, far outliers; 2D and 3D; float and double.

#include <algorithm>
#include <random>

#include <gtest/gtest.h>

#include <sph/core/error.h>
#include <sph/core/parallel.h>
#include <sph/neighbors/standard.h>

#include "support/lists.h"

namespace sph {
namespace {

using test::sorted;

template <class T>
struct Variant;
template <int D_, class R_>
struct Variant<std::pair<std::integral_constant<int, D_>, R_>> {
  static constexpr int D = D_;
  using R = R_;
};

template <class P>
class GridLists : public ::testing::Test {
 public:
  static constexpr int D = Variant<P>::D;
  using R = typename Variant<P>::R;
  using V = Vec<D, R>;

  void expect_equal_to_brute_force(const std::vector<V>& x, R radius) {
    ParticleSet<D, R> ps;
    ps.mass = R(1);
    for (const V& p : x) ps.add(p, V{});
    StandardNeighbors<D, R> grid(radius);
    grid.update(ps);
    const NeighborLists bf = brute_force_lists<D, R>(ps.position, radius);
    const NeighborLists& gl = grid.lists();
    ASSERT_EQ(gl.particle_count(), x.size());
    ASSERT_EQ(gl.entry_count(), bf.entry_count());
    for (std::size_t i = 0; i < x.size(); ++i) ASSERT_EQ(sorted(gl.of(i)), sorted(bf.of(i))) << "particle " << i;
    EXPECT_EQ(grid.counters().pairs_stored, bf.entry_count());
    EXPECT_EQ(grid.counters().lists_rebuilt, x.size());
  }

  std::vector<V> random_points(std::size_t n, R lo, R hi, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(lo, hi);
    std::vector<V> x(n);
    for (auto& p : x)
      for (int d = 0; d < D; ++d) p[d] = static_cast<R>(u(rng));
    return x;
  }
};

using Variants = ::testing::Types<
    std::pair<std::integral_constant<int, 2>, float>, std::pair<std::integral_constant<int, 2>, double>,
    std::pair<std::integral_constant<int, 3>, float>, std::pair<std::integral_constant<int, 3>, double>>;
TYPED_TEST_SUITE(GridLists, Variants);

TYPED_TEST(GridLists, RandomUniform) { this->expect_equal_to_brute_force(this->random_points(1500, 0, 1, 1), 0.08); }

TYPED_TEST(GridLists, NegativeCoordinates) {
  this->expect_equal_to_brute_force(this->random_points(1500, -3, -1.5, 2), 0.2);
  this->expect_equal_to_brute_force(this->random_points(1500, -1, 1, 3), 0.15);
}

TYPED_TEST(GridLists, Clustered) {
  using V = typename TestFixture::V;
  using R = typename TestFixture::R;
  std::mt19937 rng(4);
  std::normal_distribution<double> g(0, 0.02);
  std::vector<V> x;
  for (int c = 0; c < 5; ++c)
    for (int k = 0; k < 300; ++k) {
      V p;
      for (int d = 0; d < TestFixture::D; ++d) p[d] = static_cast<R>(0.3 * c + g(rng));
      x.push_back(p);
    }
  this->expect_equal_to_brute_force(x, 0.03);
}

TYPED_TEST(GridLists, LatticeOnCellBoundaries) {
  // Points exactly on multiples of the radius, and pairs exactly at the radius (excluded).
  using V = typename TestFixture::V;
  using R = typename TestFixture::R;
  const R radius = R(0.25);
  std::vector<V> x;
  const int n = TestFixture::D == 2 ? 16 : 7;
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b)
      for (int c = 0; c < (TestFixture::D == 3 ? n : 1); ++c) {
        V p;
        p[0] = a * radius - R(1);
        p[1] = b * radius * R(0.5);
        if constexpr (TestFixture::D == 3) p[2] = c * radius;
        x.push_back(p);
      }
  this->expect_equal_to_brute_force(x, radius);
}

TYPED_TEST(GridLists, FarOutlierAndCoincidentPoints) {
  using V = typename TestFixture::V;
  auto x = this->random_points(800, 0, 1, 5);
  V far = V::filled(1e4f);
  x.push_back(far);  // would need 1e15 dense cells: the grid must enlarge its cells
  x.push_back(x[0]);
  x.push_back(x[0]);
  this->expect_equal_to_brute_force(x, 0.05);
}

TYPED_TEST(GridLists, EmptyAndSingle) {
  this->expect_equal_to_brute_force({}, 0.1);
  this->expect_equal_to_brute_force(this->random_points(1, 0, 1, 6), 0.1);
}

TYPED_TEST(GridLists, SameListsForAnyThreadCount) {
  using R = typename TestFixture::R;
  constexpr int D = TestFixture::D;
  ParticleSet<D, R> ps;
  ps.mass = R(1);
  for (const auto& p : this->random_points(5000, 0, 1, 7)) ps.add(p, {});
  set_num_threads(1);
  StandardNeighbors<D, R> one(R(0.05));
  one.update(ps);
  set_num_threads(2);
  StandardNeighbors<D, R> two(R(0.05));
  two.update(ps);
  EXPECT_TRUE(one.lists() == two.lists());
}

TEST(NeighborMode, ParsesNamesAndRejectsOthers) {
  EXPECT_EQ(parse_neighbor_mode("standard"), NeighborMode::Standard);
  EXPECT_EQ(parse_neighbor_mode("adaptive"), NeighborMode::Adaptive);
  EXPECT_EQ(to_string(NeighborMode::Verlet), "verlet");
  EXPECT_THROW(parse_neighbor_mode("fast"), Error);
  NeighborOptions opt;
  opt.radius = 0.1;
  const NeighborMode modes[] = {NeighborMode::Standard, NeighborMode::Adaptive, NeighborMode::Verlet,
                                NeighborMode::BruteForce};
  for (NeighborMode m : modes) EXPECT_EQ((make_neighbor_strategy<3, double>(m, opt)->mode()), m);
}

}  // namespace
}  // namespace sph
