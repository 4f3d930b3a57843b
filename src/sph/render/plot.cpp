#include <sph/render/plot.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include <sph/core/error.h>
#include <sph/render/font.h>

namespace sph {

namespace {

constexpr Rgb kWhite{255, 255, 255};
constexpr Rgb kFrame{90, 90, 90};
constexpr Rgb kGrid{222, 222, 222};
constexpr Rgb kMinorGrid{240, 240, 240};
constexpr Rgb kMuted{140, 140, 140};
constexpr double kLineWidth = 2.0;
constexpr int kTick = 5;

struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  bool valid() const { return lo <= hi; }
  void add(double v) {
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
};

struct Tick {
  double value;       ///< in axis units (log10 of the data on a log axis)
  std::string label;  ///< empty: no label
  bool minor = false;
};

struct Axis {
  double lo = 0, hi = 1;  ///< axis units
  std::vector<Tick> ticks;
};

bool drawable(double x, double y, bool log_y) { return std::isfinite(x) && std::isfinite(y) && (!log_y || y > 0.0); }

/// 1, 2 or 5 x 10^k, close to span / target.
double nice_step(double span, int target) {
  const double raw = span / std::max(target, 1);
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double f = raw / mag;
  return (f < 1.5 ? 1.0 : f < 3.0 ? 2.0 : f < 7.0 ? 5.0 : 10.0) * mag;
}

/// "1.5e-05" -> "1.5e-5", "2e+06" -> "2e6".
std::string compact_exponent(std::string s) {
  const auto e = s.find('e');
  if (e == std::string::npos) return s;
  std::string mant = s.substr(0, e), exp = s.substr(e + 1);
  const bool neg = !exp.empty() && exp[0] == '-';
  if (!exp.empty() && (exp[0] == '-' || exp[0] == '+')) exp.erase(0, 1);
  exp.erase(0, std::min(exp.find_first_not_of('0'), exp.size() - 1));
  return mant + "e" + (neg ? "-" : "") + exp;
}

std::string format_tick(double v, double step, double magnitude) {
  if (v == 0.0) return "0";
  if (!std::isfinite(v) || !std::isfinite(step) || !(step > 0.0)) return compact_exponent(fmt::format("{:.3g}", v));
  const double step_exp = std::floor(std::log10(step) + 1e-9);
  if (magnitude >= 1e6 || magnitude < 1e-3) {
    // Enough significant digits to tell neighboring ticks apart.
    const double digits = std::clamp(std::floor(std::log10(std::abs(v))) - step_exp + 1.0, 1.0, 6.0);
    return compact_exponent(fmt::format("{:.{}g}", v, static_cast<int>(digits)));
  }
  const double decimals = std::clamp(-step_exp, 0.0, 15.0);
  return fmt::format("{:.{}f}", v, static_cast<int>(decimals));
}

Axis linear_axis(Range r, int target) {
  Axis a;
  if (!r.valid()) r = {0.0, 1.0};
  if (r.hi - r.lo <= 1e-12 * std::max(std::abs(r.lo), std::abs(r.hi))) {  // (nearly) constant data
    const double pad = r.lo == 0.0 ? 1.0 : std::abs(r.lo) * 0.1;
    r = {r.lo - pad, r.hi + pad};
  }
  const double step = nice_step(r.hi - r.lo, target);
  const double k0 = std::floor(r.lo / step + 1e-9), k1 = std::ceil(r.hi / step - 1e-9);
  a.lo = k0 * step;
  a.hi = std::max(k1, k0 + 1) * step;
  const double magnitude = std::max(std::abs(a.lo), std::abs(a.hi));
  const double n = k1 - k0;  // bounded below, even for absurd ranges
  const int count = n >= 0.0 && n <= 1000.0 ? static_cast<int>(n) : (n > 1000.0 ? 1000 : 0);
  for (int i = 0; i <= count; ++i) {
    double v = (k0 + i) * step;
    if (std::abs(v) < step * 1e-9) v = 0.0;
    a.ticks.push_back({v, format_tick(v, step, magnitude)});
  }
  return a;
}

std::string decade_label(int k) {
  if (k >= 0 && k <= 4) return fmt::format("{}", static_cast<long>(std::lround(std::pow(10.0, k))));
  if (k < 0 && k >= -3) return fmt::format("{:.{}f}", std::pow(10.0, k), -k);
  return fmt::format("1e{}", k);
}

/// Ticks at decades (labels at most every `max_labels`-th), minor ticks at 2..9 x 10^k.
Axis log_axis(Range r, int max_labels, bool minor) {
  Axis a;
  if (!r.valid()) r = {1.0, 10.0};
  int k0 = static_cast<int>(std::floor(std::log10(r.lo) + 1e-9));
  int k1 = static_cast<int>(std::ceil(std::log10(r.hi) - 1e-9));
  if (k1 <= k0) k1 = k0 + 1;
  a.lo = k0;
  a.hi = k1;
  const int every = std::max(1, (k1 - k0 + max_labels - 1) / std::max(max_labels, 1));
  for (int k = k0; k <= k1; ++k) {
    a.ticks.push_back({static_cast<double>(k), (k - k0) % every == 0 ? decade_label(k) : std::string()});
    if (minor && k < k1)
      for (int m = 2; m <= 9; ++m) a.ticks.push_back({k + std::log10(m), std::string(), true});
  }
  return a;
}

/// Draws a polyline with dashes of `on` pixels separated by `off`, continuing the pattern
/// across vertices.
class DashPen {
 public:
  DashPen(Image& image, Rgb color, bool dashed) : image_(image), color_(color), dashed_(dashed) {}
  void restart() { phase_ = 0.0; }
  void segment(double x0, double y0, double x1, double y1) {
    if (!dashed_) {
      image_.draw_line(x0, y0, x1, y1, color_, kLineWidth);
      return;
    }
    const double len = std::hypot(x1 - x0, y1 - y0);
    double s = 0.0;
    while (s < len) {
      const double in_period = std::fmod(phase_ + s, kOn + kOff);
      const double left = (in_period < kOn ? kOn : kOn + kOff) - in_period;
      const double e = std::min(len, s + left);
      if (in_period < kOn && len > 0.0)
        image_.draw_line(x0 + (x1 - x0) * s / len, y0 + (y1 - y0) * s / len, x0 + (x1 - x0) * e / len,
                         y0 + (y1 - y0) * e / len, color_, kLineWidth);
      s = e;
      if (left <= 0.0) break;  // defensive: never loop without progress
    }
    phase_ = std::fmod(phase_ + len, kOn + kOff);
  }

