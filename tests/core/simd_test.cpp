// simd::sum_lanes_each against sum_lanes, bit for bit: the transposed sums add each pack's lanes in
// the same order, on data where another order gives other bits. simd::gather_vectors against the
// gathers it replaces.

#include <sys/mman.h>
#include <unistd.h>

#include <cstring>
#include <random>
#include <span>
#include <vector>

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

// simd::gather_vectors: lane l of out[d] is base[D idx[l] + d], as D gathers would give, for indices
// anywhere in the array (its last vector included, repeated indices too), each value distinct.
// Registers without the last vector take the plain loads, those with it the masked ones (under
// AddressSanitizer a plain load of the last vector would read past the array).
template <int D, class R>
void expect_gather_vectors_reads_each_lanes_vector() {
  constexpr int W = simd::kLanes<R>;
  constexpr std::uint32_t kVectors = 37;
  std::vector<R> base(D * kVectors);  // exactly the vectors: the last one ends the array
  for (std::size_t k = 0; k < base.size(); ++k) base[k] = static_cast<R>(0.5 + static_cast<double>(k) * 1.25);
  std::mt19937 rng(5);
  for (int trial = 0; trial < 100; ++trial) {
    std::uint32_t idx[W];
    for (int l = 0; l < W; ++l) idx[l] = trial % 3 == 0 && l % 4 == 1 ? kVectors - 1 : rng() % kVectors;
    simd::Pack<R> out[D];
    simd::gather_vectors<D>(std::span<const R>(base), idx, out);
    for (int d = 0; d < D; ++d) {
      R lanes[W], gathered[W];
      out[d].store(lanes);
      simd::Pack<R>::template gather<D>(base.data(), idx, d).store(gathered);
      for (int l = 0; l < W; ++l) {
        EXPECT_EQ(lanes[l], base[D * idx[l] + d]) << "component " << d << ", lane " << l << ", trial " << trial;
        EXPECT_EQ(lanes[l], gathered[l]);
      }
    }
  }
}

// The same with the array's last vector ending a page whose next page may not be read: a load
// past the array would end the test with a fault (the sanitizer builds run the portable loops).
template <int D, class R>
void expect_gather_vectors_reads_nothing_past_the_array() {
  constexpr int W = simd::kLanes<R>;
  const auto page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
  void* const two = mmap(nullptr, 2 * page, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  ASSERT_NE(two, MAP_FAILED);
  char* const guard = static_cast<char*>(two) + page;
  ASSERT_EQ(mprotect(guard, page, PROT_NONE), 0);
  constexpr std::uint32_t kVectors = 50;
  R* const base = reinterpret_cast<R*>(guard) - D * kVectors;  // the last vector ends at the guard page
  for (std::size_t k = 0; k < D * kVectors; ++k) base[k] = static_cast<R>(k);
  for (std::uint32_t last_lanes = 1; last_lanes <= static_cast<std::uint32_t>(W); ++last_lanes) {
    std::uint32_t idx[W];
    for (int l = 0; l < W; ++l)
      idx[l] = static_cast<std::uint32_t>(l) < last_lanes ? kVectors - 1 : static_cast<std::uint32_t>(l) % kVectors;
    simd::Pack<R> out[D];
    simd::gather_vectors<D>(std::span<const R>(base, D * kVectors), idx, out);
    for (int d = 0; d < D; ++d) {
      R lanes[W];
      out[d].store(lanes);
      for (int l = 0; l < W; ++l) EXPECT_EQ(lanes[l], base[D * idx[l] + d]) << "component " << d << ", lane " << l;
    }
  }
  munmap(two, 2 * page);
}

TEST(Simd, GatherVectorsReadsNothingPastTheArray) {
  expect_gather_vectors_reads_nothing_past_the_array<2, float>();
  expect_gather_vectors_reads_nothing_past_the_array<3, float>();
  expect_gather_vectors_reads_nothing_past_the_array<2, double>();
  expect_gather_vectors_reads_nothing_past_the_array<3, double>();
}

TEST(Simd, GatherVectorsReadsEachLanesVector) {
  expect_gather_vectors_reads_each_lanes_vector<2, float>();
  expect_gather_vectors_reads_each_lanes_vector<3, float>();
  expect_gather_vectors_reads_each_lanes_vector<2, double>();
  expect_gather_vectors_reads_each_lanes_vector<3, double>();
}

}  // namespace
}  // namespace sph
