// libFuzzer target of the scene reader (built with -fsanitize=fuzzer,address,undefined by
// scripts/sanitize.sh; see tests/fuzz/CMakeLists.txt).
//
// Input: scene text, optionally followed by NUL-separated --set overrides
// ("SCENE\0Fluid.stiffness=2000\0FluidBlocks[0].end=[1,1]"), so the override parser is fuzzed
// along with the JSON reader. A refusal is an sph::Error, the expected outcome of bad input;
// anything else thrown (std::logic_error from SPH_CHECK, nlohmann's exceptions, bad_alloc, ...)
// aborts and is reported as a finding, as are crashes, leaks and undefined behaviour.
//
// A scene the reader accepts must keep the promises of SceneDesc (finite, positive sizes and
// masses, unit emitter directions, everything inside the container: check_accepted below; and
// the preflight's: no overlapping blocks, whole nozzles inside: check_preflight_promises); a
// broken promise is a finding too. It is then built (particles and Simulation) and stepped
// twice when it is small, so values that pass validation are also shown to be usable. What
// scene_to_json writes of it must read back to an equal SceneDesc.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <typeinfo>
#include <vector>

#include <sph/core/error.h>
#include <sph/core/parallel.h>
#include <sph/scene/builders.h>
#include <sph/scene/scene_desc.h>
#include <sph/scene/scene_reader.h>
#include <sph/scene/scene_writer.h>
#include <sph/solver/nozzle.h>

