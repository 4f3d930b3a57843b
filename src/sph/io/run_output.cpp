#include <sph/io/run_output.h>

#include <algorithm>
#include <cstdlib>
#include <sstream>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include <sph/core/error.h>
#include <sph/core/parallel.h>
#include <sph/core/state_stream.h>
#include <sph/core/timer.h>
#include <sph/core/version.h>
#include <sph/io/atomic_file.h>
#include <sph/io/checkpoint.h>
#include <sph/io/frames.h>
#include <sph/io/vtk.h>
#include <sph/scene/scene_writer.h>

namespace sph {

namespace fs = std::filesystem;

namespace {

/// Checks that files can be created in dir and dir/frames (creating them if needed).
void check_writable(const fs::path& dir) {
  make_writable_directory(dir, "the run's output");
  make_writable_directory(dir / "frames", "the run's frames");
}

/// Removes AtomicFile's temporary files (".NAME.tmpPID-N") that a killed process left in `dir`.
void remove_stale_temporaries(const fs::path& dir) {
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string f = entry.path().filename().string();
    const std::size_t tmp = f.rfind(".tmp");
    if (f.empty() || f[0] != '.' || tmp == std::string::npos || !entry.is_regular_file(ec)) continue;
    const std::string tail = f.substr(tmp + 4);  // "PID-N"
    const std::size_t dash = tail.find('-');
    const auto digits = [](const std::string& t) {
      return !t.empty() && t.find_first_not_of("0123456789") == std::string::npos;
    };
    if (dash != std::string::npos && digits(tail.substr(0, dash)) && digits(tail.substr(dash + 1)))
      fs::remove(entry.path(), ec);
  }
}

}  // namespace

std::string stats_header() {
  std::string s;
  for (const StatsColumn& c : kStatsColumns) (s += s.empty() ? "" : ",") += c.name;
  return s;
}

std::string stats_row(const StepStats& stats) {
  std::string s;
  bool first = true;
  for (const StatsColumn& c : kStatsColumns) {
    if (!first) s += ',';
    first = false;
    if (c.audit_only && !stats.info.audited) continue;
    switch (c.format) {
      case StatsFormat::Count:
        s += fmt::format("{}", c.count(stats));
        break;
      case StatsFormat::Real9:
        s += fmt::format("{:.9g}", c.real(stats));
        break;
      case StatsFormat::Real6:
        s += fmt::format("{:.6g}", c.real(stats));
        break;
    }
  }
  return s;
}

void prepare_resume_directory(const fs::path& dir) {
  std::error_code ec;
  require_directory(dir, "the output directory of an earlier run (sph run -o DIR)");
  check_writable(dir);
  remove_stale_temporaries(dir);
  remove_stale_temporaries(dir / "frames");
}

std::vector<fs::path> files_a_run_replaces(const fs::path& dir) {
  std::vector<fs::path> out;
  std::error_code ec;
  for (const char* name : {"frames.pvd", "solids.pvd", "stats.csv", "summary.json", "scene.json", kCheckpointFile,
                           kRunIdentityFile, "boundary.vtu", "bodies.csv", "view.html"})
    if (fs::exists(dir / name, ec)) out.push_back(dir / name);
  // Directory listings in name order, so that messages and removals do not depend on the file system.
  const auto sorted = [&](const fs::path& sub, const auto& wanted) {
    std::vector<fs::path> found;
    for (const auto& entry : fs::directory_iterator(sub, ec))
      if (wanted(entry.path().filename().string(), entry.path().extension().string())) found.push_back(entry.path());
    std::sort(found.begin(), found.end());
    out.insert(out.end(), found.begin(), found.end());
  };
  sorted(dir / "render", [](const std::string& f, const std::string&) { return is_render_output(f); });
  sorted(dir / "surface", [](const std::string& f, const std::string&) { return is_surface_output(f); });
  sorted(dir / "frames", [](const std::string& f, const std::string& ext) {
    return (f.rfind("frame_", 0) == 0 && (ext == ".vtu" || ext == ".vtk" || ext == ".ply")) ||
           (f.rfind("solids_", 0) == 0 && (ext == ".vtp" || ext == ".ply"));
  });
  return out;
}

