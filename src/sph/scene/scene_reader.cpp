#include <sph/scene/scene_reader.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <sph/core/error.h>
#include <sph/neighbors/neighbor_mode.h>
#include <sph/solver/time_step.h>
#include <sph/solver/wcsph.h>

namespace sph {

namespace {

using json = nlohmann::json;

/// Where values come from: the file, or --set flags for overridden key paths.
struct Context {
  std::string source;
  std::set<std::string> overridden;

  [[noreturn]] void fail(const std::string& path, const std::string& message) const {
    std::string where = source;
    auto within = [](const std::string& a, const std::string& b) {  // a is b or inside b
      return a == b || a.rfind(b + ".", 0) == 0 || a.rfind(b + "[", 0) == 0;
    };
    for (const auto& o : overridden)
      if (within(path, o) || (!path.empty() && within(o, path))) {
        where = source + " (--set " + o + ")";
        break;
      }
    if (!path.empty()) where += ": " + path;
    throw Error(message, where);
  }
};

std::string describe(const json& j) {
  // Never dump containers whole: a deeply nested value would recurse without bound.
  if (j.is_array()) return fmt::format("an array of {} element{}", j.size(), j.size() == 1 ? "" : "s");
  if (j.is_object()) return fmt::format("an object with {} key{}", j.size(), j.size() == 1 ? "" : "s");
  std::string text = j.dump();
  if (text.size() > 40) text = text.substr(0, 37) + "...";
  return std::string(j.type_name()) + " " + text;
}

/// Reads the keys of one JSON object, whose allowed keys are declared up front.
class ObjectReader {
 public:
  /// `keys` are all the keys this object may have; any other key is reported at once, before
  /// a missing-key error that a misspelt key would otherwise cause.
  ObjectReader(const json& j, std::string path, const Context& ctx, const std::vector<std::string>& keys)
      : j_(j), path_(std::move(path)), ctx_(ctx) {
    if (!j_.is_object()) ctx_.fail(path_, "expected an object { ... }, got " + describe(j_));
    for (const auto& k : keys) allowed_.insert(k);
    for (auto it = j_.begin(); it != j_.end(); ++it) {
      if (allowed_.count(it.key())) continue;
      std::string list;
      for (const auto& k : allowed_) list += (list.empty() ? "" : ", ") + k;
      ctx_.fail(child(it.key()), "unknown key; expected one of: " + list);
    }
  }

  std::string child(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }
  const Context& ctx() const { return ctx_; }

  const json* find(const std::string& key) {
    SPH_CHECK(allowed_.count(key), "scene key \"" + key + "\" read but not declared for " + path_);
    auto it = j_.find(key);
    return it == j_.end() ? nullptr : &*it;
  }
  const json& require(const std::string& key, const std::string& what) {
    const json* v = find(key);
    if (!v) ctx_.fail(child(key), "missing required key; expected " + what);
    return *v;
  }

