// Whether this machine's cores share their arithmetic (docs/performance.md, "The density sums'
// room, two list-build tries, and the tank on two threads"): a chain of dependent additions (one
// a cycle) on one thread, then on two threads at once. Prints each thread's additions per
// nanosecond, which is the clock in GHz while the chain runs alone in its core: two threads that
// each keep it share no arithmetic unit (no SMT siblings), whatever else they share.
//   bash scripts/core_share.sh [RUNS]
#include <chrono>
#include <cstdio>
#include <thread>
#include <vector>

namespace {

double chain_ghz() {
  constexpr long kAdds = 1'000'000'000;
  unsigned long x = 1;
  const auto t0 = std::chrono::steady_clock::now();
  for (long i = 0; i < kAdds; ++i) asm volatile("add $1, %0" : "+r"(x));
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return static_cast<double>(kAdds) / s * 1e-9;
}

}  // namespace

int main() {
  std::printf("1 thread:  %.2f additions/ns\n", chain_ghz());
  double ghz[2] = {0, 0};
  std::vector<std::thread> team;
  for (int t = 0; t < 2; ++t) team.emplace_back([&ghz, t] { ghz[t] = chain_ghz(); });
  for (auto& th : team) th.join();
  std::printf("2 threads: %.2f and %.2f additions/ns\n", ghz[0], ghz[1]);
}