void check_new_run_directory(const fs::path& dir, bool overwrite, const std::string& output_option,
                             const std::string& overwrite_option, const std::string& resume_hint) {
  check_output_path(dir.string(), output_option);
  if (overwrite) return;
  if (const std::optional<std::string> unfinished = unfinished_run(dir))
    throw Error(fmt::format("holds {}; {}give {} to delete it (with the run's frames, stats and summary) and start "
                            "this run there",
                            *unfinished, resume_hint.empty() ? "" : resume_hint + ", or ", overwrite_option),
                dir.string());
  std::error_code ec;
  if (fs::exists(dir / kRunIdentityFile, ec)) return;  // an earlier run's directory: its files are replaced
  const std::vector<fs::path> files = files_a_run_replaces(dir);
  if (files.empty()) return;
  std::vector<std::string> names;
  for (std::size_t k = 0; k < files.size() && k < 3; ++k) names.push_back(files[k].lexically_relative(dir).string());
  if (files.size() > 3) names.push_back(fmt::format("{} more", files.size() - 3));
  throw Error(fmt::format("is not the directory of an earlier run (no {}) but holds files a run writes ({}), which "
                          "would be replaced; expected a new or empty directory, or an earlier run's (or give {} to "
                          "replace them)",
                          kRunIdentityFile, fmt::join(names, ", "), overwrite_option),
              dir.string());
}

void prepare_output_directory(const fs::path& dir) {
  std::error_code ec;
  // Check that files can be created here before anything else is touched.
  check_writable(dir);
  remove_stale_temporaries(dir);
  remove_stale_temporaries(dir / "frames");
  // Remove what a previous run left, so that frames of two runs are never mixed.
  for (const fs::path& f : files_a_run_replaces(dir)) fs::remove(f, ec);
  for (const char* sub : {"render", "surface"}) {
    remove_abandoned_stages(dir / sub);  // (a killed render's or surface's hidden files)
    if (fs::is_empty(dir / sub, ec)) fs::remove(dir / sub, ec);
  }
}

template <int D, std::floating_point R>
RunOutput<D, R>::RunOutput(fs::path dir, const SceneDesc& desc, RunInfo info, std::string run_id)
    : dir_(std::move(dir)),
      desc_(desc),
      info_(std::move(info)),
      frames_(dir_, desc.output),
      stats_tmp_(dir_ / ".stats.csv.partial") {
  identity_ = {run_id.empty() ? new_run_id() : std::move(run_id), scene_fingerprint(scene_text(desc))};
}

template <int D, std::floating_point R>
void RunOutput<D, R>::open_stats() {
  stats_.open(stats_tmp_, std::ios::trunc);
  if (!stats_) throw Error("cannot create stats.csv", dir_.string());
  stats_ << stats_header() << '\n';
}

template <int D, std::floating_point R>
RunOutput<D, R>::~RunOutput() {
  if (!finished_ && stats_.is_open()) {
    stats_.close();
    std::error_code ec;
    fs::rename(stats_tmp_, dir_ / "stats.csv", ec);
  }
}

template <int D, std::floating_point R>
void RunOutput<D, R>::begin(const Simulation<D, R>& sim) {
  Stopwatch w;
  open_stats();
  write_file_atomic(dir_ / "scene.json", scene_text(desc_) + "\n");
  write_run_identity(dir_, identity_);
  if (desc_.output.boundary) write_boundary(sim);
  frames_.write_due(sim, false);  // frame 0, if the run writes frames
  output_seconds_ += w.lap();
}

template <int D, std::floating_point R>
void RunOutput<D, R>::write_boundary(const Simulation<D, R>& sim) const {
  const BoundarySet<D, R>& b = sim.boundary();
  if (b.size() == 0) return;
  ParticleSet<D, R> samples;
  samples.reserve(b.size());
  const std::size_t psi = samples.add_field(boundary_sample_fields().front());
  for (std::size_t k = 0; k < b.size(); ++k) samples.add(b.position[k], Vec<D, R>{});
  samples.real_field(psi) = b.psi;
  write_vtu(dir_ / "boundary.vtu", samples, 0.0, FrameFields::only({"id", "psi"}));
}

