#pragma once
// Restores the worker thread count (sph::set_num_threads) at scope exit, for tests that run the
// same work with several thread counts.

#include <sph/core/parallel.h>

namespace sph::test {

struct ThreadCount {
  int saved = num_threads();
  ThreadCount() = default;
  ThreadCount(const ThreadCount&) = delete;
  ThreadCount& operator=(const ThreadCount&) = delete;
  ~ThreadCount() { set_num_threads(saved); }
};

}  // namespace sph::test
