// The benchmark's correctness check must pass right lists and catch wrong ones: each test
// corrupts lists built by the project's own ListBuilder in one way and expects the check to fail,
// on both of its paths (every list against brute force; a sample against an exact search).

#include <algorithm>

#include <gtest/gtest.h>

#include <sph/bench/list_check.h>
#include <sph/bench/workload.h>
#include <sph/core/parallel.h>
#include <sph/neighbors/list_builder.h>
#include <sph/neighbors/reorder.h>
#include <sph/neighbors/uniform_grid.h>

namespace sph {
namespace {

using V = Vec<3, double>;

/// Lists as plain vectors, so that tests can corrupt them.
struct PlainLists {
  std::vector<std::vector<std::uint32_t>> lists;
  ListsView view() const {
    return {lists.size(), [this](std::size_t k) { return std::span<const std::uint32_t>(lists[k]); }};
  }
};

PlainLists copy_of(const NeighborLists& l) {
  PlainLists p;
  for (std::size_t k = 0; k < l.particle_count(); ++k) {
    const auto s = l.of(k);
    p.lists.emplace_back(s.begin(), s.end());
  }
  return p;
}

void erase_value(std::vector<std::uint32_t>& v, std::uint32_t x) { v.erase(std::find(v.begin(), v.end(), x)); }

class ListCheckTest : public ::testing::TestWithParam<bool> {
 protected:
  void SetUp() override {
    LatticeSpec spec;
    spec.side = 12;  // 1,728 points
    points_ = lattice_points<double>(spec);
    radius_ = 2 * spec.spacing;
    UniformGrid<3, double> grid;
    ListBuilder<3, double> builder;
    NeighborLists lists;
    grid.build(points_, radius_);
    builder.build(grid, points_, radius_, lists);
    good_ = copy_of(lists);
    // Sampled path: no brute force at all, and particle 0 is always among the samples.
    if (GetParam()) options_.full_limit = 0, options_.samples = 50;
  }
  ListCheck check(const PlainLists& l, std::span<const std::uint32_t> perm = {}) const {
    return check_neighbor_lists<3, double>(points_, radius_, l.view(), perm, options_);
  }
  /// A neighbor of particle i.
  std::uint32_t some_neighbor(std::size_t i) const { return good_.lists[i].at(good_.lists[i].size() / 2); }

