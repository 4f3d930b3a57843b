// sph.Simulation: a scene's simulation stepped from Python, its particle fields as NumPy views.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <sph/core/parallel.h>
#include <sph/core/particle_fields.h>
#include <sph/io/frame_format.h>
#include <sph/io/run_output.h>
#include <sph/neighbors/neighbor_mode.h>
#include <sph/run/driver.h>
#include <sph/scene/dispatch.h>
#include <sph/surface/surface.h>

#include "module.h"

namespace sph::python {

namespace {

/// The memory of the views of one field once the simulation has let go of it: the arrays the
/// views are have this object as their base, so it lives as long as any of them.
struct ViewMemory {
  std::shared_ptr<void> owned;  ///< empty while the memory is still the simulation's
};

/// A field's name in the plural, the name of its Simulation property: "position" ->
/// "positions", "velocity" -> "velocities", "mass" -> "masses".
std::string plural(std::string_view name) {
  std::string s(name);
  if (s.ends_with("y")) return s.substr(0, s.size() - 1) + "ies";
  if (s.ends_with("s")) return s + "es";
  return s + "s";
}

/// The dimension and precision of a RunDriver type.
template <class T>
struct DriverTraits;
template <int D, std::floating_point R>
struct DriverTraits<RunDriver<D, R>> {
  static constexpr int kDim = D;
  using Real = R;
};

template <class C>
using ElementOf = typename std::decay_t<C>::value_type;

template <class E>
inline constexpr bool kIsVec = !std::is_arithmetic_v<E>;

class PySimulation {
 public:
  PySimulation(const Scene& scene, const py::object& neighbors, const py::object& threads) {
    SceneDesc desc = with_overrides(scene.desc, run_overrides(neighbors, py::none()));
    threads_ = thread_count_arg(threads);
    py::gil_scoped_release release;
    use_threads(threads_);
    dispatch(desc, [&]<int D, class R>() {
      RunSettings settings;
      settings.every_field = true;  // (every field a view)
      driver_ = std::make_unique<RunDriver<D, R>>(std::move(desc), std::move(settings));
    });
  }
  ~PySimulation() { detach_views(); }
  PySimulation(const PySimulation&) = delete;
  PySimulation& operator=(const PySimulation&) = delete;

  /// Calls f(driver) with the driver of the scene's dimension and precision. Refused (RuntimeError)
  /// while another Python thread steps the simulation or writes its frame with the GIL released.
  template <class F>
  decltype(auto) visit(F&& f) {
    check_idle();
    return std::visit([&](auto& d) -> decltype(auto) { return f(*d); }, driver_);
  }
  template <class F>
  decltype(auto) visit(F&& f) const {
    check_idle();
    return std::visit([&](const auto& d) -> decltype(auto) { return f(*d); }, driver_);
  }

  void step(std::int64_t n) {
    if (n < 0) throw py::value_error("n must be 0 or more steps, got " + std::to_string(n));
    for (std::int64_t k = 0; k < n; ++k) {
      check_idle();
      if (!failure_.empty())
        throw SimulationError("the simulation failed earlier (" + failure_ +
                              "); its state is that of the failed step: make a new Simulation");
      detach_views();
      std::vector<std::string> warnings;
      std::optional<Error> failed;
      {
        const Busy busy(busy_);  // (reset after the GIL is taken back)
        py::gil_scoped_release release;
        use_threads(threads_);
        try {
          std::visit([&](auto& d) { warnings = d->new_warnings(d->step()); }, driver_);
        } catch (const Error& e) {
          failed = e;
        }
      }
      if (failed) {
        failure_ = failed->what();
        throw SimulationError(*failed);
      }
      for (const std::string& w : warnings)
        if (PyErr_WarnEx(error_types().health_warning.ptr(), w.c_str(), 1) != 0) throw py::error_already_set();
      // Ctrl-C during the step: Python's handler runs now, between steps (KeyboardInterrupt).
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    }
  }

