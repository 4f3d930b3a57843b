#pragma once
/// \file Checkpoints: the complete state of a run in one file, DIR/checkpoint.sphc, from which
/// `sph run --resume DIR` continues bitwise identically to a run that was never interrupted.
///
/// Layout (docs/reliability.md):
///   header   8 bytes "SPHCKPT" + NUL, u32 format version, u32 byte-order mark 0x01020304
///   payload  written by StateWriter: sph version, dimension, precision, step, the effective
///            scene (JSON text) and its file name, the audit flag, --checkpoint-every, the run id
///            and the scene fingerprint (RunIdentity), Simulation::save_state,
///            RunOutput::save_state
///   trailer  u64 payload length, u64 payload checksum (Checksum), 8 bytes "SPHCKEND"
/// The file is written under a temporary name, synced to disk and renamed over the previous
/// checkpoint: at any moment the directory holds the old checkpoint or the new one, whole.

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include <sph/io/run_output.h>
#include <sph/scene/scene_desc.h>
#include <sph/solver/simulation.h>

namespace sph {

/// The format version this build writes and reads. Version 14 stores the particles' one mass
/// after the next id, where version 13 kept a per-particle "mass" field last among the built-in
/// fields; ids of 32 bits, not 64; and the initial positions only where the run keeps them
/// (RunSettings::every_field). Version 13 stores the health monitor's seventh
/// watch (a floating body's depth into the walls) with the others, and changes the meaning of a
/// boundary-particle scene: the samples' volumes now count the solid beyond their layers, and
/// DFSPH scales its Jacobi steps on supports wider than about 3 spacings (2D) or 2.15 (3D), both
/// recomputed from the scene on resuming, so a version 12 checkpoint of such a scene would not
/// resume the run it saved. Version 12 changes no byte but the meaning of
/// a DFSPH scene's boundaryPressure: the scene text of a version 11 checkpoint always carries
/// "extrapolate" (the writer writes the key, and it was the default), which DFSPH ignored; now
/// DFSPH follows it, so a version 11 DFSPH checkpoint would not resume the run it saved. Version 10 stores the floating
/// bodies' states (RigidBodyState, after the emitters') and the frames' body rows (bodies.csv). Version 9 stores
/// DFSPH's last constant-density solve (iterations, error, converged: the next CFL step depends on it) after the last
/// CFL step. Version 8 stores the simulated time and the last CFL step after the step count, and each emitter's next
/// batch time (TimeStepping::Cfl). Version 7 changes no byte but the meaning of the scene text it carries: a
/// boundary-particle scene without Configuration.boundaryPressure now runs with the extrapolated pressure, where
/// version 6's ran with the mirrored one, so a version 6 checkpoint would not resume the run it saved. Version 6 stores
/// each neighbor list's capacity after the lists (NeighborLists::save) and knows the tracked modes. Version 4 records
/// the run's identity (run id and scene fingerprint) after --checkpoint-every, and the health monitor's state
/// (HealthMonitor::save_state) after the neighbor strategy's. Version 3 stores the particle fields by
/// name and kind, in kParticleFields order, then the fields a run added (ParticleSet::save);
/// version 2 kept the frames' times and the schedule's next tick instead of version 1's .vtu
/// file list.
inline constexpr std::uint32_t kCheckpointVersion = 14;
/// The checkpoint's file name in a run's output directory.
inline constexpr const char* kCheckpointFile = "checkpoint.sphc";

/// Writes the checkpoint of a run (its simulation and its output's frame list and totals) to
/// DIR/checkpoint.sphc, replacing the previous one atomically. Throws sph::Error on I/O failure
/// (the previous checkpoint is then kept).
/// `checkpoint_every` (the run's --checkpoint-every, 0 if none) is recorded, so that a resumed
/// run goes on writing checkpoints as often.
template <int D, std::floating_point R>
void write_checkpoint(const std::filesystem::path& dir, const SceneDesc& desc, const Simulation<D, R>& sim,
                      RunOutput<D, R>& output, double wall_seconds, std::int64_t checkpoint_every);

/// What a checkpoint says about the run before its state.
struct CheckpointHeader {
  std::string sph_version;  ///< version of the sph that wrote it
  int dimension = 0;
  Precision precision = Precision::Double;
  std::int64_t step = 0;              ///< steps done when it was written
  std::string scene_json;             ///< the effective scene of the run
  std::string scene_source;           ///< the scene file the run started from
  bool audit = false;                 ///< the run audits its lists (sph run --audit)
  std::int64_t checkpoint_every = 0;  ///< the run's --checkpoint-every (0: none)
  RunIdentity identity;               ///< the run that wrote it (run.json, summary.json)
};

/// An open checkpoint. The constructor refuses, with an sph::Error naming the file and what is
/// wrong, a missing file, a file that is not a checkpoint, another format version or byte
/// order, a truncated file and a checksum mismatch; then it reads the header.
class CheckpointReader {
 public:
  explicit CheckpointReader(std::filesystem::path file);
  ~CheckpointReader();
  const CheckpointHeader& header() const { return header_; }
  /// Restores `sim` (made from header().scene_json) and `output` (not begun), then checks that
  /// the whole payload was read. Returns RunOutput::resume's warning ("" if none).
  template <int D, std::floating_point R>
  std::string restore(Simulation<D, R>& sim, RunOutput<D, R>& output);

 private:
  std::filesystem::path file_;
  std::ifstream in_;
  std::uint64_t payload_ = 0, checksum_ = 0;
  std::unique_ptr<StateReader> reader_;
  CheckpointHeader header_;
};

}  // namespace sph
