// A particle field added in one place (ParticleSet::add_field) is carried everywhere the field
// table reaches: appends, permutation, checkpoints (ParticleSet::save / load), every frame
// format's writer and reader, and the in-memory frame view (frame_data_of).

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <sph/core/error.h>
#include <sph/core/state_stream.h>
#include <sph/io/frame_format.h>
#include <sph/io/frames.h>

#include "support/temp_dir.h"
#include "support/test_particles.h"

namespace sph {
namespace {

namespace fs = std::filesystem;

const FieldSpec kTemperature{"temperature", FieldKind::Real, "K", "K", "a test scalar"};
const FieldSpec kVorticity{"vorticity", FieldKind::Vector, "1/s", "1/s", "a test vector"};

/// A test set with the two added fields, each value a function of the particle's id.
template <int D, class R>
ParticleSet<D, R> set_with_added_fields(std::size_t n) {
  ParticleSet<D, R> ps = test::make_test_particles<D, R>(n);
  const std::size_t t = ps.add_field(kTemperature), w = ps.add_field(kVorticity);
  for (std::size_t i = 0; i < ps.size(); ++i) {
    const double id = static_cast<double>(ps.id[i]);
    ps.real_field(t)[i] = static_cast<R>(273.15 + id / 3);
    for (int d = 0; d < D; ++d) ps.vector_field(w)[i][d] = static_cast<R>(id * 0.1 - d - 1.0 / 7);
  }
  return ps;
}

template <int D, class R>
void expect_values_follow_ids(const ParticleSet<D, R>& ps) {
  const std::size_t t = static_cast<std::size_t>(ps.added_field_index("temperature"));
  const std::size_t w = static_cast<std::size_t>(ps.added_field_index("vorticity"));
  for (std::size_t i = 0; i < ps.size(); ++i) {
    const double id = static_cast<double>(ps.id[i]);
    EXPECT_EQ(ps.real_field(t)[i], static_cast<R>(273.15 + id / 3)) << i;
    for (int d = 0; d < D; ++d) EXPECT_EQ(ps.vector_field(w)[i][d], static_cast<R>(id * 0.1 - d - 1.0 / 7)) << i;
  }
}

TEST(AddedField, ZeroForParticlesPresentAndAddedLater) {
  ParticleSet<3, double> ps;
  ps.mass = 1.0;
  ps.add({}, {});
  const std::size_t t = ps.add_field(kTemperature);
  ps.real_field(t)[0] = 5;
  ps.add({}, {});
  ps.reserve(10);
  ASSERT_EQ(ps.real_field(t).size(), 2u);
  EXPECT_EQ(ps.real_field(t)[0], 5.0);
  EXPECT_EQ(ps.real_field(t)[1], 0.0);
  EXPECT_GE(ps.real_field(t).capacity(), 10u);
}

TEST(AddedField, FollowsItsParticleThroughAPermutation) {
  ParticleSet<2, float> ps = set_with_added_fields<2, float>(40);
  std::vector<std::uint32_t> perm(ps.size());
  for (std::size_t k = 0; k < perm.size(); ++k) perm[k] = static_cast<std::uint32_t>((k * 7 + 3) % perm.size());
  ps.permute(perm);
  expect_values_follow_ids(ps);
}

TEST(AddedField, RoundTripsThroughACheckpoint) {
  const ParticleSet<3, float> ps = set_with_added_fields<3, float>(25);
  std::stringstream buf;
  StateWriter w(buf);
  ps.save(w);
  ParticleSet<3, float> back;
  back.add_field(kTemperature);
  back.add_field(kVorticity);
  StateReader r(buf, w.written(), "ckpt");
  back.load(r);
  ASSERT_EQ(back.size(), ps.size());
  EXPECT_EQ(back.next_id(), ps.next_id());
  expect_values_follow_ids(back);
  EXPECT_EQ(r.checksum().value(), w.checksum().value());
}

TEST(AddedField, ACheckpointWithOtherFieldsIsRefused) {
  const ParticleSet<2, double> ps = set_with_added_fields<2, double>(5);
  std::stringstream buf;
  StateWriter w(buf);
  ps.save(w);
  {
    ParticleSet<2, double> none;  // lacks both fields
    StateReader r(buf, w.written(), "ckpt");
    EXPECT_THROW(none.load(r), Error);
  }
  buf.clear();
  buf.seekg(0);
  ParticleSet<2, double> swapped;  // the same fields in another order
  swapped.add_field(kVorticity);
  swapped.add_field(kTemperature);
  StateReader r(buf, w.written(), "ckpt");
  try {
    swapped.load(r);
    ADD_FAILURE() << "loaded a checkpoint whose fields are in another order";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("temperature"), std::string::npos) << e.what();
  }
}

TEST(AddedField, BadSpecsAreRefused) {
  ParticleSet<3, double> ps;
  EXPECT_THROW(ps.add_field({"Temperature", FieldKind::Real, "", "", ""}), Error);  // not a-z0-9_
  EXPECT_THROW(ps.add_field({"", FieldKind::Real, "", "", ""}), Error);
  EXPECT_THROW(ps.add_field({"density", FieldKind::Real, "", "", ""}), Error);  // a built-in field's name
  EXPECT_THROW(ps.add_field({"tag", FieldKind::Id, "", "", ""}), Error);
  ps.add_field(kTemperature);
  EXPECT_THROW(ps.add_field(kTemperature), Error);     // twice
  EXPECT_THROW(ps.vector_field(0), std::logic_error);  // a real field asked for as a vector
}

/// What a file of format f holds for `x`: PLY files are single precision.
double stored(FrameFormat f, double x) { return f == FrameFormat::Ply ? static_cast<float>(x) : x; }

template <int D, class R>
void check_frame_round_trip(FrameFormat f) {
  SCOPED_TRACE(::testing::Message() << frame_format_name(f) << ", " << D << "D, " << sizeof(R) * 8 << " bits");
  test::TempDir dir;
  const ParticleSet<D, R> ps = set_with_added_fields<D, R>(13);
  const fs::path path = dir / (std::string("frame_000000.") + frame_format_name(f));
  write_frame(f, path, ps, 0.5);
  const std::vector<FieldSpec> added = ps.added_field_specs();
  ASSERT_EQ(added.size(), 2u);
  const FrameData fr = read_frame(path, added);
  const FrameData mem = frame_data_of(ps, 0.5);
  std::vector<std::string> names, mem_names;
  for (const FrameField& ff : fr.fields) names.push_back(ff.name);
  for (const FrameField& ff : mem.fields) mem_names.push_back(ff.name);
  const std::vector<std::string> expected{"velocity",         "density",     "pressure", "id",
                                          "initial_position", "temperature", "vorticity"};
  EXPECT_EQ(names, expected) << "the built-in fields in table order, then the added ones";
  EXPECT_EQ(mem_names, expected);
  for (const char* name : {"temperature", "vorticity"}) {
    const FrameField* got = fr.field(name);
    const FrameField* want = mem.field(name);
    ASSERT_NE(got, nullptr) << name;
    ASSERT_NE(want, nullptr) << name;
    EXPECT_EQ(got->components, std::string(name) == "vorticity" ? 3 : 1);
    ASSERT_EQ(got->values.size(), want->values.size());
    for (std::size_t k = 0; k < got->values.size(); ++k) EXPECT_EQ(got->values[k], stored(f, want->values[k])) << k;
  }
  // Chosen by name like the built-in fields.
  write_frame(f, path, ps, 0.5, FrameFields::only({"density", "vorticity"}));
  const FrameData some = read_frame(path, added);
  ASSERT_EQ(some.fields.size(), 2u);
  EXPECT_EQ(some.fields[0].name, "density");
  EXPECT_EQ(some.fields[1].name, "vorticity");
  // A reader not told of the added field refuses it, naming it, as it refuses another program's.
  try {
    read_frame(path);
    ADD_FAILURE() << "a frame with a field the reader was not told of was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("vorticity"), std::string::npos) << e.what();
  }
}

TEST(AddedField, RoundTripsThroughEveryFrameFormat) {
  for (const FrameFormatDesc& f : kFrameFormats) {
    check_frame_round_trip<2, float>(f.format);
    check_frame_round_trip<3, double>(f.format);
  }
}

}  // namespace
}  // namespace sph
