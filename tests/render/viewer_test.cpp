// The page builder of `sph view`: base64 and quantization round trips, frame subsampling, the
// data block read back against the frames it came from, and the errors a user can cause.
// (tests/app/view_browser_test.py checks the page itself in a browser.)

#include <sph/render/viewer.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <random>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sph/core/error.h>
#include <sph/io/frames.h>

#include "support/run_sph.h"
#include "support/temp_dir.h"

namespace sph {
namespace {

namespace fs = std::filesystem;

TEST(ViewerBase64, KnownVectorsAndRoundTrip) {
  const auto enc = [](std::string_view s) {
    return base64_encode({reinterpret_cast<const std::uint8_t*>(s.data()), s.size()});
  };
  EXPECT_EQ(enc(""), "");
  EXPECT_EQ(enc("M"), "TQ==");
  EXPECT_EQ(enc("Ma"), "TWE=");
  EXPECT_EQ(enc("Man"), "TWFu");
  std::mt19937 rng(7);
  for (std::size_t n = 0; n < 70; ++n) {
    std::vector<std::uint8_t> bytes(n);
    for (auto& b : bytes) b = static_cast<std::uint8_t>(rng());
    const std::string text = base64_encode(bytes);
    EXPECT_EQ(text.size(), 4 * ((n + 2) / 3));
    EXPECT_EQ(base64_decode(text), bytes) << n;
  }
}

TEST(ViewerBase64, RejectsBadText) {
  EXPECT_THROW(base64_decode("TWF"), Error);
  EXPECT_THROW(base64_decode("TW<u"), Error);
  EXPECT_THROW(base64_decode("T=Fu"), Error);
  EXPECT_THROW(base64_decode("TQ==TQ=="), Error);
}

TEST(ViewerSubsample, KeepsAllWhenFewEnough) {
  EXPECT_EQ(subsample_frames(0, 10), std::vector<std::size_t>{});
  EXPECT_EQ(subsample_frames(3, 10), (std::vector<std::size_t>{0, 1, 2}));
  EXPECT_EQ(subsample_frames(10, 10).size(), 10u);
}

TEST(ViewerSubsample, EvenlySpacedWithFirstAndLast) {
  for (const auto& [total, max] :
       std::vector<std::pair<std::size_t, std::size_t>>{{1001, 300}, {11, 2}, {101, 100}, {5000, 7}}) {
    const auto idx = subsample_frames(total, max);
    ASSERT_EQ(idx.size(), max);
    EXPECT_EQ(idx.front(), 0u);
    EXPECT_EQ(idx.back(), total - 1);
    std::size_t lo = total, hi = 0;
    for (std::size_t k = 1; k < idx.size(); ++k) {
      ASSERT_GT(idx[k], idx[k - 1]);
      lo = std::min(lo, idx[k] - idx[k - 1]);
      hi = std::max(hi, idx[k] - idx[k - 1]);
    }
    EXPECT_LE(hi - lo, 1u) << total << " " << max;
  }
}

TEST(ViewerQuantize, BoundsClampAndNan) {
  EXPECT_EQ(quantize_position(0.0, 0.0, 2.0), 0);
  EXPECT_EQ(quantize_position(2.0, 0.0, 2.0), 65535);
  EXPECT_EQ(quantize_position(-5.0, 0.0, 2.0), 0);
  EXPECT_EQ(quantize_position(7.0, 0.0, 2.0), 65535);
  EXPECT_EQ(quantize_position(std::nan(""), 0.0, 2.0), 0);
  EXPECT_NEAR(quantize_position(1.0, 0.0, 2.0) * 2.0 / 65535.0, 1.0, 2.0 / 65535.0);
  EXPECT_EQ(quantize_scalar(0.0, 0.0, 1.0), 0);
  EXPECT_EQ(quantize_scalar(1.0, 0.0, 1.0), 254);
  EXPECT_EQ(quantize_scalar(9.0, 0.0, 1.0), 254);
  EXPECT_EQ(quantize_scalar(std::nan(""), 0.0, 1.0), 255);
}

/// A short 2D dam break with 5 frames (shared by the tests below; run once).
const fs::path& dam_run() {
  static test::TempDir dir;
  static const fs::path run = [] {
    const fs::path out = dir.path() / "dam";
    const auto r =
        test::run_sph({"run", std::string(SPH_SOURCE_DIR) + "/scenes/paper/dam_break_2d.json", "-o", out.string(),
                       "--steps", "400", "--set", "Configuration.outputEveryNSteps=100", "--no-progress"},
                      dir.path(), dir.path() / "err.txt");
    EXPECT_EQ(r.code, 0) << r.err;
    return out;
  }();
  return run;
}

TEST(ViewerPage, DataRoundTripsTheFrames) {
  const fs::path run_dir = dam_run();
  const RunDirectory run = open_run_directory(run_dir);
  ASSERT_EQ(run.frames.size(), 5u);
  ViewOptions opt;
  opt.max_frames = 3;
  const ViewPage page = build_view_page(run_dir, opt);
  EXPECT_EQ(page.runs, 1u);
  EXPECT_EQ(page.frames_total, 5u);
  EXPECT_EQ(page.frames_shown, 3u);
  ASSERT_EQ(page.notes.size(), 1u);
  EXPECT_NE(page.notes[0].find("--max-frames"), std::string::npos);
  EXPECT_NE(page.html.find("<!DOCTYPE html>"), std::string::npos);
  for (const char* marker : {"@SPH_TITLE@", "@SPH_GENERATOR@", "@SPH_CSS@", "@SPH_DATA@", "@SPH_JS@"})
    EXPECT_EQ(page.html.find(marker), std::string::npos) << marker;

  const auto data = nlohmann::json::parse(view_page_data(page.html));
  EXPECT_EQ(data["dimension"], 2);
  EXPECT_EQ(data["title"], "dam_break_2d");
  EXPECT_EQ(data["obstacles"], nlohmann::json::array());  // the dam break has none
  std::vector<std::string> names;
  for (const auto& c : data["colors"]) names.push_back(c["name"]);
  EXPECT_EQ(names, (std::vector<std::string>{"speed", "kinetic_energy", "density", "pressure", "initial_position"}));
  EXPECT_EQ(data["defaultColor"], "speed");
  ASSERT_EQ(data["runs"].size(), 1u);
  const auto& frames = data["runs"][0]["frames"];
  ASSERT_EQ(frames.size(), 3u);

  const double qlo[2] = {data["qbox"]["lo"][0], data["qbox"]["lo"][1]};
  const double qhi[2] = {data["qbox"]["hi"][0], data["qbox"]["hi"][1]};
  const auto& speed = data["colors"][0];
  const double slo = speed["lo"], shi = speed["hi"];
  EXPECT_EQ(base64_decode(speed["lut"].get<std::string>()).size(), 3u * 256u);
  for (std::size_t k = 0; k < 3; ++k) {
    const FrameData frame = read_frame(run.frames[2 * k]);  // frames 0, 2, 4 of 5
    const auto& f = frames[k];
    EXPECT_DOUBLE_EQ(f["t"].get<double>(), frame.time);
    ASSERT_EQ(f["n"].get<std::size_t>(), frame.size);
    // Particles are stored in id order.
    const FrameField* id = frame.field("id");
    ASSERT_NE(id, nullptr);
    std::vector<std::size_t> by_id(frame.size);
    for (std::size_t i = 0; i < frame.size; ++i) by_id[static_cast<std::size_t>(id->values[i])] = i;
    const std::vector<std::uint8_t> pos = base64_decode(f["pos"].get<std::string>());
    ASSERT_EQ(pos.size(), 2 * 2 * frame.size);
    const std::vector<std::uint8_t> q = base64_decode(f["f"]["speed"].get<std::string>());
    ASSERT_EQ(q.size(), frame.size);
    const FrameField* vel = frame.field("velocity");
    for (std::size_t j = 0; j < frame.size; ++j) {
      const std::size_t i = by_id[j];
      for (int d = 0; d < 2; ++d) {
        const unsigned u = pos[4 * j + 2 * d] | (pos[4 * j + 2 * d + 1] << 8);  // little endian
        const double x = qlo[d] + u * (qhi[d] - qlo[d]) / 65535.0;
        ASSERT_NEAR(x, frame.position[3 * i + d], 0.51 * (qhi[d] - qlo[d]) / 65535.0) << "frame " << k;
      }
      const double s = std::hypot(vel->values[3 * i], vel->values[3 * i + 1], vel->values[3 * i + 2]);
      ASSERT_NEAR(slo + q[j] * (shi - slo) / 254.0, std::clamp(s, slo, shi), 0.51 * (shi - slo) / 254.0);
    }
  }
  // Initial-position colors: one per particle, shared by the frames (ids 0..n-1 throughout).
  EXPECT_EQ(base64_decode(data["runs"][0]["rgb"].get<std::string>()).size(), 3 * frames[0]["n"].get<std::size_t>());
  EXPECT_FALSE(frames[0].contains("rgb"));
  // No obstacle moves: the frames carry no poses, exactly as before obstacles could move.
  for (const auto& f : frames) EXPECT_EQ(f.size(), 4u) << f.dump().substr(0, 80);  // t, n, pos, f
}

TEST(ViewerPage, TheDataListsTheScenesObstacles) {
  test::TempDir dir;
  test::spit(dir.path() / "scene.json", R"({
    "version": 1, "name": "obstacles", "dimension": 2,
    "Configuration": { "particleRadius": 0.01 },
    "Container": { "start": [0, 0], "end": [0.6, 0.4] },
    "Obstacles": [ { "start": [0.35, 0], "end": [0.45, 0.12] }, { "start": [0.5, 0.2], "end": [0.55, 0.25] } ],
    "FluidBlocks": [ { "start": [0, 0], "end": [0.1, 0.2] } ]
  })");
  const fs::path out = dir.path() / "run";
  const auto r = test::run_sph({"run", (dir.path() / "scene.json").string(), "-o", out.string(), "--steps", "20",
                                "--set", "Configuration.outputEveryNSteps=10", "--no-progress"},
                               dir.path(), dir.path() / "err.txt");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto data = nlohmann::json::parse(view_page_data(build_view_page(out, ViewOptions{}).html));
  const auto box = [](std::vector<double> lo, std::vector<double> hi) {
    return nlohmann::json{{"lo", lo}, {"hi", hi}};
  };
  EXPECT_EQ(data["obstacles"],
            nlohmann::json::array({box({0.35, 0, 0}, {0.45, 0.12, 0}), box({0.5, 0.2, 0}, {0.55, 0.25, 0})}));
  for (const auto& f : data["runs"][0]["frames"]) EXPECT_FALSE(f.contains("poses"));  // they do not move
}

/// The scene of TheDataListsTheScenesObstacles (with its number of steps, as a run directory's
/// scene.json has it), `motion` (JSON text) added to each obstacle in order ("" for none).
std::string obstacle_scene(const std::string& motion0, const std::string& motion1) {
  const auto with = [](const std::string& m) { return m.empty() ? std::string() : ", \"motion\": " + m; };
  return R"({
    "version": 1, "name": "obstacles", "dimension": 2,
    "Configuration": { "particleRadius": 0.01, "numberOfSteps": 20 },
    "Container": { "start": [0, 0], "end": [0.6, 0.4] },
    "Obstacles": [ { "start": [0.35, 0], "end": [0.45, 0.12])" +
         with(motion0) + R"( }, { "start": [0.5, 0.2], "end": [0.55, 0.25])" + with(motion1) + R"( } ],
    "FluidBlocks": [ { "start": [0, 0], "end": [0.1, 0.2] } ]
  })";
}

