#include <sph/render/image.h>

#include <algorithm>
#include <cmath>

#include <sph/core/error.h>

namespace sph {

static_assert(sizeof(Rgb) == 3 && alignof(Rgb) == 1, "pixels are stored as packed RGB bytes");

namespace {

constexpr int kMaxSide = 32768;

/// Rounded to the nearest byte, clamped (NaN gives 0). The same as lround for every value in
/// range, without its library call: this runs for every anti-aliased pixel of a render.
std::uint8_t to_byte(double v) {
  if (!(v > 0.0)) return 0;
  if (v >= 255.0) return 255;
  return static_cast<std::uint8_t>(v + 0.5);
}

double clamp01(double t) { return std::isnan(t) ? 0.0 : std::clamp(t, 0.0, 1.0); }

/// Distance from point p to the segment a-b (a point when a == b).
double segment_distance(double px, double py, double ax, double ay, double bx, double by) {
  const double dx = bx - ax, dy = by - ay;
  const double len2 = dx * dx + dy * dy;
  double t = 0.0;
  if (len2 > 0.0) t = std::clamp(((px - ax) * dx + (py - ay) * dy) / len2, 0.0, 1.0);
  const double ex = px - (ax + t * dx), ey = py - (ay + t * dy);
  return std::sqrt(ex * ex + ey * ey);
}

}  // namespace

namespace detail {
int floor_clamped(double v, int lo, int hi) {
  if (!(v >= lo)) return lo;
  if (v >= hi) return hi;
  return static_cast<int>(std::floor(v));
}
int ceil_clamped(double v, int lo, int hi) {
  if (!(v >= lo)) return lo;
  if (v >= hi) return hi;
  return static_cast<int>(std::ceil(v));
}
}  // namespace detail

Rgb mix(Rgb a, Rgb b, double t) {
  t = clamp01(t);
  return {to_byte(a.r + (b.r - a.r) * t), to_byte(a.g + (b.g - a.g) * t), to_byte(a.b + (b.b - a.b) * t)};
}

Rgb scaled(Rgb c, double factor) { return {to_byte(c.r * factor), to_byte(c.g * factor), to_byte(c.b * factor)}; }

Image::Image(int width, int height, Rgb background) : width_(width), height_(height) {
  SPH_CHECK(width >= 0 && height >= 0 && width <= kMaxSide && height <= kMaxSide,
            "image size " + std::to_string(width) + " x " + std::to_string(height) + " out of range");
  pixels_.assign(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), background);
}

Rgb Image::at(int x, int y) const {
  SPH_CHECK(contains(x, y), "pixel (" + std::to_string(x) + ", " + std::to_string(y) + ") outside the image");
  return pixels_[static_cast<std::size_t>(y) * width_ + x];
}

void Image::set(int x, int y, Rgb c) {
  if (contains(x, y)) ref(x, y) = c;
}

void Image::blend(int x, int y, Rgb c, double alpha) {
  if (!contains(x, y)) return;
  alpha = clamp01(alpha);
  if (alpha <= 0.0) return;
  Rgb& p = ref(x, y);
  p = alpha >= 1.0 ? c : mix(p, c, alpha);
}

void Image::fill(Rgb c) { std::fill(pixels_.begin(), pixels_.end(), c); }

void Image::fill_rect(int x, int y, int w, int h, Rgb c) { blend_rect(x, y, w, h, c, 1.0); }

void Image::blend_rect(int x, int y, int w, int h, Rgb c, double alpha) {
  const int x0 = std::max(x, 0), y0 = std::max(y, 0);
  const int x1 = static_cast<int>(std::min<long>(static_cast<long>(x) + w, width_));
  const int y1 = static_cast<int>(std::min<long>(static_cast<long>(y) + h, height_));
  for (int yy = y0; yy < y1; ++yy)
    for (int xx = x0; xx < x1; ++xx) blend(xx, yy, c, alpha);
}

void Image::draw_rect(int x, int y, int w, int h, Rgb c) {
  if (w <= 0 || h <= 0) return;
  fill_rect(x, y, w, 1, c);
  fill_rect(x, y + h - 1, w, 1, c);
  fill_rect(x, y, 1, h, c);
  fill_rect(x + w - 1, y, 1, h, c);
}

