// `sph render` as a user meets it: images of every frame with one color scale for the whole
// run, the scene's obstacles drawn solid, a movie checked by ffprobe, compare directories side by
// side, and clear refusals.

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <sph/render/color_by.h>
#include <sph/render/particles.h>

#include "support/expect.h"
#include "support/png_decode.h"
#include "support/run_sph.h"
#include "support/scenes.h"

namespace {

using sph::test::kBlock;
using sph::test::kDamBreak;

namespace fs = std::filesystem;
using sph::test::CommandResult;
using sph::test::error_lines;

sph::test::DecodedPng load_png(const fs::path& p) { return sph::test::decode_png(sph::test::slurp(p)); }

std::vector<std::string> pngs_in(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".png") names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

class Render : public testing::Test {
 protected:
  CommandResult sph(const std::vector<std::string>& args) {
    return sph::test::run_sph(args, tmp_.path(), tmp_.path() / "stderr.txt");
  }
  /// A short run into tmp/NAME: frames every 50 of 200 steps (5 frames).
  void run(const std::string& scene, const std::string& name, const std::vector<std::string>& extra = {}) {
    std::vector<std::string> args{
        "run", scene, "--steps", "200", "--set", "Configuration.outputEveryNSteps=50", "--no-progress", "-o", name};
    args.insert(args.end(), extra.begin(), extra.end());
    const CommandResult r = sph(args);
    ASSERT_EQ(r.code, 0) << r.err;
  }
  /// Expects a refusal: exit 2, one error line containing `what`, and no DIR/render created.
  void expect_refused(const std::vector<std::string>& args, const std::string& what, const fs::path& render_dir) {
    const CommandResult r = sph(args);
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_EQ(error_lines(r.err).size(), 1u) << r.err;
    EXPECT_CONTAINS(r.err, what);
    EXPECT_FALSE(fs::exists(render_dir)) << r.err;
  }
  sph::test::TempDir tmp_;
};

TEST_F(Render, EveryFrameBecomesAnImageWithOneColorScaleForTheRun) {
  run(kDamBreak, "db");
  const CommandResult r = sph({"render", "db", "--no-progress"});
  ASSERT_EQ(r.code, 0) << r.err;
  const fs::path out = tmp_.path() / "db" / "render";
  EXPECT_CONTAINS(r.err, "/frame_000000.png ... frame_000004.png\n");  // (the five, without a gap)
  EXPECT_EQ(pngs_in(out), (std::vector<std::string>{"frame_000000.png", "frame_000001.png", "frame_000002.png",
                                                    "frame_000003.png", "frame_000004.png"}));
  const auto first = load_png(out / "frame_000000.png");
  const auto last = load_png(out / "frame_000004.png");
  ASSERT_EQ(first.width, last.width);
  ASSERT_GT(first.height, 720);  // the panel under a caption row with the time
  ASSERT_LT(first.height, 800);
  EXPECT_GT(first.width, 1280);    // the color bar beside the 1280-pixel panel
  EXPECT_NE(first.rgb, last.rgb);  // the fluid moved
  // The color bar (the strip right of the panel) is the same in every frame: one scale.
  auto strip = [](const sph::test::DecodedPng& d) {
    std::vector<std::uint8_t> s;
    for (int y = 0; y < d.height; ++y)
      s.insert(s.end(), d.rgb.begin() + 3 * (y * d.width + 1280), d.rgb.begin() + 3 * (y * d.width + d.width));
    return s;
  };
  EXPECT_EQ(strip(first), strip(last));
  // Rendering fewer frames again replaces the earlier images.
  const CommandResult again = sph({"render", "db", "--frames", "last", "--no-progress"});
  ASSERT_EQ(again.code, 0) << again.err;
  EXPECT_EQ(pngs_in(out), (std::vector<std::string>{"frame_000004.png"}));
  // The closing line names the pictures written: a few by name, not as a range with a gap.
  const CommandResult two = sph({"render", "db", "--frames", "0,-1", "--no-progress"});
  ASSERT_EQ(two.code, 0) << two.err;
  EXPECT_CONTAINS(two.err, "/frame_000000.png, frame_000004.png\n");
  const CommandResult four = sph({"render", "db", "--frames", "0,1,3,4", "--no-progress"});
  ASSERT_EQ(four.code, 0) << four.err;
  EXPECT_CONTAINS(four.err, "/frame_000000.png, frame_000001.png, ... frame_000004.png (4 pictures)\n");
}

TEST_F(Render, ObstaclesAreDrawnAsSolidBoxes) {
  // A column collapsing onto a block standing on the floor of a 0.6 x 0.4 m tank.
  sph::test::spit(tmp_.path() / "obstacle.json", R"({
    "version": 1, "name": "obstacle", "dimension": 2,
    "Configuration": { "particleRadius": 0.0075 },
    "Container": { "start": [0, 0], "end": [0.6, 0.4] },
    "Obstacles": [ { "start": [0.35, 0], "end": [0.45, 0.12] } ],
    "FluidBlocks": [ { "start": [0, 0], "end": [0.15, 0.3] } ]
  })");
  run((tmp_.path() / "obstacle.json").string(), "ob");
  ASSERT_EQ(sph({"render", "ob", "--frames", "last", "--no-progress"}).code, 0);
  const auto img = load_png(tmp_.path() / "ob" / "render" / "frame_000004.png");
  const auto at = [&](int x, int y) {
    const std::uint8_t* p = &img.rgb[3 * (static_cast<std::size_t>(y) * img.width + x)];
    return sph::Rgb{p[0], p[1], p[2]};
  };
  // The obstacle's fill: where it is, its projected size (the 1280 x 720 panel is the image's
  // left part, under the caption row).
  int x0 = img.width, x1 = -1, y0 = img.height, y1 = -1;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      if (at(x, y) == sph::kSolidColor)
        x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
  ASSERT_GE(x1, 0) << "no pixel has the obstacle's color";
  sph::ParticleView view = sph::default_particle_view(2, 1280, 720);
  const sph::ParticleCamera cam(2, {0, 0, 0}, {0.6, 0.4, 0}, 0.0075, view);
  const double s = cam.pixels_per_unit();
  EXPECT_NEAR(0.5 * (x0 + x1 + 1), cam.project({0.4, 0.06, 0})[0], 2.0);
  EXPECT_NEAR(x1 + 1 - x0, 0.1 * s, 6.0);  // less the outline
  EXPECT_NEAR(y1 + 1 - y0, 0.12 * s, 6.0);
  const int cx = (x0 + x1) / 2, cy = (y0 + y1) / 2;
  EXPECT_EQ(at(cx, cy), sph::kSolidColor);
  // Bounded by its outline, with no obstacle beyond it.
  EXPECT_EQ(at(x0 - 1, cy), sph::kSolidEdgeColor);
  EXPECT_EQ(at(x1 + 1, cy), sph::kSolidEdgeColor);
  EXPECT_NE(at(x0 - 4, cy), sph::kSolidColor);
  EXPECT_NE(at(x1 + 4, cy), sph::kSolidEdgeColor);
}

