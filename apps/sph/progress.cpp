#include "progress.h"

#include <string>

#include <fmt/format.h>

namespace sph::app {

namespace {
std::string duration(double s) {
  if (s < 60) return fmt::format("{:.1f}s", s);
  if (s < 3600) return fmt::format("{}m{:02d}s", static_cast<int>(s) / 60, static_cast<int>(s) % 60);
  return fmt::format("{}h{:02d}m", static_cast<int>(s) / 3600, (static_cast<int>(s) / 60) % 60);
}
}  // namespace

Progress::Progress(std::int64_t total_steps, Mode mode, std::FILE* out, const char* unit)
    : total_(total_steps > 0 ? total_steps : 1), mode_(mode), out_(out), unit_(unit) {}

void Progress::update(std::int64_t done, std::size_t particles) {
  if (mode_ == Mode::Off) return;
  const double t = watch_.elapsed();
  const double frac = static_cast<double>(done) / static_cast<double>(total_);
  const double eta = done > 0 ? t * (1.0 - frac) / frac : 0.0;
  const auto count = [&] {  // formatted only when something is printed
    return fmt::format("{} {}/{}{}", unit_, done, total_,
                       particles ? fmt::format("  {} particles", particles) : std::string());
  };
  if (mode_ == Mode::Bar) {
    if (t - last_draw_ < 0.1 && done < total_) return;  // redraw at most 10 times a second
    last_draw_ = t;
    constexpr int width = 30;
    const int filled = static_cast<int>(frac * width);
    fmt::print(out_, "\r[{}{}] {:3.0f}%  {}  {} elapsed  ETA {}   ", std::string(filled, '#'),
               std::string(width - filled, ' '), 100.0 * frac, count(), duration(t), duration(eta));
    std::fflush(out_);
  } else {
    const int decile = static_cast<int>(frac * 10.0);
    if (decile <= last_decile_) return;
    last_decile_ = decile;
    fmt::print(out_, "progress: {:3d}%  {}  {} elapsed  ETA {}\n", decile * 10, count(), duration(t), duration(eta));
    std::fflush(out_);
  }
}

void Progress::finish() {
  if (mode_ == Mode::Bar) fmt::print(out_, "\n");
}

}  // namespace sph::app
