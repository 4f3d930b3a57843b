// The adaptive strategy (Algorithm 2) rebuilds exactly the flagged lists, the verlet strategy
// never misses a pair within h and rebuilds when a particle moved half the skin, and the
// auditor counts missed pairs and their penetration.

#include <algorithm>
#include <random>

#include <gtest/gtest.h>

#include <sph/core/parallel.h>
#include <sph/neighbors/adaptive.h>
#include <sph/neighbors/audit.h>
#include <sph/neighbors/neighbor_mode.h>
#include <sph/neighbors/standard.h>
#include <sph/neighbors/strategy.h>
#include <sph/neighbors/verlet.h>

#include "support/lists.h"
#include "support/thread_count.h"

namespace sph {
namespace {

using V3 = Vec<3, double>;

using test::sorted;

ParticleSet<3, double> random_particles(std::size_t n, double extent, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, extent);
  ParticleSet<3, double> ps;
  ps.mass = 1.0;
  for (std::size_t i = 0; i < n; ++i) ps.add(V3{u(rng), u(rng), u(rng)}, V3{});
  return ps;
}

void jitter(ParticleSet<3, double>& ps, double amount, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-amount, amount);
  for (auto& x : ps.position) x += V3{u(rng), u(rng), u(rng)};
}

using test::ThreadCount;

constexpr double kRadius = 0.1;

// NeighborStrategy::scratch_until_update: memory the solver may overwrite between updates (the
// force pass's copy of 1 / rho and p). Every strategy with a grid but verlet_clusters lends its grid's; the
// lists of the updates after it is filled with garbage (NaN coordinates, indices past the
// particles) equal those of the same strategy left alone, full and partial rebuilds included.
TEST(NeighborStrategy, LentScratchIsNotReadByTheNextUpdates) {
  for (NeighborMode mode : neighbor_modes(NeighborModeSet::All)) {
    SCOPED_TRACE(to_string(mode));
    NeighborOptions opt;
    opt.radius = kRadius;
    opt.full_rebuild_period = 3;
    opt.time_step = 1e-3;
    const auto lent = make_neighbor_strategy<3, double>(mode, opt);
    const auto kept = make_neighbor_strategy<3, double>(mode, opt);
    auto ps = random_particles(2000, 1.0, 7);
    for (int step = 0; step < 8; ++step) {
      for (NeighborStrategy<3, double>* s : {lent.get(), kept.get()}) {
        // (adaptive: a partial rebuild of every seventh list between the full ones)
        const std::span<std::uint8_t> flags = s->pair_exit_flags();
        for (std::size_t i = 0; i < flags.size(); i += 7) flags[i] = 1;
        s->update(ps);
      }
      ScratchBuffer* scratch = lent->scratch_until_update();
      // (brute_force has no grid to lend)
      ASSERT_EQ(scratch != nullptr, lent->fluid_grid() != nullptr && mode != NeighborMode::VerletClusters);
      const NeighborLists& a = lent->lists();
      const NeighborLists& b = kept->lists();
      ASSERT_EQ(a.particle_count(), ps.size());
      for (std::size_t i = 0; i < ps.size(); ++i) ASSERT_TRUE(std::ranges::equal(a.of(i), b.of(i))) << "step " << step;
      if (scratch) {
        ASSERT_GE(scratch->capacity(), 2 * ps.size() * sizeof(double));
        std::uint8_t* bytes = scratch->place<std::uint8_t>(0, scratch->capacity());
        std::fill_n(bytes, scratch->capacity(), std::uint8_t{0xff});
      }
      jitter(ps, 0.03 * kRadius, 100 + static_cast<unsigned>(step));
    }
  }
}

TEST(Adaptive, FirstUpdateBuildsEveryListExactly) {
  auto ps = random_particles(3000, 1.0, 1);
  AdaptiveNeighbors<3, double> a(kRadius, 200);
  a.update(ps);
  const NeighborLists bf = brute_force_lists<3, double>(ps.position, kRadius);
  EXPECT_EQ(a.counters().lists_rebuilt, ps.size());
  ASSERT_EQ(a.lists().entry_count(), bf.entry_count());
  for (std::size_t i = 0; i < ps.size(); ++i) ASSERT_EQ(sorted(a.lists().of(i)), sorted(bf.of(i)));
  ASSERT_EQ(a.pair_exit_flags().size(), ps.size());
  EXPECT_TRUE(std::all_of(a.pair_exit_flags().begin(), a.pair_exit_flags().end(), [](auto f) { return f == 0; }));
}

