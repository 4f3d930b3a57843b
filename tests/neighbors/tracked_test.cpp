// The tracked modes: lists are symmetric, hold every pair within h after any motion (the proof's
// invariant, on adversarial motions), rebuild only the particles that moved a third of the skin
// (or that Eq. 7 flagged, in adaptive_exact), and give the same lists for any thread count and
// after a save and load.

#include <algorithm>
#include <random>
#include <sstream>

#include <gtest/gtest.h>

#include <sph/core/parallel.h>
#include <sph/core/state_stream.h>
#include <sph/neighbors/standard.h>
#include <sph/neighbors/tracked.h>

#include "support/thread_count.h"

namespace sph {
namespace {

using V3 = Vec<3, double>;
using V2 = Vec<2, double>;

constexpr double kH = 0.1;
constexpr double kSkin = 0.02;

using test::ThreadCount;

template <int D>
ParticleSet<D, double> random_particles(std::size_t n, double extent, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, extent);
  ParticleSet<D, double> ps;
  ps.mass = 1.0;
  for (std::size_t i = 0; i < n; ++i) {
    Vec<D, double> x;
    for (int d = 0; d < D; ++d) x[d] = u(rng);
    ps.add(x, Vec<D, double>{});
  }
  return ps;
}

/// Every pair within h is listed both ways, the lists are symmetric, without self or
/// duplicates, and hold only pairs within h + skin + the motion allowed since (3 triggers).
template <int D>
void expect_exact(const TrackedNeighbors<D, double>& t, const ParticleSet<D, double>& ps, const std::string& when,
                  double reach = 0) {
  SCOPED_TRACE(when);
  const NeighborLists& l = t.lists();
  ASSERT_EQ(l.particle_count(), ps.size());
  ASSERT_TRUE(l.padding_is_valid());
  const NeighborLists exact = brute_force_lists<D, double>(ps.position, kH);
  std::vector<std::vector<std::uint32_t>> sorted(ps.size());
  std::size_t entries = 0;
  for (std::size_t i = 0; i < ps.size(); ++i) {
    const auto s = l.of(i);
    sorted[i].assign(s.begin(), s.end());
    std::sort(sorted[i].begin(), sorted[i].end());
    entries += s.size();
    ASSERT_EQ(std::adjacent_find(sorted[i].begin(), sorted[i].end()), sorted[i].end()) << "a duplicate in list " << i;
    ASSERT_FALSE(std::binary_search(sorted[i].begin(), sorted[i].end(), static_cast<std::uint32_t>(i)));
  }
  EXPECT_EQ(entries, l.entry_count());
  if (reach == 0) reach = kH + t.skin() + 3 * t.trigger();
  for (std::size_t i = 0; i < ps.size(); ++i) {
    for (const std::uint32_t j : exact.of(i))
      ASSERT_TRUE(std::binary_search(sorted[i].begin(), sorted[i].end(), j)) << "pair " << i << "-" << j << " missed";
    for (const std::uint32_t j : sorted[i]) {
      ASSERT_TRUE(std::binary_search(sorted[j].begin(), sorted[j].end(), static_cast<std::uint32_t>(i)))
          << "lists not symmetric: " << i << " lists " << j;
      ASSERT_LT(std::sqrt(norm2(ps.position[i] - ps.position[j])), reach) << "a pair far beyond the lists' reach";
    }
  }
}

TEST(Tracked, FirstUpdateListsThePairsWithinHPlusSkin) {
  auto ps = random_particles<3>(2500, 1.0, 1);
  TrackedNeighbors<3, double> t(kH, kSkin, 200, 1e-3, false);
  t.update(ps);
  const NeighborLists wide = brute_force_lists<3, double>(ps.position, kH + kSkin);
  EXPECT_EQ(t.counters().lists_rebuilt, ps.size());
  ASSERT_EQ(t.lists().entry_count(), wide.entry_count());
  for (std::size_t i = 0; i < ps.size(); ++i) {
    std::vector<std::uint32_t> a(t.lists().of(i).begin(), t.lists().of(i).end());
    std::vector<std::uint32_t> b(wide.of(i).begin(), wide.of(i).end());
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    ASSERT_EQ(a, b);
    EXPECT_GE(t.lists().capacity(i), t.lists().of(i).size() + 4);  // room of its own
  }
  EXPECT_EQ(t.counters().skin, kSkin);
  EXPECT_TRUE(t.pair_exit_flags().empty());
}

TEST(Tracked, RebuildsOnlyTheParticlesThatMovedAThirdOfTheSkin) {
  auto ps = random_particles<3>(2000, 1.0, 2);
  TrackedNeighbors<3, double> t(kH, kSkin, 200, 1e-3, false);
  t.update(ps);
  ps.position[10] += V3{0.9 * t.trigger(), 0, 0};  // under the trigger: kept
  t.update(ps);
  EXPECT_EQ(t.counters().lists_rebuilt, 0u);
  ps.position[10] += V3{0.2 * t.trigger(), 0, 0};  // 1.1 triggers from its build: rebuilt
  ps.position[20] += V3{0, -1.5 * t.trigger(), 0};
  t.update(ps);
  EXPECT_EQ(t.counters().lists_rebuilt, 2u);
  expect_exact(t, ps, "after two rebuilds");
  t.update(ps);  // their builds moved with them: nothing to rebuild
  EXPECT_EQ(t.counters().lists_rebuilt, 0u);
}

// The proof's worst case: two particles closing head-on, each just under the trigger per step
// (so that each is rebuilt every other step), through a resting lattice.
TEST(Tracked, TwoParticlesApproachingHeadOnAreNeverMissed) {
  ParticleSet<3, double> ps;
  ps.mass = 1.0;
  for (int a = 0; a < 12; ++a)
    for (int b = 0; b < 12; ++b)
      for (int c = 0; c < 12; ++c) ps.add(V3{0.05 * a, 0.05 * b, 0.05 * c} + V3::filled(0.0123), V3{});
  const std::size_t p = ps.size(), q = p + 1;
  ps.add(V3{0.03, 0.301, 0.302}, V3{});
  ps.add(V3{0.58, 0.302, 0.301}, V3{});
  TrackedNeighbors<3, double> t(kH, kSkin, 1000, 1e-3, false);
  t.update(ps);
  const double step = 0.999 * t.trigger();
  bool met = false;
  for (int s = 0; s < 400 && ps.position[p][0] < 0.58; ++s) {
    ps.position[p] += V3{step, 0, 0};
    ps.position[q] -= V3{step, 0, 0};
    t.update(ps);
    met = met || norm2(ps.position[p] - ps.position[q]) < kH * kH;
    expect_exact(t, ps, "step " + std::to_string(s));
    if (HasFatalFailure()) return;
    EXPECT_LE(t.counters().lists_rebuilt, 2u);  // only the two movers
  }
  EXPECT_TRUE(met);
}

// A fast particle crossing a resting cluster, several triggers per step, and random jumps of
// other particles: every step's lists are exact.
TEST(Tracked, AParticleCrossingAClusterAndRandomJumpsAreNeverMissed) {
  auto ps = random_particles<3>(1500, 0.5, 3);
  const std::size_t fast = ps.size();
  ps.add(V3{-0.1, 0.25, 0.25}, V3{});
  TrackedNeighbors<3, double> t(kH, kSkin, 1000, 1e-3, false);
  t.update(ps);
  std::mt19937 rng(4);
  std::uniform_int_distribution<std::size_t> who(0, fast - 1);
  std::uniform_real_distribution<double> u(-1, 1);
  std::uint64_t insertions = 0, removals = 0;
  for (int s = 0; s < 60; ++s) {
    ps.position[fast] += V3{0.013, 0.0005 * u(rng), 0};
    for (int k = 0; k < 20; ++k) ps.position[who(rng)] += V3{u(rng), u(rng), u(rng)} * (0.6 * t.trigger());
    t.update(ps);
    insertions += t.counters().insertions;
    removals += t.counters().removals;
    expect_exact(t, ps, "step " + std::to_string(s));
    if (HasFatalFailure()) return;
    EXPECT_LT(t.counters().lists_rebuilt, 40u);
  }
  EXPECT_GT(insertions, 100u);  // the fast particle entered many lists and left them
  EXPECT_GT(removals, 100u);
}

// An emitter next to a pool at rest: only the new particles are built, the pool's lists gain
// them by insertion, and no pair is missed (2D).
TEST(Tracked, EmissionNextToARestingPoolInsertsTheNewParticles) {
  ParticleSet<2, double> ps;
  ps.mass = 1.0;
  for (int a = 0; a < 40; ++a)
    for (int b = 0; b < 20; ++b) ps.add(V2{0.025 * a, 0.025 * b}, V2{});
  TrackedNeighbors<2, double> t(kH, kSkin, 1000, 1e-3, false);
  t.update(ps);
  for (int s = 0; s < 5; ++s) {
    const std::size_t before = ps.size();
    for (int a = 0; a < 10; ++a) ps.add(V2{0.3 + 0.025 * a, 0.5 + 0.025 * s}, V2{});
    t.update(ps);
    EXPECT_EQ(t.counters().lists_rebuilt, ps.size() - before);
    EXPECT_GT(t.counters().insertions, 0u);
    expect_exact(t, ps, "emission " + std::to_string(s));
  }
}

// A resting particle that many others crowd into: its list outgrows its room, its chunk is laid
// out again, and the lists stay exact.
TEST(Tracked, AListThatOutgrowsItsRoomIsLaidOutAgain) {
  ParticleSet<2, double> ps;
  ps.mass = 1.0;
  ps.add(V2{0.5, 0.5}, V2{});
  for (int k = 0; k < 60; ++k) ps.add(V2{0.5 + 0.3 * std::cos(k * 0.1047), 0.5 + 0.3 * std::sin(k * 0.1047)}, V2{});
  TrackedNeighbors<2, double> t(kH, kSkin, 1000, 1e-3, false);
  t.update(ps);
  ASSERT_EQ(t.lists().of(0).size(), 0u);
  std::uint64_t overflows = 0;
  for (int s = 0; s < 12; ++s) {
    for (std::size_t k = 1; k < ps.size(); ++k) ps.position[k] = V2{0.5, 0.5} + (ps.position[k] - V2{0.5, 0.5}) * 0.85;
    t.update(ps);
    overflows += t.counters().overflows;
    expect_exact(t, ps, "squeeze " + std::to_string(s));
  }
  EXPECT_GT(overflows, 0u);
  EXPECT_EQ(t.lists().of(0).size(), ps.size() - 1);
}

std::vector<NeighborCounters> run_sequence(TrackedNeighbors<3, double>& t, ParticleSet<3, double>& ps, int from,
                                           int to) {
  std::vector<NeighborCounters> out;
  for (int s = from; s < to; ++s) {
    std::mt19937 rng(100 + static_cast<unsigned>(s));
    std::uniform_real_distribution<double> u(-1, 1);
    for (auto& x : ps.position) x += V3{u(rng), u(rng), u(rng)} * (0.25 * t.trigger());
    if (s % 7 == 3)
      for (int k = 0; k < 30; ++k) ps.add(V3{0.4 + 0.01 * k, 0.5, 0.5}, V3{});
    if (!t.pair_exit_flags().empty())
      for (std::size_t i = static_cast<std::size_t>(s); i < t.pair_exit_flags().size(); i += 97)
        t.pair_exit_flags()[i] = 1;  // the solver's Eq. 7 flags, of the particles the last update saw
    t.update(ps);
    out.push_back(t.counters());
  }
  return out;
}

bool same_counts(const std::vector<NeighborCounters>& a, const std::vector<NeighborCounters>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t k = 0; k < a.size(); ++k)
    if (a[k].lists_rebuilt != b[k].lists_rebuilt || a[k].pairs_stored != b[k].pairs_stored ||
        a[k].insertions != b[k].insertions || a[k].removals != b[k].removals || a[k].overflows != b[k].overflows ||
        a[k].entries_rebuilt != b[k].entries_rebuilt)
      return false;
  return true;
}

