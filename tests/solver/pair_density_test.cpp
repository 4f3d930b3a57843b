// The density sums made while the standard mode builds its lists (PairDensity, seen by the
// ListBuilder's PairVisitor) against the density pass over the built lists: the same bits for every
// kernel, in 2D and 3D, float and double, with the vector and the scalar distance kernel, with
// boundary samples, and for any thread count.

#include <algorithm>
#include <cstring>

#include <gtest/gtest.h>

#include <sph/core/parallel.h>
#include <sph/neighbors/list_builder.h>
#include <sph/neighbors/neighbor_mode.h>
#include <sph/neighbors/standard.h>
#include <sph/solver/smoothing.h>
#include <sph/solver/wcsph.h>

#include "support/blob.h"
#include "support/thread_count.h"

namespace sph {
namespace {

using test::ThreadCount;

/// The pass tests' block (support/blob.h) with a few coincident pairs and a stray particle with
/// no neighbor added.
template <int D, class R>
struct Block : test::Blob<D, R> {
  Block(int side, unsigned seed) : test::Blob<D, R>(side, seed) {
    ParticleSet<D, R>& ps = this->ps;
    for (int q = 0; q < 5; ++q) ps.add(ps.position[static_cast<std::size_t>(q) * 7], Vec<D, R>{});  // coincident
    Vec<D, R> far;
    far[0] = static_cast<R>(-10 * this->h);
    ps.add(far, Vec<D, R>{});
  }
};

template <class R>
bool same_bits(const std::vector<R>& a, const std::vector<R>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(R)) == 0;
}

/// Density and pressure both ways: summed over the lists after the build, and summed by the
/// build's PairDensity (vector or scalar distance kernel).
template <int D, class R>
void expect_sums_while_building_match(const FluidParams& fluid, bool samples, bool vector) {
  SCOPED_TRACE(::testing::Message() << D << "D " << (sizeof(R) == 4 ? "float" : "double") << " kernel "
                                    << static_cast<int>(fluid.kernel) << (samples ? " samples" : "")
                                    << (vector ? " vector" : " scalar"));
  const Block<D, R> block(D == 3 ? 12 : 40, 11);
  const R h = static_cast<R>(block.h);
  UniformGrid<D, R> grid;
  grid.build(block.ps.position, h);
  ListBuilder<D, R> plain, visited;
  plain.use_vector_kernel(vector);
  visited.use_vector_kernel(vector);
  NeighborLists lists, visited_lists;
  plain.build(grid, block.ps.position, h, lists);
  const std::unique_ptr<PairDensity<D, R>> sums = make_pair_density<D, R>(h, fluid);
  ParticleSet<D, R> a = block.ps, b = block.ps;
  std::fill(b.density.begin(), b.density.end(), R(-7));  // (what the visitor must overwrite)
  sums->aim(b);
  visited.set_pair_visitor(sums.get());
  visited.build(grid, block.ps.position, h, visited_lists);
  ASSERT_TRUE(lists == visited_lists) << "the visitor changed the lists";

  StandardNeighbors<D, R> boundary_owner(h);  // (boundary lists of the samples)
  BoundaryView<D, R> view;
  if (samples) {
    boundary_owner.set_boundary(block.samples);
    boundary_owner.update(block.ps);
    view.position = block.samples;
    view.psi = block.psi;
    view.lists = &boundary_owner.boundary_lists();
  }
  const std::uint64_t within_a = compute_density_pressure<D, R>(a, lists, h, fluid, view);
  const std::uint64_t within_b = compute_density_pressure<D, R>(b, lists, h, fluid, view, nullptr, true);
  EXPECT_EQ(within_a, within_b);
  EXPECT_GT(within_a, (D == 3 ? 20 : 8) * a.size());
  EXPECT_TRUE(same_bits(a.density, b.density)) << "densities differ";
  if (!samples) {  // the pass takes the pairs' sums from the density field, and adds the particle's own term
    ParticleSet<D, R> c = block.ps;
    std::fill(c.density.begin(), c.density.end(), R(0));
    compute_density_pressure<D, R>(c, lists, h, fluid, view, nullptr, true);
    const R own_term = block.ps.mass * SmoothingKernels<D, R>(fluid.kernel, h).w_zero();
    EXPECT_EQ(std::count(c.density.begin(), c.density.end(), own_term), static_cast<std::ptrdiff_t>(c.size()));
  }
  EXPECT_TRUE(same_bits(a.pressure, b.pressure)) << "pressures differ";
  const R own = block.ps.mass * SmoothingKernels<D, R>(fluid.kernel, h).w_zero();
  EXPECT_EQ(b.density.back(), own) << "the stray particle has its own term only";
}

template <int D, class R>
void expect_every_kernel_matches() {
  FluidParams fluid;
  fluid.stiffness = 300;
  fluid.rest_density = 1000;
  fluid.negative_pressure = NegativePressure::Allow;
  for (bool vector : {true, false})
    for (KernelKind k : {KernelKind::Paper, KernelKind::Cubic, KernelKind::Wendland}) {
      fluid.kernel = k;
      expect_sums_while_building_match<D, R>(fluid, false, vector);
    }
  fluid.kernel = KernelKind::Cubic;
  expect_sums_while_building_match<D, R>(fluid, true, true);
}

TEST(PairDensity, SumsWhileBuildingAreThePassOverTheLists3dFloat) { expect_every_kernel_matches<3, float>(); }
TEST(PairDensity, SumsWhileBuildingAreThePassOverTheLists3dDouble) { expect_every_kernel_matches<3, double>(); }
TEST(PairDensity, SumsWhileBuildingAreThePassOverTheLists2dFloat) { expect_every_kernel_matches<2, float>(); }
TEST(PairDensity, SumsWhileBuildingAreThePassOverTheLists2dDouble) { expect_every_kernel_matches<2, double>(); }

TEST(PairDensity, SumsAreTheSameForAnyThreadCount) {
  ThreadCount restore;
  const Block<3, float> block(16, 5);  // 4,102 particles: several chunks
  const float h = static_cast<float>(block.h);
  FluidParams fluid;
  const std::unique_ptr<PairDensity<3, float>> sums = make_pair_density<3, float>(h, fluid);
  std::vector<float> out[2];
  for (int t : {1, 3}) {
    set_num_threads(t);
    StandardNeighbors<3, float> standard(h);
    ASSERT_TRUE(standard.visit_pairs_with(sums.get()));
    ParticleSet<3, float> ps = block.ps;
    sums->aim(ps);
    standard.update(ps);
    compute_density_pressure<3, float>(ps, standard.lists(), h, fluid, {}, nullptr, true);
    out[t == 1 ? 0 : 1] = ps.density;
  }
  EXPECT_TRUE(same_bits(out[0], out[1]));
}

TEST(PairDensity, OnlyTheStandardStrategyTakesTheVisitor) {
  const std::unique_ptr<PairDensity<3, double>> sums = make_pair_density<3, double>(0.04, FluidParams{});
  for (NeighborMode mode : neighbor_modes(NeighborModeSet::All)) {
    NeighborOptions opt;
    opt.radius = 0.04;
    opt.time_step = 1e-4;
    const auto strategy = make_neighbor_strategy<3, double>(mode, opt);
    EXPECT_EQ(strategy->visit_pairs_with(sums.get()), mode == NeighborMode::Standard) << to_string(mode);
  }
}

}  // namespace
}  // namespace sph
