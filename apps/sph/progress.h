#pragma once
// Progress reporting for `sph run` and `sph render`: a bar with ETA on a terminal, a plain line every 10 %
// otherwise (logs, CI).

#include <cstdint>
#include <cstdio>

#include <sph/core/timer.h>

namespace sph::app {

class Progress {
 public:
  enum class Mode { Bar, Lines, Off };
  /// `unit` names what is counted ("step" for runs, "frame" for renders).
  Progress(std::int64_t total_steps, Mode mode, std::FILE* out = stderr, const char* unit = "step");
  /// `particles` is shown when it is not 0.
  void update(std::int64_t steps_done, std::size_t particles);
  void finish();

 private:
  std::int64_t total_;
  Mode mode_;
  std::FILE* out_;
  const char* unit_;
  Stopwatch watch_;
  double last_draw_ = -1;
  int last_decile_ = 0;
};

}  // namespace sph::app