TEST(Tracked, SameListsInTheSameOrderForAnyThreadCount) {
  ThreadCount keep;
  for (const bool exit_test : {false, true}) {
    SCOPED_TRACE(exit_test ? "adaptive_exact" : "tracked");
    auto ps1 = random_particles<3>(5000, 1.0, 5);
    auto ps3 = ps1;
    TrackedNeighbors<3, double> one(kH, kSkin, 25, 1e-3, exit_test), three(kH, kSkin, 25, 1e-3, exit_test);
    set_num_threads(1);
    const auto c1 = run_sequence(one, ps1, 0, 40);
    set_num_threads(3);
    const auto c3 = run_sequence(three, ps3, 0, 40);
    EXPECT_TRUE(one.lists() == three.lists());
    EXPECT_TRUE(same_counts(c1, c3));
    expect_exact(three, ps3, "after 40 steps");
  }
}

/// Saves `from`'s state and loads it into `to` (a fresh strategy of the same settings).
void save_and_load(const TrackedNeighbors<3, double>& from, TrackedNeighbors<3, double>& to, std::size_t particles) {
  std::stringstream buf;
  StateWriter w(buf);
  from.save_state(w);
  StateReader r(buf, 1u << 30, "a test");
  to.load_state(r, particles);
}

TEST(Tracked, SavedAndLoadedStateContinuesIdentically) {
  for (const bool exit_test : {false, true}) {
    SCOPED_TRACE(exit_test ? "adaptive_exact" : "tracked");
    auto ps = random_particles<3>(3000, 1.0, 6);
    TrackedNeighbors<3, double> a(kH, 0, 25, 1e-3, exit_test);
    run_sequence(a, ps, 0, 20);
    TrackedNeighbors<3, double> b(kH, 0, 25, 1e-3, exit_test);
    save_and_load(a, b, ps.size());
    auto ps_b = ps;
    const auto ca = run_sequence(a, ps, 20, 45);
    const auto cb = run_sequence(b, ps_b, 20, 45);
    EXPECT_TRUE(a.lists() == b.lists());
    EXPECT_TRUE(same_counts(ca, cb));
    EXPECT_EQ(a.skin(), b.skin());
  }
}

