// StateWriter / StateReader / Checksum: the byte streams checkpoints are made of.

#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <sph/core/error.h>
#include <sph/core/particle_set.h>
#include <sph/core/state_stream.h>

#include "support/expect.h"

namespace sph {
namespace {

std::string bytes_of(int n) {
  std::string s;
  for (int i = 0; i < n; ++i) s += static_cast<char>((i * 37 + 11) & 0xff);
  return s;
}

TEST(Checksum, IsTheSameHoweverTheBytesAreSplit) {
  const std::string data = bytes_of(1000);
  Checksum whole;
  whole.add(data.data(), data.size());
  for (std::size_t piece : {1u, 3u, 7u, 8u, 9u, 64u, 333u}) {
    Checksum parts;
    for (std::size_t at = 0; at < data.size(); at += piece)
      parts.add(data.data() + at, std::min(piece, data.size() - at));
    EXPECT_EQ(parts.value(), whole.value()) << "pieces of " << piece;
  }
}

TEST(Checksum, ChangesWithAnyFlippedBitAndWithTrailingZeros) {
  const std::string data = bytes_of(257);
  Checksum ref;
  ref.add(data.data(), data.size());
  for (std::size_t at : {0u, 100u, 255u, 256u})
    for (int bit : {0, 7}) {
      std::string bad = data;
      bad[at] = static_cast<char>(bad[at] ^ (1 << bit));
      Checksum c;
      c.add(bad.data(), bad.size());
      EXPECT_NE(c.value(), ref.value()) << "byte " << at << " bit " << bit;
    }
  Checksum longer;
  const std::string padded = data + std::string(3, '\0');
  longer.add(padded.data(), padded.size());
  EXPECT_NE(longer.value(), ref.value());
}

TEST(StateStream, RoundTripsValuesVectorsAndStrings) {
  std::stringstream buf;
  StateWriter w(buf);
  w.put(std::int64_t{-42});
  w.put(std::vector<double>{1.5, -2.25, 1e300});
  w.put(std::string("hello"));
  w.put(std::vector<std::uint8_t>{});
  StateReader r(buf, w.written(), "test");
  EXPECT_EQ(r.get<std::int64_t>(), -42);
  std::vector<double> v;
  r.get(v);
  EXPECT_EQ(v, (std::vector<double>{1.5, -2.25, 1e300}));
  std::string s;
  r.get(s);
  EXPECT_EQ(s, "hello");
  std::vector<std::uint8_t> e{9};
  r.get(e);
  EXPECT_TRUE(e.empty());
  EXPECT_EQ(r.left(), 0u);
  EXPECT_EQ(r.checksum().value(), w.checksum().value());
}

TEST(StateStream, RefusesReadingPastTheEnd) {
  std::stringstream buf;
  StateWriter w(buf);
  w.put(std::uint32_t{7});
  StateReader r(buf, w.written(), "ckpt");
  EXPECT_THROW(r.get<std::uint64_t>(), Error);
}

TEST(StateStream, RefusesACountLargerThanTheDataWithoutAllocatingIt) {
  std::stringstream buf;
  StateWriter w(buf);
  w.put(std::uint64_t{1} << 60);  // a corrupt length: would be 8 EiB of doubles
  w.put(1.0);
  StateReader r(buf, w.written(), "ckpt");
  std::vector<double> v;
  try {
    r.get(v);
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("ckpt"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("corrupt"), std::string::npos) << e.what();
  }
}

TEST(ParticleSetState, RoundTripsEveryFieldAndTheNextId) {
  ParticleSet<3, float> a;
  a.mass = 0.25f;
  for (int i = 0; i < 5; ++i) a.add({{float(i), 2.f * i, -1.f}}, {{0.5f, 0.f, float(-i)}});
  a.density[2] = 998.f, a.pressure[3] = -4.f, a.acceleration[1][2] = 9.f;
  const std::vector<std::uint32_t> perm{4, 3, 2, 1, 0};
  a.permute(perm);
  std::stringstream buf;
  StateWriter w(buf);
  a.save(w);
  ParticleSet<3, float> b;
  b.mass = 1.f;
  StateReader r(buf, w.written(), "ckpt");
  b.load(r);
  EXPECT_EQ(b.position, a.position);
  EXPECT_EQ(b.velocity, a.velocity);
  EXPECT_EQ(b.acceleration, a.acceleration);
  EXPECT_EQ(b.initial_position, a.initial_position);
  EXPECT_EQ(b.density, a.density);
  EXPECT_EQ(b.pressure, a.pressure);
  EXPECT_EQ(b.mass, a.mass);
  EXPECT_EQ(b.id, a.id);
  EXPECT_EQ(b.next_id(), 5u);
  EXPECT_EQ(b.add({}, {}), 5u) << "ids continue where the saved set stopped";
}

/// Saves `from` and loads that state into `into`: "" if it loaded, else the error's text.
template <int D, class R>
std::string load_error(const ParticleSet<D, R>& from, ParticleSet<D, R>& into) {
  std::stringstream buf;
  StateWriter w(buf);
  from.save(w);
  StateReader r(buf, w.written(), "ckpt");
  try {
    into.load(r);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(ParticleSetState, RefusesFieldsOfDifferentLengths) {
  ParticleSet<2, double> a;
  a.add({}, {}), a.add({}, {});
  a.velocity.pop_back();  // one short
  ParticleSet<2, double> p;
  EXPECT_CONTAINS(load_error(a, p), "different lengths");
}

// A set without initial positions round-trips without them; a set that keeps them refuses its
// state, and the reverse (they hold different counts of fields).
TEST(ParticleSetState, InitialPositionsKeptOrNotOnBothSides) {
  ParticleSet<3, float> a;
  a.mass = 0.5f;
  a.keep_initial_positions(false);
  for (int i = 0; i < 3; ++i) a.add({{float(i), 1.f, 2.f}}, {{0.f, float(i), 0.f}});
  ParticleSet<3, float> b;
  b.keep_initial_positions(false);
  ASSERT_EQ(load_error(a, b), "");
  EXPECT_EQ(b.position, a.position);
  EXPECT_EQ(b.velocity, a.velocity);
  EXPECT_EQ(b.mass, 0.5f);
  EXPECT_TRUE(b.initial_position.empty());
  ParticleSet<3, float> keeps;
  EXPECT_CONTAINS(load_error(a, keeps), "it holds 6 particle fields; this run has 7");
  ParticleSet<3, float> c, drops;
  c.add({}, {});
  drops.keep_initial_positions(false);
  EXPECT_CONTAINS(load_error(c, drops), "it holds 7 particle fields; this run has 6");
}

}  // namespace
}  // namespace sph