TEST(Adaptive, RebuildsOnlyFlaggedListsAndKeepsTheOthers) {
  auto ps = random_particles(3000, 1.0, 2);
  AdaptiveNeighbors<3, double> a(kRadius, 200);
  a.update(ps);
  const NeighborLists before = a.lists();

  // Nothing flagged: the particles moved, but no list changes and nothing is rebuilt.
  jitter(ps, 0.02, 3);
  a.update(ps);
  EXPECT_EQ(a.counters().lists_rebuilt, 0u);
  EXPECT_EQ(a.lists(), before);

  // Flag a few: exactly their lists are rebuilt, at the current positions.
  const std::vector<std::size_t> flagged{0, 17, 1023, 1024, 2999};
  for (std::size_t i : flagged) a.pair_exit_flags()[i] = 1;
  a.update(ps);
  EXPECT_EQ(a.counters().lists_rebuilt, flagged.size());
  const NeighborLists now = brute_force_lists<3, double>(ps.position, kRadius);
  std::size_t changed = 0;
  for (std::size_t i = 0; i < ps.size(); ++i) {
    const bool is_flagged = std::find(flagged.begin(), flagged.end(), i) != flagged.end();
    if (is_flagged) {
      EXPECT_EQ(sorted(a.lists().of(i)), sorted(now.of(i))) << "flagged particle " << i;
      changed += sorted(before.of(i)) != sorted(now.of(i));
    } else {
      ASSERT_EQ(sorted(a.lists().of(i)), sorted(before.of(i))) << "unflagged particle " << i << " changed";
    }
  }
  EXPECT_GT(changed, 0u) << "the jitter should have changed some flagged lists (else the test proves nothing)";
  EXPECT_TRUE(std::all_of(a.pair_exit_flags().begin(), a.pair_exit_flags().end(), [](auto f) { return f == 0; }))
      << "flags are cleared by the update that consumed them";
}

TEST(Adaptive, AppendedParticlesGetListsAndFullRebuildComesOnSchedule) {
  auto ps = random_particles(500, 0.5, 4);
  AdaptiveNeighbors<3, double> a(kRadius, 3);
  a.update(ps);  // update 0: full
  for (int k = 0; k < 20; ++k) ps.add(V3{0.25 + 0.001 * k, 0.25, 0.25}, V3{});
  a.update(ps);  // update 1: only the 20 new particles
  EXPECT_EQ(a.counters().lists_rebuilt, 20u);
  ASSERT_EQ(a.lists().particle_count(), ps.size());
  const NeighborLists bf = brute_force_lists<3, double>(ps.position, kRadius);
  for (std::size_t i = 500; i < ps.size(); ++i) EXPECT_EQ(sorted(a.lists().of(i)), sorted(bf.of(i)));
  a.update(ps);  // update 2: nothing flagged
  EXPECT_EQ(a.counters().lists_rebuilt, 0u);
  jitter(ps, 0.01, 5);
  a.update(ps);  // update 3: the period's full rebuild
  EXPECT_EQ(a.counters().lists_rebuilt, ps.size());
  const NeighborLists bf2 = brute_force_lists<3, double>(ps.position, kRadius);
  for (std::size_t i = 0; i < ps.size(); ++i) ASSERT_EQ(sorted(a.lists().of(i)), sorted(bf2.of(i)));
}

TEST(Adaptive, PartialRebuildIsIdenticalForAnyThreadCount) {
  ThreadCount restore;
  NeighborLists result[2];
  for (int t : {1, 2}) {
    set_num_threads(t);
    auto ps = random_particles(5000, 1.0, 6);
    AdaptiveNeighbors<3, double> a(kRadius, 200);
    a.update(ps);
    jitter(ps, 0.02, 7);
    for (std::size_t i = 0; i < ps.size(); i += 7) a.pair_exit_flags()[i] = 1;
    a.update(ps);
    result[t - 1] = a.lists();
  }
  EXPECT_EQ(result[0], result[1]);
}

