// The Python module `sph` (docs/python.md): scenes, simulations stepped from Python with their
// particle fields as NumPy arrays, runs, comparisons and frames, through the library's API.

#include <exception>
#include <string>

#include <pybind11/stl.h>
#include <nlohmann/json.hpp>

#include <sph/core/parallel.h>
#include <sph/core/particle_fields.h>
#include <sph/core/version.h>
#include <sph/io/run_output.h>
#include <sph/neighbors/neighbor_mode.h>
#include <sph/scene/frame_formats.h>

#include "module.h"

namespace sph::python {

ErrorTypes& error_types() {
  static ErrorTypes* types = new ErrorTypes();  // (never destroyed: Python may outlive static destructors)
  return *types;
}

void use_threads(int threads) { set_num_threads(threads); }

namespace {

/// A bool: Python's, or NumPy's (which is no int subclass).
bool is_bool(const py::handle& value) {
  return py::isinstance<py::bool_>(value) ||
         py::str(py::type::of(value).attr("__name__")).cast<std::string>() == "bool_";
}

/// `value`'s type's name, for a message that says why it was refused ("got 1.5 (float)").
std::string value_and_type(const py::handle& value) {
  return py::cast<std::string>(py::repr(value)) + " (" +
         py::str(py::type::of(value).attr("__name__")).cast<std::string>() + ")";
}

}  // namespace

std::int64_t whole_number_arg(const py::handle& value, const char* name, std::int64_t lo, std::int64_t hi) {
  const std::string expected =
      std::string(name) + " must be a whole number from " + std::to_string(lo) + " to " + std::to_string(hi) + ", got ";
  // Anything with __index__ (int, numpy.int64, ...) but a bool.
  if (is_bool(value) || !PyIndex_Check(value.ptr())) throw py::type_error(expected + value_and_type(value));
  const py::int_ number = py::reinterpret_steal<py::int_>(PyNumber_Index(value.ptr()));
  if (!number) throw py::error_already_set();
  // (a Python int of any size: compared as a Python object before any conversion)
  if (number < py::int_(lo) || number > py::int_(hi))
    throw py::value_error(expected + py::cast<std::string>(py::repr(value)));
  return py::cast<std::int64_t>(number);
}

double real_arg(const py::handle& value, const char* name) {
  // Python's and NumPy's numbers (anything with __float__ or __index__) but a bool.
  const bool number = PyFloat_Check(value.ptr()) || PyIndex_Check(value.ptr()) ||
                      (Py_TYPE(value.ptr())->tp_as_number && Py_TYPE(value.ptr())->tp_as_number->nb_float);
  if (is_bool(value) || !number || PyUnicode_Check(value.ptr()))
    throw py::type_error(std::string(name) + " must be a number, got " + value_and_type(value));
  const double x = PyFloat_AsDouble(value.ptr());
  if (x == -1.0 && PyErr_Occurred()) throw py::error_already_set();
  return x;
}

std::vector<std::string> run_overrides(const py::object& neighbors, const py::object& steps) {
  std::vector<std::string> sets;
  if (!neighbors.is_none()) {
    if (!py::isinstance<py::str>(neighbors))
      throw py::type_error("neighbors must be a mode name: " +
                           join_neighbor_mode_names(NeighborModeSet::All, ", ", " or "));
    // (JSON-encoded, as the overrides are: a quote or backslash in the name stays part of it)
    sets.push_back("Configuration.neighbors=" + nlohmann::json(py::cast<std::string>(neighbors)).dump());
  }
  if (!steps.is_none())
    sets.push_back("Configuration.numberOfSteps=" +
                   std::to_string(whole_number_arg(steps, "steps", 1, std::int64_t{1'000'000'000'000})));
  return sets;
}

int& default_thread_count() {
  static int threads = 0;
  return threads;
}

int thread_count_arg(const py::handle& threads) {
  if (threads.is_none()) return default_thread_count();
  return static_cast<int>(whole_number_arg(threads, "threads", 1, 4096));
}

std::vector<std::string> names_arg(const py::handle& value, const char* name) {
  const std::string expected = std::string(name) + " must be a list of names (str)";
  if (!py::isinstance<py::list>(value) && !py::isinstance<py::tuple>(value))
    throw py::type_error(expected + ", got " + py::cast<std::string>(py::repr(value)));
  std::vector<std::string> out;
  for (const py::handle item : value) {
    if (!py::isinstance<py::str>(item))
      throw py::type_error(expected + ", got an item " + py::cast<std::string>(py::repr(item)));
    out.push_back(py::cast<std::string>(item));
  }
  return out;
}

std::string path_arg(const py::handle& value, const char* name) {
  if (py::isinstance<py::str>(value)) return py::cast<std::string>(value);
  const py::object os = py::module_::import("os");
  if (py::isinstance(value, os.attr("PathLike"))) return py::cast<std::string>(os.attr("fspath")(value));
  throw py::type_error(std::string(name) + " must be a path (str or os.PathLike), got " +
                       py::cast<std::string>(py::repr(value)));
}

namespace {

/// A new exception type sph.NAME with `bases` (a type or a tuple of types), added to the module.
py::object new_exception(py::module_& m, const char* name, const char* doc, const py::handle& bases) {
  const std::string full = std::string("sph.") + name;
  PyObject* type = PyErr_NewExceptionWithDoc(full.c_str(), doc, bases.ptr(), nullptr);
  if (!type) throw py::error_already_set();
  py::object t = py::reinterpret_steal<py::object>(type);
  m.attr(name) = t;
  return t;
}

/// Raises `type` with the error's text, and its message and location (and `key`, if given) as attributes.
void raise_as(const py::object& type, const Error& e, const py::object& key = {}) {
  py::object exc = type(e.what());
  exc.attr("message") = e.message();
  exc.attr("where") = e.where();
  if (key) exc.attr("key") = key;
  PyErr_SetObject(type.ptr(), exc.ptr());
}

/// The key path a scene error's location names: "SOURCE (overrides[\"K\"]): PATH" or "SOURCE: PATH" ->
/// PATH; None for an error of the whole file (or of its syntax: "SOURCE:LINE:COL").
py::object scene_key(const Error& e) {
  const std::string& where = e.where();
  const std::size_t colon = where.rfind(": ");
  if (colon == std::string::npos) return py::none();
  return py::str(where.substr(colon + 2));
}

}  // namespace

}  // namespace sph::python