namespace {

/// The complete rows of a stats file whose step (first column: steps done) is at most `steps`,
/// and their count.
std::pair<std::string, std::int64_t> stats_rows_before(const fs::path& file, std::int64_t steps) {
  std::ifstream in(file);
  std::string line, rows;
  std::int64_t count = 0;
  if (!std::getline(in, line) || line != stats_header()) return {};  // another header: not ours
  std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::size_t begin = 0;
  for (std::size_t end; (end = all.find('\n', begin)) != std::string::npos; begin = end + 1) {
    const std::string row = all.substr(begin, end - begin + 1);  // only whole lines
    std::int64_t step = -1;
    std::istringstream(row.substr(0, row.find(','))) >> step;
    if (step != count + 1 || step > steps) break;  // rows are consecutive steps from 1
    rows += row;
    ++count;
  }
  return {rows, count};
}

}  // namespace

template <int D, std::floating_point R>
std::string RunOutput<D, R>::resume(const Simulation<D, R>& sim, StateReader& in) {
  Stopwatch w;
  // Also removes the frames the interrupted run wrote after the checkpoint: the resumed run
  // writes them again.
  frames_.load_state(in);
  in.get(totals_);
  in.get(totals_lists_rebuilt_);
  in.get(audit_);
  in.get(audit_steps_with_misses_);
  in.get(boundary_missed_);
  in.get(boundary_steps_with_misses_);
  in.get(output_seconds_);
  in.get(earlier_wall_seconds_);
  in.get(resumed_at_);
  in.get(last_checkpoint_step_);
  const std::int64_t steps = sim.steps_done();
  resumed_at_.push_back(steps);
  write_file_atomic(dir_ / "scene.json", scene_text(desc_) + "\n");
  write_run_identity(dir_, identity_);
  std::error_code ec;
  fs::remove(dir_ / "summary.json", ec);

  // Stats rows of the steps before the checkpoint: from the partial file of a killed run if it
  // has them all, else from stats.csv (an interrupted run renames its partial file there).
  auto [rows, count] = stats_rows_before(stats_tmp_, steps);
  if (count < steps) {
    auto [rows2, count2] = stats_rows_before(dir_ / "stats.csv", steps);
    if (count2 > count) rows = std::move(rows2), count = count2;
  }
  open_stats();
  stats_ << rows;
  output_seconds_ += w.lap();
  if (count < steps)
    return fmt::format(
        "stats.csv held only the first {} of the {} steps before the checkpoint; the rows of "
        "steps {} to {} are missing from it",
        count, steps, count + 1, steps);
  return {};
}

template <int D, std::floating_point R>
void RunOutput<D, R>::save_state(StateWriter& out, const Simulation<D, R>& sim, double wall_seconds) {
  stats_.flush();
  if (!stats_) throw Error("writing stats.csv failed (disk full?)", dir_.string());
  frames_.save_state(out);
  out.put(totals_);
  out.put(totals_lists_rebuilt_);
  out.put(audit_);
  out.put(audit_steps_with_misses_);
  out.put(boundary_missed_);
  out.put(boundary_steps_with_misses_);
  out.put(output_seconds_);
  out.put(earlier_wall_seconds_ + wall_seconds);
  out.put(resumed_at_);
  last_checkpoint_step_ = sim.steps_done();
  out.put(last_checkpoint_step_);
}

