// The neighbor modes on the paper scenes, read from their files: verlet lists never miss a
// pair within h (audited every step), adaptive with a full-rebuild period of 1 is the standard
// run bit for bit (with particles reordered in memory at the same steps), and the adaptive audit sees the pairs the
// paper's test cannot.

#include <string>

#include <gtest/gtest.h>

#include <sph/scene/builders.h>
#include <sph/scene/scene_reader.h>

#include "support/scenes.h"

namespace sph {
namespace {

using test::paper_scene;

SceneDesc scene(const std::string& name, const std::string& mode, bool audit, int period = 200) {
  // The same reorder steps in every run (by default they follow fullRebuildPeriod).
  SceneDesc d = read_scene_file(paper_scene(name), {"Configuration.neighbors=\"" + mode + "\"",
                                                    "Configuration.fullRebuildPeriod=" + std::to_string(period),
                                                    "Configuration.reorderPeriod=50"});
  d.set_audit(audit);
  return d;
}

struct Audited {
  std::uint64_t missed = 0, rebuild_steps = 0, within = 0;
  std::size_t particles = 0;
};

template <int D>
Audited run_audited(const SceneDesc& d, int steps) {
  Simulation<D, double> sim = make_simulation<D, double>(d);
  Audited a;
  for (int s = 0; s < steps; ++s) {
    const StepInfo& info = sim.step();
    EXPECT_TRUE(info.audited);
    a.missed += info.audit.missed_pairs;
    a.rebuild_steps += info.neighbors.lists_rebuilt > 0 ? 1 : 0;
    a.within += info.pairs_within_h;
  }
  a.particles = sim.particles().size();
  return a;
}

template <int D>
void expect_verlet_exact(const std::string& name, int steps) {
  SCOPED_TRACE(name);
  const Audited a = run_audited<D>(scene(name, "verlet", true), steps);
  EXPECT_EQ(a.missed, 0u) << "verlet lists missed pairs within h";
  EXPECT_GT(a.within, 0u);
  EXPECT_LT(a.rebuild_steps, static_cast<std::uint64_t>(steps)) << "the skin should save some rebuilds";
}

TEST(NeighborModesE2E, VerletMissesNoPairOnDamBreak2D) { expect_verlet_exact<2>("dam_break_2d", 1000); }
TEST(NeighborModesE2E, VerletMissesNoPairOnBlock3D) { expect_verlet_exact<3>("block_3d", 300); }
TEST(NeighborModesE2E, VerletMissesNoPairOnTankFill3D) { expect_verlet_exact<3>("tank_fill_3d", 600); }

TEST(NeighborModesE2E, AdaptiveAuditSeesPairsComingIntoRange) {
  // The dam break compresses the column at once: pairs at distance h come into range, which
  // Eq. 7 (watching listed pairs only) cannot see. The audit must report them.
  const Audited a = run_audited<2>(scene("dam_break_2d", "adaptive", true), 300);
  EXPECT_GT(a.missed, 0u);
  const Audited s = run_audited<2>(scene("dam_break_2d", "standard", true), 300);
  EXPECT_EQ(s.missed, 0u) << "standard lists are exact";
}

template <int D>
void expect_period_one_is_standard(const std::string& name, int steps) {
  SCOPED_TRACE(name);
  Simulation<D, double> a = make_simulation<D, double>(scene(name, "standard", false));
  Simulation<D, double> b = make_simulation<D, double>(scene(name, "adaptive", false, 1));
  for (int s = 0; s < steps; ++s) {
    a.step();
    b.step();
  }
  ASSERT_EQ(a.particles().size(), b.particles().size());
  EXPECT_TRUE(a.particles().position == b.particles().position);
  EXPECT_TRUE(a.particles().velocity == b.particles().velocity);
}

TEST(NeighborModesE2E, AdaptivePeriodOneIsStandardOnBlock3D) { expect_period_one_is_standard<3>("block_3d", 200); }
TEST(NeighborModesE2E, AdaptivePeriodOneIsStandardOnTankFill3D) {
  expect_period_one_is_standard<3>("tank_fill_3d", 400);
}

}  // namespace
}  // namespace sph