  double number(const json& v, const std::string& key, const std::string& what) const {
    if (!v.is_number()) ctx_.fail(child(key), "expected " + what + ", got " + describe(v));
    const double x = v.get<double>();
    if (!std::isfinite(x)) ctx_.fail(child(key), "expected a finite number");
    return x;
  }
  /// A number > 0 (or >= 0 if allow_zero).
  double positive(const std::string& key, const std::string& what, std::optional<double> def = {},
                  bool allow_zero = false) {
    const json* v = find(key);
    if (!v) {
      if (def) return *def;
      ctx_.fail(child(key), "missing required key; expected " + what);
    }
    const double x = number(*v, key, what);
    if (allow_zero ? x < 0 : x <= 0) ctx_.fail(child(key), fmt::format("expected {}, got {}", what, x));
    return x;
  }
  std::int64_t integer(const std::string& key, const std::string& what, std::int64_t min, std::int64_t max,
                       std::optional<std::int64_t> def = {}) {
    const json* v = find(key);
    if (!v) {
      if (def) return *def;
      ctx_.fail(child(key), "missing required key; expected " + what);
    }
    if (!v->is_number_integer()) ctx_.fail(child(key), "expected " + what + ", got " + describe(*v));
    if (v->is_number_unsigned() && v->get<std::uint64_t>() > static_cast<std::uint64_t>(max))
      ctx_.fail(child(key), fmt::format("expected {}, got {}", what, v->get<std::uint64_t>()));
    const auto x = v->get<std::int64_t>();
    if (x < min || x > max) ctx_.fail(child(key), fmt::format("expected {}, got {}", what, x));
    return x;
  }
  std::string string(const std::string& key, const std::string& what, std::optional<std::string> def = {}) {
    const json* v = find(key);
    if (!v) {
      if (def) return *def;
      ctx_.fail(child(key), "missing required key; expected " + what);
    }
    if (!v->is_string()) ctx_.fail(child(key), "expected " + what + ", got " + describe(*v));
    return v->get<std::string>();
  }
  /// One of `choices` (strings).
  std::string choice(const std::string& key, const std::vector<std::string>& choices, const std::string& def) {
    std::string list;
    for (const auto& c : choices) list += (list.empty() ? "\"" : ", \"") + c + "\"";
    const std::string s = string(key, "one of " + list, def);
    if (std::find(choices.begin(), choices.end(), s) == choices.end())
      ctx_.fail(child(key), "unknown value \"" + s + "\"; expected one of " + list);
    return s;
  }
  template <int D>
  Vec<D, double> vec(const std::string& key, const std::string& what, std::optional<Vec<D, double>> def = {}) {
    const json* v = find(key);
    const std::string expect = fmt::format("{} as an array of {} numbers", what, D);
    if (!v) {
      if (def) return *def;
      ctx_.fail(child(key), "missing required key; expected " + expect);
    }
    if (!v->is_array() || v->size() != static_cast<std::size_t>(D))
      ctx_.fail(child(key), "expected " + expect + ", got " + describe(*v));
    Vec<D, double> out;
    for (int d = 0; d < D; ++d) {
      const json& e = (*v)[static_cast<std::size_t>(d)];
      if (!e.is_number() || !std::isfinite(e.get<double>()))
        ctx_.fail(child(key), "expected " + expect + ", got " + describe(*v));
      out[d] = e.get<double>();
    }
    return out;
  }
  /// An optional array of objects; calls f(reader) for each.
  template <class F>
  void array_of_objects(const std::string& key, const std::vector<std::string>& keys, F&& f) {
    const json* v = find(key);
    if (!v) return;
    if (!v->is_array()) ctx_.fail(child(key), "expected an array of objects [ {...}, ... ], got " + describe(*v));
    for (std::size_t i = 0; i < v->size(); ++i) {
      ObjectReader r((*v)[i], fmt::format("{}[{}]", child(key), i), ctx_, keys);
      f(r, i);
    }
  }
  /// A sub-object; an absent one reads as empty (its required keys are then reported missing).
  template <class F>
  void object(const std::string& key, const std::vector<std::string>& keys, F&& f) {
    static const json empty = json::object();
    const json* v = find(key);
    ObjectReader r(v ? *v : empty, child(key), ctx_, keys);
    f(r);
  }