TEST(ViewerPage, TheFramesPlaceMovingObstacles) {
  test::TempDir dir;
  test::spit(dir.path() / "scene.json", obstacle_scene("", ""));
  const fs::path out = dir.path() / "run";
  const auto r = test::run_sph({"run", (dir.path() / "scene.json").string(), "-o", out.string(), "--steps", "20",
                                "--set", "Configuration.outputEveryNSteps=10", "--no-progress"},
                               dir.path(), dir.path() / "err.txt");
  ASSERT_EQ(r.code, 0) << r.err;
  // The same run as if its obstacles moved: the page places them by the scene it reads, at each
  // frame's time (a paddle oscillating along x, a stirrer turning about its middle).
  test::spit(out / "scene.json",
             obstacle_scene(R"({ "type": "oscillation", "direction": [1, 0], "amplitude": 0.05, "period": 0.037 })",
                            R"({ "type": "rotation", "angularVelocity": 40 })"));
  const auto data = nlohmann::json::parse(view_page_data(build_view_page(out, ViewOptions{}).html));
  // The obstacles at rest, as for a static scene.
  const auto box = [](std::vector<double> lo, std::vector<double> hi) {
    return nlohmann::json{{"lo", lo}, {"hi", hi}};
  };
  EXPECT_EQ(data["obstacles"],
            nlohmann::json::array({box({0.35, 0, 0}, {0.45, 0.12, 0}), box({0.5, 0.2, 0}, {0.55, 0.25, 0})}));
  const auto& frames = data["runs"][0]["frames"];
  ASSERT_EQ(frames.size(), 3u);
  double moved = 0, turned = 0;
  for (const auto& f : frames) {
    const double t = f["t"];
    ASSERT_TRUE(f.contains("poses")) << t;
    const auto& poses = f["poses"];
    ASSERT_EQ(poses.size(), 2u);
    for (const auto& p : poses) ASSERT_EQ(p.size(), 15u);  // R (9), center (3), translation (3)
    // The paddle: translated along x, upright.
    const double x = 0.05 * std::sin(2 * std::numbers::pi * t / 0.037);
    EXPECT_NEAR(poses[0][12].get<double>(), x, 1e-12) << t;
    EXPECT_EQ(poses[0][13].get<double>(), 0.0);
    for (int k = 0; k < 9; ++k) EXPECT_EQ(poses[0][k].get<double>(), k % 4 == 0 ? 1.0 : 0.0) << k;
    moved = std::max(moved, std::abs(x));
    // The stirrer: turned by 40 t about its middle (the motion's default center), not translated.
    const double a = 40 * t;
    EXPECT_NEAR(poses[1][0].get<double>(), std::cos(a), 1e-12) << t;
    EXPECT_NEAR(poses[1][1].get<double>(), -std::sin(a), 1e-12) << t;
    EXPECT_NEAR(poses[1][3].get<double>(), std::sin(a), 1e-12) << t;
    EXPECT_NEAR(poses[1][4].get<double>(), std::cos(a), 1e-12) << t;
    EXPECT_EQ(poses[1][8].get<double>(), 1.0);
    EXPECT_NEAR(poses[1][9].get<double>(), 0.525, 1e-12);
    EXPECT_NEAR(poses[1][10].get<double>(), 0.225, 1e-12);
    EXPECT_EQ(poses[1][11].get<double>(), 0.0);
    for (int k = 12; k < 15; ++k) EXPECT_EQ(poses[1][k].get<double>(), 0.0) << k;
    turned = std::max(turned, std::abs(std::sin(a)));
  }
  EXPECT_GT(moved, 1e-4);  // the frames are not all at rest, or the test would prove little
  EXPECT_GT(turned, 1e-3);
}

