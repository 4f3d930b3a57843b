#include <sph/render/color_by.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <sph/core/error.h>

namespace sph {

namespace {

/// A quantity: its name, the particle field it is computed from, its legend label and, for a
/// quantity that is not the field itself, its unit (otherwise the field's, from kParticleFields;
/// none for colors).
struct Info {
  ColorBy by;
  std::string_view name, field, label, unit2 = {}, unit3 = {};
  bool colors = false;  ///< colored by the field's components: no unit in the label
};

constexpr Info kInfo[] = {
    {ColorBy::Speed, "speed", "velocity", "speed"},
    {ColorBy::KineticEnergy, "kinetic_energy", "velocity", "kinetic energy", "J/m", "J"},
    {ColorBy::Density, "density", "density", "density"},
    {ColorBy::Pressure, "pressure", "pressure", "pressure"},
    {ColorBy::InitialPosition, "initial_position", "initial_position", "initial position", {}, {}, true},
    {ColorBy::None, "none", "", "one color", {}, {}, true},
};

const Info& info(ColorBy by) {
  for (const Info& i : kInfo)
    if (i.by == by) return i;
  SPH_CHECK(false, "unknown ColorBy");
  return kInfo[0];
}

/// The p-th percentile (0..100) of sorted values, interpolated between neighbors.
double percentile(const std::vector<double>& sorted, double p) {
  if (sorted.size() == 1) return sorted[0];
  const double at = p / 100.0 * static_cast<double>(sorted.size() - 1);
  const auto k = static_cast<std::size_t>(at);
  if (k + 1 >= sorted.size()) return sorted.back();
  return sorted[k] + (at - static_cast<double>(k)) * (sorted[k + 1] - sorted[k]);
}

const FrameField& require(const FrameData& frame, ColorBy by, const RunDirectory& run) {
  const std::string_view name = color_by_field(by);
  const FrameField* f = frame.field(name);
  if (!f) {
    std::vector<std::string> held, colorable;
    for (const FrameField& g : frame.fields) held.push_back(g.name);
    for (const ColorBy other : kColorByAll)
      if (frame.field(color_by_field(other))) colorable.push_back(std::string(color_by_name(other)));
    throw Error(
        fmt::format("the run's frames hold no '{}' field, which coloring by {} needs (the run left it out "
                    "with --fields; they hold {}); {}, or run again with the field (sph view shows the "
                    "particles without one)",
                    name, color_by_name(by), held.empty() ? "positions only" : fmt::format("{}", fmt::join(held, ", ")),
                    colorable.empty() ? std::string("color them all alike with --color-by none")
                                      : fmt::format("color by {}", fmt::join(colorable, " or "))),
        run.dir.string());
  }
  const std::size_t want = frame.size * static_cast<std::size_t>(f->components);
  const FieldDesc* desc = find_particle_field(name);
  SPH_CHECK(desc, "color-by needs a field of the table");
  if (f->values.size() != want || f->components != desc->components())
    throw Error(fmt::format("the '{}' field of a frame has {} values with {} components for {} particles", name,
                            f->values.size(), f->components, frame.size),
                run.dir.string());
  return *f;
}

}  // namespace

std::string_view color_by_name(ColorBy by) { return info(by).name; }

std::optional<ColorBy> color_by_from_name(std::string_view name) {
  for (const Info& i : kInfo)
    if (i.name == name) return i.by;
  return std::nullopt;
}

std::vector<std::string> color_by_list() {
  std::vector<std::string> names;
  for (const ColorBy by : kColorByAll) names.emplace_back(color_by_name(by));
  return names;
}

std::string color_by_names() {
  std::string s;
  for (const std::string& name : color_by_list()) s += (s.empty() ? "" : ", ") + name;
  return s;
}

std::string color_by_label(ColorBy by, int dimension) {
  const Info& i = info(by);
  if (i.colors) return std::string(i.label);
  std::string_view unit = dimension == 2 ? i.unit2 : i.unit3;
  if (unit.empty()) unit = find_particle_field(i.field)->unit(dimension);
  return fmt::format("{} ({})", i.label, unit);
}

std::string_view color_by_field(ColorBy by) { return info(by).field; }

bool color_by_is_scalar(ColorBy by) { return by != ColorBy::InitialPosition && by != ColorBy::None; }

Colormap default_colormap(ColorBy by) {
  return by == ColorBy::Speed || by == ColorBy::KineticEnergy ? Colormap::Turbo : Colormap::Viridis;
}

std::vector<double> color_values(const FrameData& frame, ColorBy by, const RunDirectory& run) {
  if (by == ColorBy::None) return std::vector<double>(frame.size, 0.0);
  const FrameField& f = require(frame, by, run);
  std::vector<double> out(frame.size);
  const std::vector<double>& v = f.values;
  for (std::size_t i = 0; i < frame.size; ++i) {
    switch (by) {
      case ColorBy::Speed:
      case ColorBy::KineticEnergy: {
        const double v2 = v[3 * i] * v[3 * i] + v[3 * i + 1] * v[3 * i + 1] + v[3 * i + 2] * v[3 * i + 2];
        out[i] = by == ColorBy::Speed ? std::sqrt(v2) : 0.5 * run.particle_mass * v2;
        break;
      }
      case ColorBy::Density:
      case ColorBy::Pressure:
        out[i] = v[i];
        break;
      case ColorBy::InitialPosition:
        out[i] = v[3 * i + 1];
        break;
      case ColorBy::None:
        break;
    }
  }
  return out;
}

std::pair<double, double> color_range(ColorBy by, std::span<const std::vector<double>> values_per_frame) {
  std::vector<double> all;
  for (const auto& frame : values_per_frame)
    for (double x : frame)
      if (std::isfinite(x)) all.push_back(x);
  if (all.empty()) return {0.0, 1.0};
  std::sort(all.begin(), all.end());
  const bool from_zero = by == ColorBy::Speed || by == ColorBy::KineticEnergy || by == ColorBy::Pressure;
  double lo = from_zero ? std::min(0.0, all.front()) : percentile(all, 0.5);
  double hi = percentile(all, 99.5);
  if (by == ColorBy::InitialPosition) lo = all.front(), hi = all.back();
  if (!(hi > lo)) {
    const double pad = std::max(std::abs(lo) * 1e-3, 1e-12);
    lo -= pad;
    hi += pad;
  }
  return {lo, hi};
}

Rgb initial_position_color(const std::array<double, 3>& x0, const std::array<double, 3>& lo,
                           const std::array<double, 3>& hi) {
  std::uint8_t c[3] = {};
  for (int d = 0; d < 3; ++d) {
    const double extent = hi[d] - lo[d];
    const double t = extent > 0 ? (x0[d] - lo[d]) / extent : 0.0;  // a flat axis (z in 2D): dim
    c[d] = static_cast<std::uint8_t>(std::clamp(40.0 + 215.0 * (std::isfinite(t) ? t : 0.0), 0.0, 255.0));
  }
  return Rgb{c[0], c[1], c[2]};
}

std::vector<Rgb> particle_colors(const FrameData& frame, const ColorSpec& spec, const RunDirectory& run) {
  std::vector<Rgb> colors(frame.size, kOneColor);
  if (spec.by == ColorBy::None) return colors;
  if (spec.by == ColorBy::InitialPosition) {
    const std::vector<double>& x0 = require(frame, spec.by, run).values;
    for (std::size_t i = 0; i < frame.size; ++i)
      colors[i] = initial_position_color({x0[3 * i], x0[3 * i + 1], x0[3 * i + 2]}, run.box_lo, run.box_hi);
    return colors;
  }
  const std::vector<double> values = color_values(frame, spec.by, run);
  for (std::size_t i = 0; i < frame.size; ++i) colors[i] = colormap(spec.map, values[i], spec.lo, spec.hi);
  return colors;
}

}  // namespace sph
