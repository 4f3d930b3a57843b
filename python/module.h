#pragma once
/// \file What the parts of the Python module share: its exception types, the scene it wraps,
/// and the conversions every part uses. The module (module.cpp) is an edge of the house: every
/// function it offers calls the library's public API.

#include <cstdint>
#include <string>
#include <vector>

#include <pybind11/pybind11.h>

#include <sph/core/error.h>
#include <sph/scene/scene_desc.h>

namespace sph::python {

namespace py = pybind11;

/// A scene the reader refused (a bad key, value or file): raised as sph.SceneError.
class SceneError : public Error {
 public:
  using Error::Error;
  explicit SceneError(const Error& e) : Error(e.message(), e.where()) {}
};

/// A step that failed (a blow-up, a failed health check): raised as sph.SimulationError.
class SimulationError : public Error {
 public:
  using Error::Error;
  explicit SimulationError(const Error& e) : Error(e.message(), e.where()) {}
};

/// The Python types of the module's errors and warnings (set by module.cpp before anything runs).
struct ErrorTypes {
  py::object error, scene_error, simulation_error, health_warning;
};
ErrorTypes& error_types();

/// A scene as the strict reader accepted it (sph.Scene).
struct Scene {
  SceneDesc desc;
};

/// Calls `f` and turns the sph::Error it throws into a SceneError (the scene reader's errors).
template <class F>
decltype(auto) reading_scene(F&& f) {
  try {
    return f();
  } catch (const SceneError&) {
    throw;
  } catch (const Error& e) {
    throw SceneError(e);
  }
}

/// "KEY=VALUE" overrides (the --set flag's form) from a {key path: value} dict; each value is
/// written as JSON. Raises TypeError for a key that is not a string or a value of a type JSON
/// cannot hold, SceneError naming the override (`source` the scene's) for NaN or an infinity.
std::vector<std::string> override_strings(const py::handle& overrides, const std::string& source);

/// `desc` read again with `overrides` applied (the way sph run applies --set and its flags), so
/// that every value goes through the reader's checks. Throws SceneError.
SceneDesc with_overrides(const SceneDesc& desc, const std::vector<std::string>& overrides);

/// A keyword argument's whole number (anything with __index__: an int, a NumPy integer; not a
/// bool, Python's or NumPy's), from `lo` to `hi`: TypeError or
/// ValueError naming `name` and what is expected otherwise (pybind11's own cast says only "Unable
/// to cast Python instance to C++ type").
std::int64_t whole_number_arg(const py::handle& value, const char* name, std::int64_t lo, std::int64_t hi);

/// A keyword argument's real number (an int or float, Python's or NumPy's; not a bool:
/// pybind11's double would take True as 1.0): TypeError naming `name` and the type otherwise. The caller checks its
/// range.
double real_arg(const py::handle& value, const char* name);

/// The overrides that run()'s, compare()'s and Simulation()'s keyword arguments stand for, as
/// `sph run`'s flags stand for --set values: `neighbors` (None or a mode's name; TypeError
/// otherwise) and `steps` (None or a whole number of steps).
std::vector<std::string> run_overrides(const py::object& neighbors, const py::object& steps);

/// The threads a call asks for: its `threads` argument (a whole number from 1 to 4096), or for
/// None default_thread_count().
int thread_count_arg(const py::handle& threads);
/// The parallel loops' thread count when the module was loaded: all the cores, or OMP_NUM_THREADS.
int& default_thread_count();

/// A keyword argument's list of names (a list or tuple of str; a single str is refused, as
/// iterating it would give its letters): TypeError naming `name` otherwise.
std::vector<std::string> names_arg(const py::handle& value, const char* name);

/// A keyword argument's path: a str or an os.PathLike (pathlib.Path): TypeError naming `name`
/// otherwise.
std::string path_arg(const py::handle& value, const char* name);

/// Sets the worker threads of the calling thread's parallel loops; `threads` must be positive.
void use_threads(int threads);

/// Registers the parts of the module.
void register_scene(py::module_& m);
void register_simulation(py::module_& m);
void register_runs(py::module_& m);

}  // namespace sph::python