  /// A read-only array over the field `name` (built-in or added), without a copy.
  py::array field(const std::string& name) {
    std::optional<py::array> out;
    visit([&](auto& d) {
      using Traits = DriverTraits<std::decay_t<decltype(d)>>;
      using R = typename Traits::Real;
      d.simulation().particles().for_each_field([&](const FieldDesc& desc, const auto& column) {
        if (desc.name != name || out) return;
        using E = ElementOf<decltype(column)>;
        const py::object& base = view_memory(name);
        const auto n = static_cast<py::ssize_t>(column.size());
        py::array a;
        if constexpr (kIsVec<E>) {
          static_assert(sizeof(E) == Traits::kDim * sizeof(R), "Vec<D, R> is D packed reals");
          a = py::array(py::dtype::of<R>(), {n, static_cast<py::ssize_t>(Traits::kDim)},
                        {static_cast<py::ssize_t>(sizeof(E)), static_cast<py::ssize_t>(sizeof(R))},
                        static_cast<const void*>(column.data()), base);
        } else {
          a = py::array(py::dtype::of<E>(), {n}, {static_cast<py::ssize_t>(sizeof(E))},
                        static_cast<const void*>(column.data()), base);
        }
        a.attr("setflags")(py::arg("write") = false);
        out = std::move(a);
      });
    });
    if (!out) throw py::key_error("no particle field \"" + name + "\"; the fields are " + field_list());
    return *out;
  }

  std::vector<std::string> field_names() const {
    std::vector<std::string> names;
    visit([&](const auto& d) {
      d.simulation().particles().for_each_field(
          [&](const FieldDesc& desc, const auto&) { names.emplace_back(desc.name); });
    });
    return names;
  }

  /// Replaces the vector field `name` (positions or velocities) with `value`, checked: a NumPy
  /// array (or what numpy.asarray makes of it) of shape (particles, dimension), of a floating
  /// dtype no wider than the scene's precision, every value finite.
  void set_vectors(const std::string& name, const py::handle& value) {
    const py::array a = py::module_::import("numpy").attr("asarray")(value);
    visit([&](auto& d) {
      using Traits = DriverTraits<std::decay_t<decltype(d)>>;
      using R = typename Traits::Real;
      constexpr int kDim = Traits::kDim;
      const std::string what = "Simulation." + plural(name);
      const char kind = a.dtype().kind();
      if (kind != 'f' || a.dtype().itemsize() > static_cast<py::ssize_t>(sizeof(R)) || a.dtype().itemsize() < 4)
        throw py::type_error(what + " takes an array of dtype " +
                             (std::is_same_v<R, float> ? std::string("float32 (the scene's precision is float)")
                                                       : std::string("float64 or float32")) +
                             ", got dtype " + py::cast<std::string>(py::str(a.dtype())) +
                             (std::is_same_v<R, float> ? "; convert with a.astype(numpy.float32)" : ""));
      const std::size_t n = d.simulation().particles().size();
      if (a.ndim() != 2 || a.shape(0) != static_cast<py::ssize_t>(n) || a.shape(1) != kDim)
        throw py::value_error(what + " takes an array of shape (" + std::to_string(n) + ", " + std::to_string(kDim) +
                              ") (particles, dimension), got shape " + py::cast<std::string>(py::str(a.attr("shape"))));
      const auto values = py::array_t<R, py::array::c_style | py::array::forcecast>::ensure(a);
      if (!values) throw py::error_already_set();
      const R* v = values.data();
      for (std::size_t i = 0; i < n * kDim; ++i)
        if (!std::isfinite(v[i]))
          throw py::value_error(what + " takes finite values; [" + std::to_string(i / kDim) + ", " +
                                std::to_string(i % kDim) + "] is " + (std::isnan(v[i]) ? "nan" : "infinite"));
      detach_views(name);
      d.simulation().edit_particles().for_each_field([&](const FieldDesc& desc, auto& column) {
        using E = ElementOf<decltype(column)>;
        if constexpr (kIsVec<E>) {
          if (desc.name != name) return;
          for (std::size_t i = 0; i < n; ++i)
            for (int c = 0; c < kDim; ++c) column[i][c] = v[i * kDim + static_cast<std::size_t>(c)];
        }
      });
      d.simulation().particles_moved();
    });
  }

  /// Particle i's neighbor list of the last step (indices into the particle arrays).
  py::array_t<std::uint32_t> neighbors_of(std::int64_t i) const {
    return visit([&](const auto& d) {
      const NeighborLists& lists = checked_lists(d);
      if (i < 0 || static_cast<std::size_t>(i) >= lists.particle_count())
        throw py::index_error("particle " + std::to_string(i) + " out of range: the lists hold " +
                              std::to_string(lists.particle_count()) + " particles");
      const std::span<const std::uint32_t> l = lists.of(static_cast<std::size_t>(i));
      py::array_t<std::uint32_t> out(static_cast<py::ssize_t>(l.size()));
      std::copy(l.begin(), l.end(), out.mutable_data());
      return out;
    });
  }