TEST(ViewerPage, ChosenQuantitiesOnlyAndInOrder) {
  ViewOptions opt;
  opt.color_by = {ColorBy::Density, ColorBy::InitialPosition, ColorBy::Density};
  const auto data = nlohmann::json::parse(view_page_data(build_view_page(dam_run(), opt).html));
  ASSERT_EQ(data["colors"].size(), 2u);
  EXPECT_EQ(data["colors"][0]["name"], "density");
  EXPECT_EQ(data["colors"][1]["name"], "initial_position");
  EXPECT_EQ(data["defaultColor"], "density");
  EXPECT_FALSE(data["runs"][0]["frames"][0]["f"].contains("speed"));
}

TEST(ViewerPage, CompareDirectoryGivesOnePanelPerRun) {
  test::TempDir dir;
  for (const char* mode : {"standard", "adaptive"}) fs::copy(dam_run(), dir.path() / mode, fs::copy_options::recursive);
  test::spit(dir.path() / "runs.txt", "standard\nadaptive\n");
  const ViewPage page = build_view_page(dir.path(), ViewOptions{});
  EXPECT_EQ(page.runs, 2u);
  const auto data = nlohmann::json::parse(view_page_data(page.html));
  ASSERT_EQ(data["runs"].size(), 2u);
  EXPECT_EQ(data["runs"][0]["frames"].size(), 5u);
  EXPECT_EQ(data["runs"][1]["frames"].size(), 5u);
}

