#include <sph/render/viewer.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <utility>

#include <fmt/format.h>

#include <sph/core/error.h>
#include <sph/io/frames.h>
#include <sph/render/colormap.h>
#include <sph/render/frame_image.h>

namespace sph {

namespace detail {
// The page's sources, compiled in by cmake/embed_files.cmake (viewer_assets.cpp, generated).
std::string_view viewer_html();
std::string_view viewer_css();
std::string_view viewer_js();
}  // namespace detail

namespace {

namespace fs = std::filesystem;

using detail::append_base64;
using detail::base64_size;
using detail::html_escape;
using detail::json_number;
using detail::json_string;
using detail::little_endian;

/// Positions are quantized over the container grown by a tenth of its largest side, so that
/// spray above the walls and particles pressed into the penalty walls keep their place.
struct QuantBox {
  std::array<double, 3> lo{}, hi{};
};

QuantBox quant_box(const RunDirectory& run) {
  double extent = 0;
  for (int d = 0; d < run.dimension; ++d) extent = std::max(extent, run.box_hi[d] - run.box_lo[d]);
  if (!(extent > 0) || !std::isfinite(extent)) extent = 1;
  QuantBox q;
  for (int d = 0; d < 3; ++d) {
    q.lo[d] = run.box_lo[d] - (d < run.dimension ? 0.1 * extent : 0.0);
    q.hi[d] = run.box_hi[d] + (d < run.dimension ? 0.1 * extent : 0.0);
    if (!(q.hi[d] > q.lo[d])) q.hi[d] = q.lo[d] + 1;  // z in 2D: never stored
  }
  return q;
}

/// One frame as the page stores it, before the scalars are quantized (their range is run-wide).
struct EncodedFrame {
  double time = 0;
  std::size_t size = 0;
  std::vector<std::uint16_t> position;     ///< dim per particle
  std::vector<std::vector<float>> values;  ///< per offered scalar quantity
  std::vector<std::uint8_t> rgb;           ///< initial-position colors, when per frame
  std::vector<SolidBox> obstacles;         ///< where the obstacles are, when some obstacle moves
};

struct EncodedRun {
  std::string label;
  std::vector<EncodedFrame> frames;
  std::vector<std::uint8_t> rgb;  ///< initial-position colors by particle index, when shared
  bool rgb_per_frame = false;
};

/// Replaces each @SPH_NAME@ marker of the template by its text, in one pass (inserted text is
/// never scanned again, so data that happens to contain a marker is left alone).
std::string fill_template(std::string_view tpl,
                          const std::vector<std::pair<std::string_view, std::string_view>>& parts) {
  std::size_t total = tpl.size();
  for (const auto& p : parts) total += p.second.size();
  std::string out;
  out.reserve(total);
  std::size_t at = 0;
  while (true) {
    const std::size_t m = tpl.find("@SPH_", at);
    if (m == std::string_view::npos) break;
    const std::size_t end = tpl.find('@', m + 1);
    SPH_CHECK(end != std::string_view::npos, "unterminated marker in viewer.html");
    const std::string_view name = tpl.substr(m + 1, end - m - 1);
    const auto it = std::find_if(parts.begin(), parts.end(), [&](const auto& p) { return p.first == name; });
    if (it == parts.end()) {  // not a marker (e.g. prose in a comment): keep it
      out.append(tpl.substr(at, end - at));
      at = end;
      continue;
    }
    out.append(tpl.substr(at, m - at));
    out.append(it->second);
    at = end + 1;
  }
  out.append(tpl.substr(at));
  return out;
}

/// Frames of each run the page keeps.
std::vector<std::vector<std::size_t>> pick_frames(const std::vector<RunDirectory>& runs, std::size_t max_frames) {
  std::vector<std::vector<std::size_t>> picks;
  for (const RunDirectory& r : runs) picks.push_back(subsample_frames(r.frames.size(), max_frames));
  return picks;
}

/// The quantities offered: those asked for (each must be in the frames), or all the frames hold.
std::vector<ColorBy> offered_quantities(const std::vector<ColorBy>& asked, const std::vector<RunDirectory>& runs,
                                        const std::vector<FrameData>& first_frames) {
  const auto held = [&](ColorBy by) {
    for (const FrameData& f : first_frames)
      if (f.field(color_by_field(by)) == nullptr) return false;
    return true;
  };
  std::vector<ColorBy> out;
  if (!asked.empty()) {
    for (ColorBy by : asked) {
      if (!held(by)) {
        std::size_t k = 0;
        while (first_frames[k].field(color_by_field(by)) != nullptr) ++k;
        throw Error(fmt::format("the frames of {} hold no '{}' field, which coloring by {} needs; run the scene with "
                                "that field in Configuration.outputFields, or choose another quantity",
                                runs[k].dir.string(), color_by_field(by), color_by_name(by)),
                    "--color-by");
      }
      if (std::find(out.begin(), out.end(), by) == out.end()) out.push_back(by);
    }
    return out;
  }
  for (ColorBy by : kColorByAll)
    if (held(by)) out.push_back(by);
  return out;
}

}  // namespace

std::vector<std::size_t> subsample_frames(std::size_t total, std::size_t max_frames) {
  SPH_CHECK(max_frames >= 2, "max_frames must be at least 2");
  std::vector<std::size_t> idx;
  if (total <= max_frames) {
    idx.resize(total);
    std::iota(idx.begin(), idx.end(), std::size_t{0});
    return idx;
  }
  // Evenly spaced over [0, total - 1]: distinct, since the spacing exceeds 1.
  for (std::size_t k = 0; k < max_frames; ++k)
    idx.push_back(static_cast<std::size_t>(
        std::llround(static_cast<double>(k) * static_cast<double>(total - 1) / static_cast<double>(max_frames - 1))));
  return idx;
}

std::string view_page_data(std::string_view html) {
  const std::string_view open = "<script id=\"sph-data\" type=\"application/json\">";
  const std::size_t a = html.find(open);
  const std::size_t b = a == std::string_view::npos ? a : html.find("</script>", a);
  if (b == std::string_view::npos) throw Error("not a page of sph view: it holds no sph-data block");
  return std::string(html.substr(a + open.size(), b - a - open.size()));
}

namespace {

/// The runs of `dir` (one, or each run of a compare directory), all of one dimension.
std::vector<RunDirectory> open_runs(const fs::path& dir) {
  std::vector<RunDirectory> runs;
  for (const fs::path& d : run_directories(dir)) runs.push_back(open_run_directory(d));
  const int dim = runs.front().dimension;
  for (const RunDirectory& r : runs)
    if (r.dimension != dim)
      throw Error(fmt::format("its runs mix {}D and {}D scenes; expected runs of one scene", dim, r.dimension),
                  dir.string());
  return runs;
}

/// The colorings the page offers: all of them in order (the first is the default), the scalar
/// ones, and whether the initial-position colors are among them.
struct PageQuantities {
  std::vector<ColorBy> all;
  std::vector<ColorBy> scalars;
  bool rgb = false;
};

PageQuantities page_quantities(const std::vector<ColorBy>& asked, const std::vector<RunDirectory>& runs,
                               const std::vector<FrameData>& first_frames) {
  PageQuantities q;
  q.all = offered_quantities(asked, runs, first_frames);
  for (ColorBy by : q.all) {
    if (color_by_is_scalar(by))
      q.scalars.push_back(by);
    else
      q.rgb = true;
  }
  return q;
}

/// Refuses, before the frames are read, a page whose estimated size is above options.max_bytes.
void check_page_estimate(const fs::path& dir, const ViewOptions& options,
                         const std::vector<std::vector<std::size_t>>& picks, const PageQuantities& q, int dim,
                         std::size_t max_particles, std::size_t pose_bytes, std::size_t shape_bytes) {
  const std::size_t runs = picks.size();
  std::size_t frames = 0;
  for (const auto& p : picks) frames += p.size();
  const std::size_t per_particle = 2 * static_cast<std::size_t>(dim) + q.scalars.size();
  // What each frame adds, and what the page holds whatever the frames.
  const std::size_t per_frame = base64_size(per_particle * max_particles) + 100 + pose_bytes;
  const std::size_t fixed = (q.rgb ? base64_size(3 * max_particles) * runs : 0) + shape_bytes +
                            detail::viewer_html().size() + detail::viewer_css().size() + detail::viewer_js().size();
  const std::size_t estimate = per_frame * frames + fixed;
  if (estimate <= options.max_bytes) return;
  // --max-frames keeps up to N frames of each run.
  const std::size_t fit = options.max_bytes > fixed ? (options.max_bytes - fixed) / (per_frame * runs) : 0;
  const std::string what = fmt::format(
      "the page would be about {:.3g} MB ({} frames of up to {} particles), more "
      "than the limit of {:.3g} MB",
      static_cast<double>(estimate) / 1e6, frames, max_particles, static_cast<double>(options.max_bytes) / 1e6);
  if (fit >= 2)
    throw Error(fmt::format("{}; use --max-frames {} (or fewer), fewer quantities with --color-by, or raise the "
                            "limit with --max-size",
                            what, fit),
                dir.string());
  // Not even the least a page shows, two frames of each run, fits: --max-frames cannot help.
  const double least = static_cast<double>(per_frame * 2 * runs + fixed) / 1e6;
  throw Error(fmt::format("{}; even 2 frames of each run (the fewest --max-frames keeps) would be about {:.1f} MB: "
                          "raise the limit with --max-size (to at least {:.0f}), or use fewer quantities with "
                          "--color-by",
                          what, least, std::ceil(least)),
              dir.string());
}

/// Per scalar quantity, the samples of its values its run-wide range is taken from, one
/// vector per encoded frame.
using ScalarSamples = std::vector<std::vector<std::vector<double>>>;

/// One frame with its particles in id order (frames are written in the solver's Morton order,
/// which changes): positions quantized in `qb`, scalars as floats (every `stride`-th value
/// also appended to `samples`), initial-position colors if q.rgb. Clears `ids_dense` unless
/// the frame holds the ids 0..n-1.
EncodedFrame encode_frame(const FrameData& frame, const RunDirectory& run, const QuantBox& qb, const PageQuantities& q,
                          std::size_t stride, ScalarSamples& samples, bool& ids_dense) {
  const std::size_t n = frame.size;
  const int dim = run.dimension;
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t{0});
  if (const FrameField* id = frame.field("id"); id != nullptr && id->values.size() == n) {
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return id->values[a] < id->values[b]; });
    for (std::size_t i = 0; i < n && ids_dense; ++i) ids_dense = id->values[order[i]] == static_cast<double>(i);
  } else {
    ids_dense = false;
  }
  EncodedFrame ef;
  ef.time = frame.time;
  ef.size = n;
  ef.position.resize(n * static_cast<std::size_t>(dim));
  for (std::size_t i = 0; i < n; ++i)
    for (int d = 0; d < dim; ++d)
      ef.position[i * dim + d] = quantize_position(frame.position[3 * order[i] + d], qb.lo[d], qb.hi[d]);
  for (std::size_t s = 0; s < q.scalars.size(); ++s) {
    const std::vector<double> v = color_values(frame, q.scalars[s], run);
    std::vector<float>& out = ef.values.emplace_back(n);
    for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<float>(v[order[i]]);
    std::vector<double>& sample = samples[s].emplace_back();
    for (std::size_t i = 0; i < n; i += stride) sample.push_back(v[i]);
  }
  if (q.rgb) {
    const std::vector<Rgb> c = particle_colors(frame, ColorSpec{ColorBy::InitialPosition}, run);
    ef.rgb.resize(3 * n);
    for (std::size_t i = 0; i < n; ++i) {
      ef.rgb[3 * i] = c[order[i]].r;
      ef.rgb[3 * i + 1] = c[order[i]].g;
      ef.rgb[3 * i + 2] = c[order[i]].b;
    }
  }
  return ef;
}

