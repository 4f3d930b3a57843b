#include <sph/render/colormap.h>

#include <array>
#include <cmath>
#include <span>

namespace sph {

namespace {

struct Stop {
  double t;
  Rgb c;
};

// Control points sampled by eye from the published maps and interpolated linearly in sRGB.
// Viridis (van der Walt & Smith): luminance rises monotonically from stop to stop.
constexpr std::array<Stop, 10> kViridis = {{
    {0.0, {68, 1, 84}},
    {0.125, {71, 40, 120}},
    {0.25, {62, 74, 137}},
    {0.375, {49, 104, 142}},
    {0.5, {38, 130, 142}},
    {0.625, {31, 158, 137}},
    {0.75, {53, 183, 121}},
    {0.875, {109, 205, 89}},
    {0.9375, {180, 222, 44}},
    {1.0, {253, 231, 37}},
}};

// Coolwarm (Moreland's diverging map).
constexpr std::array<Stop, 9> kCoolwarm = {{
    {0.0, {59, 76, 192}},
    {0.125, {98, 130, 234}},
    {0.25, {141, 176, 254}},
    {0.375, {184, 208, 249}},
    {0.5, {221, 221, 221}},
    {0.625, {245, 196, 173}},
    {0.75, {244, 154, 123}},
    {0.875, {222, 96, 77}},
    {1.0, {180, 4, 38}},
}};

// Turbo (Mikhailov's improved rainbow).
constexpr std::array<Stop, 16> kTurbo = {{
    {0.0, {48, 18, 59}},
    {0.0667, {65, 69, 171}},
    {0.1333, {70, 117, 237}},
    {0.2, {57, 162, 252}},
    {0.2667, {27, 207, 212}},
    {0.3333, {36, 236, 166}},
    {0.4, {97, 252, 108}},
    {0.4667, {164, 252, 59}},
    {0.5333, {209, 232, 52}},
    {0.6, {243, 198, 58}},
    {0.6667, {254, 155, 45}},
    {0.7333, {243, 99, 21}},
    {0.8, {217, 56, 6}},
    {0.8667, {177, 25, 1}},
    {0.9333, {137, 9, 1}},
    {1.0, {122, 4, 3}},
}};

std::span<const Stop> stops(Colormap map) {
  switch (map) {
    case Colormap::Viridis:
      return kViridis;
    case Colormap::Coolwarm:
      return kCoolwarm;
    case Colormap::Turbo:
      return kTurbo;
  }
  return kViridis;
}

// Okabe-Ito palette, reordered so that the first colors are the most distinct on white;
// their yellow is replaced by a dark gray, which reads better as a thin line on white.
constexpr std::array<Rgb, 8> kSeries = {{
    {0, 114, 178},    // blue
    {213, 94, 0},     // vermillion
    {0, 158, 115},    // bluish green
    {204, 121, 167},  // reddish purple
    {230, 159, 0},    // orange
    {86, 180, 233},   // sky blue
    {0, 0, 0},        // black
    {120, 120, 120},  // gray
}};

}  // namespace

Rgb colormap(Colormap map, double t) {
  const auto s = stops(map);
  if (!(t > 0.0)) return s.front().c;  // also NaN
  if (t >= 1.0) return s.back().c;
  std::size_t i = 1;
  while (i + 1 < s.size() && s[i].t < t) ++i;
  return mix(s[i - 1].c, s[i].c, (t - s[i - 1].t) / (s[i].t - s[i - 1].t));
}

Rgb colormap(Colormap map, double value, double lo, double hi, Rgb nan_color) {
  if (std::isnan(value)) return nan_color;
  if (!(lo != hi) || !std::isfinite(hi - lo)) return colormap(map, 0.5);
  return colormap(map, (value - lo) / (hi - lo));
}

std::string_view colormap_name(Colormap map) {
  const auto k = static_cast<std::size_t>(map);
  if (k < std::size(kColormapNames)) return kColormapNames[k];
  return "viridis";
}

std::optional<Colormap> colormap_from_name(std::string_view name) {
  static_assert(std::size(kColormapNames) == static_cast<std::size_t>(Colormap::Turbo) + 1, "a name per map");
  for (std::size_t k = 0; k < std::size(kColormapNames); ++k)
    if (kColormapNames[k] == name) return static_cast<Colormap>(k);
  return std::nullopt;
}

Rgb series_color(int k) {
  const int n = static_cast<int>(kSeries.size());
  return kSeries[static_cast<std::size_t>(((k % n) + n) % n)];
}

}  // namespace sph
