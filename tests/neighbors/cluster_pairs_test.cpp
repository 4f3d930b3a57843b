// Cluster pairs (verlet_clusters): every pair of particles closer than the radius lies in a listed
// pair of clusters, each particle sits in exactly one slot, clusters are compact enough that the
// lanes they cost stay a small multiple of the pairs, the build does not depend on the thread
// count, and the strategy never lets a pair within h slip between its rebuilds.

#include <algorithm>
#include <random>
#include <set>
#include <sstream>

#include <gtest/gtest.h>

#include <sph/core/parallel.h>
#include <sph/core/state_stream.h>
#include <sph/neighbors/audit.h>
#include <sph/neighbors/cluster_pairs.h>
#include <sph/neighbors/list_builder.h>
#include <sph/neighbors/standard.h>
#include <sph/neighbors/strategy.h>
#include <sph/neighbors/verlet.h>

#include "support/thread_count.h"

namespace sph {
namespace {

using test::ThreadCount;

template <int D, class R>
std::vector<Vec<D, R>> random_points(std::size_t n, double extent, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, extent);
  std::vector<Vec<D, R>> x(n);
  for (auto& p : x)
    for (int d = 0; d < D; ++d) p[d] = static_cast<R>(u(rng));
  return x;
}

/// A jittered lattice of spacing dx: side^D points.
template <int D, class R>
std::vector<Vec<D, R>> lattice(int side, double dx, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.1 * dx, 0.1 * dx);
  std::vector<Vec<D, R>> x;
  const int nz = D == 3 ? side : 1;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < side; ++j)
      for (int i = 0; i < side; ++i) {
        Vec<D, R> p;
        p[0] = static_cast<R>(i * dx + u(rng));
        p[1] = static_cast<R>(j * dx + u(rng));
        if constexpr (D == 3) p[2] = static_cast<R>(k * dx + u(rng));
        x.push_back(p);
      }
  return x;
}

template <int D, class R>
ClusterPairs<D, R> build(std::span<const Vec<D, R>> x, R radius) {
  UniformGrid<D, R> grid;
  grid.build(x, radius);
  ClusterPairs<D, R> cp;
  cp.build(grid, x, radius);
  return cp;
}

/// Every promise of ClusterPairs on one point set; returns the lanes per pair within the radius.
template <int D, class R>
double expect_cluster_pairs_cover(std::span<const Vec<D, R>> x, R radius) {
  const ClusterPairs<D, R> cp = build<D, R>(x, radius);
  constexpr int S = ClusterPairs<D, R>::kSize;
  EXPECT_EQ(cp.particle_count(), x.size());
  // Every particle in exactly one slot, and cluster_of says which.
  std::vector<int> seen(x.size(), 0);
  for (std::size_t s = 0; s < cp.slots().size(); ++s) {
    const std::uint32_t i = cp.slots()[s];
    if (i == ClusterPairs<D, R>::kEmpty) continue;
    EXPECT_LT(i, x.size());
    ++seen[i];
    EXPECT_EQ(cp.cluster_of(i), s / S);
  }
  for (std::size_t i = 0; i < x.size(); ++i) EXPECT_EQ(seen[i], 1) << "particle " << i;
  // No cluster is empty: its first slot holds a particle.
  constexpr std::uint32_t kEmpty = ClusterPairs<D, R>::kEmpty;
  for (std::size_t c = 0; c < cp.cluster_count(); ++c) EXPECT_NE(cp.slots()[c * S], kEmpty);
  // Lists: symmetric, no repeats, each holds its own cluster.
  std::set<std::pair<std::uint32_t, std::uint32_t>> listed;
  for (std::size_t c = 0; c < cp.cluster_count(); ++c)
    for (std::uint32_t d : cp.of(c)) EXPECT_TRUE(listed.insert({static_cast<std::uint32_t>(c), d}).second);
  EXPECT_EQ(listed.size(), cp.pair_count());
  for (const auto& [c, d] : listed) EXPECT_TRUE(listed.count({d, c})) << c << " lists " << d << " but not back";
  for (std::size_t c = 0; c < cp.cluster_count(); ++c)
    EXPECT_TRUE(listed.count({static_cast<std::uint32_t>(c), static_cast<std::uint32_t>(c)}));
  // Every pair within the radius is in a listed cluster pair (exact lists: brute force for small
  // sets, else the list builder, itself tested against brute force).
  NeighborLists exact;
  if (x.size() <= 5000) {
    exact = brute_force_lists<D, R>(x, radius);
  } else {
    UniformGrid<D, R> grid;
    grid.build(x, radius);
    ListBuilder<D, R>().build(grid, x, radius, exact);
  }
  std::size_t missed = 0;
  for (std::size_t i = 0; i < x.size(); ++i)
    for (std::uint32_t j : exact.of(i)) missed += listed.count({cp.cluster_of(i), cp.cluster_of(j)}) ? 0 : 1;
  EXPECT_EQ(missed, 0u);
  return static_cast<double>(cp.pair_count() * S * S) /
         static_cast<double>(std::max<std::size_t>(1, exact.entry_count()));
}