 private:
  static constexpr double kOn = 9.0, kOff = 6.0;
  Image& image_;
  Rgb color_;
  bool dashed_;
  double phase_ = 0.0;
};

/// Where everything goes: text sizes, the plot area in pixels and its two axes.
struct PlotLayout {
  bool log_y = false;
  int ts = 1, th = 0, pad = 0;  ///< text scale, text height, padding
  int left = 0, top = 0, plot_w = 0, plot_h = 0;
  int x_label_top = 0;  ///< top of the x tick labels
  Axis x_axis, y_axis;

  /// Pixel coordinates of data values.
  double sx(double x) const { return double(left) + (x - x_axis.lo) / (x_axis.hi - x_axis.lo) * double(plot_w); }
  double sy(double y) const { return sy_axis(log_y ? std::log10(y) : y); }
  /// Pixel row of a value in y-axis units (log10 of the data on a log axis).
  double sy_axis(double v) const {
    return double(top) + double(plot_h) - (v - y_axis.lo) / (y_axis.hi - y_axis.lo) * double(plot_h);
  }
};

/// Pixel coordinate of a grid line or tick: a value range that overflows (e.g. -1e308 .. 1e308)
/// gives NaN or inf, whose conversion to int is undefined; such lines are drawn off the image.
int to_pixel(double p) {
  if (!std::isfinite(p)) return -1;
  return static_cast<int>(std::floor(std::clamp(p, -1e6, 1e6)));
}

void check_plot_inputs(const PlotSpec& spec, int width, int height) {
  if (width < 160 || height < 120 || width > 16384 || height > 16384)
    throw Error(fmt::format("plot size {} x {} is out of range (160 x 120 to 16384 x 16384 pixels)", width, height));
  for (std::size_t k = 0; k < spec.series.size(); ++k) {
    const Series& s = spec.series[k];
    if (s.x.size() != s.y.size())
      throw Error(fmt::format("series \"{}\" has {} x values but {} y values", s.name, s.x.size(), s.y.size()),
                  fmt::format("plot series {}", k));
  }
}

/// The layout for data extents xr and yr (over the drawable points).
PlotLayout layout_plot(const PlotSpec& spec, int width, int height, const Range& xr, const Range& yr) {
  PlotLayout L;
  L.log_y = spec.log_y;
  // Text sizes: scale 2 for normal sizes, 1 for small images.
  L.ts = (width >= 600 && height >= 380) ? 2 : 1;
  L.th = text_height(L.ts);
  L.pad = 6 * L.ts;
  const int ts = L.ts, th = L.th, pad = L.pad;

  // Vertical layout first: the y ticks depend on the plot height.
  L.top = pad + (spec.title.empty() ? 0 : th + pad);
  const int bottom = kTick + pad / 2 + th + (spec.x_label.empty() ? 0 : pad + th) + pad;
  L.plot_h = std::max(20, height - L.top - bottom);

  const int y_target = std::max(2, L.plot_h / (th * 4));
  L.y_axis = L.log_y ? log_axis(yr, std::max(2, L.plot_h / (th * 2)), true) : linear_axis(yr, y_target);
  if (L.log_y) {
    // Minor ticks only where a decade is tall enough to show them.
    const double decade_px = L.plot_h / std::max(1.0, L.y_axis.hi - L.y_axis.lo);
    if (decade_px < 8.0 * ts) std::erase_if(L.y_axis.ticks, [](const Tick& t) { return t.minor; });
  }
  int y_label_w = 0;
  for (const Tick& t : L.y_axis.ticks) y_label_w = std::max(y_label_w, text_width(t.label, ts));
  L.left = pad + (spec.y_label.empty() ? 0 : th + pad) + y_label_w + pad / 2 + kTick;

  // Horizontal layout: the x ticks depend on the plot width; leave room for the last label.
  const int approx_w = std::max(20, width - L.left - 3 * pad);
  L.x_axis = linear_axis(xr, std::max(2, approx_w / (text_width("-0.000", ts) + 4 * pad)));
  const int last_label_w = L.x_axis.ticks.empty() ? 0 : text_width(L.x_axis.ticks.back().label, ts);
  const int right = std::max(3 * pad, last_label_w / 2 + pad);
  L.plot_w = std::max(20, width - L.left - right);
  L.x_label_top = L.top + L.plot_h + 1 + kTick + pad / 2;
  return L;
}

/// Grid lines (minor first so that major lines stay on top).
void draw_grid(Image& img, const PlotLayout& L) {
  for (const Tick& t : L.y_axis.ticks) {
    const int y = to_pixel(L.sy_axis(t.value));
    img.fill_rect(L.left, y, L.plot_w, 1, t.minor ? kMinorGrid : kGrid);
  }
  for (const Tick& t : L.x_axis.ticks) {
    const int x = to_pixel(L.sx(t.value));
    img.fill_rect(x, L.top, 1, L.plot_h, kGrid);
  }
}

void draw_series(Image& img, const PlotSpec& spec, const PlotLayout& L) {
  for (const Series& s : spec.series) {
    DashPen pen(img, s.color, s.dashed);
    const std::size_t n = s.x.size();
    for (std::size_t i = 0; i < n; ++i) {
      if (!drawable(s.x[i], s.y[i], L.log_y)) continue;
      const bool prev = i > 0 && drawable(s.x[i - 1], s.y[i - 1], L.log_y);
      const bool next = i + 1 < n && drawable(s.x[i + 1], s.y[i + 1], L.log_y);
      if (!prev) pen.restart();
      if (next) pen.segment(L.sx(s.x[i]), L.sy(s.y[i]), L.sx(s.x[i + 1]), L.sy(s.y[i + 1]));
      if (!prev && !next) img.fill_disc(L.sx(s.x[i]), L.sy(s.y[i]), kLineWidth + 0.5, s.color);
    }
  }
}

/// The frame, ticks and tick labels, the axis labels, the title, and "no data" when nothing
/// was drawable.
void draw_frame_and_text(Image& img, const PlotSpec& spec, const PlotLayout& L, bool has_data) {
  const int ts = L.ts, th = L.th, pad = L.pad, left = L.left, top = L.top;
  img.draw_rect(left - 1, top - 1, L.plot_w + 2, L.plot_h + 2, kFrame);
  for (const Tick& t : L.y_axis.ticks) {
    if (t.minor) continue;
    const int y = to_pixel(L.sy_axis(t.value));
    img.fill_rect(left - 1 - kTick, y, kTick, 1, kFrame);
    if (!t.label.empty())
      draw_text(img, left - 1 - kTick - pad / 2 - text_width(t.label, ts), y - text_height(ts) * 7 / 18, t.label, kInk,
                ts);
  }
  for (const Tick& t : L.x_axis.ticks) {
    const int x = to_pixel(L.sx(t.value));
    img.fill_rect(x, top + L.plot_h + 1, 1, kTick, kFrame);
    draw_text(img, x - text_width(t.label, ts) / 2, L.x_label_top, t.label, kInk, ts);
  }

  if (!spec.x_label.empty())
    draw_text(img, left + (L.plot_w - text_width(spec.x_label, ts)) / 2, L.x_label_top + th + pad, spec.x_label, kInk,
              ts);
  if (!spec.y_label.empty())
    draw_text_vertical(img, pad, top + (L.plot_h - text_width(spec.y_label, ts)) / 2, spec.y_label, kInk, ts);
  if (!spec.title.empty()) {
    const int tw = text_width(spec.title, ts);
    const int tx = std::max(pad, left + (L.plot_w - tw) / 2);
    draw_text(img, tx, pad, spec.title, kInk, ts);  // drawn twice, one pixel apart: bold
    draw_text(img, tx + 1, pad, spec.title, kInk, ts);
  }

  if (!has_data) {
    const std::string_view msg = "no data";
    draw_text(img, left + (L.plot_w - text_width(msg, ts)) / 2, top + (L.plot_h - th) / 2, msg, kMuted, ts);
  }
}

/// The legend, in the corner of the plot area covering the fewest data points.
void draw_legend(Image& img, const PlotSpec& spec, const PlotLayout& L) {
  const int ts = L.ts, th = L.th, pad = L.pad, left = L.left, top = L.top;
  const int sample_w = 14 * ts;
  const int row_h = th + 2 * ts;
  std::vector<std::string> names;
  int name_w = 0;
  for (std::size_t k = 0; k < spec.series.size(); ++k) {
    names.push_back(spec.series[k].name.empty() ? fmt::format("series {}", k + 1) : spec.series[k].name);
    name_w = std::max(name_w, text_width(names.back(), ts));
  }
  const int box_w = pad + sample_w + pad + name_w + pad;
  const int box_h = pad + static_cast<int>(names.size()) * row_h - 2 * ts + pad;
  const int margin = pad;
  const std::array<std::array<int, 2>, 4> corners = {{
      {left + L.plot_w - margin - box_w, top + margin},  // top right (preferred)
      {left + margin, top + margin},                     // top left
      {left + L.plot_w - margin - box_w, top + L.plot_h - margin - box_h},
      {left + margin, top + L.plot_h - margin - box_h},
  }};
  std::array<long, 4> hits{};
  for (const Series& s : spec.series)
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!drawable(s.x[i], s.y[i], L.log_y)) continue;
      const double x = L.sx(s.x[i]), y = L.sy(s.y[i]);
      for (std::size_t c = 0; c < corners.size(); ++c)
        if (x >= corners[c][0] - pad && x <= corners[c][0] + box_w + pad && y >= corners[c][1] - pad &&
            y <= corners[c][1] + box_h + pad)
          ++hits[c];
    }
  const std::size_t best = static_cast<std::size_t>(std::min_element(hits.begin(), hits.end()) - hits.begin());
  const int bx = corners[best][0], by = corners[best][1];
  img.blend_rect(bx, by, box_w, box_h, kWhite, 0.9);
  img.draw_rect(bx, by, box_w, box_h, Rgb{170, 170, 170});
  for (std::size_t k = 0; k < names.size(); ++k) {
    const int ry = by + pad + static_cast<int>(k) * row_h;
    const double ly = ry + th * 7.0 / 18.0;
    const Series& s = spec.series[k];
    // A series drawn as dots only (no drawable point next to another: the experiment's points)
    // shows a dot, as the plot draws it; the others a piece of their line.
    bool dots = true;
    for (std::size_t i = 0; dots && i + 1 < s.x.size(); ++i)
      dots = !(drawable(s.x[i], s.y[i], L.log_y) && drawable(s.x[i + 1], s.y[i + 1], L.log_y));
    if (dots) {
      img.fill_disc(bx + pad + sample_w / 2.0, ly, kLineWidth + 0.5, s.color);
    } else {
      DashPen pen(img, s.color, s.dashed);
      pen.segment(bx + pad, ly, bx + pad + sample_w, ly);
    }
    draw_text(img, bx + pad + sample_w + pad, ry, names[k], kInk, ts);
  }
}

}  // namespace

Image render_plot(const PlotSpec& spec, int width, int height) {
  check_plot_inputs(spec, width, height);
  // Data extent over the drawable points.
  Range xr, yr;
  for (const Series& s : spec.series)
    for (std::size_t i = 0; i < s.x.size(); ++i)
      if (drawable(s.x[i], s.y[i], spec.log_y)) {
        xr.add(s.x[i]);
        yr.add(s.y[i]);
      }
  const PlotLayout layout = layout_plot(spec, width, height, xr, yr);
  Image img(width, height, kWhite);
  draw_grid(img, layout);
  draw_series(img, spec, layout);
  draw_frame_and_text(img, spec, layout, xr.valid());
  if (!spec.series.empty()) draw_legend(img, spec, layout);
  return img;
}

}  // namespace sph