 private:
  const json& j_;
  std::string path_;
  const Context& ctx_;
  std::set<std::string> allowed_;
};

/// JSON nested deeper than this is refused: copying, comparing and writing a json value recurse
/// once per level, so a value nested some ten thousand levels deep overflows the stack (a --set
/// value of 20,000 levels did).
constexpr int kMaxDepth = 64;

/// The largest kernel support h accepted, in particle spacings (2 * particleRadius).
constexpr double kMaxKernelSpacings = 10;

/// Parses JSON text; syntax errors and duplicate keys name the line and column.
json parse_json(const std::string& text, const std::string& source) {
  if (text.find_first_not_of(" \t\r\n") == std::string::npos)
    throw Error("the scene file is empty; expected a JSON object (see docs/scene-format.md)", source);
  // Duplicate keys would silently keep the last value: refuse them.
  std::vector<std::set<std::string>> keys;
  std::string duplicate;
  json::parser_callback_t cb = [&](int depth, json::parse_event_t event, json& parsed) {
    if (depth > kMaxDepth) throw Error(fmt::format("the JSON is nested more than {} levels deep", kMaxDepth), source);
    if (event == json::parse_event_t::object_start) keys.emplace_back();
    else if (event == json::parse_event_t::object_end) keys.pop_back();
    else if (event == json::parse_event_t::key && !keys.empty() && duplicate.empty()) {
      const auto k = parsed.get<std::string>();
      if (!keys.back().insert(k).second) duplicate = k;
    }
    return true;
  };
  try {
    json j = json::parse(text, cb, /*allow_exceptions=*/true, /*ignore_comments=*/false);
    if (!duplicate.empty()) throw Error("key \"" + duplicate + "\" appears twice in the same object", source);
    return j;
  } catch (const json::parse_error& e) {
    // e.byte is the 1-based offset of the offending character.
    std::size_t line = 1, col = 1;
    const std::size_t end = std::min<std::size_t>(e.byte > 0 ? e.byte - 1 : 0, text.size());
    for (std::size_t k = 0; k < end; ++k) {
      if (text[k] == '\n') ++line, col = 1;
      else ++col;
    }
    std::string what = e.what();
    const auto pos = what.find("syntax error");
    if (pos != std::string::npos) what = what.substr(pos);
    throw Error("JSON syntax error: " + what, fmt::format("{}:{}:{}", source, line, col));
  } catch (const json::exception& e) {
    // For example a number too large for a double (1e999).
    std::string what = e.what();
    const auto pos = what.find("] ");
    throw Error("invalid JSON: " + (pos == std::string::npos ? what : what.substr(pos + 2)), source);
  }
}

/// The offset of the first byte of `s` that is not part of well-formed UTF-8 (no overlong
/// forms, no surrogates, nothing above U+10FFFF), or npos if all of `s` is well-formed.
std::size_t invalid_utf8_at(const std::string& s) {
  std::size_t i = 0;
  while (i < s.size()) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c < 0x80) {
      ++i;
      continue;
    }
    // The length of the sequence a lead byte starts, and the range its second byte must be in
    // (narrower after E0, ED, F0 and F4: no overlong forms, surrogates or code points > 10FFFF).
    std::size_t len = 0;
    unsigned char lo = 0x80, hi = 0xBF;
    if (c >= 0xC2 && c <= 0xDF) {
      len = 2;
    } else if (c >= 0xE0 && c <= 0xEF) {
      len = 3;
      if (c == 0xE0) lo = 0xA0;
      if (c == 0xED) hi = 0x9F;
    } else if (c >= 0xF0 && c <= 0xF4) {
      len = 4;
      if (c == 0xF0) lo = 0x90;
      if (c == 0xF4) hi = 0x8F;
    } else {
      return i;
    }
    if (len > s.size() - i) return i;
    for (std::size_t k = 1; k < len; ++k) {
      const auto b = static_cast<unsigned char>(s[i + k]);
      if (b < (k == 1 ? lo : 0x80) || b > (k == 1 ? hi : 0xBF)) return i;
    }
    i += len;
  }
  return std::string::npos;
}

