// Whether this machine's two cores share their arithmetic or their memory (docs/performance.md,
// "The density sums' room, two list-build tries, and the tank on two threads"), each measure on
// one thread, then on two threads at once:
// - a chain of dependent additions (one a cycle): each thread's additions per nanosecond, the
//   clock in GHz. It does not tell SMT siblings apart: a core runs two such chains side by side.
// - twelve independent chains of 512-bit float additions (x86-64 with AVX-512), enough to keep
//   every vector adder busy: registers added per nanosecond. Two SMT siblings would each get
//   about half of one thread's figure; two cores each keep it.
// - reading a private buffer of 2 MB (beyond the 1 MB L2, in the L3) and of 64 MB (memory) over
//   and over: GB/s for each thread.
//   bash scripts/core_share.sh [RUNS]
#include <chrono>
#include <cstddef>
#include <cstdio>
#include <functional>
#include <thread>
#include <vector>

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

double chain_ghz() {
  constexpr long kAdds = 1'000'000'000;
  unsigned long x = 1;
  const auto t0 = std::chrono::steady_clock::now();
  for (long i = 0; i < kAdds; ++i) asm volatile("add $1, %0" : "+r"(x));
  return static_cast<double>(kAdds) / seconds_since(t0) * 1e-9;
}

#if defined(__AVX512F__)
double vector_adds_per_ns() {
  constexpr long kRounds = 200'000'000;  // twelve additions a round, on registers only
  const auto t0 = std::chrono::steady_clock::now();
  asm volatile(
      "vxorps %%zmm12, %%zmm12, %%zmm12\n"
      "vmovaps %%zmm12, %%zmm0\n vmovaps %%zmm12, %%zmm1\n vmovaps %%zmm12, %%zmm2\n vmovaps %%zmm12, %%zmm3\n"
      "vmovaps %%zmm12, %%zmm4\n vmovaps %%zmm12, %%zmm5\n vmovaps %%zmm12, %%zmm6\n vmovaps %%zmm12, %%zmm7\n"
      "vmovaps %%zmm12, %%zmm8\n vmovaps %%zmm12, %%zmm9\n vmovaps %%zmm12, %%zmm10\n vmovaps %%zmm12, %%zmm11\n"
      "mov %0, %%rcx\n"
      "1:\n"
      "vaddps %%zmm12, %%zmm0, %%zmm0\n vaddps %%zmm12, %%zmm1, %%zmm1\n vaddps %%zmm12, %%zmm2, %%zmm2\n"
      "vaddps %%zmm12, %%zmm3, %%zmm3\n vaddps %%zmm12, %%zmm4, %%zmm4\n vaddps %%zmm12, %%zmm5, %%zmm5\n"
      "vaddps %%zmm12, %%zmm6, %%zmm6\n vaddps %%zmm12, %%zmm7, %%zmm7\n vaddps %%zmm12, %%zmm8, %%zmm8\n"
      "vaddps %%zmm12, %%zmm9, %%zmm9\n vaddps %%zmm12, %%zmm10, %%zmm10\n vaddps %%zmm12, %%zmm11, %%zmm11\n"
      "dec %%rcx\n"
      "jnz 1b\n"
      :
      : "r"(kRounds)
      : "rcx", "xmm0", "xmm1", "xmm2", "xmm3", "xmm4", "xmm5", "xmm6", "xmm7", "xmm8", "xmm9", "xmm10", "xmm11",
        "xmm12", "cc");
  return 12.0 * static_cast<double>(kRounds) / seconds_since(t0) * 1e-9;
}
#endif

/// GB/s reading a buffer of `bytes` of the calling thread's, about 8 GB in all.
double read_gbs(std::size_t bytes) {
  std::vector<double> a(bytes / sizeof(double), 1.0);
  const long rounds = static_cast<long>(8e9 / static_cast<double>(bytes));
  double s[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  const auto t0 = std::chrono::steady_clock::now();
  for (long r = 0; r < rounds; ++r)
    for (std::size_t i = 0; i + 8 <= a.size(); i += 8)
      for (int k = 0; k < 8; ++k) s[k] += a[i + static_cast<std::size_t>(k)];
  const double t = seconds_since(t0);
  double sum = 0;
  for (double x : s) sum += x;
  if (sum == -1.0) std::printf("?");  // (keeps the sums)
  return static_cast<double>(rounds) * static_cast<double>(bytes) / t * 1e-9;
}

/// `what` on one thread, then on two at once.
void one_then_two(const char* what, const char* unit, const std::function<double()>& f) {
  const double one = f();
  double two[2] = {0, 0};
  std::vector<std::thread> team;
  for (int t = 0; t < 2; ++t) team.emplace_back([&two, t, &f] { two[t] = f(); });
  for (auto& th : team) th.join();
  std::printf("%-34s 1 thread: %6.2f %s   2 threads: %6.2f and %6.2f %s\n", what, one, unit, two[0], two[1], unit);
}

}  // namespace

int main() {
  one_then_two("dependent additions", "/ns", chain_ghz);
#if defined(__AVX512F__)
  one_then_two("independent 512-bit float additions", "/ns", vector_adds_per_ns);
#endif
  one_then_two("reading 2 MB (L3)", "GB/s", [] { return read_gbs(std::size_t{2} << 20); });
  one_then_two("reading 64 MB (memory)", "GB/s", [] { return read_gbs(std::size_t{64} << 20); });
}