  std::vector<V> points_;
  double radius_ = 0;
  PlainLists good_;
  ListCheckOptions options_;
};

TEST_P(ListCheckTest, AcceptsTheBuilderLists) {
  const ListCheck c = check(good_);
  EXPECT_TRUE(c.ok) << c.problem;
  EXPECT_FALSE(c.method.empty());
  EXPECT_EQ(c.lists_compared, GetParam() ? 50u : points_.size());
  std::uint64_t entries = 0;
  for (const auto& l : good_.lists) entries += l.size();
  EXPECT_EQ(c.entries, entries);
  EXPECT_GT(entries, 20u * points_.size());
}

TEST_P(ListCheckTest, AcceptsListsInAnyOrder) {
  PlainLists l = good_;
  for (auto& v : l.lists) std::reverse(v.begin(), v.end());
  EXPECT_TRUE(check(l).ok);
}

TEST_P(ListCheckTest, CatchesAOneSidedMissingNeighbor) {
  PlainLists l = good_;
  const std::size_t i = 700;  // not a sampled particle: symmetry must catch it
  erase_value(l.lists[i], some_neighbor(i));
  const ListCheck c = check(l);
  EXPECT_FALSE(c.ok);
  EXPECT_NE(c.problem.find("symmetric"), std::string::npos) << c.problem;
}

TEST_P(ListCheckTest, CatchesAPairMissingFromBothLists) {
  PlainLists l = good_;
  const std::uint32_t j = some_neighbor(0);
  erase_value(l.lists[0], j);
  erase_value(l.lists[j], 0);
  const ListCheck c = check(l);
  EXPECT_FALSE(c.ok);
  EXPECT_NE(c.problem.find("particle 0 "), std::string::npos) << c.problem;
  EXPECT_NE(c.problem.find("missing: " + std::to_string(j)), std::string::npos) << c.problem;
}

TEST_P(ListCheckTest, CatchesAFarPairAddedToBothLists) {
  PlainLists l = good_;
  const std::uint32_t far = static_cast<std::uint32_t>(points_.size() - 1);
  l.lists[5].push_back(far);
  l.lists[far].push_back(5);
  const ListCheck c = check(l);
  EXPECT_FALSE(c.ok);
  EXPECT_NE(c.problem.find("not closer than r"), std::string::npos) << c.problem;
}

TEST_P(ListCheckTest, CatchesSelfDuplicatesOutOfRangeAndWrongCounts) {
  {
    PlainLists l = good_;
    l.lists[3].push_back(3);
    EXPECT_FALSE(check(l).ok);
  }
  {
    PlainLists l = good_;
    l.lists[3].push_back(l.lists[3].front());
    const ListCheck c = check(l);
    EXPECT_FALSE(c.ok);
    EXPECT_NE(c.problem.find("twice"), std::string::npos) << c.problem;
  }
  {
    PlainLists l = good_;
    l.lists[3].push_back(static_cast<std::uint32_t>(points_.size()));
    EXPECT_FALSE(check(l).ok);
  }
  {
    PlainLists l = good_;
    l.lists.pop_back();
    EXPECT_FALSE(check(l).ok);
  }
}

TEST_P(ListCheckTest, CatchesListsThatBelongToOtherParticles) {
  PlainLists l = good_;
  std::swap(l.lists[0], l.lists[1]);  // two neighboring particles' lists swapped
  EXPECT_FALSE(check(l).ok);
}

TEST_P(ListCheckTest, MapsReorderedListsBackThroughThePermutation) {
  // Shuffled input, Morton-ordered and gathered as the benchmark does it.
  const std::vector<std::uint32_t> shuffle = shuffle_permutation(points_.size(), kShuffleSeed);
  std::vector<V> shuffled, gathered;
  gather<V>(points_, shuffle, shuffled);
  MortonOrder<3, double> morton;
  const std::span<const std::uint32_t> found = morton.compute(shuffled, radius_);
  std::vector<std::uint32_t> perm(found.begin(), found.end());
  gather<V>(shuffled, perm, gathered);
  UniformGrid<3, double> grid;
  ListBuilder<3, double> builder;
  NeighborLists lists;
  grid.build(gathered, radius_);
  builder.build(grid, gathered, radius_, lists);
  const PlainLists l = copy_of(lists);

  ListCheck c = check_neighbor_lists<3, double>(shuffled, radius_, l.view(), perm, options_);
  EXPECT_TRUE(c.ok) << c.problem;
  // The same lists read without the permutation (or with a wrong one) are wrong.
  c = check_neighbor_lists<3, double>(shuffled, radius_, l.view(), {}, options_);
  EXPECT_FALSE(c.ok);
  std::vector<std::uint32_t> wrong = perm;
  std::swap(wrong[0], wrong[wrong.size() / 2]);
  c = check_neighbor_lists<3, double>(shuffled, radius_, l.view(), wrong, options_);
  EXPECT_FALSE(c.ok);
  // A permutation that is no permutation is refused.
  wrong = perm;
  wrong[1] = wrong[0];
  c = check_neighbor_lists<3, double>(shuffled, radius_, l.view(), wrong, options_);
  EXPECT_FALSE(c.ok);
  EXPECT_NE(c.problem.find("permutation"), std::string::npos) << c.problem;
}

TEST_P(ListCheckTest, TheVerdictDoesNotDependOnTheThreadCount) {
  PlainLists l = good_;
  erase_value(l.lists[0], some_neighbor(0));
  erase_value(l.lists[900], some_neighbor(900));
  set_num_threads(1);
  const ListCheck one = check(l);
  set_num_threads(2);
  const ListCheck two = check(l);
  EXPECT_FALSE(one.ok);
  EXPECT_EQ(one.problem, two.problem);
}

INSTANTIATE_TEST_SUITE_P(Paths, ListCheckTest, ::testing::Values(false, true),
                         [](const auto& info) { return info.param ? "Sampled" : "BruteForce"; });

}  // namespace
}  // namespace sph
