#include <gtest/gtest.h>

#include <sph/core/particle_set.h>

#include <string_view>
#include <type_traits>
#include <vector>

namespace sph {
namespace {

TEST(ParticleSet, IdsAreStableThroughPermutation) {
  ParticleSet<3, float> ps;
  for (int i = 0; i < 5; ++i) ps.add({{float(i), 0, 0}}, {{0, float(i), 0}}), ps.density[i] = 1.0f + i;
  EXPECT_EQ(ps.next_id(), 5u);
  const std::vector<std::uint32_t> perm{4, 2, 0, 3, 1};
  ps.permute(perm);
  for (std::size_t k = 0; k < 5; ++k) {
    const auto id = ps.id[k];
    EXPECT_EQ(id, perm[k]);
    EXPECT_EQ(ps.position[k][0], float(id));
    EXPECT_EQ(ps.velocity[k][1], float(id));
    EXPECT_EQ(ps.initial_position[k][0], float(id));
    EXPECT_EQ(ps.density[k], 1.0f + id);
  }
  EXPECT_EQ(ps.add({}, {}), 5u);
}

TEST(ParticleSet, ASetWithoutInitialPositionsLeavesThemOutOfEveryOperation) {
  ParticleSet<3, float> ps;
  ps.mass = 2.f;
  ps.keep_initial_positions(false);
  for (int i = 0; i < 4; ++i) ps.add({{float(i), 0, 0}}, {});
  EXPECT_TRUE(ps.initial_position.empty());
  std::size_t fields = 0;
  ps.for_each_field([&](const FieldDesc& f, const auto& column) {
    EXPECT_NE(f.name, "initial_position");
    EXPECT_EQ(column.size(), 4u) << f.name;
    ++fields;
  });
  EXPECT_EQ(fields, std::size(kParticleFields) - 1);
  const std::vector<std::uint32_t> perm{3, 2, 1, 0};
  ps.permute(perm);
  EXPECT_EQ(ps.position[0][0], 3.f);
  EXPECT_EQ(ps.id[0], 3u);
  EXPECT_THROW(ps.keep_initial_positions(true), std::logic_error) << "the positions they were added at are gone";
}

TEST(ParticleSet, AddingOneOfItsOwnPositionsIsSafeWhileTheArraysGrow) {
  ParticleSet<3, double> ps;
  ps.add({1.5, -2.0, 0.25}, {0.1, 0.2, 0.3});
  for (int k = 0; k < 100; ++k) ps.add(ps.position[0], ps.velocity[0]);  // (the arrays move as they grow)
  ASSERT_EQ(ps.size(), 101u);
  for (std::size_t i = 0; i < ps.size(); ++i) {
    EXPECT_EQ(ps.position[i][0], 1.5) << i;
    EXPECT_EQ(ps.position[i][2], 0.25) << i;
    EXPECT_EQ(ps.velocity[i][1], 0.2) << i;
    EXPECT_EQ(ps.initial_position[i][1], -2.0) << i;
  }
}

TEST(ParticleSet, PermutationOfWrongSizeIsABug) {
  ParticleSet<2, double> ps;
  ps.add({}, {});
  const std::vector<std::uint32_t> perm{0, 1};
  EXPECT_THROW(ps.permute(perm), std::logic_error);
}

}  // namespace
}  // namespace sph

namespace sph {
namespace {

// for_each_field visits every field of the table once, in table order, each with a column of the
// element type its descriptor's kind says.
template <int D, class R>
void check_field_visit() {
  ParticleSet<D, R> ps;
  ps.add({}, {});
  std::size_t k = 0;
  ps.for_each_field([&](const FieldDesc& f, const auto& column) {
    using T = typename std::decay_t<decltype(column)>::value_type;
    ASSERT_LT(k, std::size(kParticleFields));
    EXPECT_EQ(f.name, kParticleFields[k].name);
    const FieldKind kind = std::is_same_v<T, Vec<D, R>> ? FieldKind::Vector
                           : std::is_same_v<T, R>       ? FieldKind::Real
                                                        : FieldKind::Id;
    EXPECT_EQ(f.kind, kind) << f.name;
    EXPECT_EQ(column.size(), 1u) << f.name;
    ++k;
  });
  EXPECT_EQ(k, std::size(kParticleFields));
}

TEST(ParticleFields, EveryFieldIsVisitedWithItsKind) {
  check_field_visit<2, float>();
  check_field_visit<3, double>();
}

TEST(ParticleFields, FrameFieldNamesAreTheTablesFrameFields) {
  std::vector<std::string_view> names;
  for (const FieldDesc& f : kParticleFields)
    if (f.in_frames) names.push_back(f.name);
  EXPECT_EQ(std::vector<std::string_view>(kFrameFieldNames.begin(), kFrameFieldNames.end()), names);
  EXPECT_EQ(frame_field_list(" or "), "velocity, density, pressure, id or initial_position");
  for (const FieldDesc& f : kParticleFields) {
    EXPECT_EQ(find_particle_field(f.name), &f);
    EXPECT_TRUE(valid_field_name(f.name)) << f.name;
    for (int c = 0; f.in_frames && c < f.components(); ++c)
      EXPECT_FALSE(f.ply[static_cast<std::size_t>(c)].empty()) << f.name;
  }
  EXPECT_EQ(find_particle_field("nope"), nullptr);
}

}  // namespace
}  // namespace sph
