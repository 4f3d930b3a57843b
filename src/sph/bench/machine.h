#pragma once
/// \file What a benchmark result needs to be compared: the machine, the build, the date; and
/// the process's memory figures (Linux /proc/self, glibc malloc statistics).

#include <cstdint>
#include <string>

namespace sph {

struct MachineInfo {
  std::string cpu_model;          ///< "model name" of /proc/cpuinfo ("unknown" elsewhere)
  int logical_cores = 0;          ///< std::thread::hardware_concurrency()
  int default_threads = 0;        ///< threads a parallel loop uses by default (OpenMP)
  std::int64_t memory_bytes = 0;  ///< MemTotal of /proc/meminfo (0 if unknown)
  std::string os;                 ///< uname: system, release, machine
  std::string compiler;           ///< compiler id and version (__VERSION__)
  std::string build_type;         ///< CMAKE_BUILD_TYPE at configure time
  std::string build_flags;        ///< CMAKE_CXX_FLAGS, the build type's flags, the directory's compile options
  std::string git_commit;         ///< commit at configure time, or "unknown"
  std::string version;            ///< sph version
  std::string date;               ///< UTC, ISO 8601, when machine_info() was called
  /// 1-minute load average when machine_info() was called (-1 if unknown): on a shared
  /// machine, a load above the core count means the timings are disturbed.
  double load_average = -1;
  /// The OpenMP environment variables that change timings (OMP_WAIT_POLICY, GOMP_SPINCOUNT,
  /// OMP_PROC_BIND, OMP_PLACES, OMP_NUM_THREADS) that are set, "NAME=value" separated by
  /// spaces; empty when none is (the runtime's defaults).
  std::string openmp_env;
};

MachineInfo machine_info();

/// Resets the kernel's peak-RSS counter (VmHWM) to the current RSS by writing "5" to
/// /proc/self/clear_refs. False if the kernel refused (the peak then covers the whole process).
bool reset_peak_rss();
/// VmRSS of /proc/self/status in bytes (-1 if unavailable).
std::int64_t current_rss_bytes();
/// VmHWM of /proc/self/status in bytes: the peak RSS since the start or the last reset (-1 if
/// unavailable).
std::int64_t peak_rss_bytes();
/// Bytes malloc has handed out and not taken back (glibc mallinfo2; -1 elsewhere).
std::int64_t heap_bytes_in_use();
/// Gives the heap's free memory back to the kernel (glibc malloc_trim), so that RSS measures
/// what is in use.
void release_free_heap();

}  // namespace sph
