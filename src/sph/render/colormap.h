#pragma once
/// \file Color maps for scalar fields (piecewise-linear approximations of well-known perceptual
/// maps) and a categorical palette for plot series.

#include <optional>
#include <string_view>

#include <sph/render/image.h>

namespace sph {

enum class Colormap {
  Viridis,   ///< sequential, dark purple -> blue -> green -> yellow; luminance increases monotonically
  Coolwarm,  ///< diverging, blue -> light gray -> red (for signed quantities around a midpoint)
  Turbo,     ///< rainbow-like, dark blue -> cyan -> green -> yellow -> red -> dark red; high contrast
};

/// The color of `t` in the map; t is clamped to [0, 1] (NaN gives the color of 0).
Rgb colormap(Colormap map, double t);

/// The color of `value` on the map stretched over [lo, hi] (lo > hi reverses it; lo == hi gives
/// the middle color). NaN values give `nan_color`.
Rgb colormap(Colormap map, double value, double lo, double hi, Rgb nan_color = {128, 128, 128});

/// The map's name in lowercase ("viridis", "coolwarm", "turbo").
std::string_view colormap_name(Colormap map);

/// The map with this (lowercase) name, or nullopt.
std::optional<Colormap> colormap_from_name(std::string_view name);
/// Every map's name, in the enum's order.
inline constexpr std::string_view kColormapNames[] = {"viridis", "coolwarm", "turbo"};

/// Color k of a categorical palette for series on a white background: distinct hues that stay
/// distinguishable for the common forms of color blindness (after Okabe & Ito), repeating after 8.
Rgb series_color(int k);

}  // namespace sph
