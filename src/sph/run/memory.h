#pragma once
/// \file Whether a scene fits in this machine's memory, asked before anything is allocated.

#include <cstdint>

#include <sph/scene/scene_desc.h>

namespace sph {

/// This machine's physical memory in bytes: MemTotal of /proc/meminfo (0 where unknown, e.g.
/// not Linux).
std::int64_t physical_memory_bytes();

/// Refuses (sph::Error naming the scene file) a scene whose particles cannot fit in this
/// machine's memory at their most (estimated_run_bytes against physical_memory_bytes), so that
/// the operating system does not kill the run, or let it swap for hours. Does nothing where the
/// memory is unknown.
void check_fits_in_memory(const SceneDesc& desc);

}  // namespace sph