TEST(ClusterPairs, EveryPairWithinTheRadiusIsInAListedClusterPair) {
  expect_cluster_pairs_cover<3, double>(random_points<3, double>(3000, 1.0, 1), 0.08);
  expect_cluster_pairs_cover<3, float>(random_points<3, float>(3000, 1.0, 2), 0.08f);
  expect_cluster_pairs_cover<2, double>(random_points<2, double>(3000, 1.0, 3), 0.03);
  expect_cluster_pairs_cover<2, float>(random_points<2, float>(3000, 1.0, 4), 0.03f);
  // A radius of many columns: the neighbor columns beyond the build's window of cursors.
  expect_cluster_pairs_cover<3, float>(random_points<3, float>(2000, 1.0, 17), 0.6f);
  expect_cluster_pairs_cover<2, double>(random_points<2, double>(2000, 1.0, 18), 0.2);
}

TEST(ClusterPairs, CoversClumpsCoincidentPointsAndAStrayParticle) {
  // Two dense clumps, a few coincident points, a line, and one particle very far away: the
  // columns widen (no column per empty metre), and nothing is missed.
  auto x = random_points<3, double>(800, 0.2, 5);
  for (const auto& p : random_points<3, double>(800, 0.05, 6)) x.push_back(p + Vec<3, double>{0.5, 0.5, 0.5});
  for (int k = 0; k < 6; ++k) x.push_back(Vec<3, double>{0.1, 0.1, 0.1});
  for (int k = 0; k < 50; ++k) x.push_back(Vec<3, double>{0.3 + 0.004 * k, 0.3, 0.3});
  x.push_back(Vec<3, double>{1e4, -1e4, 3e3});
  expect_cluster_pairs_cover<3, double>(x, 0.03);
  // 2D, and the smallest sets.
  expect_cluster_pairs_cover<2, float>(random_points<2, float>(1, 1.0, 7), 0.1f);
  expect_cluster_pairs_cover<2, float>(random_points<2, float>(5, 1.0, 8), 0.1f);
  expect_cluster_pairs_cover<3, double>(random_points<3, double>(2, 0.01, 9), 0.1);
  const ClusterPairs<3, double> none = build<3, double>(std::span<const Vec<3, double>>{}, 0.1);
  EXPECT_EQ(none.cluster_count(), 0u);
  EXPECT_EQ(none.pair_count(), 0u);
}

TEST(ClusterPairs, ClustersOfALatticeAreCompact) {
  // h = 2 spacings and a tenth of skin, as the bench's dam break: the lanes of the cluster pairs
  // are 4.6 (3D) and 2.7 (2D) times the pairs within the radius on these lattices. Columns half
  // or twice as wide (long thin clusters, or flat ones) cost 5.1 to 7.0 (3D) and 3.3 to 4.0 (2D).
  const double dx = 0.02, r = 2.2 * dx;
  EXPECT_LT((expect_cluster_pairs_cover<3, float>(lattice<3, float>(40, dx, 10), static_cast<float>(r))), 5.0);
  EXPECT_LT((expect_cluster_pairs_cover<2, float>(lattice<2, float>(120, dx, 10), static_cast<float>(r))), 3.0);
}

TEST(ClusterPairs, TheBuildIsTheSameForAnyThreadCount) {
  ThreadCount restore;
  const auto x = random_points<3, float>(5000, 1.0, 12);
  set_num_threads(1);
  const ClusterPairs<3, float> one = build<3, float>(x, 0.05f);
  set_num_threads(3);
  const ClusterPairs<3, float> three = build<3, float>(x, 0.05f);
  ASSERT_TRUE(std::ranges::equal(one.slots(), three.slots()));
  ASSERT_EQ(one.cluster_count(), three.cluster_count());
  for (std::size_t c = 0; c < one.cluster_count(); ++c) ASSERT_TRUE(std::ranges::equal(one.of(c), three.of(c)));
}

