#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

#include <sph/core/error.h>
#include <sph/core/parallel.h>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace sph {

void set_num_threads(int n) {
  SPH_CHECK(n >= 1, "thread count must be positive");
#ifdef _OPENMP
  omp_set_num_threads(n);
#endif
}

int num_threads() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}

long spin_count_lasting(double microseconds) {
#if defined(__x86_64__) || defined(__i386__)
  constexpr int kPauses = 4096;
  double best = 0;  // ns per iteration
  static std::atomic<int> never{0};
  for (int run = 0; run < 3; ++run) {
    const auto start = std::chrono::steady_clock::now();
    // (libgomp's spin: a relaxed load of the word it waits on, then a pause)
    for (int i = 0; i < kPauses; ++i) {
      if (never.load(std::memory_order_relaxed) != 0) break;
      _mm_pause();
    }
    const double ns = std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start).count();
    if (run == 0 || ns < best) best = ns;
  }
  const double count = microseconds * 1e3 / std::max(best / kPauses, 0.1);
  return std::clamp(std::lround(count / 100) * 100, 100L, 100000L);
#else
  (void)microseconds;
  return 1000;
#endif
}

int thread_index() {
#ifdef _OPENMP
  return omp_get_thread_num();
#else
  return 0;
#endif
}

namespace {
thread_local detail::LoopSplit split_of_this_thread;
}

void balance_loops(std::size_t n, std::span<const std::uint64_t> chunk_work) {
  SPH_CHECK(chunk_work.size() == chunk_count(n), "balance_loops needs one work figure per chunk");
  detail::LoopSplit& s = split_of_this_thread;
  const int threads = num_threads();
  s.n = n;
  s.threads = threads;
  s.first.assign(static_cast<std::size_t>(threads) + 1, n);
  double total = 0;
  for (const std::uint64_t w : chunk_work) total += static_cast<double>(w);
  // Thread t starts where the work before it reaches t / threads of the whole, a chunk's work
  // taken as spread evenly over its items.
  double before = 0;
  std::size_t c = 0;
  for (int t = 0; t < threads; ++t) {
    const double share = total * t / threads;
    while (c < chunk_work.size() && before + static_cast<double>(chunk_work[c]) <= share)
      before += static_cast<double>(chunk_work[c++]);
    std::size_t item = n;
    if (c < chunk_work.size()) {
      const std::size_t begin = c * kChunkSize, size = std::min(n, begin + kChunkSize) - begin;
      const double into = (share - before) / static_cast<double>(chunk_work[c]);
      item = begin + std::min(size, static_cast<std::size_t>(into * static_cast<double>(size)));
    }
    s.first[static_cast<std::size_t>(t)] = t == 0 ? 0 : std::max(item, s.first[static_cast<std::size_t>(t) - 1]);
  }
}

void clear_balance() {
  split_of_this_thread.n = 0;
  split_of_this_thread.threads = 0;
}

namespace detail {

const LoopSplit& loop_split() { return split_of_this_thread; }

int team_size() {
#ifdef _OPENMP
  return omp_get_num_threads();
#else
  return 1;
#endif
}

std::pair<std::size_t, std::size_t> item_run(const LoopSplit& split, std::size_t n) {
  const auto team = static_cast<std::size_t>(team_size());
  const auto t = static_cast<std::size_t>(thread_index());
  if (split.n == n && static_cast<std::size_t>(split.threads) == team) return {split.first[t], split.first[t + 1]};
  return {n * t / team, n * (t + 1) / team};
}

std::pair<std::size_t, std::size_t> chunk_run(const LoopSplit& split, std::size_t n, std::size_t chunks) {
  const auto team = static_cast<std::size_t>(team_size());
  const auto t = static_cast<std::size_t>(thread_index());
  if (split.n == n && static_cast<std::size_t>(split.threads) == team) {
    // The chunk boundary nearest to each thread's first item.
    const auto nearest = [&](std::size_t item) { return std::min(chunks, (item + kChunkSize / 2) / kChunkSize); };
    return {t == 0 ? 0 : nearest(split.first[t]), t + 1 == team ? chunks : nearest(split.first[t + 1])};
  }
  return {chunks * t / team, chunks * (t + 1) / team};
}

}  // namespace detail

}  // namespace sph
