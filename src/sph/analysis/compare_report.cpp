// Writing a comparison (`sph compare`): the per-step CSVs, the plots, the side-by-side images
// and report.md.

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include <fmt/format.h>

#include <sph/analysis/compare.h>
#include <sph/analysis/labels.h>
#include <sph/core/error.h>
#include <sph/core/vec.h>
#include <sph/core/version.h>
#include <sph/io/atomic_file.h>
#include <sph/render/color_by.h>
#include <sph/render/colormap.h>
#include <sph/render/compose.h>
#include <sph/render/particles.h>
#include <sph/render/plot.h>
#include <sph/render/png.h>

namespace sph {

namespace {

double mean_of(const std::vector<StepRecord>& v, std::uint64_t StepRecord::*field) {
  if (v.empty()) return 0;
  double s = 0;
  for (const auto& r : v) s += static_cast<double>(r.*field);
  return s / static_cast<double>(v.size());
}

std::vector<double> cumulative_seconds(const RunRecord& r) {
  std::vector<double> c(r.steps.size());
  double t = 0;
  for (std::size_t i = 0; i < r.steps.size(); ++i) c[i] = t += r.steps[i].seconds;
  return c;
}

/// A wide CSV with one row per step and, for each run, the columns `fields` computes.
std::string per_step_csv(const CompareResult& res, const std::vector<std::string>& names,
                         const std::function<std::vector<std::string>(const RunRecord&, std::size_t)>& fields) {
  std::string out = "step,time";
  for (const auto& r : res.runs)
    for (const auto& n : names) out += "," + slug(r.label) + "_" + n;
  out += "\n";
  for (std::size_t s = 0; s < static_cast<std::size_t>(res.steps); ++s) {
    out += fmt::format("{},{:.9g}", s + 1, static_cast<double>(s + 1) * res.dt);
    for (const auto& r : res.runs) {
      if (s < r.steps.size()) {
        for (const auto& f : fields(r, s)) out += "," + f;
      } else {
        for (std::size_t k = 0; k < names.size(); ++k) out += ",";
      }
    }
    out += "\n";
  }
  return out;
}

Rgb run_color(std::size_t k, const RunRecord& r) {
  if (r.perturbed) return Rgb{110, 110, 110};
  return series_color(static_cast<int>(k));
}

Image plot_per_step(const CompareResult& res, const std::string& title, const std::string& y_label, bool log_y,
                    const std::function<double(const RunRecord&, std::size_t)>& value, bool skip_perturbed) {
  PlotSpec spec;
  spec.title = title;
  spec.x_label = "step";
  spec.y_label = y_label;
  spec.log_y = log_y;
  for (std::size_t k = 0; k < res.runs.size(); ++k) {
    const RunRecord& r = res.runs[k];
    if (skip_perturbed && r.perturbed) continue;
    Series s;
    s.name = r.label;
    s.color = run_color(k, r);
    s.dashed = r.perturbed;
    // At most ~2000 points per line: plots stay light for long runs.
    const std::size_t stride = std::max<std::size_t>(1, r.steps.size() / 2000);
    for (std::size_t i = 0; i < r.steps.size(); i += stride) {
      s.x.push_back(static_cast<double>(i + 1));
      s.y.push_back(value(r, i));
    }
    spec.series.push_back(std::move(s));
  }
  return render_plot(spec);
}

Image divergence_plot(const CompareResult& res) {
  PlotSpec spec;
  spec.title = "Divergence from the standard run (RMS over particles)";
  spec.x_label = "simulated time (s)";
  spec.y_label = "RMS position difference / h";
  spec.log_y = true;
  for (std::size_t k = 1; k < res.runs.size(); ++k) {
    const RunRecord& r = res.runs[k];
    Series s;
    s.name = r.perturbed ? fmt::format("chaos floor: standard, perturbed by {:g} h", res.perturbation) : r.label;
    s.color = run_color(k, r);
    s.dashed = r.perturbed;
    for (const Divergence& d : res.divergence[k]) {
      s.x.push_back(d.time);
      s.y.push_back(d.rms);
    }
    spec.series.push_back(std::move(s));
  }
  return render_plot(spec);
}

/// The snapshot of `r` taken for the image at `step`, or null (the run failed before it).
const Snapshot* image_snapshot(const RunRecord& r, std::int64_t step) {
  for (const Snapshot& s : r.samples)
    if (s.step == step && !s.velocity.empty()) return &s;
  return nullptr;
}

/// The largest kinetic energy of a particle in the non-perturbed runs' pictures, at every image
/// step: the top of one color scale for all the report's pictures (as sph render keeps one for a
/// run's frames), 1 if none moves.
double largest_image_energy(const CompareResult& res, double mass) {
  double ke_max = 0;
  for (const std::int64_t step : res.image_steps)
    for (const RunRecord& r : res.runs) {
      const Snapshot* snap = r.perturbed ? nullptr : image_snapshot(r, step);
      if (!snap) continue;
      for (const auto& v : snap->velocity)
        if (!std::isnan(v[0])) ke_max = std::max(ke_max, 0.5 * mass * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]));
    }
  return ke_max > 0 ? ke_max : 1;
}

