#pragma once
/// \file RGB8 raster images and the drawing primitives the render layer builds on: pixels,
/// alpha blending, rectangles, anti-aliased thick lines and discs, copying one image into another.
/// Every drawing call clips to the image: coordinates outside it are silently ignored.
/// Pixel (x, y) covers the square [x, x+1) x [y, y+1); x grows to the right, y grows downwards.

#include <cstdint>
#include <span>
#include <vector>

namespace sph {

/// An 8-bit sRGB color.
struct Rgb {
  std::uint8_t r = 0, g = 0, b = 0;
  friend bool operator==(const Rgb&, const Rgb&) = default;
};

/// The dark grey of text, ticks and labels in every picture.
inline constexpr Rgb kInk{40, 40, 40};

/// Linear interpolation between two colors: `t = 0` gives `a`, `t = 1` gives `b` (t is clamped).
Rgb mix(Rgb a, Rgb b, double t);
/// The color scaled by `factor` (clamped to [0, 255] per channel).
Rgb scaled(Rgb c, double factor);

/// A width x height grid of RGB pixels, row-major, top row first.
class Image {
 public:
  /// An empty 0 x 0 image.
  Image() = default;
  /// A width x height image filled with `background`. Precondition: 0 <= width, height <= 32768.
  Image(int width, int height, Rgb background = {255, 255, 255});

  int width() const { return width_; }
  int height() const { return height_; }
  bool empty() const { return width_ == 0 || height_ == 0; }
  /// True if (x, y) is a pixel of the image.
  bool contains(int x, int y) const { return x >= 0 && y >= 0 && x < width_ && y < height_; }

  /// The pixel at (x, y). Precondition: contains(x, y).
  Rgb at(int x, int y) const;
  /// Sets the pixel at (x, y); ignored outside the image.
  void set(int x, int y, Rgb c);
  /// Blends `c` over the pixel at (x, y) with opacity `alpha` (clamped to [0, 1]); ignored outside.
  void blend(int x, int y, Rgb c, double alpha);
  /// Fills every pixel with `c`.
  void fill(Rgb c);
  /// Fills the w x h rectangle whose top-left pixel is (x, y), clipped to the image.
  void fill_rect(int x, int y, int w, int h, Rgb c);
  /// Blends `c` with opacity `alpha` over the w x h rectangle at (x, y), clipped to the image.
  void blend_rect(int x, int y, int w, int h, Rgb c, double alpha);
  /// Draws the 1-pixel outline of the w x h rectangle at (x, y) (inside that rectangle).
  void draw_rect(int x, int y, int w, int h, Rgb c);
  /// Draws an anti-aliased line with round caps from (x0, y0) to (x1, y1) in pixel coordinates
  /// (pixel centers are at +0.5), `thickness` pixels wide (at least 1 pixel of coverage).
  void draw_line(double x0, double y0, double x1, double y1, Rgb c, double thickness = 1.0);
  /// Fills an anti-aliased disc of radius `r` pixels centered at (cx, cy) in pixel coordinates.
  void fill_disc(double cx, double cy, double r, Rgb c);
  /// Copies `src` so that its top-left pixel lands on (x, y), clipped to this image.
  void blit(const Image& src, int x, int y);

  /// Row y of the image (width pixels), for fast loops. Precondition: 0 <= y < height.
  std::span<Rgb> row(int y);
  std::span<const Rgb> row(int y) const;

  /// All pixels, row-major (pixel (x, y) is element y * width + x).
  std::span<const Rgb> pixels() const { return pixels_; }
  /// The same, as 3 * width * height bytes R, G, B, R, ...
  std::span<const std::uint8_t> bytes() const;

  friend bool operator==(const Image&, const Image&) = default;

 private:
  Rgb& ref(int x, int y) { return pixels_[static_cast<std::size_t>(y) * width_ + x]; }

  int width_ = 0;
  int height_ = 0;
  std::vector<Rgb> pixels_;
};

namespace detail {
/// floor(v) and ceil(v) clamped to [lo, hi] without overflow (NaN gives lo), for turning
/// coordinates that may be huge into pixel indices.
int floor_clamped(double v, int lo, int hi);
int ceil_clamped(double v, int lo, int hi);
}  // namespace detail

}  // namespace sph
