#pragma once
/// \file Putting images together: a color bar beside an image, panels side by side with captions.

#include <span>
#include <string>
#include <string_view>

#include <sph/render/colormap.h>
#include <sph/render/image.h>

namespace sph {

/// A copy of `image` widened on the right by a strip with a vertical color bar for `map` over
/// [lo, hi] (lo at the bottom), tick labels for lo, the midpoint and hi, and `label` written
/// upwards beside it (omitted when empty). The strip has the color of `background`.
Image add_colorbar(const Image& image, Colormap map, double lo, double hi, std::string_view label,
                   Rgb background = {255, 255, 255});

/// The panels side by side, top-aligned, separated by a gap, each under its caption (centered
/// above it). `captions[k]` belongs to `panels[k]`; missing or empty captions leave no text, and
/// with no caption at all there is no caption row. Zero panels give an empty image.
Image hstack(std::span<const Image> panels, std::span<const std::string> captions, Rgb background = {255, 255, 255});

}  // namespace sph
