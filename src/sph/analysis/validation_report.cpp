// Writing the validation's results (`sph validate`): report.md, the CSVs and the plots.

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include <sph/analysis/labels.h>
#include <sph/analysis/validation.h>
#include <sph/core/vec.h>
#include <sph/core/version.h>
#include <sph/io/atomic_file.h>
#include <sph/render/colormap.h>
#include <sph/render/plot.h>
#include <sph/render/png.h>

namespace sph {

namespace {

std::string g(double x, int digits = 3) {
  return std::isfinite(x) ? fmt::format("{:.{}g}", x, digits) : std::string("n/a");
}

/// The experiment as separate points (NaN between them, so each is drawn as a dot).
Series experiment_series() {
  Series s;
  s.name = "Martin & Moyce (1952)";
  s.color = Rgb{0, 0, 0};
  for (const FrontPoint& p : martin_moyce_1952()) {
    if (!s.x.empty()) s.x.push_back(kNaN), s.y.push_back(kNaN);
    s.x.push_back(p.T);
    s.y.push_back(p.Z);
  }
  return s;
}

Image front_plot(const std::vector<const FrontRun*>& runs, const std::string& title) {
  PlotSpec spec;
  spec.title = title;
  spec.x_label = "T = t sqrt(2 g / a)";
  spec.y_label = "Z = front x / a";
  int k = 0;
  for (const FrontRun* r : runs) {
    Series s;
    s.name = r->label;
    s.color = series_color(k++);
    for (std::size_t i = 0; i < r->T.size(); ++i) {
      if (r->T[i] > 3.45) break;
      s.x.push_back(r->T[i]);
      s.y.push_back(r->Z[i]);
    }
    spec.series.push_back(std::move(s));
  }
  spec.series.push_back(experiment_series());
  return render_plot(spec);
}

const FrontRun* find_run(const ValidationResult& res, int resolution, const std::string& mode) {
  for (const FrontRun& r : res.front_runs)
    if (r.resolution == resolution && r.mode == mode) return &r;
  return nullptr;
}

std::vector<int> resolutions(const ValidationResult& res) {
  std::vector<int> out;
  for (const FrontRun& r : res.front_runs)
    if (r.mode == "standard" && std::find(out.begin(), out.end(), r.resolution) == out.end())
      out.push_back(r.resolution);
  std::sort(out.begin(), out.end());
  return out;
}

bool has(const ValidationResult& res, const char* c) {
  return std::find(res.cases.begin(), res.cases.end(), c) != res.cases.end();
}

std::vector<const FrontRun*> mode_runs(const ValidationResult& res) {
  std::vector<const FrontRun*> out;
  const int base = res.quick ? 20 : 40;
  for (const char* m : {"standard", "adaptive", "verlet"})
    if (const FrontRun* r = find_run(res, base, m)) out.push_back(r);
  return out;
}

std::string checks_table(const ValidationResult& res, const std::string& case_name) {
  std::string md = "| check | measured | target | result |\n| --- | ---: | --- | --- |\n";
  for (const ValidationCheck& c : res.checks) {
    if (c.case_name != case_name) continue;
    md += fmt::format("| {} | {} | {}{} | {} |\n", c.what, g(c.value), c.target,
                      c.regression ? " (regression bound)" : "", c.pass ? "PASS" : "**MISS**");
  }
  return md + "\n";
}

/// report.md's section on the dam break against Martin & Moyce (1952).
std::string report_martin_moyce(const ValidationResult& res) {
  std::string md = "## Dam break against Martin & Moyce (1952)\n\n";
  md += fmt::format(
      "Water column a x 2a (a = {} m) against the left wall of a closed 0.5 m x 0.15 m tank; front Z = x / a\n"
      "of the farthest floor particle (y < 2 spacings) with at least 3 other particles within h, plus half a\n"
      "spacing, against T = t sqrt(2 g / a). Simulated Z(T) is interpolated linearly at the experiment's\n"
      "15 points of Table 2 (0.41 <= T <= 3.33; the initial point T = 0 is left out).\n\n",
      kMartinMoyceA);
  md += "![front](front.png)\n\n";
  md += "| run | particles | spacing (m) | dt (s) | steps | wall s | max dZ | RMS dZ | mean dZ | worst at T |\n";
  md += "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
  for (const FrontRun* r : mode_runs(res))
    md += fmt::format("| {}{} | {} | {:.6g} | {:g} | {} | {:.1f} | {} | {} | {:+.3f} | {} |\n", r->label,
                      r->failure.empty() ? "" : " (failed)", r->particles, r->spacing, r->dt, r->steps, r->seconds,
                      g(r->error.max), g(r->error.rms), r->error.mean, g(r->error.worst_T));
  md += "\n" + checks_table(res, "martin_moyce");
  return md;
}

/// report.md's section on the resolution study.
std::string report_resolution(const ValidationResult& res) {
  std::string md = "## Resolution study\n\n";
  md +=
      "The same dam break at several spacings (standard mode). h, dt scale with the spacing; the wall\n"
      "stiffness with 1 / spacing^2; viscosity and stiffness are fixed. The change from the coarser is\n"
      "Z at this spacing minus Z at the next coarser one, at the experiment's times: it shrinks when the\n"
      "method converges, whatever the distance of its limit from the experiment.\n\n";
  md += "![resolution](resolution.png)\n\n![resolution error](resolution_error.png)\n\n";
  md +=
      "| spacing | particles | steps | wall s | max dZ | RMS dZ | mean dZ | max change from the coarser | RMS change "
      "|\n| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
  for (int n : resolutions(res))
    if (const FrontRun* r = find_run(res, n, "standard"))
      md +=
          fmt::format("| a/{} | {} | {} | {:.1f} | {} | {} | {:+.3f} | {} | {} |\n", n, r->particles, r->steps,
                      r->seconds, g(r->error.max), g(r->error.rms), r->error.mean, g(r->change.max), g(r->change.rms));
  md += "\n" + checks_table(res, "resolution");
  return md;
}

/// report.md's section on the boundaries case: one row per (dimension, boundary, kernel).
std::string report_boundaries(const ValidationResult& res) {
  std::string md = "## Boundaries: hydrostatic tanks per boundary handling and kernel\n\n";
  md +=
      "The hydrostatic tanks again, for each Configuration.boundaryHandling and Configuration.kernel. The\n"
      "interior error compares particles more than h from the walls (as the hydrostatic case does); the\n"
      "whole-tank error compares every particle deeper than 2 spacings, next to the walls too. Outside:\n"
      "the most particles outside the container in any step. The errors are of each particle's pressure\n"
      "and position averaged over the run's last tenth (the tank still rings); the last column is the\n"
      "whole tank's error in the last frame alone. h: the kernel support in spacings. Bins are two spacings\n"
      "deep; the layer error is the same over bins of one spacing, the particles' layers where the tank keeps\n"
      "its lattice (the pressure alternates from layer to layer under a free surface, and two-spacing bins\n"
      "average that out).\n\n";
  md +=
      "| tank | boundary | kernel | h | wall s | mean p/(rho0 g d) | max bin error, interior | max bin error, whole "
      "tank | max layer error, whole tank | max compression | outside | settling | whole tank, last frame |\n";
  md += "| --- | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
  for (const HydrostaticRun& h : res.boundaries)
    md += fmt::format(
        "| {}D{} | {} | {} | {:g} | {:.1f} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | {:.2f} % | {} | {} | {:.3f} |\n",
        h.dimension, h.failure.empty() ? "" : " (failed)", h.boundary, h.kernel, h.h / h.spacing, h.seconds,
        h.whole.mean_ratio, h.profile.max_bin_error, h.whole.max_bin_error, h.whole.max_layer_error,
        100 * h.whole.max_compression, h.max_outside,
        std::isfinite(h.settling_time) ? g(h.settling_time) + " s" : std::string("does not settle"),
        h.whole_last_frame);
  md += "\n" + checks_table(res, "boundaries");
  return md;
}

/// boundaries.csv: the table of report_boundaries.
void write_boundaries_csv(const std::filesystem::path& dir, const ValidationResult& res) {
  std::string csv =
      "dimension,boundary,kernel,support_spacings,failed,wall_seconds,mean_ratio,max_bin_error_interior,"
      "max_bin_error_whole,max_layer_error_whole,max_compression,max_outside,settling_time,"
      "max_bin_error_whole_last_frame\n";
  for (const HydrostaticRun& h : res.boundaries)
    csv += fmt::format("{},{},{},{:g},{},{:.3f},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{},{:.6g},{:.6g}\n", h.dimension,
                       h.boundary, h.kernel, h.h / h.spacing, h.failure.empty() ? 0 : 1, h.seconds, h.whole.mean_ratio,
                       h.profile.max_bin_error, h.whole.max_bin_error, h.whole.max_layer_error, h.whole.max_compression,
                       h.max_outside, h.settling_time, h.whole_last_frame);
  write_file_atomic(dir / "boundaries.csv", csv);
}

/// report.md's section on the dfsph case: the DFSPH tanks and front.
std::string report_dfsph(const ValidationResult& res) {
  std::string md = "## DFSPH: resting tanks and the dam break with the divergence-free solver\n\n";
  md +=
      "The tanks of hydrostatic_2d_dfsph.json and hydrostatic_3d_dfsph.json (boundary particles, the cubic\n"
      "spline, CFL steps), measured as the boundaries case measures its tanks (each particle's pressure,\n"
      "density and position averaged over the run's last tenth; the whole tank below 2 spacings).\n"
      "Mean density error: mean |rho - rho0| / rho0 there. Steps, mean dt and the solves' mean iterations\n"
      "per step over the whole run. Bin error: over depth bins of two spacings; layer error: over bins of one\n"
      "spacing, the particles' layers (the two-spacing bins average a pressure that alternates from layer to\n"
      "layer).\n\n";
  md +=
      "| tank | wall s | steps | mean dt (s) | density iterations | divergence iterations | mean density error | "
      "mean p/(rho0 g d) | max bin error, whole tank | max layer error, whole tank | max compression | outside | "
      "settling |\n";
  md += "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
  for (const HydrostaticRun& h : res.dfsph)
    md += fmt::format(
        "| {}{} | {:.1f} | {} | {:.3g} | {:.2f} | {:.2f} | {:.3f} % | {:.3f} | {:.3f} | {:.3f} | {:.2f} % | {} | {} "
        "|\n",
        h.label, h.failure.empty() ? "" : " (failed)", h.seconds, h.steps_taken, h.mean_dt, h.mean_iterations,
        h.mean_iterations_v, 100 * h.whole.mean_density_error, h.whole.mean_ratio, h.whole.max_bin_error,
        h.whole.max_layer_error, 100 * h.whole.max_compression, h.max_outside,
        std::isfinite(h.settling_time) ? g(h.settling_time) + " s" : std::string("does not settle"));
  for (const FrontRun& r : res.front_runs)
    if (r.mode == "standard+dfsph")
      md += fmt::format(
          "\nMartin & Moyce with DFSPH ({}): {} steps, mean dt {:.3g} s, {:.1f} s of wall time; front "
          "max |dZ| {}, mean {:+.3f}.\n",
          r.label, r.steps, r.dt, r.seconds, g(r.error.max), r.error.mean);
  md += "\n" + checks_table(res, "dfsph");
  return md;
}

/// dfsph.csv: the table of report_dfsph.
void write_dfsph_csv(const std::filesystem::path& dir, const ValidationResult& res) {
  std::string csv =
      "tank,failed,wall_seconds,steps,mean_dt,mean_iterations,mean_iterations_v,mean_density_error,mean_ratio,"
      "max_bin_error_whole,max_layer_error_whole,max_compression,max_outside,settling_time\n";
  for (const HydrostaticRun& h : res.dfsph)
    csv += fmt::format("{},{},{:.3f},{},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{},{:.6g}\n", h.label,
                       h.failure.empty() ? 0 : 1, h.seconds, h.steps_taken, h.mean_dt, h.mean_iterations,
                       h.mean_iterations_v, h.whole.mean_density_error, h.whole.mean_ratio, h.whole.max_bin_error,
                       h.whole.max_layer_error, h.whole.max_compression, h.max_outside, h.settling_time);
  write_file_atomic(dir / "dfsph.csv", csv);
}

/// report.md's section on the hydrostatic tanks.
std::string report_hydrostatic(const ValidationResult& res) {
  std::string md = "## Hydrostatic tanks\n\n";
  md +=
      "Water at rest in a closed box, settling under gravity. After the run: the free surface is the\n"
      "mean height of the top particle of each column (plus half a spacing); interior particles (more than\n"
      "h from every wall, deeper than 2 spacings) are binned by depth (bins of 2 spacings) and each bin's\n"
      "mean pressure is compared with rho0 g depth; the layer error is the same over bins of 1 spacing. The\n"
      "predicted ratio is 1 / M_yy, the spiky gradient's consistency factor on a perfect lattice\n"
      "(docs/validation.md).\n\n";
  md += "![pressure 2D](hydrostatic_2d.png)\n\n![pressure 3D](hydrostatic_3d.png)\n\n";
  md += "![surface](hydrostatic_surface.png)\n\n![settling](hydrostatic_settling.png)\n\n";
  md +=
      "| tank | particles | spacing | k | dt | steps | wall s | mean p/(rho0 g d) | predicted 1/M_yy | max bin error "
      "| max layer error | max compression | interior density range | surface sink | drift (2nd half) | settling |\n";
  md +=
      "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- | ---: | ---: | ---: "
      "|\n";
  for (const HydrostaticRun& h : res.hydrostatic)
    md += fmt::format(
        "| {}{} | {} | {:g} m | {:g} | {:g} s | {} | {:.1f} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | {:.2f} % | {:+.2f} % "
        ".. {:+.2f} % | {:.2f} spacings | {:.3f} spacings | {} s |\n",
        h.label, h.failure.empty() ? "" : " (failed)", h.particles, h.spacing, h.stiffness, h.dt, h.steps, h.seconds,
        h.profile.mean_ratio, h.predicted_ratio, h.profile.max_bin_error, h.profile.max_layer_error,
        100 * h.profile.max_compression, 100 * h.profile.interior_density_min, 100 * h.profile.interior_density_max,
        (h.initial_surface - h.profile.surface) / h.spacing, h.surface_drift / h.spacing, g(h.settling_time));
  md += "\n" + checks_table(res, "hydrostatic");
  return md;
}

/// report.md's section on momentum and energy conservation.
std::string report_conservation(const ValidationResult& res) {
  std::string md = "## Conservation\n\n";
  md +=
      "Momentum: two water blocks collide without gravity, far from every wall. Drift is the largest\n"
      "|P(t) - P(0)| over the run divided by sum m |v| at t = 0.\n\n![momentum](momentum.png)\n\n";
  md += "| run | steps | wall s | max drift | at end |\n| --- | ---: | ---: | ---: | ---: |\n";
  for (const MomentumRun& r : res.momentum)
    md += fmt::format("| {}{} | {} | {:.1f} | {} | {} |\n", r.label,
                      r.failure.empty() ? "" : fmt::format(" (failed: {})", r.failure), r.steps, r.seconds,
                      g(r.max_drift), r.drift.empty() ? "n/a" : g(r.drift.back()));
  md +=
      "\nEnergy in the closed dam-break tank (viscosity and damped walls only remove energy): kinetic +\n"
      "gravitational potential + the EOS's internal energy + the wall springs' energy. The check bounds\n"
      "the largest rise of the total (over any earlier minimum) relative to the peak kinetic energy.\n\n"
      "![energy](energy.png)\n\n![energy parts](energy_parts.png)\n\n";
  md += "| run | E(0) | E(end) | dissipated | peak KE | largest rise |\n| --- | ---: | ---: | ---: | ---: | ---: |\n";
  for (const FrontRun* r : mode_runs(res)) {
    if (r->energy.empty()) continue;
    std::vector<double> total;
    double peak = 0;
    for (const EnergyParts& e : r->energy) total.push_back(e.total()), peak = std::max(peak, e.kinetic);
    md += fmt::format("| {} | {:.6g} | {:.6g} | {:.1f} % | {:.6g} | {:.3g} |\n", r->label, total.front(), total.back(),
                      100 * (total.front() - total.back()) / total.front(), peak, largest_rise(total));
  }
  md += "\nEnergies in J/m (2D).\n\n" + checks_table(res, "conservation");
  return md;
}

std::string report_md(const ValidationResult& res, const std::vector<std::string>& files) {
  std::string md = "# Validation against experiment and physics\n\n";
  md += fmt::format(
      "{}sph {}, {} thread{}, {:.1f} s in all. Command: `sph validate{}`. Method and discussion:\n"
      "docs/validation.md.\n\n",
      res.quick ? "**Quick (coarse, short) versions: the bounds are regression bounds for CI, not the physical "
                  "targets.**\n\n"
                : "",
      kVersion, res.threads, res.threads == 1 ? "" : "s", res.seconds, res.quick ? " --quick" : "");
  std::size_t missed = 0;
  for (const auto& c : res.checks) missed += !c.pass;
  md += missed == 0 ? fmt::format("**All {} checks pass.**\n\n", res.checks.size())
                    : fmt::format("**{} of {} checks miss their target:**\n\n", missed, res.checks.size());
  for (const auto& c : res.checks)
    if (!c.pass) md += fmt::format("- {}: {} = {}, target {}\n", c.case_name, c.what, g(c.value), c.target);
  if (missed) md += "\n";

  if (has(res, "martin_moyce")) md += report_martin_moyce(res);
  if (has(res, "resolution")) md += report_resolution(res);
  if (has(res, "hydrostatic")) md += report_hydrostatic(res);
  if (has(res, "boundaries")) md += report_boundaries(res);
  if (has(res, "dfsph")) md += report_dfsph(res);
  if (has(res, "conservation")) md += report_conservation(res);
  md += "## Files\n\n";
  for (const auto& f : files) md += "- `" + f + "`\n";
  return md;
}

}  // namespace

std::vector<std::string> validation_files(const ValidationResult& res) {
  std::vector<std::string> f{"report.md", "checks.csv"};
  if (!res.front_runs.empty()) f.insert(f.end(), {"front.csv", "front_errors.csv", "front_points.csv"});
  if (has(res, "martin_moyce")) f.push_back("front.png");
  if (has(res, "resolution")) f.insert(f.end(), {"resolution.png", "resolution_error.png"});
  if (has(res, "hydrostatic")) {
    f.insert(f.end(), {"hydrostatic_profile.csv", "hydrostatic_history.csv", "hydrostatic_surface.png",
                       "hydrostatic_settling.png"});
    for (const HydrostaticRun& h : res.hydrostatic) f.push_back(fmt::format("hydrostatic_{}d.png", h.dimension));
  }
  if (has(res, "boundaries")) f.push_back("boundaries.csv");
  if (has(res, "dfsph")) f.push_back("dfsph.csv");
  if (has(res, "conservation"))
    f.insert(f.end(), {"momentum.csv", "energy.csv", "momentum.png", "energy.png", "energy_parts.png"});
  return f;
}

namespace {

/// checks.csv: every check with its value, bound and result.
void write_checks_csv(const std::filesystem::path& dir, const ValidationResult& res) {
  std::string out = "case,check,value,target,regression_bound,result\n";
  for (const auto& c : res.checks)
    out += fmt::format("{},\"{}\",{:.9g},\"{}\",{},{}\n", c.case_name, c.what, c.value, c.target,
                       c.regression ? "yes" : "no", c.pass ? "PASS" : "MISS");
  write_file_atomic(dir / "checks.csv", out);
}

/// front.csv, front_errors.csv and front_points.csv: the dam-break fronts and their errors.
void write_front_csvs(const std::filesystem::path& dir, const ValidationResult& res) {
  std::string out = "run,step,time,T,Z\n";
  for (const FrontRun& r : res.front_runs)
    for (std::size_t i = 0; i < r.T.size(); ++i)
      out += fmt::format("{},{},{:.9g},{:.6f},{:.6f}\n", r.label, r.step[i], r.time[i], r.T[i], r.Z[i]);
  write_file_atomic(dir / "front.csv", out);
  out =
      "run,resolution,mode,particles,spacing,dt,steps,seconds,points,complete,max_dZ,rms_dZ,mean_dZ,worst_T,"
      "max_change_from_coarser,rms_change_from_coarser,failure\n";
  for (const FrontRun& r : res.front_runs) {
    std::string failure = r.failure;
    std::replace(failure.begin(), failure.end(), '"', '\'');
    out += fmt::format("{},{},{},{},{:.9g},{:.9g},{},{:.3f},{},{},{:.6f},{:.6f},{:.6f},{:.2f},{:.6f},{:.6f},\"{}\"\n",
                       r.label, r.resolution, r.mode, r.particles, r.spacing, r.dt, r.steps, r.seconds, r.error.points,
                       r.error.complete ? "yes" : "no", r.error.max, r.error.rms, r.error.mean, r.error.worst_T,
                       r.change.max, r.change.rms, failure);
  }
  write_file_atomic(dir / "front_errors.csv", out);
  out = "T,Z_experiment";
  for (const FrontRun& r : res.front_runs) out += ",Z_" + slug(r.label) + ",dZ_" + slug(r.label);
  out += "\n";
  const FrontError& first = res.front_runs.front().error;
  for (std::size_t k = 0; k < first.experiment.size(); ++k) {
    out += fmt::format("{:.2f},{:.2f}", first.experiment[k].T, first.experiment[k].Z);
    for (const FrontRun& r : res.front_runs) {
      const double z = k < r.error.simulated.size() ? r.error.simulated[k] : kNaN;
      out += fmt::format(",{:.4f},{:+.4f}", z, z - first.experiment[k].Z);
    }
    out += "\n";
  }
  write_file_atomic(dir / "front_points.csv", out);
}

/// resolution.png and resolution_error.png: the fronts and their errors at each spacing.
void write_resolution_plots(const std::filesystem::path& dir, const ValidationResult& res) {
  std::vector<const FrontRun*> runs;
  for (int n : resolutions(res))
    if (const FrontRun* r = find_run(res, n, "standard")) runs.push_back(r);
  write_png(dir / "resolution.png", front_plot(runs, "Dam break front at three spacings (standard mode)"));
  PlotSpec spec;
  spec.title = "Front error against resolution";
  spec.x_label = "particles per a (a / spacing)";
  spec.y_label = "|dZ| over T <= 3.33";
  Series mx{.name = "max |dZ|", .x = {}, .y = {}, .color = series_color(0), .dashed = false};
  Series rms{.name = "RMS dZ", .x = {}, .y = {}, .color = series_color(1), .dashed = true};
  Series change{.name = "max change from the coarser", .x = {}, .y = {}, .color = series_color(2), .dashed = false};
  for (const FrontRun* r : runs) {
    mx.x.push_back(r->resolution), mx.y.push_back(r->error.max);
    rms.x.push_back(r->resolution), rms.y.push_back(r->error.rms);
    if (std::isfinite(r->change.max)) change.x.push_back(r->resolution), change.y.push_back(r->change.max);
  }
  spec.series = {mx, rms, change};
  write_png(dir / "resolution_error.png", render_plot(spec));
}

/// The hydrostatic tanks' profile and history CSVs and their plots.
void write_hydrostatic_files(const std::filesystem::path& dir, const ValidationResult& res) {
  std::string prof = "dimension,depth,pressure,rho0_g_depth,ratio,count,compared\n";
  std::string hist = "dimension,time,surface,kinetic_energy,total_energy\n";
  PlotSpec surf{.title = "Free surface height over time",
                .x_label = "time (s)",
                .y_label = "surface - initial surface (spacings)",
                .log_y = false,
                .series = {}};
  PlotSpec settle{.title = "Settling: kinetic energy over time",
                  .x_label = "time (s)",
                  .y_label = "kinetic energy / peak",
                  .log_y = true,
                  .series = {}};
  int k = 0;
  for (const HydrostaticRun& h : res.hydrostatic) {
    const double rho_g = h.rest_density * h.gravity;
    for (const DepthBin& b : h.profile.bins)
      prof += fmt::format("{},{:.6g},{:.6g},{:.6g},{:.5f},{},{}\n", h.dimension, b.depth, b.pressure, rho_g * b.depth,
                          b.ratio, b.count, b.compared ? "yes" : "no");
    const double peak = h.kinetic.empty() ? 1.0 : *std::max_element(h.kinetic.begin(), h.kinetic.end());
    Series s{.name = h.label, .x = {}, .y = {}, .color = series_color(k), .dashed = false};
    Series e{.name = h.label, .x = {}, .y = {}, .color = series_color(k), .dashed = false};
    for (std::size_t i = 0; i < h.time.size(); ++i) {
      hist += fmt::format("{},{:.6g},{:.9g},{:.9g},{:.12g}\n", h.dimension, h.time[i], h.surface[i], h.kinetic[i],
                          h.energy[i].total());
      s.x.push_back(h.time[i]), s.y.push_back((h.surface[i] - h.initial_surface) / h.spacing);
      e.x.push_back(h.time[i]), e.y.push_back(peak > 0 ? h.kinetic[i] / peak : kNaN);
    }
    surf.series.push_back(std::move(s));
    settle.series.push_back(std::move(e));
    ++k;
    // Pressure against depth: particles, bin means, rho0 g d and the predicted slope.
    PlotSpec spec;
    spec.title = fmt::format("Hydrostatic tank {}: pressure against depth after {:g} s", h.label,
                             h.dt * static_cast<double>(h.steps));
    spec.x_label = "depth below the free surface (m)";
    spec.y_label = h.dimension == 2 ? "pressure (N/m)" : "pressure (Pa)";
    Series pts{.name = "interior particles", .x = {}, .y = {}, .color = Rgb{170, 170, 170}, .dashed = false};
    double dmax = 0;
    for (const auto& [d, p] : h.scatter) {
      if (!pts.x.empty()) pts.x.push_back(kNaN), pts.y.push_back(kNaN);
      pts.x.push_back(d), pts.y.push_back(p);
      dmax = std::max(dmax, d);
    }
    Series bins{.name = "bin means (compared bins)", .x = {}, .y = {}, .color = series_color(0), .dashed = false};
    for (const DepthBin& b : h.profile.bins)
      if (b.compared) bins.x.push_back(b.depth), bins.y.push_back(b.pressure);
    Series exact{.name = "rho0 g d", .x = {0, dmax}, .y = {0, rho_g * dmax}, .color = Rgb{0, 0, 0}, .dashed = false};
    Series pred{.name = fmt::format("rho0 g d / M_yy ({:.3f})", h.predicted_ratio),
                .x = {0, dmax},
                .y = {0, rho_g * dmax * h.predicted_ratio},
                .color = series_color(1),
                .dashed = true};
    spec.series = {std::move(pts), std::move(bins), std::move(exact), std::move(pred)};
    write_png(dir / fmt::format("hydrostatic_{}d.png", h.dimension), render_plot(spec));
  }
  write_file_atomic(dir / "hydrostatic_profile.csv", prof);
  write_file_atomic(dir / "hydrostatic_history.csv", hist);
  write_png(dir / "hydrostatic_surface.png", render_plot(surf));
  write_png(dir / "hydrostatic_settling.png", render_plot(settle));
}

/// momentum.csv, energy.csv and their plots.
void write_conservation_files(const std::filesystem::path& dir, const ValidationResult& res) {
  std::string out = "run,time,drift\n";
  PlotSpec spec{.title = "Momentum drift, two blocks colliding without gravity",
                .x_label = "time (s)",
                .y_label = "|P(t) - P(0)| / sum m|v0|",
                .log_y = true,
                .series = {}};
  int k = 0;
  for (const MomentumRun& r : res.momentum) {
    Series s{.name = r.label, .x = {}, .y = {}, .color = series_color(k++), .dashed = false};
    const std::size_t stride = std::max<std::size_t>(1, r.time.size() / 2000);
    for (std::size_t i = 0; i < r.time.size(); ++i) {
      out += fmt::format("{},{:.6g},{:.6g}\n", r.label, r.time[i], r.drift[i]);
      if (i % stride == 0) s.x.push_back(r.time[i]), s.y.push_back(r.drift[i]);
    }
    spec.series.push_back(std::move(s));
  }
  write_file_atomic(dir / "momentum.csv", out);
  write_png(dir / "momentum.png", render_plot(spec));
  out = "run,step,time,kinetic,potential,internal,wall,total\n";
  PlotSpec en{.title = "Total energy in the closed dam-break tank",
              .x_label = "time (s)",
              .y_label = "E(t) - E(0) (J/m)",
              .log_y = false,
              .series = {}};
  PlotSpec parts{.title = "Energy parts, dam break (standard mode)",
                 .x_label = "time (s)",
                 .y_label = "change since t = 0 (J/m)",
                 .log_y = false,
                 .series = {}};
  k = 0;
  for (const FrontRun* r : mode_runs(res)) {
    Series s{.name = r->label, .x = {}, .y = {}, .color = series_color(k++), .dashed = false};
    for (std::size_t i = 0; i < r->energy.size(); ++i) {
      const EnergyParts& e = r->energy[i];
      out += fmt::format("{},{},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g}\n", r->label, r->step[i], r->time[i],
                         e.kinetic, e.potential, e.internal, e.wall, e.total());
      s.x.push_back(r->time[i]), s.y.push_back(e.total() - r->energy.front().total());
    }
    en.series.push_back(std::move(s));
    if (r->mode == "standard" && !r->energy.empty()) {
      const EnergyParts& e0 = r->energy.front();
      const std::array<std::pair<const char*, double EnergyParts::*>, 4> fields{
          {{"kinetic", &EnergyParts::kinetic},
           {"potential", &EnergyParts::potential},
           {"internal (EOS)", &EnergyParts::internal},
           {"wall springs", &EnergyParts::wall}}};
      int c = 0;
      for (const auto& [name, field] : fields) {
        Series p{.name = name, .x = {}, .y = {}, .color = series_color(c++), .dashed = false};
        for (std::size_t i = 0; i < r->energy.size(); ++i)
          p.x.push_back(r->time[i]), p.y.push_back(r->energy[i].*field - e0.*field);
        parts.series.push_back(std::move(p));
      }
      Series t{.name = "total", .x = {}, .y = {}, .color = Rgb{0, 0, 0}, .dashed = true};
      for (std::size_t i = 0; i < r->energy.size(); ++i)
        t.x.push_back(r->time[i]), t.y.push_back(r->energy[i].total() - e0.total());
      parts.series.push_back(std::move(t));
    }
  }
  write_file_atomic(dir / "energy.csv", out);
  write_png(dir / "energy.png", render_plot(en));
  write_png(dir / "energy_parts.png", render_plot(parts));
}

}  // namespace

void prepare_validation_directory(const std::filesystem::path& dir) {
  make_writable_directory(dir, "the validation's output");
}

void write_validation(const std::filesystem::path& dir, const ValidationResult& res) {
  // An earlier validation's files go now that this one has its own to write (not when it starts:
  // a run stopped on the way leaves the earlier report whole), those of cases it did not run too.
  std::error_code ec;
  ValidationResult every;
  every.cases.assign(kValidationCases.begin(), kValidationCases.end());
  every.front_runs.resize(1);
  every.hydrostatic.resize(2);
  every.hydrostatic[1].dimension = 3;
  for (const std::string& f : validation_files(every)) std::filesystem::remove(dir / f, ec);
  write_checks_csv(dir, res);
  if (!res.front_runs.empty()) write_front_csvs(dir, res);
  if (has(res, "martin_moyce"))
    write_png(dir / "front.png",
              front_plot(mode_runs(res), "Dam break front: neighbor modes against Martin & Moyce (1952)"));
  if (has(res, "resolution")) write_resolution_plots(dir, res);
  if (has(res, "hydrostatic")) write_hydrostatic_files(dir, res);
  if (has(res, "boundaries")) write_boundaries_csv(dir, res);
  if (has(res, "dfsph")) write_dfsph_csv(dir, res);
  if (has(res, "conservation")) write_conservation_files(dir, res);
  write_file_atomic(dir / "report.md", report_md(res, validation_files(res)));
}

}  // namespace sph