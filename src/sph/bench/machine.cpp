#include <sph/bench/machine.h>

#include <sys/utsname.h>

#include <chrono>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <sstream>
#include <thread>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <fmt/format.h>

#include <sph/core/parallel.h>
#include <sph/core/version.h>
#include <sph/run/memory.h>

#ifndef SPH_BENCH_COMPILER_ID
#define SPH_BENCH_COMPILER_ID "unknown"
#endif
#ifndef SPH_BENCH_BUILD_TYPE
#define SPH_BENCH_BUILD_TYPE "unknown"
#endif
#ifndef SPH_BENCH_BUILD_FLAGS
#define SPH_BENCH_BUILD_FLAGS "unknown"
#endif

namespace sph {

namespace bench_detail {
extern const char* const kGitCommit;  // (generated at build time: cmake/git_commit.cmake)
}  // namespace bench_detail

namespace {

std::string trim(std::string s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return {};
  const auto e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

/// The value of the first line "key : value" (/proc/cpuinfo) or "key: value" (/proc/*/status).
std::string proc_field(const char* file, const std::string& key) {
  std::ifstream in(file);
  for (std::string line; std::getline(in, line);) {
    const auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    if (trim(line.substr(0, colon)) == key) return trim(line.substr(colon + 1));
  }
  return {};
}

/// A "<number> kB" field of a /proc file, in bytes (-1 if missing).
std::int64_t proc_kib(const char* file, const std::string& key) {
  const std::string v = proc_field(file, key);
  if (v.empty()) return -1;
  try {
    return static_cast<std::int64_t>(std::stoll(v)) * 1024;
  } catch (const std::exception&) {
    return -1;
  }
}

}  // namespace

MachineInfo machine_info() {
  MachineInfo m;
  m.cpu_model = proc_field("/proc/cpuinfo", "model name");
  if (m.cpu_model.empty()) m.cpu_model = "unknown";
  m.logical_cores = static_cast<int>(std::thread::hardware_concurrency());
  m.default_threads = num_threads();
  m.memory_bytes = physical_memory_bytes();
  utsname u{};
  if (::uname(&u) == 0) m.os = fmt::format("{} {} {}", u.sysname, u.release, u.machine);
  m.compiler = fmt::format("{} {}", SPH_BENCH_COMPILER_ID, __VERSION__);
  m.build_type = SPH_BENCH_BUILD_TYPE;
  m.build_flags = trim(SPH_BENCH_BUILD_FLAGS);
  m.git_commit = bench_detail::kGitCommit;
  if (m.git_commit.empty()) m.git_commit = "unknown";
  m.version = kVersion;
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  ::gmtime_r(&now, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  m.date = buf;
  for (const char* name : {"OMP_WAIT_POLICY", "GOMP_SPINCOUNT", "OMP_PROC_BIND", "OMP_PLACES", "OMP_NUM_THREADS"})
    if (const char* v = std::getenv(name))
      m.openmp_env += fmt::format("{}{}={}", m.openmp_env.empty() ? "" : " ", name, v);
  std::ifstream loadavg("/proc/loadavg");
  if (!(loadavg >> m.load_average)) m.load_average = -1;
  return m;
}

bool reset_peak_rss() {
  std::ofstream out("/proc/self/clear_refs");
  if (!out) return false;
  out << "5";
  out.flush();
  return static_cast<bool>(out);
}

std::int64_t current_rss_bytes() { return proc_kib("/proc/self/status", "VmRSS"); }

std::int64_t peak_rss_bytes() { return proc_kib("/proc/self/status", "VmHWM"); }

std::int64_t heap_bytes_in_use() {
#if defined(__GLIBC__) && (__GLIBC__ > 2 || (__GLIBC__ == 2 && __GLIBC_MINOR__ >= 33))
  const struct mallinfo2 mi = ::mallinfo2();
  return static_cast<std::int64_t>(mi.uordblks + mi.hblkhd);
#else
  return -1;
#endif
}

void release_free_heap() {
#if defined(__GLIBC__)
  ::malloc_trim(0);
#endif
}

}  // namespace sph
