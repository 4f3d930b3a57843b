// sph.run, sph.compare and sph.read_frame: what `sph run`, `sph compare` and the frame readers do.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <sph/analysis/compare.h>
#include <sph/analysis/validation.h>
#include <sph/core/parallel.h>
#include <sph/io/frames.h>
#include <sph/io/run_directory.h>
#include <sph/io/run_output.h>
#include <sph/neighbors/neighbor_mode.h>
#include <sph/run/driver.h>
#include <sph/run/memory.h>
#include <sph/scene/dispatch.h>

#include "module.h"

namespace sph::python {

namespace {

namespace fs = std::filesystem;

/// A progress callback: None or False (none), True (a line on stderr every 10 %), or a callable.
struct Progress {
  py::object callable;
  bool lines = false;

  explicit Progress(const py::object& p) {
    if (p.is_none() || (py::isinstance<py::bool_>(p) && !py::cast<bool>(p))) return;
    if (py::isinstance<py::bool_>(p))
      lines = true;
    else if (PyCallable_Check(p.ptr()))
      callable = p;
    else
      throw py::type_error("progress must be None, a bool or a callable");
  }
};

/// Whether Python has a signal to handle (Ctrl-C): runs its handler, which leaves the exception
/// (KeyboardInterrupt) set; `pending` then keeps it for after the run.
bool python_signal(std::optional<py::error_already_set>& pending) {
  py::gil_scoped_acquire gil;
  if (PyErr_CheckSignals() == 0) return false;
  pending.emplace();  // (takes the exception out of Python's error indicator)
  return true;
}

py::dict run_scene(const Scene& scene, const py::object& output_arg, const py::object& neighbors,
                   const py::object& steps, const py::object& threads, const py::object& checkpoint_every_arg,
                   bool strict, bool overwrite, const py::object& progress_arg) {
  const std::int64_t checkpoint_every =
      whole_number_arg(checkpoint_every_arg, "checkpoint_every", 0, std::numeric_limits<std::int64_t>::max());
  const SceneDesc desc = with_overrides(scene.desc, run_overrides(neighbors, steps));
  const int n_threads = thread_count_arg(threads);
  const Progress progress(progress_arg);
  const fs::path dir(path_arg(output_arg, "output"));
  check_new_run_directory(dir, overwrite, "output", "overwrite=True", "");
  std::optional<py::error_already_set> interrupt;
  std::optional<py::error_already_set> callback_error;
  RunResult result;
  std::size_t frames = 0;
  {
    py::gil_scoped_release release;
    use_threads(n_threads);
    dispatch(desc, [&]<int D, class R>() {
      RunDriver<D, R> driver(desc, RunSettings{dir, checkpoint_every, strict, {}});
      RunCallbacks callbacks;
      std::int64_t shown = 0;
      callbacks.progress = [&](std::int64_t done, std::size_t particles) {
        if (progress.lines) {
          // A run to stopAt (desc.end_time) counts in simulated time, as sph run does: its step
          // count is then only a bound (CFL steps), and lines by steps would stop short of 10 %.
          const double t = driver.simulation().time();
          const std::int64_t tenths =
              desc.end_time > 0 ? static_cast<std::int64_t>(10 * t / desc.end_time) : 10 * done / desc.steps;
          if (tenths > shown) {
            shown = tenths;
            if (desc.end_time > 0)
              std::fprintf(stderr, "sph: %s: t = %.4g of %.4g s (%lld %%), step %lld, %zu particles\n",
                           desc.name.c_str(), t, desc.end_time, static_cast<long long>(10 * tenths),
                           static_cast<long long>(done), particles);
            else
              std::fprintf(stderr, "sph: %s: step %lld of %lld (%lld %%), %zu particles\n", desc.name.c_str(),
                           static_cast<long long>(done), static_cast<long long>(desc.steps),
                           static_cast<long long>(10 * tenths), particles);
          }
        } else if (progress.callable && !callback_error) {
          py::gil_scoped_acquire gil;
          try {
            progress.callable(done, desc.steps);
          } catch (py::error_already_set& e) {
            callback_error.emplace(std::move(e));
          }
        }
      };
      callbacks.warning = [&](const std::string& w) {
        py::gil_scoped_acquire gil;
        if (PyErr_WarnEx(error_types().health_warning.ptr(), w.c_str(), 1) != 0) callback_error.emplace();
      };
      callbacks.stop_requested = [&](std::int64_t) -> std::string {
        if (callback_error) return "an exception in a callback";
        return python_signal(interrupt) ? "KeyboardInterrupt" : "";
      };
      result = driver.run(callbacks);
      frames = driver.output()->frames_written();
    });
  }
  if (interrupt) {  // after the run's checkpoint and summary: say where they are and how to go on
    interrupt->restore();
    PyErr_Clear();
    PyErr_SetString(PyExc_KeyboardInterrupt,
                    ("sph.run stopped after step " + std::to_string(result.steps_done) + "; its checkpoint is in " +
                     dir.string() + ": continue it with sph run --resume " + dir.string())
                        .c_str());
    throw py::error_already_set();
  }
  if (callback_error) throw std::move(*callback_error);
  py::dict out;
  out["status"] = std::string(to_string(result.status));
  out["message"] = result.message;
  out["steps"] = result.steps_done;
  out["wall_seconds"] = result.wall_seconds;
  out["frames"] = frames;
  out["warnings"] = result.warnings;
  out["output"] = dir.string();
  if (result.status == RunStatus::Failed) throw SimulationError(result.error, dir.string());
  return out;
}

py::dict compare_scene(const Scene& scene, const py::object& output, const py::object& modes, const py::object& steps,
                       const py::object& threads, const py::object& frames_arg, const py::object& perturbation_arg,
                       bool audit, bool run_frames, const py::object& progress_arg) {
  CompareOptions co;
  if (!modes.is_none()) {
    co.modes.clear();
    for (const std::string& name : names_arg(modes, "modes")) {
      const NeighborMode m = parse_neighbor_mode(name, "modes", NeighborModeSet::Compared);
      if (std::find(co.modes.begin(), co.modes.end(), m) != co.modes.end())
        throw Error("mode \"" + name + "\" is listed twice", "modes");
      co.modes.push_back(m);
    }
    if (co.modes.empty()) throw Error("no mode given", "modes");
  }
  const int frames = static_cast<int>(whole_number_arg(frames_arg, "frames", 1, 100));
  const double perturbation = real_arg(perturbation_arg, "perturbation");
  if (!(perturbation >= 0 && perturbation <= 0.1)) throw py::value_error("perturbation must be 0 to 0.1 (of h)");
  co.frames = frames;
  co.perturbation = perturbation;
  co.audit = audit;
  const SceneDesc desc = with_overrides(scene.desc, run_overrides(py::none(), steps));
  co.steps = desc.steps;
  const int n_threads = thread_count_arg(threads);
  const Progress progress(progress_arg);
  std::optional<fs::path> dir;
  if (!output.is_none()) {
    dir = fs::path(path_arg(output, "output"));
    check_output_path(dir->string(), "output");
  }
  std::optional<py::error_already_set> callback_error;
  CompareResult result;
  {
    py::gil_scoped_release release;
    use_threads(n_threads);
    check_fits_in_memory(desc);
    if (dir) {
      prepare_comparison_directory(*dir);
      if (run_frames) co.runs_dir = *dir;
    }
    const CompareProgress report = [&](const std::string& label, int index, int count, std::int64_t done,
                                       std::int64_t total) {
      if (progress.lines) {
        if (done == total || (10 * done / total) > (10 * (done - 1) / total))
          std::fprintf(stderr, "sph: [%d/%d] %s: %lld %%\n", index + 1, count, label.c_str(),
                       static_cast<long long>(100 * done / total));
      } else if (progress.callable && !callback_error) {
        py::gil_scoped_acquire gil;
        try {
          progress.callable(label, index, count, done, total);
        } catch (py::error_already_set& e) {
          callback_error.emplace(std::move(e));
        }
      }
    };
    result = run_comparison(desc, co, report);
    if (dir) write_comparison(*dir, result);
  }
  if (callback_error) throw std::move(*callback_error);
  const double ref = standard_seconds(result);
  py::list runs;
  for (std::size_t k = 0; k < result.runs.size(); ++k) {
    const RunRecord& r = result.runs[k];
    py::dict run;
    run["label"] = r.label;
    run["mode"] = std::string(to_string(r.mode));
    run["perturbed"] = r.perturbed;
    run["seconds"] = r.totals.total();
    run["speedup"] = r.totals.total() > 0 ? ref / r.totals.total() : 0.0;
    run["steps"] = r.steps.size();
    run["missed_pairs"] = r.missed_pairs();
    run["boundary_missed_pairs"] = r.boundary_missed_pairs();
    run["final_rms_divergence"] =
        k > 0 && !result.divergence[k].empty() ? py::cast(result.divergence[k].back().rms) : py::none();
    run["failure"] = r.failure;
    runs.append(run);
  }
  py::dict out;
  out["scene"] = result.scene;
  out["steps"] = result.steps;
  out["threads"] = result.threads;
  out["audited"] = result.audited;
  out["runs"] = runs;
  out["output"] = dir ? py::cast(dir->string()) : py::none();
  out["report"] = dir ? py::cast((*dir / "report.md").string()) : py::none();
  return out;
}

py::dict read_frame_dict(const py::object& path_obj) {
  const std::string path = path_arg(path_obj, "path");
  FrameData frame;
  {
    py::gil_scoped_release release;
    frame = read_frame(path, boundary_sample_fields());  // (a run's boundary.vtu too)
  }
  py::dict out;
  out["time"] = frame.time;
  const auto n = static_cast<py::ssize_t>(frame.size);
  py::array_t<double> position({n, py::ssize_t{3}});
  std::copy(frame.position.begin(), frame.position.end(), position.mutable_data());
  out["position"] = position;
  for (const FrameField& f : frame.fields) {
    const FieldDesc* desc = find_particle_field(f.name);
    if (desc && desc->kind == FieldKind::Id) {
      py::array_t<std::uint64_t> ids(n);
      std::uint64_t* p = ids.mutable_data();
      for (std::size_t i = 0; i < f.values.size(); ++i) p[i] = static_cast<std::uint64_t>(f.values[i]);
      out[py::str(f.name)] = ids;
      continue;
    }
    py::array_t<double> a(f.components == 1 ? std::vector<py::ssize_t>{n} : std::vector<py::ssize_t>{n, 3});
    std::copy(f.values.begin(), f.values.end(), a.mutable_data());
    out[py::str(f.name)] = a;
  }
  return out;
}

py::array_t<double> martin_moyce_points() {
  const std::span<const FrontPoint> points = martin_moyce_1952();
  py::array_t<double> out({static_cast<py::ssize_t>(points.size()), py::ssize_t{2}});
  double* p = out.mutable_data();
  for (const FrontPoint& f : points) *p++ = f.T, *p++ = f.Z;
  return out;
}

double front_of(const py::array_t<double, py::array::c_style | py::array::forcecast>& x,
                const py::array_t<double, py::array::c_style | py::array::forcecast>& y, double floor, double spacing,
                double h, int min_neighbors) {
  if (x.ndim() != 1 || y.ndim() != 1) throw py::value_error("x and y must be 1-D arrays");
  if (x.size() != y.size())
    throw py::value_error("x and y must have one value per particle each, got " + std::to_string(x.size()) + " and " +
                          std::to_string(y.size()));
  if (!(spacing > 0) || !std::isfinite(spacing))
    throw py::value_error("spacing must be a positive length (m), got " +
                          py::cast<std::string>(py::repr(py::float_(spacing))));
  if (!(h > 0) || !std::isfinite(h))
    throw py::value_error("h must be a positive length (m), got " + py::cast<std::string>(py::repr(py::float_(h))));
  if (!std::isfinite(floor)) throw py::value_error("floor must be a finite height (m)");
  if (min_neighbors < 0) throw py::value_error("min_neighbors must be 0 or more, got " + std::to_string(min_neighbors));
  return surge_front({x.data(), static_cast<std::size_t>(x.size())}, {y.data(), static_cast<std::size_t>(y.size())},
                     floor, spacing, h, min_neighbors);
}

}  // namespace

void register_runs(py::module_& m) {
  m.def("surge_front", &front_of, py::arg("x"), py::arg("y"), py::arg("floor"), py::arg("spacing"), py::arg("h"),
        py::arg("min_neighbors") = 3,
        R"doc(The surge front of a 2D dam break, m, as `sph validate` measures it: the largest x among the
particles on the floor (y below floor + 2 spacing) with at least min_neighbors others within h,
plus half a spacing. NaN when no particle qualifies.)doc");
  m.def("martin_moyce_1952", &martin_moyce_points,
        "Martin & Moyce's (1952) measured front, an array of (T, Z) rows: Z = x / a at T = t sqrt(2 g / a) "
        "(the first row the initial state T = 0, Z = 1).");
  m.def(
      "martin_moyce_time",
      [](double t, double g, double a) {
        if (!(g > 0) || !std::isfinite(g))
          throw py::value_error("g must be the positive magnitude of gravity (m/s^2), got " +
                                py::cast<std::string>(py::repr(py::float_(g))));
        if (!(a > 0) || !std::isfinite(a))
          throw py::value_error("a must be the column's positive base width (m), got " +
                                py::cast<std::string>(py::repr(py::float_(a))));
        return martin_moyce_time(t, g, a);
      },
      py::arg("t"), py::arg("g"), py::arg("a") = kMartinMoyceA,
      "The experiment's scaled time T = t sqrt(2 g / a) of t in s (a: the column's base width, m).");
  m.attr("MARTIN_MOYCE_A") = kMartinMoyceA;
  m.def("run", &run_scene, py::arg("scene"), py::kw_only(), py::arg("output"), py::arg("neighbors") = py::none(),
        py::arg("steps") = py::none(), py::arg("threads") = py::none(), py::arg("checkpoint_every") = 0,
        py::arg("strict") = false, py::arg("overwrite") = false, py::arg("progress") = py::none(),
        R"doc(Runs the scene into the directory `output`, as `sph run SCENE -o OUTPUT` does (frames, stats.csv,
summary.json, scene.json; checkpoints every `checkpoint_every` steps).

neighbors and steps override Configuration.neighbors and numberOfSteps (as --neighbors, --steps);
threads as --threads; strict: health warnings fail the run; overwrite: start even where an
unfinished run's checkpoint is (as --overwrite). progress: True (a line on stderr every 10 %),
or a callable progress(steps_done, steps). Returns {"status", "message", "steps",
"wall_seconds", "frames", "warnings", "output"}. Ctrl-C stops the run after its step with a
checkpoint (continue it with `sph run --resume OUTPUT`), then raises KeyboardInterrupt. A failed
run raises sph.SimulationError (the frames before the failure are kept).)doc");
  m.def("compare", &compare_scene, py::arg("scene"), py::kw_only(), py::arg("output") = py::none(),
        py::arg("modes") = py::none(), py::arg("steps") = py::none(), py::arg("threads") = py::none(),
        py::arg("frames") = 3, py::arg("perturbation") = 1e-9, py::arg("audit") = true, py::arg("run_frames") = true,
        py::arg("progress") = py::none(),
        R"doc(Runs the neighbor modes on the scene and compares them, as `sph compare` does.

modes: names of sph.NEIGHBOR_MODES that are compared (default: all but brute_force, as sph
compare; standard, the reference, is always run); output: the report's directory (report.md, CSVs, images and, with
run_frames, each mode's frames), or None for no files; frames, perturbation (of h: the chaos
floor) and audit as the flags. progress: True, or a callable progress(label, index, count,
steps_done, steps), called at every twentieth of each run's steps and at its last.
"speedup": the mean seconds of the standard runs (the reference and the perturbed one)
divided by this run's. Returns {"scene", "steps", "threads", "audited", "runs": [{"label", "mode",
"perturbed", "seconds", "speedup", "steps", "missed_pairs", "boundary_missed_pairs" (fluid-boundary
pairs, 0 without boundary particles), "final_rms_divergence", "failure"}], "output", "report"}.)doc");
  m.def("read_frame", &read_frame_dict, py::arg("path"),
        R"doc(Reads a frame file written by sph (.vtu, .vtk, .ply) into a dict of arrays: "time" (s),
"position" (particles, 3; z = 0 in 2D, float64) and each point field the file holds, by its
name (velocity (particles, 3), density, pressure, id (uint64), initial_position); a run's
boundary.vtu gives the boundary samples' "position", "id" and "psi". Raises sph.Error naming
the file for anything else.)doc");
}

}  // namespace sph::python