/// The --max-frames N that a too-large page's message suggests gives a page within the limit,
/// when an obstacle's shape (a polygon of 1,500 vertices here) goes into the page too: the
/// estimate counts the shapes.
TEST(ViewerPage, TheSuggestedMaxFramesFitsWithALargeShape) {
  test::TempDir dir;
  std::string polygon;
  for (int k = 0; k < 1500; ++k) {
    const double a = 2 * std::numbers::pi * k / 1500;
    polygon += fmt::format("{}[{:.6f}, {:.6f}]", k ? ", " : "", 0.45 + 0.08 * std::cos(a), 0.2 + 0.08 * std::sin(a));
  }
  test::spit(dir.path() / "scene.json", R"({
    "version": 1, "name": "shape", "dimension": 2,
    "Configuration": { "particleRadius": 0.0025 },
    "Container": { "start": [0, 0], "end": [0.6, 0.4] },
    "Obstacles": [ { "polygon": [)" + polygon +
                                            R"(] } ],
    "FluidBlocks": [ { "start": [0, 0], "end": [0.3, 0.2] } ]
  })");
  const fs::path out = dir.path() / "run";
  const auto r = test::run_sph({"run", (dir.path() / "scene.json").string(), "-o", out.string(), "--steps", "40",
                                "--set", "Configuration.outputEveryNSteps=2", "--no-progress"},
                               dir.path(), dir.path() / "err.txt");
  ASSERT_EQ(r.code, 0) << r.err;
  const ViewPage whole = build_view_page(out, ViewOptions{});
  ASSERT_EQ(whole.frames_shown, 21u);
  ViewOptions limited;
  limited.max_bytes = whole.html.size() * 3 / 5;
  std::string refused;
  try {
    build_view_page(out, limited);
  } catch (const Error& e) {
    refused = e.what();
  }
  const std::size_t at = refused.find("--max-frames ");
  ASSERT_NE(at, std::string::npos) << refused;
  limited.max_frames = std::stoul(refused.substr(at + 13));
  ASSERT_GE(limited.max_frames, 2u) << refused;
  ASSERT_LT(limited.max_frames, 21u) << refused;
  const ViewPage fits = build_view_page(out, limited);  // throws if the page is above the limit
  EXPECT_LE(fits.html.size(), limited.max_bytes);
}

TEST(ViewerPage, Errors) {
  test::TempDir dir;
  const auto message = [](const auto& f) {
    try {
      f();
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  // Missing, not a run directory, no frames.
  EXPECT_NE(message([&] { build_view_page(dir.path() / "missing", {}); }).find("no such directory"), std::string::npos);
  EXPECT_NE(message([&] { build_view_page(dir.path(), {}); }).find("neither a run directory"), std::string::npos);
  fs::create_directories(dir.path() / "empty");
  fs::copy_file(dam_run() / "scene.json", dir.path() / "empty" / "scene.json");
  EXPECT_NE(message([&] { build_view_page(dir.path() / "empty", {}); }).find("no frames"), std::string::npos);
  // Too large: refused before the frames are read, naming the option that helps.
  ViewOptions small;
  small.max_bytes = 100'000;
  const std::string too_big = message([&] { build_view_page(dam_run(), small); });
  EXPECT_NE(too_big.find("--max-frames"), std::string::npos) << too_big;
  ViewOptions one;
  one.max_frames = 1;
  EXPECT_NE(message([&] { build_view_page(dam_run(), one); }).find("--max-frames"), std::string::npos);
  // The --max-frames N suggested is the most that the limit lets through: N passes the estimate,
  // N + 1 does not.
  const ViewPage whole = build_view_page(dam_run(), {});
  ASSERT_GT(whole.frames_shown, 4u);
  ViewOptions half;
  half.max_bytes = whole.html.size() * 3 / 5;
  const std::string refused = message([&] { build_view_page(dam_run(), half); });
  const std::size_t at = refused.find("--max-frames ");
  ASSERT_NE(at, std::string::npos) << refused;
  const std::size_t n = std::stoul(refused.substr(at + 13));
  ASSERT_GE(n, 2u) << refused;
  ASSERT_LT(n, whole.frames_shown) << refused;
  half.max_frames = n;
  EXPECT_EQ(message([&] { build_view_page(dam_run(), half); }).find("would be about"), std::string::npos);
  half.max_frames = n + 1;
  EXPECT_NE(message([&] { build_view_page(dam_run(), half); }).find("would be about"), std::string::npos);
  // A limit that not even two frames of the run fit: no --max-frames N to suggest (two is the
  // fewest it keeps), but a --max-size that two frames fit.
  ViewOptions tiny;
  tiny.max_bytes = 1;
  const std::string no_fit = message([&] { build_view_page(dam_run(), tiny); });
  EXPECT_EQ(no_fit.find("or fewer"), std::string::npos) << no_fit;
  const std::size_t size_at = no_fit.find("--max-size (to at least ");
  ASSERT_NE(size_at, std::string::npos) << no_fit;
  tiny.max_bytes = static_cast<std::size_t>(std::stod(no_fit.substr(size_at + 24)) * 1e6);
  tiny.max_frames = 2;
  EXPECT_EQ(message([&] { build_view_page(dam_run(), tiny); }).find("would be about"), std::string::npos);
}

}  // namespace
}  // namespace sph