// The path rule (set_time): particles followed along their velocity at their build.

/// How far apart a listed pair can be: its paths met within h + s in the windows, each path
/// runs kTrackedReach h, and each particle is up to a trigger off its path.
double path_reach(const TrackedNeighbors<3, double>& t) {
  return kH + t.skin() + 4 * kTrackedReach * kH + 3 * t.trigger() + 1e-9;
}

/// One step of a flow: v += a dt, x += v dt, then the lists at the new time.
void flow_step(TrackedNeighbors<3, double>& t, ParticleSet<3, double>& ps, const std::vector<V3>& a, double dt,
               double& time) {
  for (std::size_t i = 0; i < ps.size(); ++i) {
    ps.velocity[i] += a[i] * dt;
    ps.position[i] += ps.velocity[i] * dt;
  }
  time += dt;
  t.set_time(time);
  t.update(ps);
}

TEST(TrackedPaths, ABlockMovingAsOneIsRebuiltOnlyWhenItsPathsRunOut) {
  ParticleSet<3, double> ps;
  ps.mass = 1.0;
  const V3 v{3, -2, 1};  // 3.7 mm per step: the displacement rule would rebuild every other step
  for (int a = 0; a < 10; ++a)
    for (int b = 0; b < 10; ++b)
      for (int c = 0; c < 10; ++c) ps.add(V3{0.04 * a, 0.04 * b, 0.04 * c}, v);
  TrackedNeighbors<3, double> t(kH, kSkin, 1000, 1e-3, false);
  double time = 0;
  t.set_time(time);
  t.update(ps);
  const std::vector<V3> still(ps.size());
  std::size_t rebuilt = 0;
  int rebuild_steps = 0;
  for (int s = 0; s < 60; ++s) {
    flow_step(t, ps, still, 1e-3, time);
    rebuilt += t.counters().lists_rebuilt;
    rebuild_steps += t.counters().lists_rebuilt > 0;
    expect_exact(t, ps, "step " + std::to_string(s), path_reach(t));
    if (HasFatalFailure()) return;
  }
  // A path runs kTrackedReach h in |v| / (kTrackedReach h) steps; the lists are rebuilt on the
  // first step past it.
  EXPECT_EQ(rebuilt, static_cast<std::size_t>(rebuild_steps) * ps.size());  // all at once, when the paths run out
  const double window_steps = kTrackedReach * kH / std::sqrt(norm2(v)) / 1e-3;
  EXPECT_NEAR(rebuild_steps, 60 / (std::floor(window_steps) + 1), 1.0);
  EXPECT_LT(rebuild_steps, 30);  // the displacement rule: every other step
}