/// Whether an obstacle of the run's scene moves (its frames then carry the obstacles' poses).
bool obstacles_move(const RunDirectory& run) {
  return run.scene.visit_body([](const auto& body) { return any_obstacle_moves(body.sim); });
}

/// The obstacles' placements in a frame: [[r00, r01, r02, r10, r11, r12, r20, r21, r22, cx, cy,
/// cz, tx, ty, tz], ...], one per obstacle in the scene's order (SolidBox: a point p of the box at
/// rest is at c + t + R (p - c); 2D: the upper-left 2 x 2 of R, z = 0).
std::string poses_json(const std::vector<SolidBox>& obstacles) {
  std::string out = "[";
  for (const SolidBox& b : obstacles) {
    out += out.size() > 1 ? ",[" : "[";
    bool first = true;
    const auto add = [&](double v) {
      out += first ? "" : ",";
      out += json_number(v);
      first = false;
    };
    for (double v : b.rotation) add(v);
    for (double v : b.center) add(v);
    for (double v : b.translation) add(v);
    out += ']';
  }
  out += ']';
  return out;
}

/// The kept frames `picks` of one run, `first` being the first of them, already read; raises
/// `max_particles` to the largest frame.
EncodedRun encode_run(const RunDirectory& run, const std::vector<std::size_t>& picks, FrameData first,
                      const QuantBox& qb, const PageQuantities& q, std::size_t stride, ScalarSamples& samples,
                      std::size_t& max_particles) {
  EncodedRun er;
  er.label = run.label;
  const bool moving = obstacles_move(run);
  bool ids_dense = true;
  std::vector<std::uint8_t> rgb_by_id;
  for (std::size_t k = 0; k < picks.size(); ++k) {
    FrameData frame;
    if (k == 0)
      std::swap(frame, first);  // (read already)
    else
      frame = read_frame(run.frames[picks[k]]);
    EncodedFrame ef = encode_frame(frame, run, qb, q, stride, samples, ids_dense);
    if (moving) ef.obstacles = run_obstacles(run, frame.time);
    if (ef.rgb.size() > rgb_by_id.size()) rgb_by_id = ef.rgb;
    max_particles = std::max(max_particles, frame.size);
    er.frames.push_back(std::move(ef));
  }
  // A particle keeps its id, and so its initial position: when every frame holds ids 0..n-1,
  // one color per id serves all frames.
  if (q.rgb) {
    er.rgb_per_frame = !ids_dense;
    if (ids_dense) {
      er.rgb = std::move(rgb_by_id);
      for (EncodedFrame& f : er.frames) f.rgb.clear();
    }
  }
  return er;
}