/// Side-by-side images of the non-perturbed runs at one image step.
Image frame_image(const CompareResult& res, std::int64_t step, double mass, double ke_max) {
  std::vector<Image> panels;
  std::vector<std::string> captions;
  const ParticleView view =
      default_particle_view(res.dimension, res.dimension == 2 ? 640 : 560, res.dimension == 2 ? 420 : 520);
  // Color scale: kinetic energy (2D, like the paper's Fig. 2) from 0 to ke_max
  // (largest_image_energy); initial position (3D without emitters, like Fig. 3); emission order otherwise.
  const bool by_energy = res.dimension == 2;
  const bool by_initial = !by_energy && !res.has_emitters;
  // The obstacles where they are at this step.
  const auto at = std::find(res.image_steps.begin(), res.image_steps.end(), step);
  std::span<const SolidBox> solids;
  if (at != res.image_steps.end() &&
      static_cast<std::size_t>(at - res.image_steps.begin()) < res.image_obstacles.size())
    solids = res.image_obstacles[static_cast<std::size_t>(at - res.image_steps.begin())];
  for (const RunRecord& r : res.runs) {
    if (r.perturbed) continue;
    const Snapshot* snap = image_snapshot(r, step);
    std::vector<double> xyz;
    std::vector<Rgb> colors;
    if (snap) {
      const std::size_t ids = snap->position.size();
      for (std::size_t id = 0; id < ids; ++id) {
        const auto& x = snap->position[id];
        if (std::isnan(x[0])) continue;
        for (int d = 0; d < res.dimension; ++d) xyz.push_back(x[d]);
        if (by_energy) {
          const auto& v = snap->velocity[id];
          colors.push_back(
              colormap(Colormap::Turbo, 0.5 * mass * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]), 0.0, ke_max));
        } else if (by_initial) {
          colors.push_back(initial_position_color(snap->initial[id], res.box_lo, res.box_hi));
        } else {
          colors.push_back(colormap(Colormap::Viridis, static_cast<double>(id), 0.0, static_cast<double>(ids)));
        }
      }
    }
    Image panel =
        render_particles(xyz, res.dimension, colors, res.particle_radius, res.box_lo, res.box_hi, view, solids);
    panels.push_back(std::move(panel));
    captions.push_back(r.failure.empty() ? fmt::format("{} (step {})", r.label, step)
                                         : fmt::format("{} (blew up before step {})", r.label, step));
  }
  Image img = hstack(panels, captions);
  if (by_energy) return add_colorbar(img, Colormap::Turbo, 0.0, ke_max, "kinetic energy per particle (J/m)");
  if (!by_initial && res.has_emitters)
    return add_colorbar(img, Colormap::Viridis, 0.0, 1.0, "emission order (first to last)");
  return img;
}

