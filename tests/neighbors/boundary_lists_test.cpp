// Boundary lists (fluid particles against static boundary samples): the grid's query lists equal
// brute force, for points inside and far outside the samples' box, in the scalar and vector
// kernels and for any thread count; every strategy keeps them by its own rule (standard and
// verlet never miss a pair within h, adaptive rebuilds a flagged particle's boundary list with
// its fluid list), and the auditor counts the boundary pairs a list misses.

#include <algorithm>
#include <random>
#include <set>

#include <gtest/gtest.h>

#include <sph/core/parallel.h>
#include <sph/neighbors/adaptive.h>
#include <sph/neighbors/audit.h>
#include <sph/neighbors/standard.h>
#include <sph/neighbors/tracked.h>
#include <sph/neighbors/verlet.h>

#include "support/lists.h"

namespace sph {
namespace {

using V3 = Vec<3, double>;
constexpr double kSupport = 0.1;

using test::sorted;

/// Samples on the six faces of the unit cube, two layers, spacing 0.05.
template <std::floating_point R>
std::vector<Vec<3, R>> wall_samples() {
  std::vector<Vec<3, R>> out;
  const int n = 20;
  for (int layer = 0; layer < 2; ++layer)
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b) {
        const R u = static_cast<R>((a + 0.5) / n), v = static_cast<R>((b + 0.5) / n);
        const R lo = static_cast<R>(-0.025 - 0.05 * layer), hi = static_cast<R>(1.025 + 0.05 * layer);
        for (R w : {lo, hi}) {
          out.push_back({{w, u, v}});
          out.push_back({{u, w, v}});
          out.push_back({{u, v, w}});
        }
      }
  return out;
}

template <std::floating_point R>
ParticleSet<3, R> random_particles(std::size_t n, double lo, double hi, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(lo, hi);
  ParticleSet<3, R> ps;
  ps.mass = R(1);
  for (std::size_t i = 0; i < n; ++i)
    ps.add(Vec<3, R>{{static_cast<R>(u(rng)), static_cast<R>(u(rng)), static_cast<R>(u(rng))}}, Vec<3, R>{});
  return ps;
}

template <std::floating_point R>
void expect_equal_lists(const NeighborLists& a, const NeighborLists& b) {
  ASSERT_EQ(a.particle_count(), b.particle_count());
  ASSERT_EQ(a.entry_count(), b.entry_count());
  for (std::size_t i = 0; i < a.particle_count(); ++i) ASSERT_EQ(sorted(a.of(i)), sorted(b.of(i))) << "particle " << i;
}

template <std::floating_point R>
void check_queries_match_brute_force() {
  const auto samples = wall_samples<R>();
  // Particles inside the box, near the walls, and far outside it (clamped to the edge cells).
  const auto ps = random_particles<R>(4000, -0.6, 1.6, 7);
  UniformGrid<3, R> grid;
  grid.build(samples, static_cast<R>(kSupport));
  const NeighborLists bf = brute_force_query_lists<3, R>(ps.position, samples, static_cast<R>(kSupport));
  EXPECT_GT(bf.entry_count(), 1000u);
  for (bool vector : {true, false}) {
    ListBuilder<3, R> builder;
    builder.use_vector_kernel(vector);
    NeighborLists lists;
    builder.build_queries(grid, ps.position, static_cast<R>(kSupport), lists);
    expect_equal_lists<R>(lists, bf);
  }
}

TEST(BoundaryLists, QueriesMatchBruteForceDouble) { check_queries_match_brute_force<double>(); }
TEST(BoundaryLists, QueriesMatchBruteForceFloat) { check_queries_match_brute_force<float>(); }

TEST(BoundaryLists, SameForAnyThreadCount) {
  const auto samples = wall_samples<double>();
  const auto ps = random_particles<double>(5000, 0.0, 1.0, 9);
  const int saved = num_threads();
  std::vector<NeighborLists> out;
  for (int t : {1, 2, 3}) {
    set_num_threads(t);
    StandardNeighbors<3, double> s(kSupport);
    s.set_boundary(samples);
    s.update(ps);
    out.push_back(s.boundary_lists());
  }
  set_num_threads(saved);
  EXPECT_EQ(out[0], out[1]);
  EXPECT_EQ(out[0], out[2]);
}

TEST(BoundaryLists, NoSamplesNoLists) {
  const auto ps = random_particles<double>(100, 0.0, 1.0, 3);
  StandardNeighbors<3, double> s(kSupport);
  s.update(ps);
  EXPECT_EQ(s.boundary_lists().particle_count(), 0u);
  EXPECT_EQ(s.counters().boundary_pairs_stored, 0u);
}

TEST(BoundaryLists, EveryStrategyListsThePairsWithinH) {
  const auto samples = wall_samples<double>();
  auto ps = random_particles<double>(3000, 0.0, 1.0, 11);
  const NeighborLists exact = brute_force_query_lists<3, double>(ps.position, samples, kSupport);
  for (NeighborMode mode : {NeighborMode::Standard, NeighborMode::Adaptive, NeighborMode::Verlet, NeighborMode::Tracked,
                            NeighborMode::AdaptiveExact, NeighborMode::VerletClusters, NeighborMode::BruteForce}) {
    NeighborOptions opt;
    opt.radius = kSupport;
    auto s = make_neighbor_strategy<3, double>(mode, opt);
    s->set_boundary(samples);
    s->update(ps);
    ASSERT_EQ(s->boundary_lists().particle_count(), ps.size()) << to_string(mode);
    EXPECT_EQ(s->counters().boundary_pairs_stored, s->boundary_lists().entry_count()) << to_string(mode);
    ListAuditor<3, double> auditor;
    const ListAudit a = auditor.audit_boundary(ps.position, samples, s->boundary_lists(), kSupport);
    EXPECT_EQ(a.missed_pairs, 0u) << to_string(mode);
    if (mode == NeighborMode::Standard || mode == NeighborMode::Adaptive || mode == NeighborMode::BruteForce) {
      expect_equal_lists<double>(s->boundary_lists(), exact);
    } else {  // h + skin: a superset
      EXPECT_GT(s->boundary_lists().entry_count(), exact.entry_count());
    }
  }
}

TEST(BoundaryLists, VerletNeverMissesWhileParticlesMoveWithinTheSkin) {
  const auto samples = wall_samples<double>();
  auto ps = random_particles<double>(2000, 0.0, 1.0, 12);
  VerletNeighbors<3, double> v(kSupport, 0.2 * kSupport);
  v.set_boundary(samples);
  ListAuditor<3, double> auditor;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.004, 0.004);
  for (int step = 0; step < 30; ++step) {
    for (auto& x : ps.position) x += V3{{u(rng), u(rng), u(rng)}};
    v.update(ps);
    ASSERT_EQ(auditor.audit_boundary(ps.position, samples, v.boundary_lists(), kSupport).missed_pairs, 0u) << step;
  }
}