// Two particles closing head-on at 12 m/s through a resting lattice: they follow their paths
// exactly (never off them), so only the path test can list them before they meet.
TEST(TrackedPaths, FastParticlesClosingHeadOnAreNeverMissed) {
  ParticleSet<3, double> ps;
  ps.mass = 1.0;
  for (int a = 0; a < 12; ++a)
    for (int b = 0; b < 12; ++b)
      for (int c = 0; c < 12; ++c) ps.add(V3{0.05 * a, 0.05 * b, 0.05 * c} + V3::filled(0.0123), V3{});
  const std::size_t p = ps.size(), q = p + 1;
  ps.add(V3{0.03, 0.301, 0.302}, V3{6, 0, 0});
  ps.add(V3{0.58, 0.302, 0.301}, V3{-6, 0, 0});
  TrackedNeighbors<3, double> t(kH, kSkin, 1000, 1e-3, false);
  double time = 0;
  t.set_time(time);
  t.update(ps);
  const std::vector<V3> still(ps.size());
  bool met = false;
  for (int s = 0; s < 100 && ps.position[p][0] < 0.58; ++s) {
    flow_step(t, ps, still, 1e-3, time);
    met = met || norm2(ps.position[p] - ps.position[q]) < kH * kH;
    expect_exact(t, ps, "step " + std::to_string(s), path_reach(t));
    if (HasFatalFailure()) return;
  }
  EXPECT_TRUE(met);
}

