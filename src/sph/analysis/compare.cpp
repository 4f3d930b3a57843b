#include <sph/analysis/compare.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <sph/analysis/labels.h>
#include <sph/core/error.h>
#include <sph/core/parallel.h>
#include <sph/core/vec.h>
#include <sph/io/atomic_file.h>
#include <sph/io/frames.h>
#include <sph/io/run_directory.h>
#include <sph/render/frame_image.h>
#include <sph/run/driver.h>
#include <sph/scene/dispatch.h>

namespace sph {

namespace {

constexpr std::uint64_t kPerturbationSeed = 20240917;

/// Steps (after the step, 1-based counts) at which images are taken: evenly spaced, the last
/// one at the end.
std::vector<std::int64_t> image_steps(std::int64_t steps, int frames) {
  std::vector<std::int64_t> out;
  for (int k = 1; k <= frames; ++k) {
    const std::int64_t s = std::max<std::int64_t>(1, steps * k / frames);
    if (out.empty() || out.back() != s) out.push_back(s);
  }
  return out;
}

template <int D, std::floating_point R>
Snapshot snapshot(const Simulation<D, R>& sim, bool with_velocity) {
  const FrameData f =
      frame_data_of(sim.particles(), sim.time(),
                    FrameFields::only(with_velocity ? std::vector<std::string>{"velocity", "id", "initial_position"}
                                                    : std::vector<std::string>{"id"}));
  Snapshot s;
  s.step = sim.steps_done();
  s.time = sim.time();
  for (std::size_t b = 0; with_velocity && b < sim.bodies().size(); ++b) {
    BodyPoseRow row;
    row.time = sim.time();
    row.obstacle = sim.body_obstacles()[b];
    for (int d = 0; d < D; ++d) row.position[static_cast<std::size_t>(d)] = sim.bodies()[b].position[d];
    row.orientation = sim.bodies()[b].orientation;
    s.bodies.push_back(row);
  }
  const std::size_t ids = static_cast<std::size_t>(sim.particles().next_id());
  const std::array<double, 3> none{kNaN, kNaN, kNaN};
  s.position.assign(ids, none);
  if (with_velocity) {
    s.velocity.assign(ids, none);
    s.initial.assign(ids, none);
  }
  const auto at = [](const std::vector<double>& v, std::size_t i) {
    return std::array<double, 3>{v[3 * i], v[3 * i + 1], v[3 * i + 2]};
  };
  const std::vector<double>& id = f.field("id")->values;
  for (std::size_t i = 0; i < f.size; ++i) {
    const auto k = static_cast<std::size_t>(id[i]);  // ids < 2^53: exact as doubles
    s.position[k] = at(f.position, i);
    if (with_velocity) {
      s.velocity[k] = at(f.field("velocity")->values, i);
      s.initial[k] = at(f.field("initial_position")->values, i);
    }
  }
  return s;
}

/// The step's figures as the comparison records them.
StepRecord step_record(const StepInfo& info, double kinetic_energy) {
  StepRecord r;
  r.time = info.time;
  r.seconds = info.seconds.total();
  r.kinetic_energy = kinetic_energy;
  r.particles = info.particles;
  r.lists_rebuilt = info.neighbors.lists_rebuilt;
  r.pairs_stored = info.neighbors.pairs_stored;
  r.pairs_within_h = info.pairs_within_h;
  r.missed_pairs = info.audit.missed_pairs;
  r.boundary_missed_pairs = info.boundary_audit.missed_pairs;
  r.max_missed_penetration = info.audit.max_penetration;
  return r;
}

/// The scene of one run: `base` with the run's mode, the audit and the comparison's steps.
template <int D>
SceneDesc run_scene(const SceneDesc& base, NeighborMode mode, bool audit, std::int64_t steps) {
  SceneDesc desc = base;
  desc.body<D>().sim.neighbors = mode;
  desc.body<D>().sim.audit = audit;
  desc.steps = steps;
  return desc;
}

template <int D, std::floating_point R>
RunRecord run_one(const SceneDesc& base, NeighborMode mode, bool perturbed, const CompareOptions& opt,
                  std::int64_t steps, const std::vector<std::int64_t>& images, int index, int count,
                  const CompareProgress& progress) {
  RunRecord rec;
  rec.mode = mode;
  rec.perturbed = perturbed;
  rec.label = std::string(to_string(mode)) + (perturbed ? " (perturbed)" : "");
  // Each mode's run (not the chaos floor's) writes its run directory as `sph run -o DIR` would.
  RunSettings settings;
  settings.every_field = true;  // (the snapshots read the initial positions)
  if (!opt.runs_dir.empty() && !perturbed) settings.dir = opt.runs_dir / slug(rec.label);
  RunDriver<D, R> run(run_scene<D>(base, mode, opt.audit, steps), settings);
  Simulation<D, R>& sim = run.simulation();
  const double amplitude = opt.perturbation * sim.params().kernel_radius;
  if (perturbed) sim.perturb_positions(0, amplitude, kPerturbationSeed);

  const std::int64_t every = std::max<std::int64_t>(1, steps / std::max(1, opt.samples));
  const auto is_image = [&](std::int64_t s) { return std::find(images.begin(), images.end(), s) != images.end(); };
  rec.samples.push_back(snapshot(sim, false));
  rec.steps.reserve(static_cast<std::size_t>(steps));
  const std::int64_t report_every = std::max<std::int64_t>(1, steps / 20);
  RunCallbacks callbacks;
  if (progress)
    callbacks.progress = [&](std::int64_t s, std::size_t) {
      if (s % report_every == 0 || s == steps) progress(rec.label, index, count, s, steps);
    };
  const RunResult result = run.run(callbacks, [&](Simulation<D, R>& sim, const StepInfo& info) {
    if (perturbed && info.emitted > 0)
      sim.perturb_positions(info.particles - info.emitted, amplitude, kPerturbationSeed);
    rec.steps.push_back(step_record(info, sim.kinetic_energy()));
    rec.totals += info.seconds;
    const std::int64_t s = sim.steps_done();
    if (s % every == 0 || s == steps || is_image(s)) rec.samples.push_back(snapshot(sim, is_image(s)));
  });
  rec.failure = result.error;
  return rec;
}

std::vector<Divergence> divergence(const RunRecord& ref, const RunRecord& run, double h) {
  std::vector<Divergence> out;
  std::size_t a = 0, b = 0;
  while (a < ref.samples.size() && b < run.samples.size()) {
    const Snapshot& x = ref.samples[a];
    const Snapshot& y = run.samples[b];
    if (x.step < y.step) {
      ++a;
      continue;
    }
    if (y.step < x.step) {
      ++b;
      continue;
    }
    Divergence d;
    d.step = x.step;
    d.time = x.time;
    double sum = 0;
    std::size_t n = 0;
    const std::size_t ids = std::min(x.position.size(), y.position.size());
    for (std::size_t id = 0; id < ids; ++id) {
      const auto& p = x.position[id];
      const auto& q = y.position[id];
      if (std::isnan(p[0]) || std::isnan(q[0])) continue;
      const double dx = p[0] - q[0], dy = p[1] - q[1], dz = p[2] - q[2];
      const double r2 = (dx * dx + dy * dy + dz * dz) / (h * h);
      sum += r2;
      d.max = std::max(d.max, std::sqrt(r2));
      ++n;
    }
    d.rms = n ? std::sqrt(sum / static_cast<double>(n)) : 0.0;
    out.push_back(d);
    ++a, ++b;
  }
  return out;
}

template <int D, std::floating_point R>
CompareResult run_all(const SceneDesc& desc, const CompareOptions& opt, const CompareProgress& progress) {
  CompareResult res;
  const SimulationParams<D>& p = desc.body<D>().sim;
  res.scene = desc.name;
  res.dimension = D;
  res.precision = std::is_same_v<R, float> ? "float" : "double";
  res.threads = num_threads();
  res.h = p.kernel_radius;
  res.dt = p.time_step;
  res.particle_radius = p.particle_radius;
  res.particle_mass = p.particle_mass;
  res.perturbation = opt.perturbation;
  for (int d = 0; d < D; ++d) res.box_lo[d] = p.container.lo[d], res.box_hi[d] = p.container.hi[d];
  res.has_emitters = !p.emitters.empty();
  res.has_boundary_particles = p.boundary.handling == BoundaryHandling::Particles;
  res.audited = opt.audit;
  res.steps = opt.steps > 0 ? opt.steps : desc.steps;
  res.image_steps = image_steps(res.steps, std::max(1, opt.frames));
  // Each picture's obstacles, where they are at its step's time (the steps are fixed).
  for (const std::int64_t step : res.image_steps) {
    std::vector<SolidBox>& at = res.image_obstacles.emplace_back();
    for (std::size_t k = 0; k < p.obstacles.size(); ++k)
      at.push_back(obstacle_solid(p, k, static_cast<double>(step) * p.time_step));
  }

  std::vector<NeighborMode> modes = opt.modes;
  modes.erase(std::remove(modes.begin(), modes.end(), NeighborMode::Standard), modes.end());
  modes.insert(modes.begin(), NeighborMode::Standard);
  const int count = static_cast<int>(modes.size()) + (opt.perturbation > 0 ? 1 : 0);
  // Warm-up, not recorded: the first run would otherwise pay for cold caches, page faults and
  // thread start-up, and the reference would look slower than it is.
  {
    SceneDesc warm_desc = desc;
    warm_desc.steps = std::min<std::int64_t>(res.steps, 50);
    RunDriver<D, R> warm(warm_desc, RunSettings{});
    (void)warm.run();  // a failure: the recorded standard run will meet it and report it
  }
  int index = 0;
  for (NeighborMode m : modes)
    res.runs.push_back(run_one<D, R>(desc, m, false, opt, res.steps, res.image_steps, index++, count, progress));
  if (!opt.runs_dir.empty()) {
    std::vector<std::string> names;
    for (NeighborMode m : modes) names.push_back(slug(std::string(to_string(m))));
    write_run_list(opt.runs_dir, names);
  }
  if (opt.perturbation > 0)
    res.runs.push_back(
        run_one<D, R>(desc, NeighborMode::Standard, true, opt, res.steps, res.image_steps, index++, count, progress));
  // Floating bodies: the pictures draw them where the standard run had them at each picture's step.
  if (any_dynamic_body(p))
    for (std::size_t j = 0; j < res.image_steps.size(); ++j)
      for (const Snapshot& snap : res.runs[0].samples)
        if (snap.step == res.image_steps[j] && !snap.bodies.empty())
          for (std::size_t k = 0; k < p.obstacles.size(); ++k)
            res.image_obstacles[j][k] = obstacle_solid(p, k, snap.time, snap.bodies);
  res.divergence.resize(res.runs.size());
  for (std::size_t k = 1; k < res.runs.size(); ++k) res.divergence[k] = divergence(res.runs[0], res.runs[k], res.h);
  return res;
}

}  // namespace

double standard_seconds(const CompareResult& result) {
  double sum = 0;
  int n = 0;
  for (const RunRecord& r : result.runs)
    if (r.mode == NeighborMode::Standard && r.failure.empty()) sum += r.totals.total(), ++n;
  return n ? sum / n : (result.runs.empty() ? 0.0 : result.runs[0].totals.total());
}

void check_comparable(const SceneDesc& desc) {
  dispatch(desc, [&]<int D, class R>() {
    const SimulationParams<D>& p = desc.body<D>().sim;
    if (p.time_stepping == TimeStepping::Cfl)
      throw Error(
          "sph compare runs every neighbor mode with the same fixed time step and compares them step by "
          "step, and this scene takes CFL steps (each mode would take its own); give it fixed steps: --set "
          "Configuration.cflMethod=none --set Configuration.timeStepSize=DT (DT: for example a CFL run's "
          "mean step, from the dt column of sph run's stats.csv)",
          "Configuration.cflMethod");
  });
}

CompareResult run_comparison(const SceneDesc& desc, const CompareOptions& options, const CompareProgress& progress) {
  check_comparable(desc);
  return dispatch(desc, [&]<int D, class R>() { return run_all<D, R>(desc, options, progress); });
}

void prepare_comparison_directory(const std::filesystem::path& dir) {
  std::error_code ec;
  // A run's own directory: the comparison's files would sit among the run's, and sph render would
  // go on showing the run.
  for (const char* file : {kRunIdentityFile, "scene.json"})
    if (std::filesystem::exists(dir / file, ec))
      throw Error(fmt::format("holds a run ({}: sph run's output); expected a directory of the comparison's own, e.g. "
                              "out/my_compare",
                              file),
                  dir.string());
  make_writable_directory(dir, "the comparison's output");
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const std::string f = entry.path().filename().string();
    // Files whose set depends on the options: images of other steps, the audit's plot.
    const bool frame = f.rfind("frame_", 0) == 0 && entry.path().extension() == ".png";
    // runs.txt too: with --no-run-frames an earlier comparison's run directories must not be shown.
    if (frame || f == "missed_pairs.png" || f == kRunListFile) std::filesystem::remove(entry.path(), ec);
  }
}

}  // namespace sph
