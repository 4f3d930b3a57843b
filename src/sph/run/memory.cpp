#include <sph/run/memory.h>

#include <fstream>
#include <sstream>
#include <string>

#include <fmt/format.h>

#include <sph/core/error.h>
#include <sph/scene/builders.h>

namespace sph {

std::int64_t physical_memory_bytes() {
  std::ifstream in("/proc/meminfo");
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("MemTotal:", 0) != 0) continue;
    std::istringstream value(line.substr(9));
    std::int64_t kib = -1;
    value >> kib;  // "   16314088 kB"
    return kib > 0 ? kib * 1024 : 0;
  }
  return 0;
}

void check_fits_in_memory(const SceneDesc& desc) {
  const double need = estimated_run_bytes(desc);
  const std::int64_t have = physical_memory_bytes();
  if (have > 0 && need > static_cast<double>(have))
    throw Error(fmt::format("the scene holds up to {} particles, which need about {:.3g} GB (particle fields, "
                            "neighbor lists, grid), more than this machine's {:.3g} GB of memory; use fewer "
                            "particles (a larger Configuration.particleRadius, smaller blocks or emitter budgets)",
                            max_particles(desc), need / 1e9, static_cast<double>(have) / 1e9),
                desc.source);
}

}  // namespace sph
