// Frame files in every format (.vtu, legacy .vtk, .ply) read back through read_frame: values,
// times and field selection; the frame schedule (every N steps, frames per simulated second);
// malformed, truncated and foreign files refused with the file named; run and compare
// directories opened.

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <gtest/gtest.h>

#include <sph/core/error.h>
#include <sph/io/frame_writer.h>
#include <sph/io/frames.h>
#include <sph/io/ply.h>
#include <sph/io/run_directory.h>
#include <sph/io/run_output.h>
#include <sph/io/vtk.h>
#include <sph/scene/builders.h>
#include <sph/scene/scene_reader.h>

#include "support/scenes.h"
#include "support/temp_dir.h"
#include "support/test_particles.h"

namespace sph {
namespace {

using sph::test::kDamBreak;

namespace fs = std::filesystem;
using test::slurp;
using test::spit;
using test::TempDir;

constexpr FrameFormat kFormats[] = {FrameFormat::Vtu, FrameFormat::Vtk, FrameFormat::Ply};

/// Which of kFrameFieldNames a test frame holds: bit k for kFrameFieldNames[k].
using FieldMask = unsigned;
constexpr FieldMask kFieldVelocity = 1u << 0, kFieldDensity = 1u << 1, kFieldPressure = 1u << 2, kFieldId = 1u << 3,
                    kFieldInitialPosition = 1u << 4, kAllFrameFields = 0x1Fu;

FrameFields fields_of(FieldMask mask) {
  std::vector<std::string> names;
  for (std::size_t k = 0; k < kFrameFieldNames.size(); ++k)
    if (mask & (1u << k)) names.emplace_back(kFrameFieldNames[k]);
  return FrameFields::only(names);
}

template <int D, class R>
void write_frame(FrameFormat f, const fs::path& path, const ParticleSet<D, R>& ps, double time, FieldMask mask) {
  sph::write_frame(f, path, ps, time, fields_of(mask));
}

fs::path frame_path(const TempDir& dir, FrameFormat f) {
  return dir / (std::string("frame_000000.") + frame_format_name(f));
}

/// What a file of format f holds for `x`: PLY files are single precision.
template <class R>
double stored(FrameFormat f, R x) {
  return f == FrameFormat::Ply ? static_cast<double>(static_cast<float>(x)) : static_cast<double>(x);
}

template <int D, class R>
void check_round_trip(FrameFormat f, std::size_t n, FieldMask mask) {
  SCOPED_TRACE(::testing::Message() << frame_format_name(f) << ", " << D << "D, "
                                    << (sizeof(R) == 4 ? "float" : "double") << ", N = " << n << ", fields " << mask);
  TempDir dir;
  const ParticleSet<D, R> ps = test::make_test_particles<D, R>(n);
  const double time = 0.1 + 0.025;  // 0.125 with a rounding error: the time must survive exactly
  write_frame(f, frame_path(dir, f), ps, time, mask);
  const FrameData fr = read_frame(frame_path(dir, f));
  EXPECT_EQ(fr.time, time);
  ASSERT_EQ(fr.size, n);
  ASSERT_EQ(fr.position.size(), 3 * n);
  std::vector<std::string> expected_fields;
  for (int k = 0; k < 5; ++k)
    if (mask & (1u << k)) expected_fields.emplace_back(kFrameFieldNames[k]);
  std::vector<std::string> got;
  for (const FrameField& ff : fr.fields) got.push_back(ff.name);
  EXPECT_EQ(got, expected_fields) << "exactly the chosen fields, in kFrameFieldNames order";
  const auto vec_field = [&](const char* name, const std::vector<Vec<D, R>>& v) {
    const FrameField* ff = fr.field(name);
    ASSERT_NE(ff, nullptr) << name;
    ASSERT_EQ(ff->components, 3);
    ASSERT_EQ(ff->values.size(), 3 * n);
    for (std::size_t i = 0; i < n; ++i)
      for (int d = 0; d < 3; ++d)
        EXPECT_EQ(ff->values[3 * i + d], d < D ? stored(f, v[i][d]) : 0.0) << name << " " << i << "," << d;
  };
  for (std::size_t i = 0; i < n; ++i)
    for (int d = 0; d < 3; ++d) EXPECT_EQ(fr.position[3 * i + d], d < D ? stored(f, ps.position[i][d]) : 0.0);
  const auto scalar = [&](const char* name, auto value_of) {
    const FrameField* ff = fr.field(name);
    ASSERT_NE(ff, nullptr) << name;
    ASSERT_EQ(ff->components, 1);
    ASSERT_EQ(ff->values.size(), n);
    for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(ff->values[i], value_of(i)) << name << " " << i;
  };
  if (mask & kFieldVelocity) vec_field("velocity", ps.velocity);
  if (mask & kFieldInitialPosition) vec_field("initial_position", ps.initial_position);
  if (mask & kFieldDensity) scalar("density", [&](std::size_t i) { return stored(f, ps.density[i]); });
  if (mask & kFieldPressure) scalar("pressure", [&](std::size_t i) { return stored(f, ps.pressure[i]); });
  if (mask & kFieldId) scalar("id", [&](std::size_t i) { return static_cast<double>(ps.id[i]); });
  for (int k = 0; k < 5; ++k)
    if (!(mask & (1u << k))) {
      EXPECT_EQ(fr.field(kFrameFieldNames[k]), nullptr) << kFrameFieldNames[k];
    }
}

class FrameRoundTrip : public testing::TestWithParam<FrameFormat> {};

TEST_P(FrameRoundTrip, EveryDimensionAndPrecisionAllFields) {
  check_round_trip<2, float>(GetParam(), 11, kAllFrameFields);
  check_round_trip<2, double>(GetParam(), 7, kAllFrameFields);
  check_round_trip<3, float>(GetParam(), 5, kAllFrameFields);
  check_round_trip<3, double>(GetParam(), 2500, kAllFrameFields);
}

TEST_P(FrameRoundTrip, ChosenFieldsOnly) {
  check_round_trip<3, double>(GetParam(), 9, kFieldVelocity | kFieldId);
  check_round_trip<2, float>(GetParam(), 9, kFieldDensity | kFieldPressure | kFieldInitialPosition);
  check_round_trip<3, float>(GetParam(), 9, 0);  // positions only
}

TEST_P(FrameRoundTrip, NoParticles) {
  // Emitter scenes start with none: frame 0 is empty.
  check_round_trip<3, double>(GetParam(), 0, kAllFrameFields);
}

INSTANTIATE_TEST_SUITE_P(Formats, FrameRoundTrip, testing::ValuesIn(kFormats),
                         [](const auto& info) { return std::string(frame_format_name(info.param)); });

TEST(FrameFiles, PrecisionOfTheRunIsKept) {
  TempDir dir;
  write_vtu(dir / "f.vtu", test::make_test_particles<3, float>(3), 0.5);
  write_vtu(dir / "d.vtu", test::make_test_particles<3, double>(3), 0.5);
  EXPECT_NE(slurp(dir / "f.vtu").find("type=\"Float32\" Name=\"position\""), std::string::npos);
  EXPECT_NE(slurp(dir / "d.vtu").find("type=\"Float64\" Name=\"position\""), std::string::npos);
  write_legacy_vtk(dir / "f.vtk", test::make_test_particles<3, float>(3), 0.5);
  write_legacy_vtk(dir / "d.vtk", test::make_test_particles<3, double>(3), 0.5);
  EXPECT_NE(slurp(dir / "f.vtk").find("POINTS 3 float\n"), std::string::npos);
  EXPECT_NE(slurp(dir / "d.vtk").find("POINTS 3 double\n"), std::string::npos);
  // The PLY header: the time as a comment, Blender/Houdini property names.
  write_ply(dir / "p.ply", test::make_test_particles<2, double>(3), 0.125, fields_of(kFieldVelocity | kFieldId));
  const std::string ply = slurp(dir / "p.ply");
  EXPECT_EQ(ply.substr(0, ply.find("end_header\n") + 11),
            "ply\nformat binary_little_endian 1.0\ncomment sph frame\ncomment time 0.125\nelement vertex 3\n"
            "property float x\nproperty float y\nproperty float z\nproperty float vx\nproperty float vy\n"
            "property float vz\nproperty uint id\nend_header\n");
  EXPECT_EQ(ply.size(), ply.find("end_header\n") + 11 + 3 * 28u);
}

// ---- refused files --------------------------------------------------------------------------

/// read_frame(path) throws an sph::Error naming the file whose message contains `what`.
void expect_refused(const fs::path& path, const std::string& what) {
  try {
    read_frame(path);
    ADD_FAILURE() << path << " was accepted; expected an error containing \"" << what << "\"";
  } catch (const Error& e) {
    EXPECT_EQ(e.where(), path.string()) << e.what();
    EXPECT_NE(e.message().find(what), std::string::npos) << e.what();
  }
}

TEST_P(FrameRoundTrip, EveryTruncationIsRefusedOrAWholeShorterFile) {
  const FrameFormat f = GetParam();
  TempDir dir;
  const auto ps = test::make_test_particles<3, double>(5);
  const fs::path path = frame_path(dir, f);
  write_frame(f, path, ps, 0.25, kAllFrameFields);
  const std::string good = slurp(path);
  const FrameData full = read_frame(path);
  std::size_t refused = 0;
  for (std::size_t len = 0; len < good.size(); ++len) {
    spit(path, good.substr(0, len));
    try {
      const FrameData fr = read_frame(path);
      // Accepted: only the final newline was cut, or (legacy format only, which has no end
      // marker) the file was cut at a section boundary and is a whole file with fewer sections.
      // It must then hold the same values.
      const bool only_whitespace = good.find_first_not_of(" \n", len) == std::string::npos;
      EXPECT_TRUE(only_whitespace || f == FrameFormat::Vtk)
          << "cut at " << len << " of " << good.size() << " was accepted";
      EXPECT_EQ(fr.size, full.size);
      EXPECT_EQ(fr.position, full.position);
      for (const FrameField& ff : fr.fields) {
        ASSERT_NE(full.field(ff.name), nullptr);
        EXPECT_EQ(ff.values, full.field(ff.name)->values) << ff.name << " cut at " << len;
      }
      if (!only_whitespace) {
        EXPECT_LT(fr.fields.size(), full.fields.size()) << "cut at " << len;
      }
    } catch (const Error& e) {
      EXPECT_EQ(e.where(), path.string());
      ++refused;
    }
  }
  EXPECT_GE(refused, good.size() - 12) << "nearly every cut is refused";
}

TEST_P(FrameRoundTrip, CorruptBytesNeverCrash) {
  // Every byte of the header region (and a sample of the data) replaced by a few values: the
  // reader throws sph::Error or returns a frame, never reads out of bounds (run under ASan in CI).
  const FrameFormat f = GetParam();
  TempDir dir;
  const fs::path path = frame_path(dir, f);
  write_frame(f, path, test::make_test_particles<3, float>(4), 1.5, kAllFrameFields);
  const std::string good = slurp(path);
  std::size_t refused = 0;
  for (std::size_t at = 0; at < good.size(); ++at)
    for (const char c : {'\0', '9', '\xff', ' ', '\n'}) {
      if (good[at] == c) continue;
      std::string bad = good;
      bad[at] = c;
      spit(path, bad);
      try {
        const FrameData fr = read_frame(path);
        EXPECT_EQ(fr.position.size(), 3 * fr.size);
        for (const FrameField& ff : fr.fields) EXPECT_EQ(ff.values.size(), fr.size * ff.components);
      } catch (const Error& e) {
        EXPECT_EQ(e.where(), path.string());
        ++refused;
      }
    }
  EXPECT_GT(refused, 0u);
}

TEST(FrameFiles, ForeignAndMissingFilesAreRefused) {
  TempDir dir;
  expect_refused(dir / "missing.vtu", "no such frame file");
  fs::create_directory(dir / "d.ply");
  expect_refused(dir / "d.ply", "is not a file");
  spit(dir / "frame.txt", "hello");
  expect_refused(dir / "frame.txt", "expected .vtu, .vtk or .ply");
  spit(dir / "ascii.ply",
       "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
       "property float z\nend_header\n1 2 3\n");
  expect_refused(dir / "ascii.ply", "binary little-endian");
  spit(dir / "faces.ply",
       "ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\nproperty float y\n"
       "property float z\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n");
  expect_refused(dir / "faces.ply", "element other than");
  spit(dir / "color.ply",
       "ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\nproperty float y\n"
       "property float z\nproperty float red\nend_header\n");
  expect_refused(dir / "color.ply", "\"red\"");
  spit(dir / "noz.ply",
       "ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\nproperty float y\n"
       "end_header\n");
  expect_refused(dir / "noz.ply", "x, y and z");
  spit(dir / "ascii.vtk", "# vtk DataFile Version 4.2\nt\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 1 float\n0 0 0\n");
  expect_refused(dir / "ascii.vtk", "BINARY");
  spit(dir / "poly.vtk", "# vtk DataFile Version 4.2\nt\nBINARY\nDATASET STRUCTURED_POINTS\n");
  expect_refused(dir / "poly.vtk", "UNSTRUCTURED_GRID");
  spit(dir / "huge.vtk",
       "# vtk DataFile Version 4.2\nt\nBINARY\nDATASET UNSTRUCTURED_GRID\nPOINTS 99999999999999 float\n");
  expect_refused(dir / "huge.vtk", "more than its");
  spit(dir / "other.vtu", "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\"></VTKFile>\n");
  expect_refused(dir / "other.vtu", "not a VTK XML unstructured grid");
  // A .vtu another program wrote, compressed: refused, not misread.
  write_vtu(dir / "c.vtu", test::make_test_particles<3, double>(2), 0);
  std::string c = slurp(dir / "c.vtu");
  c.replace(c.find("header_type"), 0, "compressor=\"vtkZLibDataCompressor\" ");
  spit(dir / "c.vtu", c);
  expect_refused(dir / "c.vtu", "compressed");
  // An unknown point field.
  write_vtu(dir / "u.vtu", test::make_test_particles<3, double>(2), 0);
  std::string u = slurp(dir / "u.vtu");
  u.replace(u.find("Name=\"pressure\""), 15, "Name=\"temperat\"");
  spit(dir / "u.vtu", u);
  expect_refused(dir / "u.vtu", "\"temperat\"");
}

TEST(FrameFiles, VtuWithoutTimeReadsAsTimeZero) {
  // Frames written before frames carried their time.
  TempDir dir;
  write_vtu(dir / "a.vtu", test::make_test_particles<2, double>(3), 7.5);
  std::string s = slurp(dir / "a.vtu");
  const std::size_t b = s.find("    <FieldData>"), e = s.find("</FieldData>\n") + 13;
  s.erase(b, e - b);
  spit(dir / "a.vtu", s);
  const FrameData fr = read_frame(dir / "a.vtu");  // the offsets still point at the blocks
  EXPECT_EQ(fr.time, 0.0);
  EXPECT_EQ(fr.size, 3u);
}

// ---- schedule ---------------------------------------------------------------------------------

/// The steps s in [0, steps] that FrameSchedule writes, given dt and the output settings.
std::vector<std::int64_t> scheduled(const OutputDesc& out, double dt, std::int64_t steps) {
  FrameSchedule sched(out);
  std::vector<std::int64_t> frames;
  for (std::int64_t s = 0; s <= steps; ++s) {
    const double t = static_cast<double>(s) * dt;  // as Simulation::time()
    if (sched.due(s, t, s == steps)) {
      frames.push_back(s);
      sched.written(t);
    }
  }
  return frames;
}

TEST(FrameSchedule, EveryNStepsAndTheLastStep) {
  OutputDesc out;
  out.every_steps = 4;
  EXPECT_EQ(scheduled(out, 0.01, 10), (std::vector<std::int64_t>{0, 4, 8, 10}));
  out.every_steps = 0;
  EXPECT_TRUE(scheduled(out, 0.01, 10).empty()) << "no schedule: no frames, not even the last";
}

TEST(FrameSchedule, FramesPerSecondAtTheFirstStepReachingEachTick) {
  // dt = 1.5e-4 s, 1000 frames/s: frame k at the first step s with 15 s >= 100 k (integers, so
  // the expectation has no round-off); ticks 3 and 6 fall exactly on steps 20 and 40.
  OutputDesc out;
  out.every_steps = 0;
  out.fps = 1000;
  std::vector<std::int64_t> expected;
  for (std::int64_t k = 0; (100 * k + 14) / 15 <= 400; ++k) expected.push_back((100 * k + 14) / 15);
  expected.push_back(401);  // the last step
  EXPECT_EQ(scheduled(out, 1.5e-4, 401), expected);
  // Ticks that land on steps in exact arithmetic, whatever the rounding of s * dt: dt = a / b,
  // so frame k is at the first s with s a fps >= k b (integers).
  struct Case {
    std::int64_t a, b, fps;
  };
  for (const Case c : {Case{1, 10, 10}, Case{1, 100, 100}, Case{1, 1000, 30}, Case{3, 10, 1}, Case{7, 100, 3}}) {
    const double dt = static_cast<double>(c.a) / static_cast<double>(c.b);
    SCOPED_TRACE(::testing::Message() << "dt " << dt << ", fps " << c.fps);
    std::vector<std::int64_t> want;
    for (std::int64_t k = 0;; ++k) {
      const std::int64_t s = (k * c.b + c.a * c.fps - 1) / (c.a * c.fps);
      if (s > 3000) break;
      want.push_back(s);
    }
    if (want.back() != 3000) want.push_back(3000);
    EXPECT_EQ(scheduled(OutputDesc{0, static_cast<double>(c.fps), {FrameFormat::Vtu}, {}}, dt, 3000), want);
  }
}

TEST(FrameSchedule, StepsLongerThanTheFramePeriodWriteOneFramePerStep) {
  OutputDesc out{0, 10000, {FrameFormat::Vtu}, {}};  // a frame every 1e-4 s, steps of 1.5e-4 s
  std::vector<std::int64_t> every(31);
  for (std::int64_t s = 0; s <= 30; ++s) every[static_cast<std::size_t>(s)] = s;
  EXPECT_EQ(scheduled(out, 1.5e-4, 30), every) << "one frame per step, no backlog";
  // Steps of exactly 3 periods: still one frame each.
  EXPECT_EQ(scheduled(OutputDesc{0, 30, {FrameFormat::Vtu}, {}}, 0.1, 5),
            (std::vector<std::int64_t>{0, 1, 2, 3, 4, 5}));
}

TEST(FrameWriter, WritesEveryFormatWithTheSimulatedTime) {
  TempDir dir;
  SceneDesc desc = read_scene_file(
      kDamBreak, {"Configuration.numberOfSteps=41", "Configuration.outputEveryNSteps=0", "Configuration.outputFps=1000",
                  "Configuration.outputFormats=[\"ply\",\"vtk\"]", "Configuration.outputFields=[\"id\",\"velocity\"]"});
  fs::create_directories(dir / "frames");
  Simulation<2, double> sim = make_simulation<2, double>(desc);
  FrameWriter<2, double> w(dir.path(), desc.output);
  EXPECT_TRUE(w.write_due(sim, false));
  for (int s = 1; s <= 41; ++s) {
    sim.step();
    w.write_due(sim, s == 41);
  }
  // Steps 0, 7, 14, 20, 27, 34, 40 and the last, 41.
  const std::vector<std::int64_t> steps{0, 7, 14, 20, 27, 34, 40, 41};
  ASSERT_EQ(w.frames_written(), steps.size());
  EXPECT_FALSE(fs::exists(dir / "frames.pvd")) << "no .vtu frames, no ParaView collection";
  for (std::size_t k = 0; k < steps.size(); ++k) {
    for (const char* ext : {"ply", "vtk"}) {
      const FrameData fr = read_frame(dir / fmt::format("frames/frame_{:06d}.{}", k, ext));
      EXPECT_EQ(fr.time, static_cast<double>(steps[k]) * 1.5e-4) << k << ext;
      EXPECT_EQ(fr.size, sim.particles().size());
      ASSERT_EQ(fr.fields.size(), 2u);
      EXPECT_EQ(fr.fields[0].name, "velocity");
      EXPECT_EQ(fr.fields[1].name, "id");
    }
  }
  EXPECT_FALSE(fs::exists(dir / "frames/frame_000000.vtu"));
  EXPECT_FALSE(fs::exists(dir / "frames/frame_000008.ply"));
  // The last frame holds the simulation's state.
  const FrameData last = read_frame(dir / "frames/frame_000007.vtk");
  const auto& ps = sim.particles();
  for (std::size_t i = 0; i < ps.size(); i += 97) {
    EXPECT_EQ(last.position[3 * i], ps.position[i][0]);
    EXPECT_EQ(last.field("id")->values[i], static_cast<double>(ps.id[i]));
  }
}

// ---- run and compare directories ---------------------------------------------------------------

/// A finished run of the dam break into `dir` with the given extra overrides.
void make_run(const fs::path& dir, std::vector<std::string> sets, int steps = 6) {
  sets.push_back("Configuration.numberOfSteps=" + std::to_string(steps));
  sets.push_back("Configuration.outputEveryNSteps=2");
  const SceneDesc desc = read_scene_file(kDamBreak, sets);
  prepare_output_directory(dir);
  Simulation<2, double> sim = make_simulation<2, double>(desc);
  RunOutput<2, double> out(dir, desc, {"standard", 1});
  out.begin(sim);
  for (int s = 0; s < steps; ++s) out.after_step(sim, sim.step(), s + 1 == steps);
  out.finish(sim, "completed", 0.1);
}

TEST(RunDirectory, ReadsTheSceneAndListsTheFrames) {
  TempDir tmp;
  const fs::path dir = tmp / "run";
  make_run(dir, {"Configuration.outputFormats=[\"ply\",\"vtk\"]", "Fluid.particleMass=0.0125"});
  const RunDirectory run = open_run_directory(dir);
  EXPECT_EQ(run.format, FrameFormat::Vtk) << "vtk comes before ply when there is no vtu";
  ASSERT_EQ(run.frames.size(), 4u);  // steps 0, 2, 4, 6
  for (std::size_t k = 0; k < 4; ++k) EXPECT_EQ(run.frames[k], dir / fmt::format("frames/frame_{:06d}.vtk", k));
  EXPECT_EQ(run.dimension, 2);
  EXPECT_EQ(run.label, "dam_break_2d");
  const SceneDesc desc = read_scene_file(kDamBreak);
  EXPECT_EQ(run.particle_radius, desc.body<2>().sim.particle_radius);
  EXPECT_EQ(run.kernel_radius, desc.body<2>().sim.kernel_radius);
  EXPECT_EQ(run.rest_density, desc.body<2>().sim.fluid.rest_density);
  EXPECT_EQ(run.particle_mass, 0.0125);
  EXPECT_EQ(run.box_lo[0], desc.body<2>().sim.container.lo[0]);
  EXPECT_EQ(run.box_hi[1], desc.body<2>().sim.container.hi[1]);
  EXPECT_EQ(run.box_hi[2], 0.0);
  EXPECT_EQ(open_run_directory(dir, FrameFormat::Ply).frames.back(), dir / "frames/frame_000003.ply");
  try {
    open_run_directory(dir, FrameFormat::Vtu);
    ADD_FAILURE() << "no .vtu frames, yet accepted";
  } catch (const Error& e) {
    EXPECT_NE(e.message().find("no .vtu frames"), std::string::npos) << e.what();
  }
  // Stray files are ignored; a gap in the numbering is an error naming the missing frame.
  spit(dir / "frames" / "notes.txt", "x");
  spit(dir / "frames" / ".frame_000004.vtk.tmp123-1", "partial");
  EXPECT_EQ(open_run_directory(dir).frames.size(), 4u);
  fs::remove(dir / "frames/frame_000001.vtk");
  try {
    open_run_directory(dir);
    ADD_FAILURE() << "a gap was accepted";
  } catch (const Error& e) {
    EXPECT_NE(e.message().find("frame_000001.vtk"), std::string::npos) << e.what();
  }
}

TEST(RunDirectory, DefaultMassAndTheMissingCases) {
  TempDir tmp;
  const fs::path dir = tmp / "run";
  make_run(dir, {});
  const RunDirectory run = open_run_directory(dir);
  EXPECT_EQ(run.format, FrameFormat::Vtu);
  const SceneDesc desc = read_scene_file(kDamBreak);
  const Simulation<2, double> sim = make_simulation<2, double>(desc);
  EXPECT_EQ(run.particle_mass, sim.particles().mass);
  EXPECT_GT(run.particle_mass, 0);
  const auto refused = [](const fs::path& d, const std::string& what) {
    try {
      open_run_directory(d);
      ADD_FAILURE() << d << " accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.where(), d.string());
      EXPECT_NE(e.message().find(what), std::string::npos) << e.what();
    }
  };
  refused(tmp / "nothing", "no such directory");
  refused(tmp.path(), "no scene.json");
  make_run(tmp / "noframes", {"Configuration.numberOfSteps=3"});
  for (const auto& e : fs::directory_iterator(tmp / "noframes/frames")) fs::remove(e.path());
  refused(tmp / "noframes", "holds no frames");
}

TEST(RunDirectories, ARunOrTheRunsOfACompareDirectoryInOrder) {
  TempDir tmp;
  make_run(tmp / "single", {});
  EXPECT_EQ(run_directories(tmp / "single"), std::vector<fs::path>{tmp / "single"});

  const fs::path cmp = tmp / "cmp";
  make_run(cmp / "verlet", {"Configuration.neighbors=verlet"});
  make_run(cmp / "standard", {"Configuration.neighbors=standard"});
  write_run_list(cmp, {"standard", "verlet"});
  EXPECT_EQ(slurp(cmp / kRunListFile), "standard\nverlet\n");
  EXPECT_EQ(run_directories(cmp), (std::vector<fs::path>{cmp / "standard", cmp / "verlet"}));
  EXPECT_EQ(open_run_directory(cmp / "verlet").label, "verlet");
  EXPECT_EQ(open_run_directory(cmp / "standard").label, "standard");

  const auto refused = [&](const std::string& list, const std::string& what) {
    spit(cmp / kRunListFile, list);
    try {
      run_directories(cmp);
      ADD_FAILURE() << "accepted " << list;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("runs.txt"), std::string::npos) << e.what();
    }
  };
  refused("standard\nadaptive\n", "\"adaptive\", which is not a run directory");
  refused("\n\n", "lists no runs");
  refused("standard\n../single\n", "line 2");
  refused("standard\nstandard\n", "line 2");
  spit(cmp / kRunListFile, "verlet\r\n\nstandard  \n");  // blank lines and trailing blanks
  EXPECT_EQ(run_directories(cmp), (std::vector<fs::path>{cmp / "verlet", cmp / "standard"}));

