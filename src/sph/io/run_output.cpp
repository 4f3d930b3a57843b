#include <sph/io/run_output.h>

#include <cstdlib>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <sph/core/error.h>
#include <sph/core/parallel.h>
#include <sph/core/timer.h>
#include <sph/core/version.h>
#include <sph/io/atomic_file.h>

namespace sph {

namespace fs = std::filesystem;

void prepare_output_directory(const fs::path& dir) {
  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
    throw Error("exists and is not a directory; expected a directory for the run's output", dir.string());
  fs::create_directories(dir / "frames", ec);
  if (ec) throw Error("cannot create the output directory: " + ec.message(), dir.string());
  // Check that files can be created here before anything else is touched.
  { AtomicFile probe(dir / ".write-test"); }
  { AtomicFile probe(dir / "frames" / ".write-test"); }
  // Remove what a previous run left, so that frames of two runs are never mixed.
  for (const char* name : {"frames.pvd", "stats.csv", "summary.json", "scene.json"}) fs::remove(dir / name, ec);
  for (const auto& entry : fs::directory_iterator(dir / "frames", ec)) {
    const std::string f = entry.path().filename().string();
    if (f.rfind("frame_", 0) == 0 && entry.path().extension() == ".vtu") fs::remove(entry.path(), ec);
  }
}

template <int D, std::floating_point R>
RunOutput<D, R>::RunOutput(fs::path dir, const SceneDesc& desc, RunInfo info)
    : dir_(std::move(dir)), desc_(desc), info_(std::move(info)) {
  stats_tmp_ = dir_ / ".stats.csv.partial";
  stats_.open(stats_tmp_, std::ios::trunc);
  if (!stats_) throw Error("cannot create stats.csv", dir_.string());
  stats_ << kStatsColumns << '\n';
}

template <int D, std::floating_point R>
RunOutput<D, R>::~RunOutput() {
  if (!finished_) {
    stats_.close();
    std::error_code ec;
    fs::rename(stats_tmp_, dir_ / "stats.csv", ec);
  }
}

template <int D, std::floating_point R>
void RunOutput<D, R>::write_frame(const Simulation<D, R>& sim) {
  const std::string file = fmt::format("frames/frame_{:06d}.vtu", pvd_.size());
  write_vtu(dir_ / file, sim.particles());
  pvd_.push_back({sim.time(), file});
  write_pvd(dir_ / "frames.pvd", pvd_);
}

template <int D, std::floating_point R>
void RunOutput<D, R>::begin(const Simulation<D, R>& sim) {
  Stopwatch w;
  write_file_atomic(dir_ / "scene.json", desc_.effective_json + "\n");
  if (desc_.output_every_steps > 0) write_frame(sim);
  output_seconds_ += w.lap();
}

template <int D, std::floating_point R>
double RunOutput<D, R>::after_step(const Simulation<D, R>& sim, const StepInfo& info, bool last) {
  Stopwatch w;
  const std::int64_t every = desc_.output_every_steps;
  if (every > 0 && (sim.steps_done() % every == 0 || last)) write_frame(sim);
  const double t_output = w.lap();
  totals_ += info.seconds;
  output_seconds_ += t_output;
  const double mean_neighbors =
      info.particles ? static_cast<double>(info.neighbors.pairs_stored) / static_cast<double>(info.particles) : 0.0;
  const std::string audit = info.audited ? fmt::format("{},{},{:.6g}", info.audit.missed_pairs,
                                                       info.audit.particles_missing, info.audit.max_penetration)
                                         : std::string(",,");
  stats_ << fmt::format("{},{:.9g},{},{:.9g},{:.9g},{:.6g},{},{},{},{},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g}\n",
                        info.step, info.time, info.particles, sim.kinetic_energy(), sim.max_speed(), mean_neighbors,
                        info.neighbors.lists_rebuilt, info.neighbors.pairs_stored, info.pairs_within_h, audit,
                        info.seconds.grid, info.seconds.lists, info.seconds.density, info.seconds.forces,
                        info.seconds.integrate, t_output);
  if (info.audited) {
    audit_.missed_pairs += info.audit.missed_pairs;
    audit_.max_penetration = std::max(audit_.max_penetration, info.audit.max_penetration);
    audit_steps_with_misses_ += info.audit.missed_pairs > 0 ? 1 : 0;
  }
  totals_lists_rebuilt_ += info.neighbors.lists_rebuilt;
  if (last || (every > 0 && sim.steps_done() % every == 0)) stats_.flush();
  return t_output;
}

template <int D, std::floating_point R>
void RunOutput<D, R>::finish(const Simulation<D, R>& sim, const std::string& status, double wall_seconds) {
  stats_.close();
  if (stats_.fail()) throw Error("writing stats.csv failed (disk full?)", dir_.string());
  std::error_code ec;
  fs::rename(stats_tmp_, dir_ / "stats.csv", ec);
  if (ec) throw Error("cannot move stats.csv into place: " + ec.message(), dir_.string());
  finished_ = true;

  nlohmann::ordered_json s;
  s["sph_version"] = kVersion;
  s["status"] = status;
  s["scene"] = desc_.name;
  s["scene_file"] = desc_.source;
  s["dimension"] = D;
  s["precision"] = std::is_same_v<R, float> ? "float" : "double";
  s["neighbors"] = info_.mode;
  s["threads"] = info_.threads;
  // How idle OpenMP threads wait (sph sets GOMP_SPINCOUNT=1000 unless the user chose).
  std::string wait;
  for (const char* var : {"OMP_WAIT_POLICY", "GOMP_SPINCOUNT"})
    if (const char* v = std::getenv(var)) wait += (wait.empty() ? "" : " ") + std::string(var) + "=" + v;
  s["openmp_wait"] = wait;
  s["steps"] = sim.steps_done();
  s["simulated_time"] = sim.time();
  s["time_step"] = sim.params().time_step;
  s["particles"] = sim.particles().size();
  s["frames"] = pvd_.size();
  s["wall_seconds"] = wall_seconds;
  s["phase_seconds"] = {{"grid", totals_.grid},     {"lists", totals_.lists},         {"density", totals_.density},
                        {"forces", totals_.forces}, {"integrate", totals_.integrate}, {"output", output_seconds_}};
  s["lists_rebuilt"] = totals_lists_rebuilt_;
  if (sim.params().audit)
    s["audit"] = {{"missed_pairs", audit_.missed_pairs},
                  {"steps_with_misses", audit_steps_with_misses_},
                  {"max_missed_penetration", audit_.max_penetration}};
  s["kinetic_energy"] = sim.kinetic_energy();
  s["max_speed"] = sim.max_speed();
  write_file_atomic(dir_ / "summary.json", s.dump(2) + "\n");
}

template class RunOutput<2, float>;
template class RunOutput<2, double>;
template class RunOutput<3, float>;
template class RunOutput<3, double>;

}  // namespace sph