/// A scalar quantity's run-wide range, and whether some value lies above it.
struct OfferedScalar {
  ColorBy by;
  double lo = 0, hi = 1;
  bool clipped = false;
};

/// The scalars' ranges, shared by every run of a compare directory so that a color means the
/// same in every panel. Frees the samples.
std::vector<OfferedScalar> scalar_ranges(const std::vector<ColorBy>& scalars, ScalarSamples& samples) {
  std::vector<OfferedScalar> offered;
  for (std::size_t s = 0; s < scalars.size(); ++s) {
    const auto [lo, hi] = color_range(scalars[s], samples[s]);
    offered.push_back({scalars[s], lo, hi, false});
    samples[s].clear();
    samples[s].shrink_to_fit();
  }
  return offered;
}

/// The runs' part of the data block (the bulk): scalars quantized to the ranges of `offered`,
/// whose `clipped` it sets. Frees the encoded frames as it goes.
std::string runs_json(std::vector<EncodedRun>& encoded, std::vector<OfferedScalar>& offered, bool rgb) {
  std::string out = "[";
  for (std::size_t r = 0; r < encoded.size(); ++r) {
    EncodedRun& er = encoded[r];
    out += (r ? ",{" : "{") + std::string("\"label\":") + json_string(er.label);
    if (rgb && !er.rgb_per_frame) {
      out += ",\"rgb\":\"";
      append_base64(out, er.rgb);
      out += '"';
    }
    out += ",\"frames\":[";
    for (std::size_t k = 0; k < er.frames.size(); ++k) {
      EncodedFrame& f = er.frames[k];
      out += fmt::format("{}{{\"t\":{},\"n\":{},\"pos\":\"", k ? "," : "", json_number(f.time), f.size);
      append_base64(out, little_endian(f.position));
      out += "\",\"f\":{";
      for (std::size_t s = 0; s < offered.size(); ++s) {
        std::vector<std::uint8_t> q(f.size);
        for (std::size_t i = 0; i < f.size; ++i) {
          q[i] = quantize_scalar(f.values[s][i], offered[s].lo, offered[s].hi);
          offered[s].clipped = offered[s].clipped || f.values[s][i] > offered[s].hi;
        }
        out += fmt::format("{}\"{}\":\"", s ? "," : "", color_by_name(offered[s].by));
        append_base64(out, q);
        out += '"';
      }
      out += '}';
      if (!f.rgb.empty()) {
        out += ",\"rgb\":\"";
        append_base64(out, f.rgb);
        out += '"';
      }
      if (!f.obstacles.empty()) out += ",\"poses\":" + poses_json(f.obstacles);
      out += '}';
      f = EncodedFrame{};  // free as we go
    }
    out += "]}";
  }
  out += ']';
  return out;
}

