#pragma once
/// \file The one parallel-loop abstraction (OpenMP underneath). Loops either write only to
/// their own index, or use parallel_chunks with a chunking that does not depend on the thread
/// count, so that results are bitwise identical for any number of threads.

#include <cstddef>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

namespace sph {

/// Sets the number of worker threads used by parallel loops (n >= 1).
void set_num_threads(int n);
/// The number of worker threads parallel loops use.
int num_threads();

/// How long idle OpenMP threads spin before they sleep when sph chooses (apps/sph/main.cpp):
/// long enough to bridge the serial stretches of a small scene's step (a sleeping thread takes
/// tens of microseconds to wake on a virtual machine), short enough that a program competing
/// for the cores loses little (docs/performance.md, "How idle threads wait").
inline constexpr double kSpinMicroseconds = 30;

/// libgomp's GOMP_SPINCOUNT that spins about `microseconds` on this CPU, rounded to a hundred
/// (at least 100, at most 100,000). Each of libgomp's spin iterations is one `pause`, whose cost
/// differs ten times and more between CPUs (10 ns on the Intel Xeon this project measured on
/// 2026-12-05, where the fixed count of 1,000 that served on an AMD EPYC spun only 10 us): the
/// count is calibrated by timing libgomp's spin iteration (a relaxed load, then a pause; the
/// fastest of three runs of 4,096, about 0.1-1 ms in all). 1,000 where there is no `pause` to
/// time (not x86).
long spin_count_lasting(double microseconds);

/// The calling thread's index in [0, num_threads()) inside a parallel loop (0 outside one).
/// Only for per-thread scratch: results must never depend on which thread ran what.
int thread_index();

/// Fixed chunk size used by parallel_chunks: chunk boundaries depend only on n. Small enough that
/// the paper's scenes (3,200 to 8,000 particles) give each of two threads several chunks of
/// every loop: with 1,024 the 2D dam break's second thread gave 1.41-1.43x, with 256 1.66-1.69x
/// (docs/performance.md, "Chunks of 256 particles").
inline constexpr std::size_t kChunkSize = 256;

/// Balances the loops over n items between the threads by the work of each chunk of kChunkSize
/// items (chunk_work[c], any unit, taken as spread evenly over the chunk's items): until the next
/// call, parallel_for(n) gives each thread one contiguous run of items holding about an equal
/// share of the work, instead of an equal share of the items, and parallel_chunks(n) the run of
/// chunks nearest to it. Loops over another count split evenly. Only which thread runs an item
/// changes, never what it computes: every loop writes only what its index or chunk owns, so
/// results stay the same bit for bit. The split belongs to the calling thread (each host thread
/// that runs loops keeps its own).
void balance_loops(std::size_t n, std::span<const std::uint64_t> chunk_work);
/// Forgets the split: every loop splits its items evenly again.
void clear_balance();

namespace detail {
/// The split of balance_loops: thread t of a team of `threads` takes items [first[t], first[t+1]).
struct LoopSplit {
  std::size_t n = 0;
  int threads = 0;
  std::vector<std::size_t> first;
};
const LoopSplit& loop_split();
int team_size();
/// The calling thread's run [begin, end) of the items [0, n), and of the chunks [0, chunks) of a
/// loop over n items: the balanced split when it applies to n and to this team, else an even one.
std::pair<std::size_t, std::size_t> item_run(const LoopSplit& split, std::size_t n);
std::pair<std::size_t, std::size_t> chunk_run(const LoopSplit& split, std::size_t n, std::size_t chunks);
}  // namespace detail

/// Calls f(i) for i in [0, n), in parallel. f must only write data owned by index i.
template <class F>
void parallel_for(std::size_t n, F&& f) {
  const detail::LoopSplit& split = detail::loop_split();
  if (split.n != n || split.threads < 2) {
    const auto count = static_cast<long long>(n);
#pragma omp parallel for schedule(static)
    for (long long i = 0; i < count; ++i) f(static_cast<std::size_t>(i));
    return;
  }
#pragma omp parallel
  {
    const auto [first, last] = detail::item_run(split, n);
    for (std::size_t i = first; i < last; ++i) f(i);
  }
}

/// The blocks that sums feeding results are taken in (chunked_sum: DFSPH's residuals, the kinetic
/// energy, momentum; the floating bodies' loads, the tracked modes' mean speed), fixed apart from
/// kChunkSize: they do not change when the loops' chunking does.
inline constexpr std::size_t kSumBlock = 1024;

/// Number of chunks of Size (kChunkSize, or kSumBlock for a sum) that cover [0, n).
template <std::size_t Size = kChunkSize>
std::size_t chunk_count(std::size_t n) {
  return (n + Size - 1) / Size;
}

/// Calls f(begin, end) once in each thread with the thread's contiguous run [begin, end) of
/// [0, n) (parallel_for's runs: balanced by balance_loops when it applies to n), none empty, in
/// parallel: for loops that handle their items a few at a time. f must only write data owned by
/// the indices of its run.
template <class F>
void parallel_runs(std::size_t n, F&& f) {
  const detail::LoopSplit& split = detail::loop_split();
#pragma omp parallel
  {
    const auto [first, last] = detail::item_run(split, n);
    if (first < last) f(first, last);
  }
}

/// Calls f(chunk, begin, end) for each chunk of [0, n) of size Size, in parallel.
/// The chunks are the same for any thread count, so per-chunk partial results combined in
/// chunk order give thread-count-independent results. Each thread takes one contiguous run of
/// chunks (a static schedule), as parallel_for takes one contiguous run of indices: the loops of
/// a step then hand every particle to the same core, whose cache still holds what the previous
/// loop wrote (dealt out one chunk at a time, the paper scenes ran 1.13x slower on 2 threads:
/// docs/performance.md, "Static chunk schedule").
template <std::size_t Size = kChunkSize, class F>
void parallel_chunks(std::size_t n, F&& f) {
  const detail::LoopSplit& split = detail::loop_split();
  if (Size != kChunkSize || split.n != n || split.threads < 2) {
    const auto chunks = static_cast<long long>(chunk_count<Size>(n));
#pragma omp parallel for schedule(static)
    for (long long c = 0; c < chunks; ++c) {
      const std::size_t begin = static_cast<std::size_t>(c) * Size;
      const std::size_t end = begin + Size < n ? begin + Size : n;
      f(static_cast<std::size_t>(c), begin, end);
    }
    return;
  }
#pragma omp parallel
  {
    const auto [first, last] = detail::chunk_run(split, n, chunk_count<Size>(n));
    for (std::size_t c = first; c < last; ++c) {
      const std::size_t begin = c * Size;
      f(c, begin, begin + Size < n ? begin + Size : n);
    }
  }
}

/// The sum of term(i) over [0, n), the same for any thread count: each fixed block of kSumBlock
/// indices sums its terms in index order into `partial` (kept by the caller, so that a step
/// allocates nothing), and the blocks' sums are added in block order.
template <class F>
double chunked_sum(std::size_t n, std::vector<double>& partial, F&& term) {
  partial.assign(chunk_count<kSumBlock>(n), 0.0);
  parallel_chunks<kSumBlock>(n, [&](std::size_t c, std::size_t begin, std::size_t end) {
    double s = 0;
    for (std::size_t i = begin; i < end; ++i) s += term(i);
    partial[c] = s;
  });
  double s = 0;
  for (const double p : partial) s += p;
  return s;
}

}  // namespace sph