  fs::remove(cmp / kRunListFile);
  try {
    run_directories(cmp);
    ADD_FAILURE() << "neither a run nor a compare directory, yet accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.where(), cmp.string());
    EXPECT_NE(e.message().find("neither a run directory"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace sph

namespace sph {
namespace {

TEST(BodiesTable, ReadsWhatTheWriterWritesAndRefusesAnythingElse) {
  test::TempDir tmp;
  const std::string header = fmt::format("{}\n", fmt::join(kBodyColumns, ","));
  const std::string row = "3,0.25,1,0.5,0.75,0,1,0,0,0,0.1,0,0,0,0,0.2,1,2,0,0,0,3\n";
  test::spit(tmp / "good.csv", header + row);
  const std::vector<BodyPoseRow> rows = read_body_rows(tmp / "good.csv");
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].time, 0.25);
  EXPECT_EQ(rows[0].obstacle, 1u);
  EXPECT_EQ(rows[0].position, (std::array<double, 3>{0.5, 0.75, 0}));
  EXPECT_EQ(rows[0].orientation, (std::array<double, 4>{1, 0, 0, 0}));
  // A wrong header, a short row, a word, a negative, fractional or huge obstacle, a negative frame,
  // an orientation that is not a unit quaternion: one error naming the file.
  for (const std::string& bad : {std::string("frame,time\n") + row, header + "3,0.25,1\n",
                                 header + "3,0.25,one,0.5,0.75,0,1,0,0,0,0.1,0,0,0,0,0.2,1,2,0,0,0,3\n",
                                 header + "3,0.25,-1,0.5,0.75,0,1,0,0,0,0.1,0,0,0,0,0.2,1,2,0,0,0,3\n",
                                 header + "3,0.25,1.5,0.5,0.75,0,1,0,0,0,0.1,0,0,0,0,0.2,1,2,0,0,0,3\n",
                                 header + "3,0.25,1e300,0.5,0.75,0,1,0,0,0,0.1,0,0,0,0,0.2,1,2,0,0,0,3\n",
                                 header + "-3,0.25,1,0.5,0.75,0,1,0,0,0,0.1,0,0,0,0,0.2,1,2,0,0,0,3\n",
                                 header + "3,0.25,1,0.5,0.75,0,0,0,0,0,0.1,0,0,0,0,0.2,1,2,0,0,0,3\n"}) {
    test::spit(tmp / "bad.csv", bad);
    try {
      read_body_rows(tmp / "bad.csv");
      ADD_FAILURE() << "accepted: " << bad;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("bad.csv"), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(read_body_rows(tmp / "missing.csv"), Error);
}

}  // namespace
}  // namespace sph