std::string frame_file(std::int64_t step) { return fmt::format("frame_{:06d}.png", step); }

std::string fmt_ratio(double x) { return std::isfinite(x) ? fmt::format("{:.2f}", x) : std::string("n/a"); }

/// report.md's title, its paragraph on how the runs were made, and its "Speed" section.
std::string report_speed(const CompareResult& res) {
  const RunRecord& ref = res.runs[0];
  const double ref_total = standard_seconds(res);
  std::string md;
  md += fmt::format("# Neighbor modes compared on `{}`\n\n", res.scene);
  md += fmt::format(
      "{}D, {}, h = {:g} m, dt = {:g} s, {} steps, {} particles at the end, {} thread{}; sph {}.\n"
      "Every run is the same scene in the same process, one after the other. Times are the sum of the\n"
      "step phases (grid, lists, density, forces, integration, and DFSPH's solves), measured inside the solver; the "
      "list\n"
      "audit and output are not timed. One run per mode: repeat the command to see the noise.\n\n",
      res.dimension, res.precision, res.h, res.dt, res.steps, ref.steps.empty() ? 0 : ref.steps.back().particles,
      res.threads, res.threads == 1 ? "" : "s", kVersion);

  md += "## Speed\n\n![cumulative time](timing.png)\n\n";
  md +=
      "| run | total (s) | ms/step | grid | lists | density | forces | integrate | solve | speed vs standard | lists "
      "rebuilt per step | pairs stored per particle |\n";
  md += "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
  for (const RunRecord& r : res.runs) {
    const bool is_ref = &r == &ref;  // the table's reference: say what it is instead of a ratio
    const double total = r.totals.total();
    const double n = static_cast<double>(std::max<std::size_t>(1, r.steps.size()));
    double per_particle = 0;
    for (const auto& s : r.steps)
      per_particle += s.particles ? static_cast<double>(s.pairs_stored) / static_cast<double>(s.particles) : 0;
    double rebuilt_frac = 0;
    for (const auto& s : r.steps)
      rebuilt_frac += s.particles ? static_cast<double>(s.lists_rebuilt) / static_cast<double>(s.particles) : 0;
    md += fmt::format(
        "| {}{} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | {} | {:.1f} % | {:.1f} |\n",
        r.label, r.failure.empty() ? "" : " (failed)", total, 1e3 * total / n, r.totals.grid, r.totals.lists,
        r.totals.density, r.totals.forces, r.totals.integrate, r.totals.solve,
        is_ref ? std::string("reference") : fmt_ratio(total > 0 ? ref_total / total : kNaN) + "x",
        100.0 * rebuilt_frac / n, per_particle / n);
  }
  md +=
      "\nPhase columns are seconds over the whole run. \"speed vs standard\" is the mean total time of\n"
      "the standard runs (the reference and the perturbed one, which repeats the standard algorithm)\n"
      "divided by this run's, so that the order of the runs biases no ratio. The perturbed run's own\n"
      "ratio shows how much timings vary between two runs of the same work.\n\n";
  return md;
}

