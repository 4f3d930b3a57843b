// The parallel loops' split between threads: balance_loops gives each thread a contiguous run
// of items holding about an equal share of the work (parallel_chunks: the nearest run of
// chunks; parallel_runs: the same runs as parallel_for), every item is still visited exactly once
// (by parallel_for, parallel_chunks and parallel_runs, under the split, for other counts and for a team of
// another size), and clear_balance splits evenly again.

#include <algorithm>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include <sph/core/parallel.h>

#include "support/thread_count.h"

namespace sph {
namespace {

using test::ThreadCount;

/// The thread that ran each item of parallel_for(n), of parallel_chunks(n) (by chunk) and of
/// parallel_runs(n) (by run); every entry is checked to have been written exactly once.
struct Owners {
  std::vector<int> of_item, of_chunk_item, of_run_item;
};

Owners run_loops(std::size_t n) {
  Owners o{std::vector<int>(n, -1), std::vector<int>(n, -1), std::vector<int>(n, -1)};
  std::vector<int> visits(n, 0), chunk_visits(n, 0), run_visits(n, 0);
  std::vector<int> runs(static_cast<std::size_t>(num_threads()), 0);
  parallel_runs(n, [&](std::size_t first, std::size_t last) {
    EXPECT_LT(first, last) << "an empty run";
    ++runs[static_cast<std::size_t>(thread_index())];
    for (std::size_t i = first; i < last; ++i) {
      o.of_run_item[i] = thread_index();
      ++run_visits[i];
    }
  });
  for (int r : runs) EXPECT_LE(r, 1) << "one run a thread";
  parallel_for(n, [&](std::size_t i) {
    o.of_item[i] = thread_index();
    ++visits[i];
  });
  parallel_chunks(n, [&](std::size_t c, std::size_t b, std::size_t e) {
    EXPECT_EQ(b, c * kChunkSize);
    EXPECT_EQ(e, std::min(n, b + kChunkSize));
    for (std::size_t i = b; i < e; ++i) {
      o.of_chunk_item[i] = thread_index();
      ++chunk_visits[i];
    }
  });
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_EQ(visits[i], 1) << "parallel_for, item " << i;
    EXPECT_EQ(chunk_visits[i], 1) << "parallel_chunks, item " << i;
    EXPECT_EQ(run_visits[i], 1) << "parallel_runs, item " << i;
  }
  return o;
}

/// The first item thread 1 ran (n if none).
std::size_t first_of_thread_one(const std::vector<int>& owner) {
  return static_cast<std::size_t>(std::find(owner.begin(), owner.end(), 1) - owner.begin());
}

TEST(BalanceLoops, SplitsTheWorkNotTheItems) {
  ThreadCount restore;
  set_num_threads(2);
  // 40 chunks: the first 10 hold 9 units of work each, the other 30 one each (120 in all), so
  // the halves of the work meet 6 2/3 chunks in, where an even split of the items puts 20.
  const std::size_t n = 40 * kChunkSize - 100;  // (a short last chunk)
  std::vector<std::uint64_t> work(chunk_count(n), 1);
  std::fill(work.begin(), work.begin() + 10, 9);
  balance_loops(n, work);
  const Owners balanced = run_loops(n);
  const std::size_t items_first = 6 * kChunkSize + kChunkSize * 2 / 3;  // (the item 6 2/3 chunks in)
  EXPECT_EQ(first_of_thread_one(balanced.of_item), items_first);
  EXPECT_EQ(balanced.of_run_item, balanced.of_item) << "parallel_runs runs parallel_for's runs";
  EXPECT_EQ(first_of_thread_one(balanced.of_chunk_item), 7 * kChunkSize) << "the chunk boundary nearest to it";
  // One contiguous run each: thread 0 before the first item of thread 1, thread 1 from it.
  for (const auto* owner : {&balanced.of_item, &balanced.of_chunk_item}) {
    const std::size_t first = first_of_thread_one(*owner);
    for (std::size_t i = 0; i < n; ++i) EXPECT_EQ((*owner)[i], i < first ? 0 : 1) << "item " << i;
  }

  // A loop over another count splits evenly, visiting every item once.
  const Owners other = run_loops(n + 1);
  EXPECT_NEAR(static_cast<double>(first_of_thread_one(other.of_chunk_item)), (n + 1) / 2.0, kChunkSize);

  // A team of another size than the split's still covers every item once.
  set_num_threads(3);
  run_loops(n);
  set_num_threads(2);

  clear_balance();
  const Owners even = run_loops(n);
  EXPECT_NEAR(static_cast<double>(first_of_thread_one(even.of_item)), n / 2.0, 1.0);
  EXPECT_NEAR(static_cast<double>(first_of_thread_one(even.of_run_item)), n / 2.0, 1.0);
  EXPECT_NEAR(static_cast<double>(first_of_thread_one(even.of_chunk_item)), n / 2.0, kChunkSize);
}

TEST(BalanceLoops, ChunksWithoutWorkGoToTheThreadBeforeTheWork) {
  ThreadCount restore;
  set_num_threads(2);
  const std::size_t n = 8 * kChunkSize;
  std::vector<std::uint64_t> work(8, 0);
  work[5] = 100;
  balance_loops(n, work);
  const Owners o = run_loops(n);
  // Half the work lies in the middle of chunk 5: thread 1's items start there, its chunks at 6.
  EXPECT_EQ(first_of_thread_one(o.of_item), 5 * kChunkSize + kChunkSize / 2);
  EXPECT_EQ(first_of_thread_one(o.of_chunk_item), 6 * kChunkSize);
  clear_balance();
}

TEST(BalanceLoops, RefusesAWorkListOfTheWrongLength) {
  const std::vector<std::uint64_t> work(3, 1);
  EXPECT_ANY_THROW(balance_loops(10 * kChunkSize, work));
}

TEST(SpinCount, IsAWholeHundredWithinItsBoundsAndGrowsWithTheTime) {
  // (calibrated by timing pauses: the two durations are a thousand times apart, far beyond what
  // a busy machine changes in the fastest of three timings)
  const long brief = spin_count_lasting(kSpinMicroseconds);
  const long nothing = spin_count_lasting(0);
  const long long_one = spin_count_lasting(1000 * kSpinMicroseconds);
  for (long c : {brief, nothing, long_one}) {
    EXPECT_GE(c, 100);
    EXPECT_LE(c, 100000);
    EXPECT_EQ(c % 100, 0);
  }
#if defined(__x86_64__) || defined(__i386__)
  EXPECT_EQ(nothing, 100);
  EXPECT_GT(long_one, brief);
#else
  EXPECT_EQ(brief, 1000);  // (no pause to time)
#endif
}

}  // namespace
}  // namespace sph
