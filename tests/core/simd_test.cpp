// simd::sum_lanes_each against sum_lanes, bit for bit: the transposed sums add each pack's lanes in
// the same order, on data where another order gives other bits.

#include <cstring>
#include <random>

#include <gtest/gtest.h>

#include <sph/core/simd.h>

namespace sph {
namespace {

template <class R>
void expect_each_sum_is_sum_lanes() {
  constexpr int W = simd::kLanes<R>;
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> mantissa(-1, 1);
  std::uniform_int_distribution<int> exponent(-12, 12);
  int order_matters = 0;
  for (int trial = 0; trial < 200; ++trial) {
    simd::Pack<R> packs[W];
    R lanes[W][W];
    for (int k = 0; k < W; ++k) {
      for (int l = 0; l < W; ++l) lanes[k][l] = static_cast<R>(std::ldexp(mantissa(rng), exponent(rng)));
      packs[k] = simd::Pack<R>::load(lanes[k]);
    }
    const int count = 1 + trial % W;
    R out[W];
    for (int k = 0; k < W; ++k) out[k] = R(-1234);
    simd::sum_lanes_each(packs, count, out);
    for (int k = 0; k < W; ++k) {
      if (k >= count) {
        EXPECT_EQ(out[k], R(-1234)) << "wrote past count";
        continue;
      }
      R in_order = 0, reversed = 0;
      for (int l = 0; l < W; ++l) in_order += lanes[k][l];
      for (int l = W - 1; l >= 0; --l) reversed += lanes[k][l];
      order_matters += std::memcmp(&in_order, &reversed, sizeof(R)) != 0;
      const R one = simd::sum_lanes(packs[k]);
      EXPECT_EQ(std::memcmp(&one, &in_order, sizeof(R)), 0) << "sum_lanes adds in lane order";
      EXPECT_EQ(std::memcmp(&out[k], &one, sizeof(R)), 0) << "pack " << k << " of " << count << ", trial " << trial;
    }
  }
  EXPECT_GT(order_matters, 100) << "the data must tell the summation orders apart";
}

TEST(Simd, SumLanesEachIsSumLanesBitForBitFloat) { expect_each_sum_is_sum_lanes<float>(); }
TEST(Simd, SumLanesEachIsSumLanesBitForBitDouble) { expect_each_sum_is_sum_lanes<double>(); }

}  // namespace
}  // namespace sph