/// report.md's "Accuracy" section: divergence from the standard run and kinetic energy.
std::string report_accuracy(const CompareResult& res) {
  const RunRecord& ref = res.runs[0];
  std::string md;
  md += "## Accuracy\n\n![divergence](divergence.png)\n\n";
  md += "Position difference of each particle (matched by stable id) from the standard run, in units of h.\n";
  if (res.perturbation > 0)
    md += fmt::format(
        "The chaos floor is a standard run whose particles were displaced by {:g} h when they appeared:\n"
        "how far two runs drift apart from round-off alone. A mode whose divergence follows the chaos\n"
        "floor is as close to standard as round-off allows; the question the paper asks (does the\n"
        "error accumulate?) is whether it stays above the floor by a growing factor.\n\n",
        res.perturbation);
  md += "On the logarithmic axis a run that is still bitwise identical to standard (difference 0) is not drawn.\n\n";
  md += "| run | RMS at 1/4 | RMS at 1/2 | RMS at end | max at end | max over the run (RMS) |\n";
  md += "| --- | ---: | ---: | ---: | ---: | ---: |\n";
  for (std::size_t k = 1; k < res.runs.size(); ++k) {
    const auto& dv = res.divergence[k];
    if (dv.empty()) continue;
    const auto at = [&](double f) {
      return dv[std::min(dv.size() - 1, static_cast<std::size_t>(f * static_cast<double>(dv.size() - 1)))];
    };
    double peak = 0;
    for (const auto& d : dv) peak = std::max(peak, d.rms);
    md += fmt::format("| {} | {:.3g} | {:.3g} | {:.3g} | {:.3g} | {:.3g} |\n", res.runs[k].label, at(0.25).rms,
                      at(0.5).rms, dv.back().rms, dv.back().max, peak);
  }
  md += "\n![kinetic energy](energy.png)\n\n";
  md += "| run | kinetic energy at end | relative to standard |\n| --- | ---: | ---: |\n";
  const double ke_ref = ref.steps.empty() ? kNaN : ref.steps.back().kinetic_energy;
  for (const RunRecord& r : res.runs) {
    const double ke = r.steps.empty() ? kNaN : r.steps.back().kinetic_energy;
    md += fmt::format("| {} | {:.6g} | {} |\n", r.label, ke,
                      &r == &ref ? std::string("reference") : fmt_ratio(ke / ke_ref));
  }
  return md;
}

/// report.md's "Missed pairs" section (the audit's figures).
std::string report_missed_pairs(const CompareResult& res) {
  std::string md = "\n## Missed pairs\n\n";
  if (!res.audited) {
    md += "Not measured: the comparison ran with --no-audit.\n";
  } else {
    md += "![missed pairs](missed_pairs.png)\n\n";
    md +=
        "The audit compares each step's lists with exact lists. A missed pair is a pair closer than h that a\n"
        "particle's list lacks (counted once per list). Eq. 7 only watches listed pairs leaving the radius;\n"
        "it cannot see particles coming into range, which is what the adaptive mode misses.\n\n";
    if (res.has_boundary_particles)
      md +=
          "The scene has boundary particles: the first columns count fluid pairs; the last, the fluid-boundary\n"
          "pairs (a fluid particle and a wall or obstacle sample closer than h) missing from the boundary lists.\n\n";
    md +=
        "| run | missed pairs (all steps) | per step | as % of pairs within h | steps with misses | largest "
        "penetration (h - r) / h |";
    md += res.has_boundary_particles ? " fluid-boundary missed pairs (all steps) |\n" : "\n";
    md += res.has_boundary_particles ? "| --- | ---: | ---: | ---: | ---: | ---: | ---: |\n"
                                     : "| --- | ---: | ---: | ---: | ---: | ---: |\n";
    for (const RunRecord& r : res.runs) {
      std::uint64_t missed = 0, within = 0, steps_with = 0;
      double pen = 0;
      for (const auto& s : r.steps) {
        missed += s.missed_pairs;
        within += s.pairs_within_h + s.missed_pairs;
        steps_with += s.missed_pairs > 0;
        pen = std::max(pen, s.max_missed_penetration);
      }
      md += fmt::format("| {} | {} | {:.1f} | {:.3f} % | {} | {:.3f} |", r.label, missed,
                        static_cast<double>(missed) / static_cast<double>(std::max<std::size_t>(1, r.steps.size())),
                        within ? 100.0 * static_cast<double>(missed) / static_cast<double>(within) : 0.0, steps_with,
                        pen);
      md += res.has_boundary_particles ? fmt::format(" {} |\n", r.boundary_missed_pairs()) : "\n";
    }
  }
  return md;
}