/// The page's colorings: each scalar with its range and colormap, the initial-position colors,
/// or one plain color when the frames hold neither.
std::string colors_json(const std::vector<OfferedScalar>& offered, bool rgb, int dim) {
  std::string colors = "[";
  for (const OfferedScalar& o : offered) {
    std::vector<std::uint8_t> lut;
    const Colormap map = default_colormap(o.by);
    for (int i = 0; i < 256; ++i) {
      const Rgb c = colormap(map, i / 255.0);
      lut.insert(lut.end(), {c.r, c.g, c.b});
    }
    colors += fmt::format(
        "{}{{\"name\":\"{}\",\"label\":{},\"scalar\":true,\"lo\":{},\"hi\":{},\"clipped\":{},"
        "\"colormap\":\"{}\",\"lut\":\"{}\"}}",
        colors.size() > 1 ? "," : "", color_by_name(o.by), json_string(color_by_label(o.by, dim)), json_number(o.lo),
        json_number(o.hi), o.clipped ? "true" : "false", colormap_name(map), base64_encode(lut));
  }
  if (rgb)
    colors += fmt::format("{}{{\"name\":\"{}\",\"label\":{},\"scalar\":false}}", colors.size() > 1 ? "," : "",
                          color_by_name(ColorBy::InitialPosition),
                          json_string(color_by_label(ColorBy::InitialPosition, dim)));
  if (offered.empty() && !rgb) {
    // Frames with positions only: one plain color (every particle at the middle of this map).
    const std::vector<std::uint8_t> lut(3 * 256, 0);
    std::vector<std::uint8_t> blue = lut;
    for (int i = 0; i < 256; ++i) blue[3 * i] = 52, blue[3 * i + 1] = 110, blue[3 * i + 2] = 190;
    colors += fmt::format(
        "{{\"name\":\"uniform\",\"label\":\"one color (the frames hold no field to color by)\","
        "\"scalar\":true,\"lo\":0,\"hi\":1,\"clipped\":false,\"lut\":\"{}\"}}",
        base64_encode(blue));
  }
  colors += ']';
  return colors;
}

