#include <gtest/gtest.h>

#include <sph/core/particle_set.h>

namespace sph {
namespace {

TEST(ParticleSet, IdsAreStableThroughPermutation) {
  ParticleSet<3, float> ps;
  for (int i = 0; i < 5; ++i) ps.add({{float(i), 0, 0}}, {{0, float(i), 0}}, 1.0f + i);
  EXPECT_EQ(ps.next_id(), 5u);
  const std::vector<std::uint32_t> perm{4, 2, 0, 3, 1};
  ps.permute(perm);
  for (std::size_t k = 0; k < 5; ++k) {
    const auto id = ps.id[k];
    EXPECT_EQ(id, perm[k]);
    EXPECT_EQ(ps.position[k][0], float(id));
    EXPECT_EQ(ps.velocity[k][1], float(id));
    EXPECT_EQ(ps.initial_position[k][0], float(id));
    EXPECT_EQ(ps.mass[k], 1.0f + id);
  }
  EXPECT_EQ(ps.add({}, {}, 1.0f), 5u);
}

TEST(ParticleSet, PermutationOfWrongSizeIsABug) {
  ParticleSet<2, double> ps;
  ps.add({}, {}, 1.0);
  const std::vector<std::uint32_t> perm{0, 1};
  EXPECT_THROW(ps.permute(perm), std::logic_error);
}

}  // namespace
}  // namespace sph