std::string report_md(const CompareResult& res, const std::vector<std::string>& files) {
  std::string md = report_speed(res) + report_accuracy(res) + report_missed_pairs(res);
  md += "\n## Frames\n\n";
  md += res.dimension == 2 ? "Colored by kinetic energy (as in the paper's Fig. 2).\n\n"
                           : (res.has_emitters ? "Colored by emission order.\n\n"
                                               : "Colored by initial position (as in the paper's Fig. 3).\n\n");
  for (std::int64_t s : res.image_steps) md += fmt::format("![step {}]({})\n\n", s, frame_file(s));

  md += "## Failures\n\n";
  bool any = false;
  for (const RunRecord& r : res.runs)
    if (!r.failure.empty()) {
      md += fmt::format("- {}: {}\n", r.label, r.failure);
      any = true;
    }
  if (!any) md += "None: every run completed.\n";
  md += "\n## Files\n\n";
  for (const auto& f : files) md += "- `" + f + "`\n";
  return md;
}

}  // namespace

std::vector<std::string> comparison_files(const CompareResult& result) {
  std::vector<std::string> f{"report.md",     "timing.csv", "phases.csv",     "divergence.csv", "energy.csv",
                             "neighbors.csv", "timing.png", "divergence.png", "energy.png"};
  if (result.audited) f.push_back("missed_pairs.png");
  for (std::int64_t s : result.image_steps) f.push_back(frame_file(s));
  return f;
}

namespace {

/// timing.csv: each run's cumulative step seconds.
std::string timing_csv(const CompareResult& res, const std::vector<std::vector<double>>& cumulative) {
  std::string out = "step";
  for (const auto& r : res.runs) out += "," + slug(r.label) + "_seconds";
  out += "\n";
  for (std::size_t s = 0; s < static_cast<std::size_t>(res.steps); ++s) {
    out += std::to_string(s + 1);
    for (const auto& c : cumulative) out += s < c.size() ? fmt::format(",{:.6g}", c[s]) : std::string(",");
    out += "\n";
  }
  return out;
}

/// neighbors.csv: each run's list counters per step.
std::string neighbors_csv(const CompareResult& res) {
  return per_step_csv(res,
                      {"particles", "lists_rebuilt", "pairs_stored", "pairs_within_h", "missed_pairs",
                       "max_missed_penetration", "boundary_missed_pairs"},
                      [&res](const RunRecord& r, std::size_t s) {
                        const StepRecord& x = r.steps[s];
                        // Without the audit the missed-pair cells are empty, not 0.
                        return std::vector<std::string>{
                            std::to_string(x.particles),
                            std::to_string(x.lists_rebuilt),
                            std::to_string(x.pairs_stored),
                            std::to_string(x.pairs_within_h),
                            res.audited ? std::to_string(x.missed_pairs) : std::string(),
                            res.audited ? fmt::format("{:.6g}", x.max_missed_penetration) : std::string(),
                            res.audited ? std::to_string(x.boundary_missed_pairs) : std::string()};
                      });
}

/// phases.csv: one row per run with its phase totals and means.
std::string phases_csv(const CompareResult& res) {
  std::string out =
      "run,steps,grid_s,lists_s,density_s,forces_s,integrate_s,solve_s,total_s,ms_per_step,speed_vs_standard,"
      "mean_lists_rebuilt,mean_pairs_stored,mean_pairs_within_h,missed_pairs,boundary_missed_pairs,failure\n";
  const double ref = standard_seconds(res);
  for (const auto& r : res.runs) {
    const double t = r.totals.total();
    const std::uint64_t missed = r.missed_pairs();
    std::string failure = r.failure;
    std::replace(failure.begin(), failure.end(), '"', '\'');
    out += fmt::format(
        "{},{},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{},{},\"{}\"\n",
        r.label, r.steps.size(), r.totals.grid, r.totals.lists, r.totals.density, r.totals.forces, r.totals.integrate,
        r.totals.solve, t, r.steps.empty() ? 0.0 : 1e3 * t / static_cast<double>(r.steps.size()),
        t > 0 ? ref / t : kNaN, mean_of(r.steps, &StepRecord::lists_rebuilt),
        mean_of(r.steps, &StepRecord::pairs_stored), mean_of(r.steps, &StepRecord::pairs_within_h),
        res.audited ? std::to_string(missed) : std::string(),
        res.audited ? std::to_string(r.boundary_missed_pairs()) : std::string(), failure);
  }
  return out;
}

/// divergence.csv: each run's divergence at the reference's samples.
std::string divergence_csv(const CompareResult& res) {
  std::string out = "step,time";
  for (std::size_t k = 1; k < res.runs.size(); ++k)
    out += "," + slug(res.runs[k].label) + "_rms_h," + slug(res.runs[k].label) + "_max_h";
  out += "\n";
  for (const Snapshot& s : res.runs[0].samples) {
    out += fmt::format("{},{:.9g}", s.step, s.time);
    for (std::size_t k = 1; k < res.runs.size(); ++k) {
      const auto& dv = res.divergence[k];
      const auto it = std::find_if(dv.begin(), dv.end(), [&](const Divergence& d) { return d.step == s.step; });
      out += it == dv.end() ? std::string(",,") : fmt::format(",{:.6g},{:.6g}", it->rms, it->max);
    }
    out += "\n";
  }
  return out;
}

/// timing.png: the cumulative step seconds of every run.
Image timing_plot(const CompareResult& res, const std::vector<std::vector<double>>& cumulative) {
  PlotSpec spec;
  spec.title = "Cumulative wall time (cf. the paper's Fig. 4)";
  spec.x_label = "step";
  spec.y_label = "seconds";
  for (std::size_t k = 0; k < res.runs.size(); ++k) {
    Series s;
    s.name = res.runs[k].perturbed ? "standard (repeat, perturbed)" : res.runs[k].label;
    s.color = run_color(k, res.runs[k]);
    s.dashed = res.runs[k].perturbed;
    const std::size_t stride = std::max<std::size_t>(1, cumulative[k].size() / 2000);
    for (std::size_t i = 0; i < cumulative[k].size(); i += stride) {
      s.x.push_back(static_cast<double>(i + 1));
      s.y.push_back(cumulative[k][i]);
    }
    spec.series.push_back(std::move(s));
  }
  return render_plot(spec);
}

}  // namespace