  /// Every list of the last step: offsets (particles + 1) and the indices they delimit.
  py::tuple neighbor_lists() const {
    return visit([&](const auto& d) {
      const NeighborLists& lists = checked_lists(d);
      const std::size_t n = lists.particle_count();
      py::array_t<std::int64_t> offsets(static_cast<py::ssize_t>(n + 1));
      py::array_t<std::uint32_t> indices(static_cast<py::ssize_t>(lists.entry_count()));
      std::int64_t* o = offsets.mutable_data();
      std::uint32_t* x = indices.mutable_data();
      o[0] = 0;
      for (std::size_t i = 0; i < n; ++i) {
        const std::span<const std::uint32_t> l = lists.of(i);
        std::copy(l.begin(), l.end(), x + o[i]);
        o[i + 1] = o[i] + static_cast<std::int64_t>(l.size());
      }
      return py::make_tuple(offsets, indices);
    });
  }

  /// The last step's stats.csv row as {column: value} (empty before the first step).
  py::dict counters() const {
    py::dict out;
    visit([&](const auto& d) {
      const auto& sim = d.simulation();
      if (sim.steps_done() == 0) return;
      const StepStats stats{sim.last_step(), sim.kinetic_energy(), sim.max_speed(), 0.0};
      for (const StatsColumn& c : kStatsColumns) {
        const py::str key(std::string(c.name));
        if (c.audit_only && !stats.info.audited)
          out[key] = py::none();
        else if (c.format == StatsFormat::Count)
          out[key] = c.count(stats);
        else
          out[key] = c.real(stats);
      }
    });
    return out;
  }

  void write_frame(const py::object& path_obj, const py::object& fields) const {
    const std::string path = path_arg(path_obj, "path");
    const std::string ext = std::filesystem::path(path).extension().string();
    const std::optional<FrameFormat> format = parse_frame_format(ext.empty() ? ext : ext.substr(1));
    if (!format)
      throw Error("expected a frame file name ending in " + frame_format_list("", " or ", false, ".") +
                      " (the format comes from the extension)",
                  path);
    FrameFields selected;
    if (!fields.is_none()) {
      const auto names = names_arg(fields, "fields");
      const std::vector<std::string> known = field_names();
      for (const std::string& f : names) {
        const FieldDesc* desc = find_particle_field(f);
        if ((desc && !desc->in_frames) || (!desc && std::find(known.begin(), known.end(), f) == known.end()))
          throw Error("\"" + f + "\" is not a field frames hold; expected some of " + frame_field_list(" or "),
                      "fields");
      }
      selected = FrameFields::only(names);
    }
    visit([&](const auto& d) {
      const auto& sim = d.simulation();
      const Busy busy(busy_);
      py::gil_scoped_release release;
      sph::write_frame(*format, path, sim.particles(), sim.time(), selected);
    });
  }

  /// The free surface now (RunDriver::surface): {"vertices": (n, 3) float32, "normals": (n, 3)
  /// float32 (3D; (0, 3) in 2D), "triangles": (m, 3) uint32 (3D) or "segments": (m, 2) uint32
  /// (2D), "voxel_size": float}.
  py::dict surface(const py::object& resolution, const py::object& smoothing, const py::object& iso) const {
    SurfaceSettings settings;
    settings.resolution = real_arg(resolution, "resolution");
    settings.smoothing = real_arg(smoothing, "smoothing");
    settings.iso = real_arg(iso, "iso");
    settings.spacing = 1;  // (the scene's, set by RunDriver::surface: here only the three are checked)
    if (const std::string e = surface_settings_error(settings); !e.empty()) throw py::value_error(e);
    SurfaceMesh mesh;
    visit([&](const auto& d) {
      const Busy busy(busy_);
      py::gil_scoped_release release;
      use_threads(threads_);
      mesh = d.surface(settings);
    });
    const auto rows = [](const auto& v, auto zero) {
      constexpr std::size_t kCols = std::tuple_size_v<std::decay_t<decltype(v[0])>>;
      py::array_t<decltype(zero)> a({static_cast<py::ssize_t>(v.size()), static_cast<py::ssize_t>(kCols)});
      if (!v.empty()) std::memcpy(a.mutable_data(), v.data(), v.size() * sizeof(v[0]));
      return a;
    };
    py::dict out;
    out["vertices"] = rows(mesh.vertices, 0.0f);
    out["normals"] = rows(mesh.normals, 0.0f);
    if (mesh.dimension == 3)
      out["triangles"] = rows(mesh.triangles, std::uint32_t{0});
    else
      out["segments"] = rows(mesh.segments, std::uint32_t{0});
    out["voxel_size"] = mesh.voxel_size;
    return out;
  }