/// A gas of particles with random velocities (up to 4 m/s) and random accelerations (up to
/// 200 m/s^2, redrawn every step), at random steps of 0.5 to 1.5 ms; some emitted on the way.
std::vector<NeighborCounters> random_flow(TrackedNeighbors<3, double>& t, ParticleSet<3, double>& ps, double& time,
                                          int from, int to, bool check) {
  std::vector<NeighborCounters> out;
  for (int s = from; s < to; ++s) {
    std::mt19937 rng(300 + static_cast<unsigned>(s));
    std::uniform_real_distribution<double> u(-1, 1);
    if (s % 9 == 4)
      for (int k = 0; k < 20; ++k) ps.add(V3{0.3 + 0.012 * k, 0.2, 0.25}, V3{0, 2, 0});
    std::vector<V3> a(ps.size());
    for (auto& ai : a) ai = V3{u(rng), u(rng), u(rng)} * 115.0;
    if (!t.pair_exit_flags().empty())
      for (std::size_t i = static_cast<std::size_t>(s); i < t.pair_exit_flags().size(); i += 97)
        t.pair_exit_flags()[i] = 1;
    flow_step(t, ps, a, 1e-3 * (1 + 0.5 * u(rng)), time);
    out.push_back(t.counters());
    if (check) expect_exact(t, ps, "step " + std::to_string(s), path_reach(t));
  }
  return out;
}

ParticleSet<3, double> moving_gas(std::size_t n, unsigned seed) {
  auto ps = random_particles<3>(n, 0.5, seed);
  std::mt19937 rng(seed + 1);
  std::uniform_real_distribution<double> u(-1, 1);
  for (auto& v : ps.velocity) v = V3{u(rng), u(rng), u(rng)} * 2.3;
  return ps;
}