TEST_F(Render, TheChosenFieldCameraAndSizeAreUsed) {
  run(kBlock, "block");
  ASSERT_EQ(sph({"render", "block", "--frames", "-1", "--size", "320x240", "-o", "a", "--no-progress"}).code, 0);
  ASSERT_EQ(
      sph({"render", "block", "--frames", "-1", "--size", "320x240", "--azimuth", "-60", "-o", "b", "--no-progress"})
          .code,
      0);
  ASSERT_EQ(sph({"render", "block", "--frames", "-1", "--size", "320x240", "--color-by", "initial_position", "-o", "c",
                 "--no-progress"})
                .code,
            0);
  const auto a = load_png(tmp_.path() / "a" / "frame_000004.png");
  const auto b = load_png(tmp_.path() / "b" / "frame_000004.png");
  const auto c = load_png(tmp_.path() / "c" / "frame_000004.png");
  EXPECT_GT(a.height, 240);
  EXPECT_LT(a.height, 300);
  EXPECT_EQ(a.width, b.width);
  EXPECT_NE(a.rgb, b.rgb);  // another camera
  EXPECT_EQ(c.width, 320);  // initial position: a key, no color bar
}

// A run that left the velocities out (--fields) is colored by the first quantity its frames hold,
// and one that kept positions only is drawn in one color, without a bar: `sph run` suggests
// `sph render` for every run, and these were refused until 2026-12-07 ("no quantity can color
// them"). `--color-by none` asks for one color; sph view, whose page does it by itself, refuses it.
TEST_F(Render, FramesWithoutVelocitiesAreColoredByWhatTheyHoldOrInOneColor) {
  run(kDamBreak, "rho", {"--fields", "density"});
  run(kDamBreak, "pos", {"--fields", "none"});
  const CommandResult a = sph({"render", "rho", "--frames", "-1", "--size", "160x120", "-o", "a", "--no-progress"});
  ASSERT_EQ(a.code, 0) << a.err;
  EXPECT_CONTAINS(a.err, "colored by density");
  EXPECT_GT(load_png(tmp_.path() / "a" / "frame_000004.png").width, 160) << "a density color bar";
  const CommandResult b = sph(
      {"render", "pos", "--frames", "-1", "--size", "160x120", "--flat", "--range", "0,1", "-o", "b", "--no-progress"});
  ASSERT_EQ(b.code, 0) << b.err;
  EXPECT_CONTAINS(b.err, "every particle in one color");
  EXPECT_CONTAINS(b.err, "sph: warning: --range: particles in one color take no color map: it is ignored");
  const auto png = load_png(tmp_.path() / "b" / "frame_000004.png");
  EXPECT_EQ(png.width, 160) << "no color bar";
  std::size_t blue = 0;
  for (std::size_t k = 0; k + 2 < png.rgb.size(); k += 3)
    blue += png.rgb[k] == sph::kOneColor.r && png.rgb[k + 1] == sph::kOneColor.g && png.rgb[k + 2] == sph::kOneColor.b;
  EXPECT_GT(blue, 200u) << "the particles' one color";
  const CommandResult c = sph({"render", "rho", "--frames", "-1", "--size", "160x120", "--flat", "--color-by", "none",
                               "-o", "c", "--no-progress"});
  ASSERT_EQ(c.code, 0) << c.err;
  EXPECT_EQ(load_png(tmp_.path() / "c" / "frame_000004.png").rgb, png.rgb) << "the same picture, asked for";
  const CommandResult v = sph({"view", "pos", "--color-by", "none", "-o", "pos/view.html"});
  EXPECT_EQ(v.code, 2) << v.err;
  EXPECT_CONTAINS(v.err, "--color-by: none is sph render's");
}