/// Applies "a.b[2].c=VALUE" overrides to the JSON document.
void apply_overrides(json& doc, const std::vector<std::string>& overrides, Context& ctx) {
  for (const std::string& o : overrides) {
    // JSON text is UTF-8: a key or a plain-string value with other bytes could never be written
    // back out (SceneDesc::effective_json), so it is refused here, without echoing the bytes.
    if (const std::size_t bad = invalid_utf8_at(o); bad != std::string::npos)
      throw Error(fmt::format("expected KEY=VALUE as UTF-8 text; byte {} (0x{:02X}) is not valid UTF-8", bad,
                              static_cast<unsigned char>(o[bad])),
                  "--set");
    const auto eq = o.find('=');
    if (eq == std::string::npos || eq == 0)
      throw Error("expected KEY=VALUE with KEY a key path such as Fluid.stiffness, got \"" + o + "\"", "--set");
    const std::string key = o.substr(0, eq);
    const std::string value_text = o.substr(eq + 1);
    json value;
    try {
      const json::parser_callback_t depth_limit = [&](int depth, json::parse_event_t, json&) {
        if (depth > kMaxDepth)
          throw Error(fmt::format("the value is nested more than {} levels deep", kMaxDepth), "--set " + key);
        return true;
      };
      value = json::parse(value_text, depth_limit);
    } catch (const json::parse_error&) {
      value = value_text;  // not JSON: a plain string such as adaptive
    } catch (const json::exception& e) {
      throw Error("the value \"" + value_text + "\" is not a usable number (out of range)", "--set " + key);
    }
    // Split the path into object keys and [index] parts.
    std::vector<std::string> parts;
    std::string cur;
    for (std::size_t k = 0; k < key.size(); ++k) {
      const char c = key[k];
      if (c == '.' || c == '[') {
        if (!cur.empty()) parts.push_back(cur);
        cur.clear();
        if (c == '[') cur = "[";
      } else if (c == ']') {
        parts.push_back(cur + "]");
        cur.clear();
      } else {
        cur += c;
      }
    }
    if (!cur.empty()) parts.push_back(cur);
    json* node = &doc;
    std::string path;
    for (std::size_t k = 0; k < parts.size(); ++k) {
      const std::string& p = parts[k];
      const bool last = k + 1 == parts.size();
      if (p.front() == '[') {
        const std::string digits = p.substr(1, p.size() - 2);
        if (node->is_null())
          throw Error("\"" + path + "\" is not in the scene, so it has no element " + p, "--set " + key);
        if (!node->is_array())
          throw Error("\"" + path + "\" is not an array, so it has no element " + p, "--set " + key);
        if (digits.empty() || digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos)
          throw Error("bad array index " + p + "; expected [0], [1], ...", "--set " + key);
        const std::size_t idx = std::stoul(digits);
        if (idx >= node->size())
          throw Error(fmt::format("\"{}\" has {} element{}; index {} does not exist", path, node->size(),
                                  node->size() == 1 ? "" : "s", idx),
                      "--set " + key);
        path += p;
        node = &(*node)[idx];
      } else {
        if (!node->is_object())
          throw Error("\"" + path + "\" is not an object, so it has no key \"" + p + "\"", "--set " + key);
        path += (path.empty() ? "" : ".") + p;
        if (!last && !node->contains(p)) {
          if (parts[k + 1].front() == '[')
            throw Error("\"" + path + "\" is not in the scene, so it has no element " + parts[k + 1], "--set " + key);
          (*node)[p] = json::object();
        }
        node = &(*node)[p];
      }
      (void)last;
    }
    if (parts.empty()) throw Error("empty key path", "--set");
    *node = value;
    ctx.overridden.insert(path);
  }
}

template <int D>
bool inside(const Vec<D, double>& x, const Box<D>& b) {
  for (int d = 0; d < D; ++d)
    if (x[d] < b.lo[d] || x[d] > b.hi[d]) return false;
  return true;
}

template <int D>
std::string vec_text(const Vec<D, double>& v) {
  std::string s = "[";
  for (int d = 0; d < D; ++d) s += fmt::format("{}{:g}", d ? ", " : "", v[d]);
  return s + "]";
}

template <int D>
Box<D> read_box(ObjectReader& r, const char* what) {
  Box<D> b;
  b.lo = r.vec<D>("start", std::string("the lower corner of the ") + what + ", m");
  b.hi = r.vec<D>("end", std::string("the upper corner of the ") + what + ", m");
  for (int d = 0; d < D; ++d)
    if (!(b.hi[d] > b.lo[d]))
      r.ctx().fail(r.child("end"), fmt::format("must be greater than \"start\" in every coordinate; got start {} "
                                               "and end {}",
                                               vec_text<D>(b.lo), vec_text<D>(b.hi)));
  // Corners near +-1.8e308 would make the size itself infinite (and every count built on it).
  for (int d = 0; d < D; ++d)
    if (!std::isfinite(b.hi[d] - b.lo[d]))
      r.ctx().fail(r.child("end"), fmt::format("the {} from start {} to end {} is too large: its size overflows a "
                                               "double in some coordinate",
                                               what, vec_text<D>(b.lo), vec_text<D>(b.hi)));
  return b;
}

