// The neighbor-mode table: every name parses back to its mode, the strategy made for a mode
// runs that mode, the error for an unknown name lists every name, and the lists that flags,
// `sph compare` and `sph bench` take from the table hold what they held when they were
// written out by hand.

#include <set>

#include <gtest/gtest.h>

#include <sph/core/error.h>
#include <sph/neighbors/neighbor_mode.h>
#include <sph/neighbors/strategy.h>

namespace sph {
namespace {

TEST(NeighborModeTable, EveryNameParsesBackToItsModeAndItsStrategy) {
  std::set<std::string_view> names;
  for (const NeighborModeInfo& info : kNeighborModes) {
    EXPECT_TRUE(names.insert(info.name).second) << "repeated name " << info.name;
    EXPECT_EQ(parse_neighbor_mode(info.name), info.mode);
    EXPECT_EQ(to_string(info.mode), info.name);
    EXPECT_EQ(&neighbor_mode_info(info.mode), &info);
    EXPECT_FALSE(info.description.empty()) << info.name;
    EXPECT_EQ(info.description.find('\n'), std::string_view::npos) << info.name << ": one line";
    NeighborOptions options;
    options.radius = 0.1;
    EXPECT_EQ((make_neighbor_strategy<2, double>(info.mode, options)->mode()), info.mode);
    EXPECT_EQ((make_neighbor_strategy<3, float>(info.mode, options)->mode()), info.mode);
  }
  EXPECT_EQ(names.size(), 7u);
}

TEST(NeighborModeTable, UnknownNameIsRefusedNamingEveryMode) {
  try {
    parse_neighbor_mode("fast", "--neighbors");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.where(), "--neighbors");
    EXPECT_EQ(e.message(),
              "unknown neighbor mode \"fast\"; expected one of \"standard\", \"adaptive\", \"verlet\", \"tracked\", "
              "\"adaptive_exact\", \"verlet_clusters\", \"brute_force\"");
  }
  EXPECT_THROW(parse_neighbor_mode(""), Error);
  EXPECT_THROW(parse_neighbor_mode("Standard"), Error) << "names are case-sensitive";
}

TEST(NeighborModeTable, ListsDerivedFromTheTable) {
  EXPECT_EQ(neighbor_mode_names(), (std::vector<std::string>{"standard", "adaptive", "verlet", "tracked",
                                                             "adaptive_exact", "verlet_clusters", "brute_force"}));
  EXPECT_EQ(
      neighbor_mode_names(NeighborModeSet::Compared),
      (std::vector<std::string>{"standard", "adaptive", "verlet", "tracked", "adaptive_exact", "verlet_clusters"}));
  EXPECT_EQ(
      neighbor_modes(NeighborModeSet::Compared),
      (std::vector<NeighborMode>{NeighborMode::Standard, NeighborMode::Adaptive, NeighborMode::Verlet,
                                 NeighborMode::Tracked, NeighborMode::AdaptiveExact, NeighborMode::VerletClusters}));
  EXPECT_EQ(neighbor_modes(NeighborModeSet::All).size(), std::size(kNeighborModes));
  EXPECT_FALSE(neighbor_mode_info(NeighborMode::BruteForce).compared) << "the oracle is too slow to time";
  for (const NeighborModeInfo& info : kNeighborModes)  // the modes that read Configuration.trackedSkin
    EXPECT_EQ(info.tracked, info.mode == NeighborMode::Tracked || info.mode == NeighborMode::AdaptiveExact)
        << info.name;
  for (const NeighborModeInfo& info : kNeighborModes)  // the modes that read Configuration.verletSkin
    EXPECT_EQ(info.verlet, info.mode == NeighborMode::Verlet || info.mode == NeighborMode::VerletClusters) << info.name;
  EXPECT_EQ(join_neighbor_mode_names(NeighborModeSet::Compared, ",", ","),
            "standard,adaptive,verlet,tracked,adaptive_exact,verlet_clusters");
  EXPECT_EQ(join_neighbor_mode_names(NeighborModeSet::Compared, ", ", " or "),
            "standard, adaptive, verlet, tracked, adaptive_exact or verlet_clusters");
  EXPECT_EQ(join_neighbor_mode_names(NeighborModeSet::All, ", ", " and "),
            "standard, adaptive, verlet, tracked, adaptive_exact, verlet_clusters and brute_force");
}

}  // namespace
}  // namespace sph