PYBIND11_MODULE(sph, m) {
  namespace py = pybind11;
  using namespace sph::python;
  m.doc() = R"doc(sph: the SPH fluid simulator (adaptive neighbor pairing) from Python.

    scene = sph.load_scene("scenes/paper/dam_break_2d.json", overrides={"Configuration.numberOfSteps": 100})
    sim = sph.Simulation(scene, neighbors="adaptive", threads=2)
    sim.step(10)
    x = sim.positions          # (particles, 2) read-only view, no copy
    sim.counters["pairs_stored"]

See docs/python.md for the API and a tutorial.)doc";
  m.attr("__version__") = sph::kVersion;
  // All the cores (or OMP_NUM_THREADS), read once: the parallel loops' thread count is the last
  // call's afterwards, and a later call's default would be that.
  sph::python::default_thread_count() = sph::num_threads();

  ErrorTypes& t = error_types();
  t.error = new_exception(m, "Error",
                          "An error the input caused (a scene, a path, an option): `message` is the text without its "
                          "location, `where` the location (file, key path or option).",
                          PyExc_RuntimeError);
  t.scene_error = new_exception(m, "SceneError",
                                "A scene the strict reader refused: `where` names the source and the key path, `key` "
                                "the key path alone (None for an error of the whole file).",
                                py::make_tuple(t.error, py::handle(PyExc_ValueError)));
  t.simulation_error = new_exception(m, "SimulationError",
                                     "A step failed: the simulation blew up or a health check failed (the message "
                                     "names the step, the particle and what to change).",
                                     t.error);
  PyObject* warning = PyErr_NewExceptionWithDoc("sph.HealthWarning",
                                                "A health warning of a step (docs/reliability.md, \"Health monitor\").",
                                                PyExc_UserWarning, nullptr);
  if (!warning) throw py::error_already_set();
  t.health_warning = py::reinterpret_steal<py::object>(warning);
  m.attr("HealthWarning") = t.health_warning;

  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const SceneError& e) {
      raise_as(error_types().scene_error, e, scene_key(e));
    } catch (const SimulationError& e) {
      raise_as(error_types().simulation_error, e);
    } catch (const sph::Error& e) {
      raise_as(error_types().error, e);
    }
  });

  // The vocabularies, from their tables.
  py::list modes, fields, formats, columns;
  for (const sph::NeighborModeInfo& info : sph::kNeighborModes) modes.append(py::str(std::string(info.name)));
  for (const sph::FieldDesc& f : sph::kParticleFields) fields.append(py::str(std::string(f.name)));
  for (const sph::FrameFormatDesc& f : sph::kFrameFormats) formats.append(py::str(std::string(f.name)));
  for (const sph::StatsColumn& c : sph::kStatsColumns) columns.append(py::str(std::string(c.name)));
  m.attr("NEIGHBOR_MODES") = py::tuple(modes);
  m.attr("FIELDS") = py::tuple(fields);
  m.attr("FRAME_FORMATS") = py::tuple(formats);
  m.attr("STATS_COLUMNS") = py::tuple(columns);

  register_scene(m);
  register_simulation(m);
  register_runs(m);
}
