#pragma once
/// \file Opening a run's directory to continue it from its checkpoint (`sph run --resume DIR`).

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <sph/io/checkpoint.h>
#include <sph/scene/scene_desc.h>

namespace sph {

/// A run to continue: its open checkpoint and the scene to build the RunDriver with.
struct RunToResume {
  std::filesystem::path dir;
  std::unique_ptr<CheckpointReader> checkpoint;
  /// The run's scene (from the checkpoint), with the new total of steps if one was given and
  /// the run's audit flag.
  SceneDesc desc;
  /// The run's checkpoint cadence (0: none), for RunSettings::checkpoint_every unless the caller
  /// chooses another.
  std::int64_t checkpoint_every = 0;
  /// Warnings to show, e.g. a checkpoint written by another sph version.
  std::vector<std::string> warnings;
};

/// Opens the checkpoint of the run in `dir` and reads its scene; `steps` > 0 is the new total
/// of steps (0: the run's own). Refuses with sph::Error naming the path: a missing directory or
/// checkpoint, a damaged checkpoint (CheckpointReader), a checkpoint of another run than the
/// directory's files (check_run_identity), a run that has already done all its steps (or `steps`
/// not beyond the checkpoint; for a finished run, per its summary.json, a plain resume or `steps`
/// not beyond the steps it did: never dropping frames or stats rows), and a checkpoint whose
/// dimension or precision differs from its scene's. Touches nothing in `dir`.
RunToResume open_run_to_resume(const std::filesystem::path& dir, std::int64_t steps = 0);

}  // namespace sph