  Scene scene() const {
    return visit([](const auto& d) { return Scene{d.scene()}; });
  }
  int threads() const { return threads_; }
  void set_threads(const py::object& n) { threads_ = static_cast<int>(whole_number_arg(n, "threads", 1, 4096)); }

 private:
  /// Marks the simulation busy for its life (with the GIL held when it starts and ends).
  class Busy {
   public:
    explicit Busy(bool& flag) : flag_(flag) { flag_ = true; }
    ~Busy() { flag_ = false; }
    Busy(const Busy&) = delete;
    Busy& operator=(const Busy&) = delete;

   private:
    bool& flag_;
  };

  void check_idle() const {
    if (busy_)
      throw std::runtime_error(
          "the simulation is stepping or writing a frame in another thread; use it from one thread at a time");
  }

  template <class Driver>
  const NeighborLists& checked_lists(const Driver& d) const {
    if (d.simulation().steps_done() == 0)
      throw Error("there are no neighbor lists before the first step: call step() first");
    return d.simulation().neighbors().lists();
  }

  std::string field_list() const {
    std::string s;
    for (const std::string& n : field_names()) s += (s.empty() ? "" : ", ") + n;
    return s;
  }

  /// The base object of the views of `name` over the simulation's current memory.
  const py::object& view_memory(const std::string& name) {
    for (const auto& [n, memory] : views_)
      if (n == name) return memory;
    views_.emplace_back(name, py::cast(ViewMemory{}));
    return views_.back().second;
  }

  /// Before the simulation changes a field (a step, a setter) or goes away: the views of it that
  /// are still alive get its memory as it is (moved out, the simulation goes on with a copy), so
  /// that no view ever shows memory changed or freed under it. With `only`, that field alone.
  void detach_views(const std::string& only = {}) {
    for (std::size_t k = 0; k < views_.size();) {
      const std::string& name = views_[k].first;
      const py::object& memory = views_[k].second;
      if (!only.empty() && name != only) {
        ++k;
        continue;
      }
      if (memory.ref_count() > 1) {
        visit([&](auto& d) {
          d.simulation().edit_particles().for_each_field([&](const FieldDesc& desc, auto& column) {
            if (desc.name != name) return;
            auto kept = std::make_shared<std::decay_t<decltype(column)>>(std::move(column));
            column = {};
            column.reserve(kept->capacity());  // (emitters append without allocating)
            column.assign(kept->begin(), kept->end());
            py::cast<ViewMemory&>(memory).owned = std::move(kept);
          });
        });
      }
      views_.erase(views_.begin() + static_cast<std::ptrdiff_t>(k));
    }
  }

