#pragma once
/// \file Line plots (time series, convergence curves) rendered straight to an image.

#include <string>
#include <vector>

#include <sph/render/image.h>

namespace sph {

/// One line of a plot. Points are (x[i], y[i]); a point with a NaN or infinite coordinate (or,
/// on a log axis, y <= 0) is not drawn and breaks the line. A point with no drawn neighbor is
/// drawn as a dot.
struct Series {
  std::string name;  ///< shown in the legend ("series k" when empty)
  std::vector<double> x, y;
  Rgb color;  ///< e.g. series_color(k) from <sph/render/colormap.h>
  bool dashed = false;
};

struct PlotSpec {
  std::string title, x_label, y_label;  ///< each may be empty
  bool log_y = false;                   ///< logarithmic y axis with a tick per decade
  std::vector<Series> series;
};

/// Renders the plot on a white background: a framed plot area with light gray grid lines at
/// "nice" ticks (1, 2, 5 x 10^k; decades on a log axis), tick labels, axis labels, the title, and
/// a legend box naming every series (placed in the corner of the plot area with the least data).
/// The axes span all drawable points of all series; with none at all, the plot says "no data".
/// Throws sph::Error if width < 160 or height < 120, or if a series has x and y of unequal sizes.
Image render_plot(const PlotSpec& spec, int width = 900, int height = 560);

}  // namespace sph