template <int D, std::floating_point R>
double RunOutput<D, R>::after_step(const Simulation<D, R>& sim, const StepInfo& info, bool last) {
  Stopwatch w;
  const bool wrote = frames_.write_due(sim, last);
  const double t_output = w.lap();
  totals_ += info.seconds;
  output_seconds_ += t_output;
  const auto [kinetic, fastest] = sim.kinetic_energy_and_max_speed();
  stats_ << stats_row({info, kinetic, fastest, t_output});
  if (info.audited) {
    boundary_missed_ += info.boundary_audit.missed_pairs;
    boundary_steps_with_misses_ += info.boundary_audit.missed_pairs > 0 ? 1 : 0;
    audit_.missed_pairs += info.audit.missed_pairs;
    audit_.max_penetration = std::max(audit_.max_penetration, info.audit.max_penetration);
    audit_steps_with_misses_ += info.audit.missed_pairs > 0 ? 1 : 0;
  }
  totals_lists_rebuilt_ += info.neighbors.lists_rebuilt;
  stats_ << '\n';
  if (last || wrote) stats_.flush();
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
  s["run_id"] = identity_.run_id;
  s["scene_fingerprint"] = identity_.scene_fingerprint;
  s["status"] = status;
  s["scene"] = desc_.name;
  s["scene_file"] = desc_.source;
  s["dimension"] = D;
  s["precision"] = std::is_same_v<R, float> ? "float" : "double";
  s["neighbors"] = info_.mode;
  s["threads"] = info_.threads;
  // How idle OpenMP threads wait (sph sets a calibrated GOMP_SPINCOUNT unless the user chose).
  std::string wait;
  for (const char* var : {"OMP_WAIT_POLICY", "GOMP_SPINCOUNT"})
    if (const char* v = std::getenv(var)) wait += (wait.empty() ? "" : " ") + std::string(var) + "=" + v;
  s["openmp_wait"] = wait;
  s["steps"] = sim.steps_done();
  s["simulated_time"] = sim.time();
  s["time_step"] = sim.params().time_step;
  s["particles"] = sim.particles().size();
  s["boundary_samples"] = sim.boundary().size();
  s["frames"] = frames_.frames_written();
  nlohmann::ordered_json formats = nlohmann::ordered_json::array();
  for (FrameFormat f : desc_.output.formats) formats.push_back(frame_format_name(f));
  s["frame_formats"] = formats;
  s["wall_seconds"] = earlier_wall_seconds_ + wall_seconds;
  if (!resumed_at_.empty()) s["resumed_at_steps"] = resumed_at_;
  if (last_checkpoint_step_ >= 0) s["last_checkpoint_step"] = last_checkpoint_step_;
  s["phase_seconds"] = {{"grid", totals_.grid},     {"lists", totals_.lists},         {"density", totals_.density},
                        {"forces", totals_.forces}, {"integrate", totals_.integrate}, {"solve", totals_.solve},
                        {"output", output_seconds_}};
  s["lists_rebuilt"] = totals_lists_rebuilt_;
  if (sim.params().audit)
    s["audit"] = {{"missed_pairs", audit_.missed_pairs},
                  {"steps_with_misses", audit_steps_with_misses_},
                  {"max_missed_penetration", audit_.max_penetration},
                  {"boundary_missed_pairs", boundary_missed_},
                  {"boundary_steps_with_misses", boundary_steps_with_misses_}};
  s["kinetic_energy"] = sim.kinetic_energy();
  s["max_speed"] = sim.max_speed();
  // The health monitor (docs/reliability.md, "Health monitor"): warnings in the order given,
  // the steps each kind's condition held, and the extremes of the run.
  const HealthMonitor& health = sim.health();
  s["warnings"] = health.warnings();
  nlohmann::ordered_json counts;
  for (const HealthWatch& w : kHealthWatches) counts[w.name] = health.counts()[static_cast<std::size_t>(w.kind)];
  s["warning_counts"] = counts;
  s["health"] = {{"max_mach", health.max_mach()},
                 {"rho_min", health.rho_min()},
                 {"rho_max", health.rho_max()},
                 {"initial_energy", health.initial_energy()},
                 {"max_energy", health.max_energy()}};
  write_file_atomic(dir_ / "summary.json", s.dump(2) + "\n");
}

template class RunOutput<2, float>;
template class RunOutput<2, double>;
template class RunOutput<3, float>;
template class RunOutput<3, double>;

}  // namespace sph