TEST(TrackedPaths, AnAcceleratingGasAtRandomStepsIsNeverMissed) {
  for (const bool exit_test : {false, true}) {
    SCOPED_TRACE(exit_test ? "adaptive_exact" : "tracked");
    auto ps = moving_gas(1500, 8);
    TrackedNeighbors<3, double> t(kH, kSkin, 1000, 1e-3, exit_test);
    double time = 0.37;
    t.set_time(time);
    t.update(ps);
    const auto counts = random_flow(t, ps, time, 0, 50, true);
    std::size_t rebuilt = 0, particles = 0;
    for (const auto& c : counts) rebuilt += c.lists_rebuilt;
    for (int s = 0; s < 50; ++s) particles += 1500 + 20 * static_cast<std::size_t>((s + 5) / 9);
    EXPECT_LT(rebuilt, particles) << "not every list every step";
  }
}

TEST(TrackedPaths, SameListsForAnyThreadCountAndAfterASaveAndLoad) {
  ThreadCount keep;
  auto ps1 = moving_gas(3000, 9);
  auto ps3 = ps1;
  TrackedNeighbors<3, double> one(kH, 0, 25, 1e-3, false), three(kH, 0, 25, 1e-3, false);
  double t1 = 0, t3 = 0;
  set_num_threads(1);
  const auto c1 = random_flow(one, ps1, t1, 0, 30, false);
  set_num_threads(3);
  const auto c3 = random_flow(three, ps3, t3, 0, 30, false);
  EXPECT_TRUE(one.lists() == three.lists());
  EXPECT_TRUE(same_counts(c1, c3));
  // Saved after 30 steps and loaded into a fresh strategy: the next 20 steps are the same.
  TrackedNeighbors<3, double> loaded(kH, 0, 25, 1e-3, false);
  save_and_load(three, loaded, ps3.size());
  auto ps_loaded = ps3;
  double t_loaded = t3;
  const auto ca = random_flow(three, ps3, t3, 30, 50, false);
  const auto cb = random_flow(loaded, ps_loaded, t_loaded, 30, 50, false);
  EXPECT_TRUE(three.lists() == loaded.lists());
  EXPECT_TRUE(same_counts(ca, cb));
}

TEST(AdaptiveExact, Eq7FlagsRebuildTheFlaggedParticles) {
  auto ps = random_particles<3>(2000, 1.0, 7);
  TrackedNeighbors<3, double> t(kH, kSkin, 200, 1e-3, true);
  t.update(ps);
  ASSERT_EQ(t.pair_exit_flags().size(), ps.size());
  EXPECT_EQ(t.pair_exit_radius(), (kH + kSkin + t.trigger() + 2 * kTrackedReach * kH) * 1.0001);
  t.pair_exit_flags()[5] = 1;
  t.pair_exit_flags()[700] = 1;
  t.update(ps);
  EXPECT_EQ(t.counters().lists_rebuilt, 2u);
  EXPECT_TRUE(std::all_of(t.pair_exit_flags().begin(), t.pair_exit_flags().end(), [](auto f) { return f == 0; }));
  expect_exact(t, ps, "after the flagged rebuilds");
}

TEST(TrackedSkin, GrowsWithTheSpeedAndStaysWithinItsBounds) {
  const double h = 0.04, dt = 4e-4;
  EXPECT_EQ(tracked_skin(h, 0.0, dt, 3), 0.02 * h);
  EXPECT_EQ(tracked_skin(h, 1e6, dt, 3), 0.5 * h);
  double last = 0;
  for (const double v : {0.1, 0.3, 1.0, 3.0}) {
    const double s = tracked_skin(h, v, dt, 3);
    EXPECT_GT(s, last);
    EXPECT_GE(s, 0.02 * h);
    EXPECT_LE(s, 0.5 * h);
    last = s;
  }
  EXPECT_GT(tracked_skin(h, 1.0, dt, 2), tracked_skin(h, 1.0, dt, 3));
}

}  // namespace
}  // namespace sph