void write_comparison(const std::filesystem::path& dir, const CompareResult& res) {
  SPH_CHECK(!res.runs.empty(), "a comparison has at least the standard run");
  // Per-step CSVs.
  std::vector<std::vector<double>> cumulative;
  for (const auto& r : res.runs) cumulative.push_back(cumulative_seconds(r));
  write_file_atomic(dir / "timing.csv", timing_csv(res, cumulative));
  write_file_atomic(dir / "energy.csv", per_step_csv(res, {"kinetic_energy"}, [](const RunRecord& r, std::size_t s) {
                      return std::vector<std::string>{fmt::format("{:.9g}", r.steps[s].kinetic_energy)};
                    }));
  write_file_atomic(dir / "neighbors.csv", neighbors_csv(res));
  write_file_atomic(dir / "phases.csv", phases_csv(res));
  write_file_atomic(dir / "divergence.csv", divergence_csv(res));

  // Plots.
  write_png(dir / "timing.png", timing_plot(res, cumulative));
  write_png(dir / "divergence.png", divergence_plot(res));
  write_png(dir / "energy.png",
            plot_per_step(
                res, "Kinetic energy", res.dimension == 2 ? "J/m" : "J", false,
                [](const RunRecord& r, std::size_t i) { return r.steps[i].kinetic_energy; }, false));
  if (res.audited)
    write_png(
        dir / "missed_pairs.png",
        plot_per_step(
            res, "Pairs within h missing from the lists (audit)", "missed pairs per step", false,
            [](const RunRecord& r, std::size_t i) { return static_cast<double>(r.steps[i].missed_pairs); }, true));
  // Frames.
  const double ke_max = largest_image_energy(res, res.particle_mass);
  for (std::int64_t s : res.image_steps) write_png(dir / frame_file(s), frame_image(res, s, res.particle_mass, ke_max));
  write_file_atomic(dir / "report.md", report_md(res, comparison_files(res)));
}

}  // namespace sph