// sph.Scene, sph.load_scene: the strict scene reader, from a file, a dict or JSON text.

#include <string>
#include <utility>
#include <vector>

#include <pybind11/stl.h>

#include <sph/scene/scene_reader.h>
#include <sph/scene/scene_writer.h>

#include "module.h"

namespace sph::python {

namespace {

/// Python's json.dumps of `value`, refusing NaN and infinities (JSON has none; the SceneError's
/// location is `where`) and writing NumPy scalars and arrays as the numbers and lists they hold.
std::string json_text(const py::handle& value, const std::string& where = {}) {
  const py::object json = py::module_::import("json");
  const py::cpp_function plain([](const py::object& o) -> py::object {
    if (py::hasattr(o, "tolist")) return o.attr("tolist")();
    throw py::type_error("a scene value must be a dict, list, str, number, bool or None, got " +
                         std::string(py::str(py::type::of(o).attr("__name__"))));
  });
  try {
    return py::cast<std::string>(json.attr("dumps")(value, py::arg("allow_nan") = false, py::arg("default") = plain));
  } catch (py::error_already_set& e) {
    if (!e.matches(PyExc_ValueError)) throw;
    throw SceneError(Error("a scene value is NaN or infinite, which JSON cannot hold; expected finite numbers", where));
  }
}

/// The scene read from `text` (named `source` in messages) with `overrides`, or a SceneError.
SceneDesc parse(const std::string& text, const std::string& source, const std::vector<std::string>& overrides) {
  return reading_scene([&] { return parse_scene(text, source, overrides, OverrideNaming::Python); });
}

py::object scene_dict(const SceneDesc& desc) { return py::module_::import("json").attr("loads")(scene_text(desc)); }

}  // namespace

std::vector<std::string> override_strings(const py::handle& overrides, const std::string& source) {
  std::vector<std::string> sets;
  if (overrides.is_none()) return sets;
  if (!py::isinstance<py::dict>(overrides))
    throw py::type_error("overrides must be a dict of {\"Key.path\": value}, e.g. {\"Fluid.stiffness\": 2000}");
  for (const auto& [key, value] : py::reinterpret_borrow<py::dict>(overrides)) {
    if (!py::isinstance<py::str>(key))
      throw py::type_error("an override's key must be a key path string such as \"Fluid.stiffness\"");
    const auto path = py::cast<std::string>(key);
    // (a value JSON cannot hold is named as the reader names an override's: SOURCE (overrides["KEY"]): KEY)
    sets.push_back(path + "=" + json_text(value, source + " (overrides[\"" + path + "\"]): " + path));
  }
  return sets;
}

SceneDesc with_overrides(const SceneDesc& desc, const std::vector<std::string>& overrides) {
  if (overrides.empty()) return desc;
  return parse(scene_text(desc), desc.source, overrides);
}

void register_scene(py::module_& m) {
  py::class_<Scene>(m, "Scene", R"doc(A scene accepted by the strict scene reader (docs/scene-format.md).

Made by sph.load_scene(path), Scene.from_dict(d) or Scene.from_json(text); each refuses a bad
key or value with sph.SceneError, whose `where` names the key path, with the messages of
`sph run`. A Scene is immutable: with_overrides() returns a new one.)doc")
      .def_static(
          "from_dict",
          [](const py::dict& d, const py::object& overrides) {
            return Scene{parse(json_text(d), "<dict>", override_strings(overrides, "<dict>"))};
          },
          py::arg("d"), py::arg("overrides") = py::none(),
          R"doc(The scene described by the dict `d` (the JSON of a scene file as Python values).

overrides: {"Key.path": value} applied first, as `sph run --set Key.path=value` does.
Raises sph.SceneError (key path in `where`) for anything the reader refuses.)doc")
      .def_static(
          "from_json",
          [](const std::string& text, const std::string& source, const py::object& overrides) {
            return Scene{parse(text, source, override_strings(overrides, source))};
          },
          py::arg("text"), py::arg("source") = "<string>", py::arg("overrides") = py::none(),
          R"doc(The scene in the JSON text `text`; `source` names it in messages.)doc")
      .def(
          "with_overrides",
          [](const Scene& s, const py::dict& overrides) {
            return Scene{with_overrides(s.desc, override_strings(overrides, s.desc.source))};
          },
          py::arg("overrides"),
          R"doc(A new scene: this one with {"Key.path": value} overrides, read again by the strict reader.)doc")
      .def(
          "to_dict", [](const Scene& s) { return scene_dict(s.desc); },
          "Every key of the scene as the reader resolved it (defaults written out), as Python values.")
      .def(
          "to_json", [](const Scene& s) { return scene_text(s.desc); },
          "The scene as JSON text (what a run's scene.json holds).")
      .def_property_readonly(
          "name", [](const Scene& s) { return s.desc.name; }, "The scene's name.")
      .def_property_readonly(
          "source", [](const Scene& s) { return s.desc.source; },
          "Where it was read from: the file, \"<dict>\" (from_dict), or from_json's `source` (\"<string>\" by "
          "default).")
      .def_property_readonly(
          "dimension", [](const Scene& s) { return s.desc.dimension; }, "2 or 3.")
      .def_property_readonly(
          "precision", [](const Scene& s) { return s.desc.precision == Precision::Float ? "float" : "double"; },
          "\"float\" or \"double\" (Configuration.precision): the dtype of the simulation's arrays.")
      .def_property_readonly(
          "steps", [](const Scene& s) { return s.desc.steps; }, "Configuration.numberOfSteps.")
      .def_property_readonly(
          "warnings", [](const Scene& s) { return s.desc.warnings; },
          "The reader's warnings (e.g. a time step close to its limit), as sph run prints them.")
      .def(
          "__eq__",
          [](const Scene& a, const py::object& other) -> py::object {
            if (!py::isinstance<Scene>(other)) return py::reinterpret_borrow<py::object>(py::handle(Py_NotImplemented));
            // Where each was read from aside (Scene.from_dict(s.to_dict()) == s): the same run.
            SceneDesc x = a.desc, y = other.cast<const Scene&>().desc;
            x.source.clear(), y.source.clear();
            return py::bool_(x == y);
          },
          "Equal when the two scenes run the same way, wherever each was read from; False for other objects.")
      .def("__repr__", [](const Scene& s) {
        return "<sph.Scene " + s.desc.name + " (" + std::to_string(s.desc.dimension) + "D, " +
               std::to_string(s.desc.steps) + " steps) from " + s.desc.source + ">";
      });

  m.def(
      "load_scene",
      [](const py::object& path_obj, const py::object& overrides) {
        const std::string path = path_arg(path_obj, "path");
        const std::vector<std::string> sets = override_strings(overrides, path);
        return Scene{reading_scene([&] { return read_scene_file(path, sets, OverrideNaming::Python); })};
      },
      py::arg("path"), py::arg("overrides") = py::none(),
      R"doc(Reads the scene file `path` with the strict reader of `sph run`.

overrides: {"Key.path": value}, as `sph run --set Key.path=value` (values are written as JSON).
Raises sph.SceneError naming the file, line and column (syntax) or the key path (`where`).)doc");
}

}  // namespace sph::python
