#include <sph/io/frame_writer.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <fmt/format.h>

#include <sph/io/atomic_file.h>
#include <sph/io/ply.h>
#include <sph/io/solids.h>
#include <sph/io/vtk.h>

namespace sph {

namespace fs = std::filesystem;

namespace {

/// Round-off allowed when comparing t * fps with a frame index (relative).
constexpr double kTickTolerance = 1e-9;

std::string frame_name(std::size_t index, FrameFormat f) {
  return fmt::format("frames/frame_{:06d}.{}", index, frame_format_name(f));
}

std::string solids_name(std::size_t index) { return fmt::format("frames/solids_{:06d}.vtp", index); }

}  // namespace

template <int D, std::floating_point R>
void write_frame(FrameFormat format, const fs::path& path, const ParticleSet<D, R>& particles, double time,
                 const FrameFields& fields) {
  switch (format) {
    case FrameFormat::Vtu:
      return write_vtu(path, particles, time, fields);
    case FrameFormat::Vtk:
      return write_legacy_vtk(path, particles, time, fields);
    case FrameFormat::Ply:
      return write_ply(path, particles, time, fields);
  }
}

bool FrameSchedule::due(std::int64_t step, double time, bool last) const {
  if (every_ > 0) return step % every_ == 0 || last;
  if (fps_ > 0) return last || time * fps_ >= static_cast<double>(next_tick_) * (1 - kTickTolerance);
  return false;
}

void FrameSchedule::written(double time) {
  if (fps_ <= 0) return;
  // The first k with k (1 - tol) > t * fps: frames of ticks this frame already covers are not
  // written late.
  const double k = std::floor(time * fps_ / (1 - kTickTolerance)) + 1;
  // (Clamped: an absurd fps times a long run must not overflow the conversion.)
  next_tick_ = std::max(next_tick_, k < 9e18 ? static_cast<std::int64_t>(k) : std::int64_t{9'000'000'000'000'000'000});
}

template <int D, std::floating_point R>
FrameWriter<D, R>::FrameWriter(fs::path dir, OutputDesc output)
    : dir_(std::move(dir)),
      output_(std::move(output)),
      fields_(FrameFields::only(output_.fields)),
      schedule_(output_) {}

template <int D, std::floating_point R>
bool FrameWriter<D, R>::write_due(const Simulation<D, R>& sim, bool last) {
  if (!schedule_.due(sim.steps_done(), sim.time(), last)) return false;
  const bool on_schedule = schedule_.due(sim.steps_done(), sim.time(), false);
  write(sim);
  last_off_schedule_ = !on_schedule;
  return true;
}

template <int D, std::floating_point R>
void FrameWriter<D, R>::write(const Simulation<D, R>& sim) {
  const std::size_t index = times_.size();
  for (FrameFormat f : output_.formats)
    write_frame(f, dir_ / frame_name(index, f), sim.particles(), sim.time(), fields_);
  if (!sim.params().obstacles.empty()) {
    const std::vector<RigidPose<D>> poses = sim.obstacle_poses();
    write_solids_vtp<D>(dir_ / solids_name(index), sim.params().obstacles, poses, sim.time(), sim.params().shapes);
    if (std::find(output_.formats.begin(), output_.formats.end(), FrameFormat::Ply) != output_.formats.end())
      write_solids_ply<D>(dir_ / fmt::format("frames/solids_{:06d}.ply", index), sim.params().obstacles, poses,
                          sim.time(), sim.params().shapes);
    solids_ = true;
  }
  // The floating bodies: a row each in bodies.csv (kBodyColumns).
  for (std::size_t s = 0; s < sim.bodies().size(); ++s) {
    const RigidBodyState<D>& b = sim.bodies()[s];
    const BodyLoad<D>& f = sim.body_fluid_forces()[s];
    std::vector<double> row{static_cast<double>(index), sim.time(), static_cast<double>(sim.body_obstacles()[s])};
    const auto add = [&row](const auto& v, int n) {
      for (int c = 0; c < 3; ++c) row.push_back(c < n ? v[c] : 0.0);
    };
    add(b.position, D);
    row.insert(row.end(), b.orientation.begin(), b.orientation.end());
    add(b.velocity, D);
    add(b.angular_velocity, 3);
    add(f.impulse, D);
    add(f.angular_impulse, 3);
    body_rows_.insert(body_rows_.end(), row.begin(), row.end());
  }
  if (!sim.bodies().empty()) write_bodies();
  times_.push_back(sim.time());
  schedule_.written(sim.time());
  last_off_schedule_ = false;
  write_index();
}

template <int D, std::floating_point R>
void FrameWriter<D, R>::write_bodies() const {
  std::string text = fmt::format("{}\n", fmt::join(kBodyColumns, ","));
  const std::size_t columns = std::size(kBodyColumns);
  for (std::size_t r = 0; r + columns <= body_rows_.size(); r += columns) {
    const double* v = &body_rows_[r];
    text += fmt::format("{:.0f},{:.17g},{:.0f}", v[0], v[1], v[2]);
    for (std::size_t c = 3; c < columns; ++c) text += fmt::format(",{:.17g}", v[c]);
    text += '\n';
  }
  write_file_atomic(dir_ / "bodies.csv", text);
}

template <int D, std::floating_point R>
void FrameWriter<D, R>::write_index() const {
  if (solids_) {
    std::vector<PvdEntry> solids;
    for (std::size_t i = 0; i < times_.size(); ++i) solids.push_back({times_[i], solids_name(i)});
    write_pvd(dir_ / "solids.pvd", solids);
  }
  if (std::find(output_.formats.begin(), output_.formats.end(), FrameFormat::Vtu) == output_.formats.end()) return;
  std::vector<PvdEntry> entries;
  entries.reserve(times_.size());
  for (std::size_t i = 0; i < times_.size(); ++i) entries.push_back({times_[i], frame_name(i, FrameFormat::Vtu)});
  write_pvd(dir_ / "frames.pvd", entries);
}

template <int D, std::floating_point R>
void FrameWriter<D, R>::save_state(StateWriter& out) const {
  out.put(times_);
  out.put(schedule_.next_tick());
  out.put(static_cast<std::uint8_t>(last_off_schedule_));
  out.put(body_rows_);
}

template <int D, std::floating_point R>
void FrameWriter<D, R>::load_state(StateReader& in) {
  in.get(times_);
  std::int64_t tick = 0;
  in.get(tick);
  in.expect(tick >= 0, "a negative frame tick");
  schedule_.set_next_tick(tick);
  const auto off = in.get<std::uint8_t>();
  in.expect(off <= 1 && (off == 0 || !times_.empty()), "a bad frame flag");
  // A frame the run wrote only because its step was the last: a run that goes on past that
  // step does not have it (an uninterrupted run of more steps writes no frame there), so it goes.
  if (off) times_.pop_back();
  last_off_schedule_ = false;
  // The frames the run wrote before the checkpoint (checked before anything is written: a resumed
  // run would list in frames.pvd files that are not there, and sph render would refuse the run).
  std::error_code ec;
  for (std::size_t k = 0; k < times_.size(); ++k)
    for (FrameFormat f : output_.formats)
      if (!fs::is_regular_file(dir_ / frame_name(k, f), ec))
        throw Error(fmt::format("is missing: the run wrote frames 0 to {} before its checkpoint, and a resumed run "
                                "would list a file that is not there; put the run's frames back, or start a new run "
                                "(sph run SCENE -o DIR)",
                                times_.size() - 1),
                    (dir_ / frame_name(k, f)).string());
  in.get(body_rows_);
  const std::size_t columns = std::size(kBodyColumns);
  in.expect(body_rows_.size() % columns == 0, "a bad floating body table");
  std::size_t keep = 0;  // (the rows of the frames kept)
  while (keep < body_rows_.size() && body_rows_[keep] < static_cast<double>(times_.size())) keep += columns;
  body_rows_.resize(keep);
  if (!body_rows_.empty()) write_bodies();
  // Frames the interrupted run wrote after the checkpoint, in any format.
  for (const auto& entry : fs::directory_iterator(dir_ / "frames", ec)) {
    const std::string f = entry.path().filename().string();
    unsigned index = 0;
    char ext[4] = {};
    if (std::sscanf(f.c_str(), "frame_%u.%3s", &index, ext) == 2 && parse_frame_format(ext) &&
        f == fmt::format("frame_{:06d}.{}", index, ext) && index >= times_.size())
      fs::remove(entry.path(), ec);
    if (std::sscanf(f.c_str(), "solids_%u.%3s", &index, ext) == 2 &&
        (f == fmt::format("solids_{:06d}.vtp", index) || f == fmt::format("solids_{:06d}.ply", index)) &&
        index >= times_.size())
      fs::remove(entry.path(), ec);
  }
  solids_ = fs::exists(dir_ / "solids.pvd", ec);
  if (!times_.empty()) write_index();  // (a run without frames has no frames.pvd)
}

#define SPH_INSTANTIATE(D, R) \
  template void write_frame<D, R>(FrameFormat, const fs::path&, const ParticleSet<D, R>&, double, const FrameFields&);
SPH_INSTANTIATE(2, float)
SPH_INSTANTIATE(2, double)
SPH_INSTANTIATE(3, float)
SPH_INSTANTIATE(3, double)
#undef SPH_INSTANTIATE

template class FrameWriter<2, float>;
template class FrameWriter<2, double>;
template class FrameWriter<3, float>;
template class FrameWriter<3, double>;

}  // namespace sph