TEST_F(Render, AMovieHasOneFramePerImage) {
  run(kDamBreak, "db");
  const CommandResult r = sph({"render", "db", "--mp4", "--no-png", "--size", "320x240", "--no-progress"});
  ASSERT_EQ(r.code, 0) << r.err;
  const fs::path movie = tmp_.path() / "db" / "render" / "movie.mp4";
  ASSERT_TRUE(fs::is_regular_file(movie)) << r.err;
  EXPECT_TRUE(pngs_in(movie.parent_path()).empty());
  const CommandResult probe = sph::test::run_sph({}, tmp_.path(), tmp_.path() / "probe_err.txt",
                                                 "ffprobe -v error -count_frames -select_streams v:0 -show_entries "
                                                 "stream=codec_name,nb_read_frames -of csv=p=0 " +
                                                     sph::test::shell_quote(movie.string()) + " #");
  EXPECT_CONTAINS(probe.out, "h264,5");
}

TEST_F(Render, ACompareDirectoryShowsTheModesSideBySide) {
  const CommandResult c =
      sph({"compare", kDamBreak, "--steps", "100", "--modes", "standard,adaptive", "--set",
           "Configuration.outputEveryNSteps=50", "--perturbation", "0", "--no-audit", "--no-progress", "-o", "cmp"});
  ASSERT_EQ(c.code, 0) << c.err;
  // Each mode's run directory, in run order, with its own mode in scene.json; not the chaos run.
  EXPECT_EQ(sph::test::slurp(tmp_.path() / "cmp" / "runs.txt"), "standard\nadaptive\n");
  EXPECT_CONTAINS(sph::test::slurp(tmp_.path() / "cmp" / "adaptive" / "scene.json"), "\"neighbors\": \"adaptive\"");
  EXPECT_TRUE(fs::is_regular_file(tmp_.path() / "cmp" / "adaptive" / "frames" / "frame_000002.vtu"));
  const CommandResult r = sph({"render", "cmp", "--frames", "last", "--size", "300x200", "--no-progress"});
  ASSERT_EQ(r.code, 0) << r.err;
  const auto img = load_png(tmp_.path() / "cmp" / "render" / "frame_000002.png");
  EXPECT_GT(img.width, 600);   // two panels and the color bar
  EXPECT_GT(img.height, 200);  // under a caption row
}