/// An optional array of distinct strings, each one of `choices`, at `key`; nullopt if absent.
std::optional<std::vector<std::string>> string_set(ObjectReader& c, const std::string& key,
                                                   const std::vector<std::string>& choices, const std::string& what) {
  const json* v = c.find(key);
  if (!v) return std::nullopt;
  std::string list;
  for (const auto& ch : choices) list += (list.empty() ? "\"" : ", \"") + ch + "\"";
  if (!v->is_array())
    c.ctx().fail(c.child(key), "expected " + what + ": an array of " + list + ", got " + describe(*v));
  std::vector<std::string> out;
  for (std::size_t i = 0; i < v->size(); ++i) {
    const json& e = (*v)[i];
    const std::string at = fmt::format("{}[{}]", c.child(key), i);
    if (!e.is_string()) c.ctx().fail(at, "expected one of " + list + ", got " + describe(e));
    const std::string name = e.get<std::string>();
    if (std::find(choices.begin(), choices.end(), name) == choices.end())
      c.ctx().fail(at, "unknown value \"" + name + "\"; expected one of " + list);
    if (std::find(out.begin(), out.end(), name) != out.end())
      c.ctx().fail(at, "\"" + name + "\" appears twice; expected each at most once");
    out.push_back(name);
  }
  return out;
}

/// Configuration.outputEveryNSteps, outputFps, outputFormats, outputFields.
void read_output(ObjectReader& c, SceneDesc& desc) {
  OutputDesc& out = desc.output;
  out.fps = c.positive("outputFps", "a frame rate >= 0 in frames per simulated second (0: frames by outputEveryNSteps)",
                       0.0, true);
  // Frames by time replace the default frames by steps; both given is a contradiction.
  out.every_steps = c.integer("outputEveryNSteps", "a frame interval in steps (0: no frames)", 0, 1'000'000'000'000LL,
                              out.fps > 0 ? 0 : std::max<std::int64_t>(1, desc.steps / 100));
  if (out.fps > 0 && out.every_steps > 0)
    c.ctx().fail(c.child("outputFps"),
                 fmt::format("outputEveryNSteps = {} and outputFps = {:g} both choose when frames are written; give "
                             "one of them (or set the other to 0)",
                             out.every_steps, out.fps));
  if (auto formats = string_set(c, "outputFormats", {"vtu", "vtk", "ply"}, "the frame formats")) {
    if (formats->empty())
      c.ctx().fail(c.child("outputFormats"), "expected at least one frame format of \"vtu\", \"vtk\", \"ply\"");
    out.formats.clear();
    for (const std::string& f : *formats)
      out.formats.push_back(f == "vtu" ? FrameFormat::Vtu : f == "vtk" ? FrameFormat::Vtk : FrameFormat::Ply);
  }
  const std::vector<std::string> all(std::begin(kFrameFieldNames), std::end(kFrameFieldNames));
  if (auto fields = string_set(c, "outputFields", all, "the point fields of each frame (empty: positions only)")) {
    out.fields.clear();
    for (const std::string& name : all)  // in kFrameFieldNames order, whatever the file's
      if (std::find(fields->begin(), fields->end(), name) != fields->end()) out.fields.push_back(name);
  }
}