void Image::draw_line(double x0, double y0, double x1, double y1, Rgb c, double thickness) {
  if (!std::isfinite(x0) || !std::isfinite(y0) || !std::isfinite(x1) || !std::isfinite(y1)) return;
  if (empty()) return;
  const double half = std::max(std::isfinite(thickness) ? thickness : 1.0, 1.0) / 2.0;
  const double reach = half + 0.5;  // beyond this distance from the segment a pixel gets no ink
  // Clip the segment to the image grown by `reach` (Liang-Barsky), so that huge coordinates
  // become small ones before any squaring. A clipped end is put exactly on the clipping edge.
  {
    const double ex = x1 - x0, ey = y1 - y0;
    const double edge[4] = {-reach, width_ + reach, -reach, height_ + reach};  // x min, x max, y min, y max
    const double p[4] = {-ex, ex, -ey, ey};
    const double q[4] = {x0 - edge[0], edge[1] - x0, y0 - edge[2], edge[3] - y0};
    double t0 = 0.0, t1 = 1.0;
    int k0 = -1, k1 = -1;
    for (int k = 0; k < 4; ++k) {
      if (p[k] == 0.0) {
        if (q[k] < 0.0) return;  // parallel to this edge and outside it
        continue;
      }
      const double t = q[k] / p[k];
      if (p[k] < 0.0 && t > t0) {
        t0 = t;
        k0 = k;
      } else if (p[k] > 0.0 && t < t1) {
        t1 = t;
        k1 = k;
      }
    }
    if (t0 > t1) return;
    auto on_edge = [&](int k, double& x, double& y) {
      if (k < 2) {
        x = edge[k];
        y = y0 + (edge[k] - x0) * (ey / ex);
      } else {
        y = edge[k];
        x = x0 + (edge[k] - y0) * (ex / ey);
      }
    };
    double ax = x0, ay = y0, bx = x1, by = y1;
    if (k0 >= 0) on_edge(k0, ax, ay);
    if (k1 >= 0) on_edge(k1, bx, by);
    x0 = ax;
    y0 = ay;
    x1 = bx;
    y1 = by;
  }
  // Rows the capsule can touch, clipped to the image.
  const int ya = detail::floor_clamped(std::min(y0, y1) - reach, 0, height_);
  const int yb = detail::ceil_clamped(std::max(y0, y1) + reach, -1, height_ - 1);
  const double bx_lo = std::min(x0, x1) - reach, bx_hi = std::max(x0, x1) + reach;
  const double dx = x1 - x0, dy = y1 - y0;
  const double len = std::sqrt(dx * dx + dy * dy);
  for (int y = ya; y <= yb; ++y) {
    const double yc = y + 0.5;
    double lo = bx_lo, hi = bx_hi;
    if (std::abs(dy) > 1e-9 * std::max(1.0, len)) {
      // Points of this row within `reach` of the infinite line through the segment.
      double u = x0 + ((yc - y0) * dx - reach * len) / dy;
      double v = x0 + ((yc - y0) * dx + reach * len) / dy;
      if (u > v) std::swap(u, v);
      lo = std::max(lo, u);
      hi = std::min(hi, v);
    }
    if (lo > hi) continue;
    const int xa = detail::floor_clamped(lo - 0.5, 0, width_);
    const int xb = detail::ceil_clamped(hi - 0.5, -1, width_ - 1);
    for (int x = xa; x <= xb; ++x) {
      const double d = segment_distance(x + 0.5, yc, x0, y0, x1, y1);
      const double coverage = half + 0.5 - d;
      if (coverage > 0.0) blend(x, y, c, coverage);
    }
  }
}

void Image::fill_disc(double cx, double cy, double r, Rgb c) {
  if (!std::isfinite(cx) || !std::isfinite(cy) || !std::isfinite(r) || r <= 0.0 || empty()) return;
  const double reach = r + 0.5;
  const int ya = detail::floor_clamped(cy - reach, 0, height_);
  const int yb = detail::ceil_clamped(cy + reach, -1, height_ - 1);
  for (int y = ya; y <= yb; ++y) {
    const double ey = y + 0.5 - cy;
    if (std::abs(ey) >= reach) continue;
    const double w = std::sqrt(reach * reach - ey * ey);
    const int xa = detail::floor_clamped(cx - w, 0, width_);
    const int xb = detail::ceil_clamped(cx + w, -1, width_ - 1);
    for (int x = xa; x <= xb; ++x) {
      const double ex = x + 0.5 - cx;
      const double coverage = reach - std::sqrt(ex * ex + ey * ey);
      if (coverage > 0.0) blend(x, y, c, coverage);
    }
  }
}

void Image::blit(const Image& src, int x, int y) {
  const int sx0 = std::max(0, -x), sy0 = std::max(0, -y);
  const int sx1 = std::min(src.width_, width_ - x), sy1 = std::min(src.height_, height_ - y);
  if (sx0 >= sx1) return;
  for (int sy = sy0; sy < sy1; ++sy) {
    const auto row = src.pixels_.begin() + static_cast<std::ptrdiff_t>(sy) * src.width_;
    std::copy(row + sx0, row + sx1, pixels_.begin() + (static_cast<std::ptrdiff_t>(y + sy) * width_ + x + sx0));
  }
}

std::span<Rgb> Image::row(int y) {
  SPH_CHECK(y >= 0 && y < height_, "row " + std::to_string(y) + " outside the image");
  return {pixels_.data() + static_cast<std::size_t>(y) * width_, static_cast<std::size_t>(width_)};
}

std::span<const Rgb> Image::row(int y) const {
  SPH_CHECK(y >= 0 && y < height_, "row " + std::to_string(y) + " outside the image");
  return {pixels_.data() + static_cast<std::size_t>(y) * width_, static_cast<std::size_t>(width_)};
}

std::span<const std::uint8_t> Image::bytes() const {
  return {reinterpret_cast<const std::uint8_t*>(pixels_.data()), pixels_.size() * 3};
}

}  // namespace sph