// The tracked modes rebuild a particle's boundary list with its fluid list (after it moved a
// third of the skin) and index the samples again when a full rebuild chooses another skin.
TEST(BoundaryLists, TrackedNeverMissesWhileParticlesMoveAndTheSkinChanges) {
  const auto samples = wall_samples<double>();
  auto ps = random_particles<double>(2000, 0.0, 1.0, 14);
  TrackedNeighbors<3, double> t(kSupport, 0, 10, 0.1, false);  // automatic skin, full rebuild every 10
  t.set_boundary(samples);
  ListAuditor<3, double> auditor;
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> u(-0.004, 0.004);
  std::set<double> skins;
  for (int step = 0; step < 40; ++step) {
    for (std::size_t i = 0; i < ps.size(); ++i) {
      const V3 dx{{u(rng), u(rng), u(rng)}};
      ps.position[i] += dx;
      ps.velocity[i] = dx * (1.0 + step);  // faster and faster: a larger automatic skin
    }
    t.update(ps);
    skins.insert(t.skin());
    ASSERT_EQ(auditor.audit_boundary(ps.position, samples, t.boundary_lists(), kSupport).missed_pairs, 0u) << step;
    ASSERT_EQ(t.boundary_lists().particle_count(), ps.size());
  }
  EXPECT_GE(skins.size(), 3u) << "the skin was chosen again at the full rebuilds";
}

TEST(BoundaryLists, AdaptiveRebuildsAFlaggedParticlesBoundaryListAndTheAuditSeesTheRest) {
  const auto samples = wall_samples<double>();
  auto ps = random_particles<double>(2000, 0.0, 1.0, 13);
  AdaptiveNeighbors<3, double> a(kSupport, 200);
  a.set_boundary(samples);
  a.update(ps);
  const NeighborLists before = a.boundary_lists();
  // Every particle moves towards the low x wall; none is flagged: nothing is rebuilt, and the
  // audit counts exactly the pairs within h now missing from the old lists.
  for (auto& x : ps.position) x[0] -= 0.03;
  a.update(ps);
  EXPECT_EQ(a.boundary_lists(), before);
  const NeighborLists exact = brute_force_query_lists<3, double>(ps.position, samples, kSupport);
  std::uint64_t missing = 0;
  for (std::size_t i = 0; i < ps.size(); ++i) {
    const auto have = sorted(before.of(i));
    for (std::uint32_t b : exact.of(i)) missing += std::binary_search(have.begin(), have.end(), b) ? 0 : 1;
  }
  EXPECT_GT(missing, 0u);
  ListAuditor<3, double> auditor;
  EXPECT_EQ(auditor.audit_boundary(ps.position, samples, a.boundary_lists(), kSupport).missed_pairs, missing);
  // Flag particle 5 and 1500: their boundary lists become exact, the others stay as they were.
  a.pair_exit_flags()[5] = 1;
  a.pair_exit_flags()[1500] = 1;
  a.update(ps);
  for (std::size_t i = 0; i < ps.size(); ++i) {
    if (i == 5 || i == 1500)
      EXPECT_EQ(sorted(a.boundary_lists().of(i)), sorted(exact.of(i)));
    else
      EXPECT_EQ(sorted(a.boundary_lists().of(i)), sorted(before.of(i)));
  }
}

}  // namespace
}  // namespace sph