template <int D>
void read_body(ObjectReader& root, SceneDesc& desc) {
  SceneBody<D>& body = desc.body<D>();
  SimulationParams<D>& sim = body.sim;
  Vec<D, double> default_g{};
  default_g[1] = -9.81;

  root.object("Configuration",
              {"precision", "timeStepSize", "numberOfSteps", "particleRadius", "kernelRadius", "gravitation",
               "neighbors", "fullRebuildPeriod", "verletSkin", "reorderPeriod", "outputEveryNSteps", "outputFps",
               "outputFormats", "outputFields"},
              [&](ObjectReader& c) {
    const std::string prec = c.choice("precision", {"double", "float"}, "double");
    desc.precision = prec == "float" ? Precision::Float : Precision::Double;
    sim.time_step = c.positive("timeStepSize", "a positive time step in seconds");
    desc.steps = c.integer("numberOfSteps", "a number of steps between 1 and 1e12", 1, 1'000'000'000'000LL);
    sim.particle_radius = c.positive("particleRadius", "a positive particle radius in metres");
    sim.kernel_radius = c.positive("kernelRadius", "a positive kernel support radius h in metres",
                                   4.0 * sim.particle_radius);
    if (sim.kernel_radius <= 2.0 * sim.particle_radius)
      c.ctx().fail(c.child("kernelRadius"),
                   fmt::format("h = {:g} m must exceed the particle spacing 2 * particleRadius = {:g} m (typical: "
                               "4 * particleRadius)",
                               sim.kernel_radius, 2 * sim.particle_radius));
    // Work per particle grows as (h / spacing)^D: the default particle mass sums the kernel over
    // that many lattice sites, and every list would hold that many neighbors.
    if (sim.kernel_radius > kMaxKernelSpacings * 2.0 * sim.particle_radius)
      c.ctx().fail(c.child("kernelRadius"),
                   fmt::format("h = {:g} m is more than {:g} particle spacings (2 * particleRadius = {:g} m): every "
                               "particle would have thousands of neighbors; expected at most {:g} m (typical: 4 * "
                               "particleRadius)",
                               sim.kernel_radius, kMaxKernelSpacings, 2 * sim.particle_radius,
                               kMaxKernelSpacings * 2.0 * sim.particle_radius));
    sim.gravity = c.vec<D>("gravitation", "the gravity acceleration in m/s^2", default_g);
    sim.neighbors = parse_neighbor_mode(c.choice("neighbors", neighbor_mode_names(), "standard"), c.child("neighbors"));
    sim.full_rebuild_period = static_cast<int>(
        c.integer("fullRebuildPeriod", "a full-rebuild period of at least 1 step", 1, 1'000'000'000, 200));
    sim.reorder_period = static_cast<int>(c.integer("reorderPeriod",
                                                    "a whole number of steps, 0 or more (0: never reorder particles in memory)",
                                                    0, 1'000'000'000, sim.full_rebuild_period));
    sim.verlet_skin = c.positive("verletSkin", "a positive verlet skin in metres (default 0.1 h)",
                                 kDefaultSkinFraction * sim.kernel_radius);
    if (sim.verlet_skin > 2.0 * sim.kernel_radius)
      c.ctx().fail(c.child("verletSkin"),
                   fmt::format("a skin of {:g} m is more than twice h = {:g} m: lists would hold over 27 times the "
                               "pairs needed in 3D; expected a skin between 0.05 h and 0.5 h",
                               sim.verlet_skin, sim.kernel_radius));
    read_output(c, desc);
  });

  root.object("Fluid",
              {"density0", "stiffness", "viscosity", "negativePressure", "pressureForce", "gradientCorrection",
               "particleMass"},
              [&](ObjectReader& f) {
    sim.fluid.rest_density = f.positive("density0", "a positive rest density in kg/m^" + std::to_string(D), 1000.0);
    sim.fluid.stiffness = f.positive("stiffness", "a positive EOS stiffness k in m^2/s^2 (p = k (rho - rho0))");
    sim.fluid.viscosity = f.positive("viscosity", "a viscosity >= 0 in Pa s", 0.0, true);
    sim.fluid.negative_pressure =
        f.choice("negativePressure", {"clamp", "allow"}, "clamp") == "allow" ? NegativePressure::Allow
                                                                             : NegativePressure::Clamp;
    const std::string form = f.choice("pressureForce", {"paper", "symmetric", "variational"}, "paper");
    sim.fluid.pressure_force = form == "symmetric"     ? PressureForce::Symmetric
                               : form == "variational" ? PressureForce::Variational
                                                       : PressureForce::Paper;
    sim.fluid.gradient_correction = f.choice("gradientCorrection", {"none", "renormalize"}, "none") == "renormalize"
                                        ? GradientCorrection::Renormalize
                                        : GradientCorrection::None;
    if (f.find("particleMass")) {
      sim.particle_mass = f.positive("particleMass", "a positive particle mass in kg");
    } else {
      // Extreme scales (h^9 in the kernel's normalization) can overflow to inf or NaN.
      sim.particle_mass = lattice_mass<D>(sim.fluid.rest_density, 2.0 * sim.particle_radius, sim.kernel_radius);
      if (!(std::isfinite(sim.particle_mass) && sim.particle_mass > 0))
        f.ctx().fail(f.child("particleMass"),
                     fmt::format("the default particle mass computed from density0 = {:g}, particleRadius = {:g} and "
                                 "kernelRadius = {:g} is {:g}; expected a positive finite mass: give particleMass or "
                                 "use less extreme values",
                                 sim.fluid.rest_density, sim.particle_radius, sim.kernel_radius, sim.particle_mass));
    }
  });

  {
    const json& cj = root.require("Container", "an object with \"start\" and \"end\" corners");
    ObjectReader c(cj, root.child("Container"), root.ctx(), {"start", "end", "wallStiffness", "wallDamping"});
    sim.container = read_box<D>(c, "container");
    sim.walls.stiffness = c.positive("wallStiffness", "a positive wall spring stiffness in 1/s^2");
    sim.walls.damping = c.positive("wallDamping", "a wall damping >= 0 in 1/s", 0.0, true);
    for (int d = 0; d < D; ++d)
      if (sim.container.hi[d] - sim.container.lo[d] < 4 * sim.particle_radius)
        c.ctx().fail(c.child("end"), "the container must be at least two particle diameters wide in every direction");
  }

  const double dx = 2.0 * sim.particle_radius;
  double total = 0;
  root.array_of_objects("FluidBlocks", {"start", "end", "velocity"}, [&](ObjectReader& b, std::size_t) {
    FluidBlockDesc<D> blk;
    blk.box = read_box<D>(b, "fluid block");
    blk.velocity = b.vec<D>("velocity", "the initial velocity in m/s", Vec<D, double>{});
    if (!inside<D>(blk.box.lo, sim.container) || !inside<D>(blk.box.hi, sim.container))
      b.ctx().fail(b.child("start"), fmt::format("the block {} .. {} is not inside the container {} .. {}",
                                                 vec_text<D>(blk.box.lo), vec_text<D>(blk.box.hi),
                                                 vec_text<D>(sim.container.lo), vec_text<D>(sim.container.hi)));
    // Each axis on its own: a product taken first could be inf * 0 = NaN, which no comparison
    // refuses (a block far longer than 2e9 spacings one way and thinner than one the other).
    double count = 1;
    for (int d = 0; d < D; ++d) {
      const double along = std::floor((blk.box.hi[d] - blk.box.lo[d]) / dx + 1e-9);
      if (!(along >= 1))
        b.ctx().fail(b.child("end"), fmt::format("the block is thinner than one particle spacing ({:g} m) in some "
                                                 "direction, so it holds no particle",
                                                 dx));
      count *= along;
    }
    total += count;
    body.blocks.push_back(blk);
  });

  root.array_of_objects("Obstacles", {"start", "end"}, [&](ObjectReader& o, std::size_t) {
    Box<D> b = read_box<D>(o, "obstacle");
    sim.obstacles.push_back(b);
  });

  std::vector<std::string> emitter_keys{"translation",     "direction",    "velocity",      "width",
                                        "emitEveryNSteps", "maxParticles", "emitStartTime", "emitEndTime"};
  if (D == 3) emitter_keys.push_back("height");  // a 2D nozzle is a line of `width` particles
  root.array_of_objects("Emitters", emitter_keys, [&](ObjectReader& e, std::size_t) {
    EmitterParams<D> em;
    em.origin = e.vec<D>("translation", "the center of the emitter nozzle in m");
    Vec<D, double> dir = e.vec<D>("direction", "the emission direction (any non-zero length)");
    // Scaled by its largest component first: the squared length of [1e200, 1e200, 0] overflows
    // (1 / inf = 0 made it a zero direction: particles emitted at rest, all on the nozzle) and
    // that of [1e-200, 0, 0] underflows to 0 (a non-zero direction refused as zero).
    double largest = 0;
    for (int d = 0; d < D; ++d) largest = std::max(largest, std::abs(dir[d]));
    if (!(largest > 0)) e.ctx().fail(e.child("direction"), "expected a non-zero direction vector");
    for (int d = 0; d < D; ++d) dir[d] /= largest;  // divided, not multiplied by 1 / largest (1 / 1e-310 = inf)
    em.direction = dir * (1.0 / norm(dir));
    em.speed = e.positive("velocity", "a positive emission speed in m/s");
    em.width = static_cast<int>(e.integer("width", "a nozzle width of 1 to 10000 particles", 1, 10000));
    em.height = D == 3 ? static_cast<int>(e.integer("height", "a nozzle height of 1 to 10000 particles", 1, 10000))
                       : 1;
    em.spacing = dx;
    em.every_steps = static_cast<int>(
        e.integer("emitEveryNSteps", "an emission interval of at least 1 step", 1, 1'000'000'000, 16));
    em.max_particles = e.integer("maxParticles", "a positive particle budget", 1, 4'000'000'000LL);
    em.start_time = e.positive("emitStartTime", "a start time >= 0 in s", 0.0, true);
    em.end_time = e.positive("emitEndTime", "an end time > 0 in s", std::numeric_limits<double>::infinity());
    if (!inside<D>(em.origin, sim.container))
      e.ctx().fail(e.child("translation"), fmt::format("the nozzle center {} is outside the container",
                                                       vec_text<D>(em.origin)));
    // Each batch must have left the nozzle before the next one is placed there.
    const double travel = em.speed * em.every_steps * sim.time_step;
    if (travel < dx)
      e.ctx().fail(e.child("velocity"),
                   fmt::format("a batch moves {:.3g} m in {} steps, less than the particle spacing {:.3g} m, so "
                               "batches would overlap; raise velocity to at least {:.3g} m/s or emitEveryNSteps",
                               travel, em.every_steps, dx, dx / (em.every_steps * sim.time_step)));
    total += static_cast<double>(em.max_particles);
    sim.emitters.push_back(em);
  });

  if (total < 1) root.ctx().fail("FluidBlocks", "the scene has no particles: add a FluidBlocks entry or an Emitters entry");
  if (total > 2e9)
    root.ctx().fail("FluidBlocks", fmt::format("the scene would hold {:.3g} particles; at most 2e9 are supported", total));

  try {
    for (const std::string& w : check_time_step<D>(sim)) desc.warnings.push_back(w);
  } catch (const Error& e) {
    root.ctx().fail(e.where(), e.message());
  }
}

json load(const std::string& text, const std::string& source, const std::vector<std::string>& overrides,
          Context& ctx) {
  json doc = parse_json(text, source);
  if (!doc.is_object()) throw Error("expected a JSON object { ... } at the top level, got " + describe(doc), source);
  apply_overrides(doc, overrides, ctx);
  return doc;
}

}  // namespace

SceneDesc parse_scene(const std::string& text, const std::string& source, const std::vector<std::string>& overrides) {
  Context ctx{source, {}};
  const json doc = load(text, source, overrides, ctx);
  SceneDesc desc;
  desc.source = source;
  desc.effective_json = doc.dump(2);
  ObjectReader root(doc, "", ctx,
                    {"version", "name", "description", "units", "dimension", "Configuration", "Fluid", "Container",
                     "FluidBlocks", "Obstacles", "Emitters"});
  desc.version = static_cast<int>(root.integer("version", "the scene format version 1", 1, 1));
  desc.name = root.string("name", "a scene name (letters, digits, - and _)", "scene");
  if (desc.name.empty() || desc.name.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789-_") != std::string::npos)
    ctx.fail("name", "expected a non-empty name of letters, digits, - and _, got \"" + desc.name + "\"");
  desc.description = root.string("description", "a description", "");
  root.string("units", "\"SI\"", "SI");
  if (doc.contains("units") && doc["units"] != "SI") ctx.fail("units", "only \"SI\" units are supported");
  desc.dimension = static_cast<int>(root.integer("dimension", "the dimension 2 or 3", 2, 3));
  if (desc.dimension == 2) read_body<2>(root, desc);
  else read_body<3>(root, desc);
  return desc;
}

std::string read_scene_text(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw Error("is a directory; expected a scene file (.json)", path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("cannot open the scene file (does it exist and is it readable?)", path);
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw Error("cannot read the scene file", path);
  return ss.str();
}

SceneDesc read_scene_file(const std::string& path, const std::vector<std::string>& overrides) {
  return parse_scene(read_scene_text(path), path, overrides);
}

}  // namespace sph