std::string json_vec3(const std::array<double, 3>& v) {
  return fmt::format("[{},{},{}]", json_number(v[0]), json_number(v[1]), json_number(v[2]));
}

/// The scene's obstacles at rest as [{"lo": [x, y, z], "hi": [x, y, z]}, ...] (z = 0 in 2D), a polygon or
/// mesh with its vertices "v", triangles "f" (3D) and "inv" (inverted); a
/// moving one's frames place them ("poses", poses_json).
std::string obstacles_json(const RunDirectory& run) {
  std::string out = "[";
  for (const SolidBox& b : run_obstacles(run, 0.0)) {
    out += fmt::format("{}{{\"lo\":{},\"hi\":{}", out.size() > 1 ? "," : "", json_vec3(b.lo), json_vec3(b.hi));
    if (!b.vertices.empty()) {  // a polygon or mesh: its vertices at rest ("v"), triangles ("f"), "inv"
      out += ",\"v\":[";
      for (std::size_t i = 0; i < b.vertices.size(); ++i) out += (i ? "," : "") + json_vec3(b.vertices[i]);
      out += "]";
      if (!b.triangles.empty()) {
        out += ",\"f\":[";
        for (std::size_t i = 0; i < b.triangles.size(); ++i)
          out += fmt::format("{}[{},{},{}]", i ? "," : "", b.triangles[i][0], b.triangles[i][1], b.triangles[i][2]);
        out += "]";
      }
      out += fmt::format(",\"inv\":{}", b.inverted);
    }
    out += '}';
  }
  out += ']';
  return out;
}

/// The data block: the header (scene, boxes, obstacles, colorings, notes) around the runs, which
/// are freed.
std::string data_json(const RunDirectory& run0, const std::string& obstacles, const QuantBox& qb,
                      const std::string& colors, const std::string& default_color,
                      const std::vector<std::string>& page_notes, std::string& runs) {
  std::string notes = "[";
  for (const std::string& n : page_notes) notes += (notes.size() > 1 ? "," : "") + json_string(n);
  notes += ']';
  std::string data = fmt::format(
      "{{\"format\":\"sph-view\",\"version\":1,\"title\":{},\"description\":{},\"dimension\":{},"
      "\"box\":{{\"lo\":{},\"hi\":{}}},\"obstacles\":{},\"qbox\":{{\"lo\":{},\"hi\":{}}},\"radius\":{},"
      "\"colors\":{},\"defaultColor\":\"{}\",\"notes\":{},\"runs\":",
      json_string(run0.scene.name), json_string(run0.scene.description), run0.dimension, json_vec3(run0.box_lo),
      json_vec3(run0.box_hi), obstacles, json_vec3(qb.lo), json_vec3(qb.hi), json_number(run0.particle_radius), colors,
      default_color, notes);
  data += runs;
  runs.clear();
  runs.shrink_to_fit();
  data += '}';
  return data;
}

}  // namespace

