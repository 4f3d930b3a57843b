#include <sph/run/resume.h>

#include <fmt/format.h>

#include <sph/core/error.h>
#include <sph/core/version.h>
#include <sph/io/atomic_file.h>
#include <sph/io/run_directory.h>
#include <sph/scene/scene_reader.h>

namespace sph {

namespace {

/// Refuses to continue a finished run (summary.json says it completed) unless `steps` is a total
/// above the steps it did: a smaller one would drop its frames and stats rows past it. Adds a
/// warning when the checkpoint (at `checkpoint_step`) is behind the steps the run did.
void check_finished_run(const std::filesystem::path& dir, std::int64_t checkpoint_step, std::int64_t steps,
                        std::vector<std::string>& warnings) {
  const std::optional<RunEnd> end = read_run_end(dir);
  if (!end) return;
  if (end->finished() && steps == 0)
    throw Error(fmt::format("the run already did all its {} steps ({}); give --steps N with N > {} to continue "
                            "it further",
                            end->steps, end->status, end->steps),
                dir.string());
  // (a total not beyond the checkpoint itself is refused as such by the caller)
  if (end->finished() && steps <= end->steps && steps > checkpoint_step)
    throw Error(fmt::format("--steps {} is not beyond the {} steps the run already did ({}); give a total above {} "
                            "(a smaller one would drop its frames and stats rows past step {})",
                            steps, end->steps, end->status, end->steps, steps),
                dir.string());
  if (end->steps > checkpoint_step)
    warnings.push_back(
        fmt::format("the run reached step {} ({}) but its checkpoint is at step {}: steps {} to {} "
                    "are computed again and their frames and stats rows replaced",
                    end->steps, end->status, checkpoint_step, checkpoint_step + 1, end->steps));
}

}  // namespace

RunToResume open_run_to_resume(const std::filesystem::path& dir, std::int64_t steps) {
  require_directory(dir, "the output directory of an earlier run (sph run -o DIR)");
  RunToResume run;
  run.dir = dir;
  run.checkpoint = std::make_unique<CheckpointReader>(dir / kCheckpointFile);
  const CheckpointHeader& h = run.checkpoint->header();
  check_run_identity(dir, h.identity);
  if (h.sph_version != kVersion)
    run.warnings.push_back(
        fmt::format("the checkpoint was written by sph {}, this is sph {}", h.sph_version, kVersion));
  std::vector<std::string> sets;
  if (steps > 0) sets.push_back("Configuration.numberOfSteps=" + std::to_string(steps));
  run.desc = parse_scene(h.scene_json, h.scene_source, sets);
  run.checkpoint_every = h.checkpoint_every;
  SceneDesc& desc = run.desc;
  desc.set_audit(h.audit);
  check_finished_run(dir, h.step, steps, run.warnings);
  // (a run to an end time is finished by its time, which check_finished_run saw)
  if (desc.steps <= h.step && (steps > 0 || desc.end_time <= 0))
    throw Error(steps > 0
                    ? fmt::format("--steps {} is not beyond the checkpoint, which is at step {}; give a larger total",
                                  steps, h.step)
                    : fmt::format("the run already did all its {} steps (its checkpoint is at step {}); give "
                                  "--steps N with N > {} to continue it further",
                                  desc.steps, h.step, h.step),
                dir.string());
  const bool f = desc.precision == Precision::Float;
  if (desc.dimension != h.dimension || f != (h.precision == Precision::Float))
    throw Error("the checkpoint's dimension or precision differs from its scene's: the file is corrupt",
                (dir / kCheckpointFile).string());
  return run;
}

}  // namespace sph
