#pragma once
/// \file FrameWriter: writes a simulation's frames into a run directory on a schedule, in the
/// formats and with the fields an OutputDesc chooses. RunOutput uses one; so can any caller
/// with a Simulation (sph compare's run directories):
///
///   FrameWriter<3, double> frames(dir, desc.output);   // dir/frames/ must exist
///   frames.write_due(sim, false);                      // the initial frame (step 0 is always due)
///   for (...) { sim.step(); frames.write_due(sim, last); }
///
/// Files: DIR/frames/frame_NNNNNN.EXT for each format (NNNNNN counts frames from 0, the same
/// number in every format) and, when vtu is among the formats, DIR/frames.pvd (ParaView's time
/// series of the .vtu files, rewritten after every frame). Without vtu no index is written:
/// every frame file carries its simulated time (read_frame in frames.h reads it back).
/// A scene with obstacles also gets DIR/frames/solids_NNNNNN.vtp with each frame (the obstacles
/// where they are at its time, io/solids.h; with the ply format also solids_NNNNNN.ply) and
/// DIR/solids.pvd, their time series. A scene with floating bodies also gets DIR/bodies.csv,
/// a row per body per frame (kBodyColumns), rewritten after every frame.

#include <cstdint>
#include <filesystem>
#include <limits>
#include <vector>

#include <sph/core/state_stream.h>
#include <sph/io/frame_format.h>
#include <sph/io/run_directory.h>
#include <sph/scene/scene_desc.h>
#include <sph/solver/simulation.h>

namespace sph {

/// The frame schedule, apart from the writing: when the frame after a step is due.
///   every_steps > 0: after each step that is a multiple of every_steps (and step 0).
///   fps > 0: frame k (k = 0, 1, ...) at the first step whose time t reaches k / fps; after a
///     frame at time t the next k is the first with k / fps > t, so a step longer than 1 / fps
///     writes one frame, not a backlog. "Reaches" allows a relative 1e-9 of round-off, so that
///     t = steps * dt equal to k / fps in exact arithmetic counts whatever the rounding.
///   both 0: no frames at all (not even the last step's).
/// With a schedule, the last step of a run always has a frame (`last`).
class FrameSchedule {
 public:
  explicit FrameSchedule(const OutputDesc& out) : every_(out.every_steps), fps_(out.fps) {}
  bool active() const { return every_ > 0 || fps_ > 0; }
  bool due(std::int64_t step, double time, bool last) const;
  /// Records that a frame was written at `time`.
  void written(double time);
  /// The next frame index k of an fps schedule (state a checkpoint keeps).
  std::int64_t next_tick() const { return next_tick_; }
  void set_next_tick(std::int64_t k) { next_tick_ = k; }
  /// The time of the next frame of an fps schedule, s (infinity without one): a run with CFL
  /// steps ends a step on it (Simulation::set_time_barrier).
  double next_time() const {
    return fps_ > 0 ? static_cast<double>(next_tick_) / fps_ : std::numeric_limits<double>::infinity();
  }

 private:
  std::int64_t every_;
  double fps_;
  std::int64_t next_tick_ = 0;
};

template <int D, std::floating_point R>
class FrameWriter {
 public:
  /// Frames go to dir/frames/ (which must exist: prepare_output_directory creates it).
  FrameWriter(std::filesystem::path dir, OutputDesc output);

  /// Writes a frame of `sim` in every format if one is due after its latest step (`last`: the
  /// run's last step). Returns whether it wrote one. Throws sph::Error if a file cannot be written.
  bool write_due(const Simulation<D, R>& sim, bool last);
  /// Writes a frame of `sim` now, whatever the schedule.
  void write(const Simulation<D, R>& sim);

  std::size_t frames_written() const { return times_.size(); }
  /// FrameSchedule::next_time of the schedule.
  double next_frame_time() const { return schedule_.next_time(); }
  /// The simulated time of each frame written so far.
  const std::vector<double>& times() const { return times_; }
  const OutputDesc& output() const { return output_; }

  /// The schedule's state and the frame times, for a checkpoint.
  void save_state(StateWriter& out) const;
  /// Restores what save_state wrote, removes the frame files numbered from frames_written() on
  /// (written after the checkpoint by the interrupted run; the resumed run writes them again)
  /// and rewrites frames.pvd to match. The frame of a run's last step that was not on the
  /// schedule is dropped as well: the continued run goes past that step, and a run of that
  /// length never interrupted has no frame there.
  void load_state(StateReader& in);

 private:
  void write_index() const;
  void write_bodies() const;

  std::filesystem::path dir_;
  OutputDesc output_;
  FrameFields fields_;
  FrameSchedule schedule_;
  std::vector<double> times_;
  bool last_off_schedule_ = false;  // the latest frame was written only because its step was the last
  bool solids_ = false;             // the scene has obstacles: each frame has its solids_NNNNNN.vtp
  std::vector<double> body_rows_;   // bodies.csv's rows, kBodyColumns values each
};

extern template class FrameWriter<2, float>;
extern template class FrameWriter<2, double>;
extern template class FrameWriter<3, float>;
extern template class FrameWriter<3, double>;

}  // namespace sph
