#include <sph/render/compose.h>

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include <sph/render/font.h>

namespace sph {

namespace {

/// Dark text on light backgrounds, light text on dark ones.
Rgb ink_for(Rgb background) {
  const double luma = 0.2126 * background.r + 0.7152 * background.g + 0.0722 * background.b;
  return luma > 128.0 ? Rgb{40, 40, 40} : Rgb{225, 225, 225};
}

/// A short label for a color-bar value: whole numbers from 1000 to 999999, otherwise 3
/// significant digits with a compact exponent ("1.5e-5").
std::string format_value(double v) {
  if (v == 0.0) return "0";
  const double a = std::abs(v);
  if (a >= 1e3 && a < 1e6) return fmt::format("{:.0f}", v);
  std::string s = fmt::format("{:.3g}", v);
  const auto e = s.find('e');
  if (e != std::string::npos) {
    std::string exp = s.substr(e + 1);
    const bool neg = exp[0] == '-';
    exp.erase(0, 1);
    exp.erase(0, std::min(exp.find_first_not_of('0'), exp.size() - 1));
    s = s.substr(0, e) + "e" + (neg ? "-" : "") + exp;
  }
  return s;
}

}  // namespace

Image add_colorbar(const Image& image, Colormap map, double lo, double hi, std::string_view label, Rgb background) {
  const int ts = image.height() >= 380 ? 2 : 1;
  const int pad = 5 * ts;
  const int th = text_height(ts);
  const int bar_w = 10 * ts;
  const int tick = 3 * ts;

  const bool single = !(lo != hi);
  const std::string labels[3] = {format_value(hi), format_value(0.5 * (lo + hi)), format_value(lo)};
  int label_w = 0;
  for (const auto& l : labels) label_w = std::max(label_w, text_width(l, ts));
  const int strip_w = pad + bar_w + tick + pad / 2 + label_w + (label.empty() ? 0 : pad + th) + pad;

  const int height = image.height();
  Image out(image.width() + strip_w, std::max(height, 1), background);
  out.blit(image, 0, 0);

  // The bar spans most of the height, leaving room for the end labels.
  const int bar_h = std::max(2, std::min(height - 2 * th, static_cast<int>(std::lround(height * 0.7))));
  const int bar_y = (height - bar_h) / 2;
  const int bar_x = image.width() + pad;
  for (int y = 0; y < bar_h; ++y) {
    const double t = bar_h > 1 ? 1.0 - static_cast<double>(y) / (bar_h - 1) : 0.5;
    out.fill_rect(bar_x, bar_y + y, bar_w, 1, colormap(map, t));
  }
  const Rgb ink = ink_for(background);
  out.draw_rect(bar_x - 1, bar_y - 1, bar_w + 2, bar_h + 2, ink);

  // Ticks at hi (top), mid and lo (bottom); one label when the range is empty.
  const int tick_y[3] = {bar_y, bar_y + bar_h / 2, bar_y + bar_h - 1};
  const int text_x = bar_x + bar_w + 1 + tick + pad / 2;
  for (int k = 0; k < 3; ++k) {
    if (single && k != 1) continue;
    out.fill_rect(bar_x + bar_w + 1, tick_y[k], tick, 1, ink);
    draw_text(out, text_x, tick_y[k] - th * 7 / 18, single ? format_value(lo) : labels[k], ink, ts);
  }
  if (!label.empty()) {
    const int len = text_width(label, ts);
    draw_text_vertical(out, text_x + label_w + pad, std::max(0, bar_y + (bar_h - len) / 2), label, ink, ts);
  }
  return out;
}

Image hstack(std::span<const Image> panels, std::span<const std::string> captions, Rgb background) {
  if (panels.empty()) return Image();
  int max_h = 0;
  int total_w = 0;
  for (const Image& p : panels) {
    max_h = std::max(max_h, p.height());
    total_w += p.width();
  }
  const int ts = max_h >= 300 ? 2 : 1;
  const int gap = 6 * ts;
  const int th = text_height(ts);
  bool any_caption = false;
  for (std::size_t k = 0; k < panels.size() && k < captions.size(); ++k)
    any_caption = any_caption || !captions[k].empty();
  const int band = any_caption ? th + 2 * gap : 0;
  total_w += gap * static_cast<int>(panels.size() - 1);

  Image out(std::max(total_w, 1), std::max(band + max_h, 1), background);
  const Rgb ink = ink_for(background);
  int x = 0;
  for (std::size_t k = 0; k < panels.size(); ++k) {
    const Image& p = panels[k];
    if (k < captions.size() && !captions[k].empty()) {
      const int w = text_width(captions[k], ts);
      draw_text(out, x + std::max(0, (p.width() - w) / 2), gap, captions[k], ink, ts);
    }
    out.blit(p, x, band);
    x += p.width() + gap;
  }
  return out;
}

}  // namespace sph