TEST(Verlet, NeverMissesAPairWithinHAndRebuildsAtHalfTheSkin) {
  auto ps = random_particles(2000, 1.0, 8);
  const double skin = 0.02;
  VerletNeighbors<3, double> v(kRadius, skin);
  ListAuditor<3, double> auditor;
  v.update(ps);
  EXPECT_EQ(v.counters().lists_rebuilt, ps.size());
  // Lists hold exactly the pairs within h + skin.
  const NeighborLists wide = brute_force_lists<3, double>(ps.position, kRadius + skin);
  for (std::size_t i = 0; i < ps.size(); ++i) ASSERT_EQ(sorted(v.lists().of(i)), sorted(wide.of(i)));

  // Random small moves: rebuilds happen only after someone moved skin / 2, and nothing within
  // h is ever missed in between.
  int rebuilds = 0, reuses = 0;
  std::vector<V3> built = ps.position;
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-0.002, 0.002);
  for (int step = 0; step < 40; ++step) {
    for (auto& x : ps.position) x += V3{u(rng), u(rng), u(rng)};
    double max_move = 0;
    for (std::size_t i = 0; i < ps.size(); ++i) max_move = std::max(max_move, norm(ps.position[i] - built[i]));
    v.update(ps);
    if (v.counters().lists_rebuilt > 0) {
      ++rebuilds;
      EXPECT_GT(max_move, 0.4999 * skin) << "rebuilt before any particle moved skin / 2";
      built = ps.position;
    } else {
      ++reuses;
      EXPECT_LE(max_move, 0.5 * skin);
    }
    const ListAudit audit = auditor.audit(ps.position, v.lists(), kRadius);
    ASSERT_EQ(audit.missed_pairs, 0u) << "step " << step;
  }
  EXPECT_GT(rebuilds, 0);
  EXPECT_GT(reuses, rebuilds) << "the skin should let most steps reuse the lists";
}

TEST(Verlet, RebuildsWhenParticlesAreAdded) {
  auto ps = random_particles(300, 0.5, 10);
  VerletNeighbors<3, double> v(kRadius, 0.02);
  v.update(ps);
  v.update(ps);
  EXPECT_EQ(v.counters().lists_rebuilt, 0u);
  ps.add(V3{0.25, 0.25, 0.25}, V3{});
  v.update(ps);
  EXPECT_EQ(v.counters().lists_rebuilt, ps.size());
  EXPECT_EQ(v.lists().particle_count(), ps.size());
}

TEST(Audit, CountsMissedPairsAndTheirPenetration) {
  ParticleSet<3, double> ps;
  ps.mass = 1.0;
  ps.add(V3{0, 0, 0}, V3{});
  ps.add(V3{0.03, 0, 0}, V3{});  // 0.3 h from particle 0
  ps.add(V3{0, 0.08, 0}, V3{});  // 0.8 h from particle 0
  ps.add(V3{1, 1, 1}, V3{});     // alone
  ListAuditor<3, double> auditor;
  const NeighborLists exact = brute_force_lists<3, double>(ps.position, kRadius);
  EXPECT_EQ(auditor.audit(ps.position, exact, kRadius).missed_pairs, 0u);

  // Particle 0 lists only particle 2; particle 1 lists nothing; particle 2 lists 0.
  const NeighborLists lists = NeighborLists::from({{2}, {}, {0}, {}});
  const ListAudit a = auditor.audit(ps.position, lists, kRadius);
  // Missed: 0->1 and 1->0 (r = 0.3 h, penetration 0.7), 2->1? |(0,0.08)-(0.03,0)| = 0.0854 < h: 2->1 and 1->2.
  EXPECT_EQ(a.missed_pairs, 4u);
  EXPECT_EQ(a.particles_missing, 3u);
  EXPECT_NEAR(a.max_penetration, 0.7, 1e-12);
}

TEST(Audit, FindsWhatAdaptiveListsMissWhenParticlesApproach) {
  // Two particles out of range, approaching: no listed pair leaves, so nothing is flagged and
  // the adaptive lists keep missing the pair until the full rebuild.
  ParticleSet<3, double> ps;
  ps.mass = 1.0;
  ps.add(V3{0, 0, 0}, V3{});
  ps.add(V3{0.15, 0, 0}, V3{});
  AdaptiveNeighbors<3, double> a(kRadius, 200);
  ListAuditor<3, double> auditor;
  a.update(ps);
  EXPECT_EQ(a.lists().entry_count(), 0u);
  ps.position[1][0] = 0.05;
  a.update(ps);
  const ListAudit audit = auditor.audit(ps.position, a.lists(), kRadius);
  EXPECT_EQ(audit.missed_pairs, 2u);
  EXPECT_NEAR(audit.max_penetration, 0.5, 1e-12);
}

}  // namespace
}  // namespace sph