  std::variant<std::unique_ptr<RunDriver<2, float>>, std::unique_ptr<RunDriver<2, double>>,
               std::unique_ptr<RunDriver<3, float>>, std::unique_ptr<RunDriver<3, double>>>
      driver_;
  int threads_ = 1;
  std::string failure_;        // the error of the step that failed ("" if none)
  mutable bool busy_ = false;  // stepping or writing with the GIL released (Busy)
  std::vector<std::pair<std::string, py::object>> views_;
};

}  // namespace

void register_simulation(py::module_& m) {
  const py::class_<ViewMemory> memory_type(m, "_ViewMemory",
                                           "The memory of Simulation views (internal: the base of their arrays).");

  py::class_<PySimulation> cls(m, "Simulation", R"doc(A scene's simulation, stepped from Python.

Simulation(scene, neighbors=None, threads=None): neighbors overrides Configuration.neighbors
(one of sph.NEIGHBOR_MODES), threads the worker threads of its steps (default: all cores).
Results are bitwise identical for any thread count, and to `sph run` of the same scene.

Particle fields are read-only NumPy arrays over the simulation's memory, without a copy
(positions, velocities, densities, pressures, ids, ...; field(name) for any field). The rule:
a view shows the state at the moment it was taken and never changes afterwards. A step or a
setter that would change the memory under a view still alive hands that memory to the view
(the simulation goes on with a copy), and deleting the simulation does the same, so no view
ever outlives its memory or shows data changed under it. Take a new view after each step.)doc");
  cls.def(py::init<const Scene&, const py::object&, const py::object&>(), py::arg("scene"),
          py::arg("neighbors") = py::none(), py::arg("threads") = py::none())
      .def("step", &PySimulation::step, py::arg("n") = 1, R"doc(Advances n steps (the GIL is released during each).

Health warnings are given as sph.HealthWarning. A failed step (a blow-up, a failed health
check) raises sph.SimulationError, and the simulation refuses further steps. Ctrl-C interrupts
after the current step with KeyboardInterrupt; the simulation stays usable.)doc")
      .def_property_readonly(
          "time", [](const PySimulation& s) { return s.visit([](const auto& d) { return d.simulation().time(); }); },
          "Simulated time, s.")
      .def_property_readonly(
          "particle_mass",
          [](const PySimulation& s) {
            return s.visit([](const auto& d) { return static_cast<double>(d.simulation().particles().mass); });
          },
          "Every particle's mass, kg (kg/m in 2D): one for all, the scene's Fluid.particleMass or the lattice's.")
      .def_property_readonly(
          "steps",
          [](const PySimulation& s) { return s.visit([](const auto& d) { return d.simulation().steps_done(); }); },
          "Steps done.")
      .def_property_readonly(
          "dt",
          [](const PySimulation& s) {
            return s.visit([](const auto& d) {
              const auto& sim = d.simulation();
              return sim.steps_done() > 0 && sim.last_step().dt > 0 ? sim.last_step().dt : sim.params().time_step;
            });
          },
          "The time step, s: the last step's (CFL steps vary; Configuration.timeStepSize before the first step).")
      .def_property_readonly(
          "dimension",
          [](const PySimulation& s) {
            return s.visit([](const auto& d) { return DriverTraits<std::decay_t<decltype(d)>>::kDim; });
          },
          "2 or 3.")
      .def_property_readonly(
          "dtype",
          [](const PySimulation& s) {
            return s.visit(
                [](const auto& d) { return py::dtype::of<typename DriverTraits<std::decay_t<decltype(d)>>::Real>(); });
          },
          "The dtype of the real fields: float32 or float64 (the scene's precision).")
      .def_property_readonly(
          "neighbor_mode", [](const PySimulation& s) { return s.visit([](const auto& d) { return d.info().mode; }); },
          "The neighbor mode's name.")
      .def_property("threads", &PySimulation::threads, &PySimulation::set_threads,
                    "Worker threads of the following steps.")
      .def_property_readonly("scene", &PySimulation::scene, "The simulation's scene (with its overrides).")
      .def("__len__",
           [](const PySimulation& s) {
             return s.visit([](const auto& d) { return d.simulation().particles().size(); });
           })
      .def_property_readonly(
          "particle_count",
          [](const PySimulation& s) {
            return s.visit([](const auto& d) { return d.simulation().particles().size(); });
          },
          "Particles now (emitters add more).")
      .def_property_readonly("counters", &PySimulation::counters,
                             "The last step's stats.csv row as a dict {column: value} (sph.STATS_COLUMNS; the audit "
                             "columns None unless audited, t_output 0); empty before the first step.")
      .def_property_readonly(
          "bodies",
          [](const PySimulation& s) {
            return s.visit([](const auto& d) {
              const auto& sim = d.simulation();
              constexpr int kDim = DriverTraits<std::decay_t<decltype(d)>>::kDim;
              const auto list = [](const auto& v, int n) {
                py::list l;
                for (int a = 0; a < n; ++a) l.append(v[a]);
                return l;
              };
              py::list out;
              for (std::size_t b = 0; b < sim.bodies().size(); ++b) {
                const auto& st = sim.bodies()[b];
                const auto& f = sim.body_fluid_forces()[b];
                py::dict e;
                e["obstacle"] = sim.body_obstacles()[b];
                e["mass"] = sim.body_masses()[b].mass;
                e["position"] = list(st.position, kDim);
                e["orientation"] = list(st.orientation, 4);
                e["velocity"] = list(st.velocity, kDim);
                e["angular_velocity"] = kDim == 2 ? py::object(py::float_(st.angular_velocity[2]))
                                                  : py::object(list(st.angular_velocity, 3));
                e["force"] = list(f.impulse, kDim);
                e["moment"] =
                    kDim == 2 ? py::object(py::float_(f.angular_impulse[2])) : py::object(list(f.angular_impulse, 3));
                out.append(e);
              }
              return out;
            });
          },
          "The floating bodies (Obstacles[].dynamic) now, one dict each: obstacle (its index in Obstacles), mass "
          "(kg; 2D: kg/m), position (the centre of mass, m), orientation (a unit quaternion w, x, y, z), velocity "
          "(m/s), angular_velocity (rad/s: 2D a number, 3D a list), force and moment (the fluid's, N and N m, the "
          "mean over the last step); as bodies.csv's columns.")
      .def_property_readonly(
          "warnings",
          [](const PySimulation& s) {
            return s.visit([](const auto& d) { return d.simulation().health().warnings(); });
          },
          "The health warnings given so far.")
      .def(
          "kinetic_energy",
          [](const PySimulation& s) { return s.visit([](const auto& d) { return d.simulation().kinetic_energy(); }); },
          "Total kinetic energy, J (J/m in 2D).")
      .def(
          "max_speed",
          [](const PySimulation& s) { return s.visit([](const auto& d) { return d.simulation().max_speed(); }); },
          "Largest particle speed, m/s.")
      .def("field", &PySimulation::field, py::arg("name"),
           "A read-only view of the particle field `name` (one of field_names).")
      .def_property_readonly("field_names", &PySimulation::field_names,
                             "Every particle field, in storage order (sph.FIELDS, then fields added at run time).")
      .def("neighbors", &PySimulation::neighbors_of, py::arg("i"),
           "Particle i's neighbor list of the last step (indices into the particle arrays; a copy).")
      .def("neighbor_lists", &PySimulation::neighbor_lists,
           "Every list of the last step as (offsets, indices): particle i's neighbors are "
           "indices[offsets[i]:offsets[i + 1]] (copies).")
      .def("surface", &PySimulation::surface, py::kw_only(), py::arg("resolution") = 2.0, py::arg("smoothing") = 2.0,
           py::arg("iso") = 0.5,
           R"doc(The water's free surface now, as sph run --surface meshes each frame (docs/visualization.md,
"Surfaces"): resolution voxels per particle spacing (0.5 to 8), smoothing the kernel radius in
spacings (1 to 4), iso the colour field's level (0.05 to 0.95); cut by the container's walls and
the obstacles where they are now. A dict: "vertices" (n, 3) float32, "normals" (n, 3) float32
(outward; (0, 3) in 2D), "triangles" (m, 3) uint32 (3D, counter-clockwise seen from outside) or
"segments" (m, 2) uint32 (2D, the water on their left), "voxel_size" (m). ValueError for a
setting out of range.)doc")
      .def("write_frame", &PySimulation::write_frame, py::arg("path"), py::arg("fields") = py::none(),
           "Writes the particles as one frame file, as sph run writes its frames; the format comes from the "
           "extension (.vtu, .vtk, .ply); fields: the point fields (default: all frames hold).");

  // One property per built-in field, named and documented from the field table; positions and
  // velocities can be set.
  for (const FieldDesc& f : kParticleFields) {
    const std::string name(f.name);
    const std::string doc =
        std::string(f.what) +
        (f.unit3.empty() ? "" : " (" + std::string(f.unit3) + " in 3D, " + std::string(f.unit2) + " in 2D)") +
        ": a read-only view, shape (particles" + (f.kind == FieldKind::Vector ? ", dimension)" : ")");
    const auto get = [name](PySimulation& s) { return s.field(name); };
    const bool settable = &f == &kParticleFields[field::kPosition] || &f == &kParticleFields[field::kVelocity];
    if (settable)
      cls.def_property(
          plural(f.name).c_str(), get, [name](PySimulation& s, const py::object& v) { s.set_vectors(name, v); },
          (doc + ". Settable: an array of that shape, finite, of the scene's precision (float32 is accepted by double "
                 "scenes); the next step rebuilds every neighbor list, and the state set is where the run starts from "
                 "now (densities and pressures measured again, the energy watch's reference its energy).")
              .c_str());
    else
      cls.def_property_readonly(plural(f.name).c_str(), get, doc.c_str());
  }
}

}  // namespace sph::python
