#include <sph/run/resume.h>

#include <fmt/format.h>

#include <sph/core/error.h>
#include <sph/core/version.h>
#include <sph/scene/scene_reader.h>

namespace sph {

RunToResume open_run_to_resume(const std::filesystem::path& dir, std::int64_t steps) {
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec))
    throw Error("no such directory; expected the output directory of an earlier run (sph run -o DIR)", dir.string());
  RunToResume run;
  run.dir = dir;
  run.checkpoint = std::make_unique<CheckpointReader>(dir / kCheckpointFile);
  const CheckpointHeader& h = run.checkpoint->header();
  if (h.sph_version != kVersion)
    run.warnings.push_back(
        fmt::format("the checkpoint was written by sph {}, this is sph {}", h.sph_version, kVersion));
  std::vector<std::string> sets;
  if (steps > 0) sets.push_back("Configuration.numberOfSteps=" + std::to_string(steps));
  run.desc = parse_scene(h.scene_json, h.scene_source, sets);
  run.checkpoint_every = h.checkpoint_every;
  SceneDesc& desc = run.desc;
  desc.set_audit(h.audit);
  if (desc.steps <= h.step)
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