namespace {

/// Scenes with more particles (blocks plus every emitter's budget) than this are only read:
/// building and stepping them would dominate the fuzzer's time (and reserve their memory).
constexpr double kMaxSimulatedParticles = 2000;
/// Overrides taken from one input; more are ignored.
constexpr std::size_t kMaxOverrides = 8;

[[noreturn]] void finding(const char* kind, const char* what) {
  std::fprintf(stderr, "scene_reader_fuzz: %s escaped (not an sph::Error): %s\n", kind, what);
  std::abort();
}

void promise(bool kept, const char* what) {
  if (kept) return;
  std::fprintf(stderr, "scene_reader_fuzz: an accepted scene breaks a promise: %s\n", what);
  std::abort();
}

bool positive_finite(double x) { return std::isfinite(x) && x > 0; }

template <int D>
bool proper_box(const sph::Box<D>& b) {
  for (int d = 0; d < D; ++d)
    if (!(b.lo[d] < b.hi[d] && std::isfinite(b.hi[d] - b.lo[d]))) return false;
  return true;
}

template <int D>
bool inside(const sph::Vec<D, double>& x, const sph::Box<D>& b) {
  for (int d = 0; d < D; ++d)
    if (!(x[d] >= b.lo[d] && x[d] <= b.hi[d])) return false;
  return true;
}

/// What every scene the reader accepts must satisfy: the solver and the builders rely on it.
template <int D>
void check_accepted(const sph::SceneDesc& desc) {
  const sph::SceneBody<D>& body = desc.body<D>();
  const sph::SimulationParams<D>& p = body.sim;
  promise(desc.steps >= 1 && desc.output.every_steps >= 0, "step counts");
  promise(positive_finite(p.time_step), "time step > 0");
  promise(positive_finite(p.particle_radius), "particle radius > 0");
  promise(positive_finite(p.kernel_radius) && p.kernel_radius > 2 * p.particle_radius, "h > spacing");
  promise(positive_finite(p.particle_mass), "particle mass > 0");
  promise(positive_finite(p.fluid.rest_density) && positive_finite(p.fluid.stiffness), "density0, stiffness > 0");
  promise(std::isfinite(p.fluid.viscosity) && p.fluid.viscosity >= 0, "viscosity >= 0");
  promise(positive_finite(p.walls.stiffness) && std::isfinite(p.walls.damping) && p.walls.damping >= 0, "walls");
  promise(positive_finite(p.verlet_skin), "verlet skin > 0");
  promise(p.full_rebuild_period >= 1 && p.reorder_period >= 0, "periods");
  for (int d = 0; d < D; ++d) promise(std::isfinite(p.gravity[d]), "finite gravity");
  promise(proper_box<D>(p.container), "container: lo < hi, finite size");
  for (const auto& o : p.obstacles) promise(proper_box<D>(o), "obstacle: lo < hi, finite size");
  for (const auto& b : body.blocks) {
    promise(proper_box<D>(b.box), "fluid block: lo < hi, finite size");
    promise(inside<D>(b.box.lo, p.container) && inside<D>(b.box.hi, p.container), "fluid block inside the container");
    for (int d = 0; d < D; ++d) promise(std::isfinite(b.velocity[d]), "finite block velocity");
  }
  double total = static_cast<double>(sph::count_block_particles<D>(body));
  for (const auto& e : p.emitters) {
    double length2 = 0;
    for (int d = 0; d < D; ++d) length2 += e.direction[d] * e.direction[d];
    promise(std::abs(length2 - 1) < 1e-12, "emitter direction is a unit vector");
    promise(inside<D>(e.origin, p.container), "emitter nozzle center inside the container");
    promise(positive_finite(e.speed) && e.width >= 1 && e.height >= 1 && e.every_steps >= 1, "emitter values");
    promise(e.max_particles >= 1 && e.start_time >= 0 && !(e.end_time < 0), "emitter budget and times");
    total += static_cast<double>(e.max_particles);
  }
  promise(total >= 1 && total <= 2e9, "between 1 and 2e9 particles");
}

/// The writer's promise: the scene it writes reads back to an equal SceneDesc.
void check_written(const sph::SceneDesc& desc) {
  try {
    promise(sph::parse_scene(sph::scene_text(desc), desc.source) == desc, "the written scene reads back equal");
  } catch (const sph::Error& e) {
    finding("a refusal of the written scene", e.what());
  }
}

template <int D>
double particle_budget(const sph::SceneDesc& desc) {
  const sph::SceneBody<D>& body = desc.body<D>();
  double total = static_cast<double>(sph::count_block_particles<D>(body));
  for (const auto& e : body.sim.emitters) total += static_cast<double>(e.max_particles);
  return total;
}

/// The preflight's promises on a small accepted scene, checked on what the builders and the
/// emitter make: no two particles of different fluid blocks closer than half a spacing, and
/// every nozzle particle at least a particle radius inside the container.
template <int D>
void check_preflight_promises(const sph::SceneDesc& desc) {
  const sph::SceneBody<D>& body = desc.body<D>();
  const sph::SimulationParams<D>& p = body.sim;
  const double dx = 2 * p.particle_radius;
  const auto ps = sph::build_particles<D, double>(body);
  // Each block's kept particles, in block order (a block cut by obstacle shapes keeps fewer
  // particles than its lattice has sites).
  std::vector<std::size_t> block_of;
  const std::vector<sph::BlockCount> counts = sph::count_block_particles_kept<D>(body);
  for (std::size_t b = 0; b < counts.size(); ++b) block_of.insert(block_of.end(), counts[b].kept, b);
  promise(block_of.size() == ps.size(), "one block per built particle");
  for (std::size_t i = 0; i < ps.size(); ++i)
    for (std::size_t j = i + 1; j < ps.size(); ++j)
      if (block_of[i] != block_of[j])
        promise(sph::norm(ps.position[i] - ps.position[j]) >= 0.5 * dx * (1 - 1e-9), "no overlapping blocks");
  for (const auto& e : p.emitters) {
    const auto [u, w] = sph::nozzle_axes<D>(e.direction);
    for (int a : {0, e.width - 1})
      for (int b : {0, D == 3 ? e.height - 1 : 0}) {
        const auto x = sph::nozzle_position<D>(e, u, w, a, b);
        for (int d = 0; d < D; ++d)
          promise(x[d] >= p.container.lo[d] + p.particle_radius * (1 - 1e-6) &&
                      x[d] <= p.container.hi[d] - p.particle_radius * (1 - 1e-6),
                  "every nozzle particle a particle radius inside the container");
      }
  }
}

template <int D, class R>
void simulate_briefly(const sph::SceneDesc& desc) {
  auto sim = sph::make_simulation<D, R>(desc);
  for (int s = 0; s < 2; ++s) sim.step();
}

template <int D>
void check_and_simulate(const sph::SceneDesc& desc) {
  check_accepted<D>(desc);
  if (particle_budget<D>(desc) > kMaxSimulatedParticles) return;
  check_preflight_promises<D>(desc);
  if (desc.precision == sph::Precision::Float)
    simulate_briefly<D, float>(desc);
  else
    simulate_briefly<D, double>(desc);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  sph::set_num_threads(1);  // one thread: the fuzzer's own process runs the small simulations
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string input(reinterpret_cast<const char*>(data), size);
  const std::size_t nul = input.find('\0');
  const std::string text = input.substr(0, nul);
  std::vector<std::string> overrides;
  for (std::size_t at = nul; at != std::string::npos && overrides.size() < kMaxOverrides;) {
    const std::size_t next = input.find('\0', at + 1);
    overrides.push_back(input.substr(at + 1, next == std::string::npos ? std::string::npos : next - at - 1));
    at = next;
  }
  try {
    const sph::SceneDesc desc = sph::parse_scene(text, "fuzz", overrides);
    promise(desc.dimension == 2 || desc.dimension == 3, "dimension 2 or 3");
    check_written(desc);
    if (desc.dimension == 2)
      check_and_simulate<2>(desc);
    else
      check_and_simulate<3>(desc);
  } catch (const sph::Error&) {
    // Refused with a message: what bad input must get.
  } catch (const std::exception& e) {
    finding(typeid(e).name(), e.what());
  } catch (...) {
    finding("a non-std exception", "");
  }
  return 0;
}
