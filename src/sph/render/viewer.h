#pragma once
/// \file The browser viewer of `sph view`: one self-contained HTML page (no network, no
/// libraries) that plays a run, or the runs of a compare directory side by side, in 3D. The
/// page's HTML, CSS and JavaScript (src/sph/render/viewer/) are compiled into the program; the
/// run's frames are inlined, quantized, as base64 (docs/visualization.md).

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <sph/render/color_by.h>
#include <sph/render/view_codec.h>  // the page's encodings (quantization, base64)

namespace sph {

/// What goes into the page.
struct ViewOptions {
  /// Frames kept per run; a run with more is subsampled evenly (first and last kept). At least 2.
  std::size_t max_frames = 300;
  /// The quantities the page offers, the first one shown first; empty: every quantity the
  /// frames hold (speed first).
  std::vector<ColorBy> color_by;
  /// A page larger than this (bytes) is refused before the frames are read, with a message
  /// naming the options that make it smaller.
  std::size_t max_bytes = std::size_t{200} << 20;
  /// Written into the page's generator tag (the program and its version).
  std::string generator = "sph";
};

/// The page and what it shows.
struct ViewPage {
  std::string html;
  std::size_t runs = 0;            ///< panels (1 for a run directory)
  std::size_t frames_total = 0;    ///< frames of the first run on disk
  std::size_t frames_shown = 0;    ///< frames of the first run in the page
  std::size_t max_particles = 0;   ///< the most particles of any frame shown
  std::vector<std::string> notes;  ///< what the page says about subsampling (also shown on the page)
};

/// Builds the page for `dir`: a run directory (`sph run -o DIR`) or a compare directory (`sph
/// compare -o DIR`, one panel per run in its order). Throws sph::Error naming the path or the
/// option if `dir` is neither, a run holds no frames, a frame cannot be read, a quantity of
/// `options.color_by` needs a field the frames do not hold, or the page would exceed
/// `options.max_bytes`.
ViewPage build_view_page(const std::filesystem::path& dir, const ViewOptions& options);

/// The indices of at most `max_frames` (>= 2) of `total` frames, evenly spaced, ascending, the
/// first and the last included; all of them if total <= max_frames.
std::vector<std::size_t> subsample_frames(std::size_t total, std::size_t max_frames);

/// The JSON data block of a page built by build_view_page (for tests and tools); throws
/// sph::Error if `html` holds none.
std::string view_page_data(std::string_view html);

}  // namespace sph