TEST(VerletClusters, NeverMissesAPairWithinHAndKeepsVerletsListsForWhoAsks) {
  // Random small moves, as verlet's own test: rebuilt only after a particle moved half the skin,
  // the cluster pairs cover every pair within h at every step, and lists() are verlet's lists.
  const double h = 0.1, skin = 0.02;
  auto x = random_points<3, double>(2000, 1.0, 13);
  ParticleSet<3, double> ps;
  ps.mass = 1.0;
  for (const auto& p : x) ps.add(p, {});
  VerletNeighbors<3, double> clusters(h, skin, true), verlet(h, skin);
  EXPECT_EQ(clusters.mode(), NeighborMode::VerletClusters);
  ASSERT_NE(clusters.cluster_pairs(), nullptr);
  EXPECT_EQ(verlet.cluster_pairs(), nullptr);
  ListAuditor<3, double> auditor;
  std::mt19937 rng(14);
  std::uniform_real_distribution<double> u(-0.002, 0.002);
  int rebuilds = 0;
  for (int step = 0; step < 40; ++step) {
    if (step > 0)
      for (auto& p : ps.position) p += Vec<3, double>{u(rng), u(rng), u(rng)};
    clusters.update(ps);
    verlet.update(ps);
    ASSERT_EQ(clusters.counters().lists_rebuilt, verlet.counters().lists_rebuilt) << "step " << step;
    rebuilds += clusters.counters().lists_rebuilt > 0 ? 1 : 0;
    EXPECT_EQ(clusters.counters().pairs_stored, clusters.cluster_pairs()->pair_count() * 16);
    const ListAudit a = auditor.audit_clusters(ps.position, *clusters.cluster_pairs(), h);
    ASSERT_EQ(a.missed_pairs, 0u) << "step " << step;
    if (step % 10 == 0) {
      ASSERT_TRUE(clusters.lists() == verlet.lists()) << "step " << step;
    }
  }
  EXPECT_GT(rebuilds, 1);
  EXPECT_LT(rebuilds, 30);
}

TEST(VerletClusters, TheAuditSeesAPairTheClustersMiss) {
  // Two particles in different clusters, far apart when the clusters were built, then moved on
  // top of each other without a rebuild: the cluster audit counts the pair, both ways.
  const double h = 0.1;
  std::vector<Vec<3, double>> x = random_points<3, double>(400, 1.0, 15);
  x[0] = {0.05, 0.05, 0.05};
  x[1] = {0.95, 0.95, 0.95};
  const ClusterPairs<3, double> cp = build<3, double>(x, h);
  x[1] = x[0] + Vec<3, double>{0.01, 0, 0};
  ListAuditor<3, double> auditor;
  const ListAudit a = auditor.audit_clusters(x, cp, h);
  EXPECT_GE(a.missed_pairs, 2u);
  EXPECT_GT(a.max_penetration, 0.8);
}

TEST(VerletClusters, LoadingItsStateRebuildsTheSameClusters) {
  auto x = random_points<2, float>(1500, 1.0, 16);
  ParticleSet<2, float> ps;
  ps.mass = 1.0f;
  for (const auto& p : x) ps.add(p, {});
  NeighborOptions opt;
  opt.radius = 0.04;
  auto a = make_neighbor_strategy<2, float>(NeighborMode::VerletClusters, opt);
  a->update(ps);
  std::stringstream bytes;
  StateWriter out(bytes);
  a->save_state(out);
  auto b = make_neighbor_strategy<2, float>(NeighborMode::VerletClusters, opt);
  StateReader in(bytes, bytes.str().size(), "test");
  b->load_state(in, ps.size());
  ASSERT_NE(b->cluster_pairs(), nullptr);
  EXPECT_TRUE(std::ranges::equal(a->cluster_pairs()->slots(), b->cluster_pairs()->slots()));
  for (std::size_t c = 0; c < a->cluster_pairs()->cluster_count(); ++c)
    ASSERT_TRUE(std::ranges::equal(a->cluster_pairs()->of(c), b->cluster_pairs()->of(c)));
  EXPECT_TRUE(a->lists() == b->lists());
}

}  // namespace
}  // namespace sph