TEST_F(Render, MistakesAreRefusedBeforeAnythingIsWritten) {
  run(kDamBreak, "db", {"--set", "Configuration.outputFields=[\"velocity\"]"});
  const fs::path out = tmp_.path() / "db" / "render";
  expect_refused({"render", "missing"}, "missing", tmp_.path() / "missing");
  fs::create_directories(tmp_.path() / "empty");
  expect_refused({"render", "empty"}, "empty", tmp_.path() / "empty" / "render");
  expect_refused({"render", "db", "--color-by", "velocity"}, "expected one of: speed", out);
  expect_refused({"render", "db", "--color-by", "density"}, "'density'", out);
  expect_refused({"render", "db", "--color-by", "initial_position"}, "--fields", out);
  expect_refused({"render", "db", "--size", "12x"}, "--size", out);
  expect_refused({"render", "db", "--frames", "5"}, "frame 5 does not exist", out);
  expect_refused({"render", "db", "--frames", "1,x"}, "--frames", out);
  // An empty list rendered nothing, then crashed (it read the first of no frames).
  expect_refused({"render", "db", "--frames", ""}, "--frames: an empty frame list", out);
  expect_refused({"surface", "db", "--frames", ""}, "--frames: an empty frame list", tmp_.path() / "db" / "surface");
  expect_refused({"render", "db", "--range", "2,1"}, "--range", out);
  expect_refused({"render", "db", "--colormap", "jet"}, "--colormap", out);
  expect_refused({"render", "db", "--no-png"}, "--mp4", out);
  expect_refused({"render", "db", "--format", "ply"}, "ply", out);
  // A floating body's run without its bodies.csv, or with a table that lost the last frame's rows:
  // the boxes would be drawn where they started, or where an earlier frame had them.
  const std::string floating = SPH_SOURCE_DIR "/scenes/examples/floating_boxes_2d.json";
  run(floating, "fb", {"--set", "Configuration.outputFps=0"});
  fs::rename(tmp_.path() / "fb" / "bodies.csv", tmp_.path() / "bodies.csv");
  expect_refused({"render", "fb"}, "fb/bodies.csv: is missing", tmp_.path() / "fb" / "render");
  expect_refused({"view", "fb"}, "fb/bodies.csv: is missing", tmp_.path() / "fb" / "render");
  const std::string table = sph::test::slurp(tmp_.path() / "bodies.csv");
  std::size_t cut = table.size() - 1;
  for (int rows = 0; rows < 3; ++rows) cut = table.rfind('\n', cut - 1);  // the last frame's 3 boxes
  sph::test::spit(tmp_.path() / "fb" / "bodies.csv", table.substr(0, cut + 1));
  expect_refused({"render", "fb", "--frames", "last"}, "bodies.csv: has no row of obstacle",
                 tmp_.path() / "fb" / "render");
  sph::test::spit(tmp_.path() / "afile", "x");
  const CommandResult r = sph({"render", "db", "-o", "afile/sub", "--no-progress"});
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_CONTAINS(r.err, "afile");
}

}  // namespace