ViewPage build_view_page(const fs::path& dir, const ViewOptions& options) {
  if (options.max_frames < 2) throw Error("must be at least 2", "--max-frames");
  const std::vector<RunDirectory> runs = open_runs(dir);
  const RunDirectory& run0 = runs.front();
  const auto picks = pick_frames(runs, options.max_frames);

  // First and last frames: the fields the runs hold, and particle counts for the size estimate
  // (refused before the other frames are read; emitters only ever add particles).
  std::vector<FrameData> first_frames;
  std::size_t max_particles = 0;
  for (std::size_t r = 0; r < runs.size(); ++r) {
    first_frames.push_back(read_frame(runs[r].frames[picks[r].front()]));
    max_particles = std::max(max_particles, first_frames.back().size);
    if (picks[r].size() > 1) max_particles = std::max(max_particles, read_frame(runs[r].frames[picks[r].back()]).size);
  }
  const PageQuantities q = page_quantities(options.color_by, runs, first_frames);
  // A scene with moving obstacles places each obstacle in every frame: 15 numbers, at most ~25
  // characters each.
  const std::size_t pose_bytes =
      obstacles_move(run0) ? 400 * run0.scene.visit_body([](const auto& b) { return b.sim.obstacles.size(); }) : 0;
  // The obstacles' shapes (a mesh's every vertex and triangle) go into the page once.
  const std::string obstacles = obstacles_json(run0);
  check_page_estimate(dir, options, picks, q, run0.dimension, max_particles, pose_bytes, obstacles.size());

  // Read every kept frame once: positions quantized now, scalars kept until their run-wide
  // range is known. The range comes from a sample of at most ~4 million values per quantity
  // (a percentile does not need them all).
  std::size_t total_values = 0;
  for (const auto& p : picks) total_values += p.size() * max_particles;
  const std::size_t stride = std::max<std::size_t>(1, total_values / 4'000'000);
  ScalarSamples samples(q.scalars.size());
  const QuantBox qb = quant_box(run0);
  std::vector<EncodedRun> encoded;
  for (std::size_t r = 0; r < runs.size(); ++r)
    encoded.push_back(encode_run(runs[r], picks[r], std::move(first_frames[r]), qb, q, stride, samples, max_particles));
  std::vector<OfferedScalar> offered = scalar_ranges(q.scalars, samples);
  std::string runs_part = runs_json(encoded, offered, q.rgb);

  ViewPage page;
  page.runs = runs.size();
  page.frames_total = run0.frames.size();
  page.frames_shown = picks.front().size();
  page.max_particles = max_particles;
  if (page.frames_shown < page.frames_total)
    page.notes.push_back(
        fmt::format("Showing {} of the run's {} frames, evenly spaced (sph view --max-frames N "
                    "keeps up to N).",
                    page.frames_shown, page.frames_total));
  const std::string default_color = !q.all.empty() ? std::string(color_by_name(q.all.front())) : "uniform";
  const std::string data =
      data_json(run0, obstacles, qb, colors_json(offered, q.rgb, run0.dimension), default_color, page.notes, runs_part);

  const std::string html_title = html_escape(run0.scene.name) + " - sph view";
  const std::string generator = html_escape(options.generator);
  page.html = fill_template(detail::viewer_html(), {{"SPH_TITLE", html_title},
                                                    {"SPH_GENERATOR", generator},
                                                    {"SPH_CSS", detail::viewer_css()},
                                                    {"SPH_DATA", data},
                                                    {"SPH_JS", detail::viewer_js()}});
  if (page.html.size() > options.max_bytes)
    throw Error(fmt::format("the page is {:.3g} MB, more than the limit of {:.3g} MB; use a smaller --max-frames, "
                            "fewer quantities with --color-by, or raise the limit with --max-size",
                            static_cast<double>(page.html.size()) / 1e6, static_cast<double>(options.max_bytes) / 1e6),
                dir.string());
  return page;
}

}  // namespace sph
