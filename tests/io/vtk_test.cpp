// write_vtu / write_pvd: the XML header agrees with the raw appended blocks (offsets, UInt64
// byte counts, file length), values round-trip, and .pvd entries keep their order.

#include <algorithm>
#include <bit>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <map>
#include <regex>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <sph/core/error.h>
#include <sph/io/vtk.h>

#include "support/temp_dir.h"
#include "support/test_particles.h"

namespace sph {
namespace {

namespace fs = std::filesystem;
using test::entries;
using test::slurp;
using test::TempDir;

struct ArrayInfo {
  std::map<std::string, std::string> attr;
  std::string name() const { return attr.count("Name") ? attr.at("Name") : ""; }
  std::string type() const { return attr.at("type"); }
  int components() const { return std::stoi(attr.at("NumberOfComponents")); }
  std::uint64_t offset() const { return std::stoull(attr.at("offset")); }
};

std::map<std::string, std::string> attributes(const std::string& s) {
  std::map<std::string, std::string> m;
  static const std::regex re(R"re((\w+)="([^"]*)")re");
  for (std::sregex_iterator it(s.begin(), s.end(), re), end; it != end; ++it) m[(*it)[1]] = (*it)[2];
  return m;
}

std::size_t type_size(const std::string& t) {
  if (t == "Float32") return 4;
  if (t == "Float64" || t == "UInt64" || t == "Int64") return 8;
  if (t == "UInt8") return 1;
  ADD_FAILURE() << "unexpected DataArray type " << t;
  return 0;
}

/// A parsed .vtu: header attributes, arrays, and the raw appended data.
struct Vtu {
  std::map<std::string, std::string> file_attr, piece_attr;
  std::vector<ArrayInfo> arrays;
  std::string blob;  // everything between '_' and the closing tags
  std::size_t n = 0;

  const ArrayInfo& array(const std::string& name) const {
    for (const auto& a : arrays)
      if (a.name() == name) return a;
    throw std::runtime_error("no array " + name);
  }
  /// The values of an array, checking the UInt64 byte count in front of the block.
  template <class T>
  std::vector<T> values(const std::string& name) const {
    const ArrayInfo& a = array(name);
    EXPECT_EQ(type_size(a.type()), sizeof(T)) << name;
    std::uint64_t bytes = 0;
    std::memcpy(&bytes, blob.data() + a.offset(), sizeof(bytes));
    std::vector<T> v(bytes / sizeof(T));
    if (bytes > 0) std::memcpy(v.data(), blob.data() + a.offset() + sizeof(bytes), bytes);  // (null data if empty)
    return v;
  }
};

/// Parses the file and checks its structure; failures are reported through gtest.
Vtu parse_vtu(const fs::path& path, std::size_t n_expected) {
  Vtu v;
  const std::string file = slurp(path);
  const std::string open_tag = "<AppendedData encoding=\"raw\">";
  const std::size_t ad = file.find(open_tag);
  EXPECT_NE(ad, std::string::npos) << "no raw AppendedData";
  if (ad == std::string::npos) return v;
  const std::size_t underscore = file.find('_', ad + open_tag.size());
  EXPECT_NE(underscore, std::string::npos);
  EXPECT_EQ(file.find_first_not_of(" \t\r\n", ad + open_tag.size()), underscore) << "only whitespace before '_'";
  const std::string header = file.substr(0, ad);
  const std::size_t data_start = underscore + 1;

  std::smatch m;
  EXPECT_TRUE(std::regex_search(header, m, std::regex(R"(<VTKFile([^>]*)>)")));
  v.file_attr = attributes(m[1]);
  EXPECT_EQ(v.file_attr["type"], "UnstructuredGrid");
  EXPECT_EQ(v.file_attr["header_type"], "UInt64");
  EXPECT_EQ(v.file_attr["byte_order"], std::endian::native == std::endian::little ? "LittleEndian" : "BigEndian");
  EXPECT_TRUE(std::regex_search(header, m, std::regex(R"(<Piece([^>]*)>)")));
  v.piece_attr = attributes(m[1]);
  EXPECT_EQ(v.piece_attr["NumberOfPoints"], std::to_string(n_expected));
  EXPECT_EQ(v.piece_attr["NumberOfCells"], std::to_string(n_expected));
  v.n = n_expected;

  static const std::regex da(R"(<DataArray([^>]*)/>)");
  for (std::sregex_iterator it(header.begin(), header.end(), da), end; it != end; ++it)
    v.arrays.push_back({attributes((*it)[1])});
  EXPECT_EQ(v.arrays.size(), 10u) << "TimeValue, velocity, density, pressure, id, initial_position, position, cells x3";

  // Walk the blocks in offset order: each starts where the previous one ended, and each byte
  // count matches N * components * sizeof(type).
  std::vector<ArrayInfo> by_offset = v.arrays;
  std::sort(by_offset.begin(), by_offset.end(), [](const auto& a, const auto& b) { return a.offset() < b.offset(); });
  std::uint64_t pos = 0;
  for (const auto& a : by_offset) {
    EXPECT_EQ(a.attr.at("format"), "appended") << a.name();
    EXPECT_EQ(a.offset(), pos) << "block of " << a.name() << " does not start where the previous one ended";
    EXPECT_LE(data_start + a.offset() + 8, file.size()) << a.name();
    if (data_start + a.offset() + 8 > file.size()) return v;
    std::uint64_t bytes = 0;
    std::memcpy(&bytes, file.data() + data_start + a.offset(), sizeof(bytes));
    const std::uint64_t tuples = a.name() == "TimeValue" ? 1 : n_expected;  // FieldData: one time
    EXPECT_EQ(bytes, tuples * static_cast<std::uint64_t>(a.components()) * type_size(a.type()))
        << "byte count of " << a.name();
    pos = a.offset() + 8 + bytes;
  }
  EXPECT_LE(data_start + pos, file.size());
  if (data_start + pos > file.size()) return v;
  // After the last block: only the closing tags (and whitespace). This pins the file length.
  const std::string tail = file.substr(data_start + pos);
  std::string compact;
  for (char c : tail)
    if (!std::isspace(static_cast<unsigned char>(c))) compact += c;
  EXPECT_EQ(compact, "</AppendedData></VTKFile>") << "file length does not match the blocks";
  EXPECT_EQ(file.size(), data_start + pos + tail.size());
  v.blob = file.substr(data_start, pos);
  return v;
}

template <int D, class R>
void check_round_trip(std::size_t n) {
  SCOPED_TRACE(::testing::Message() << D << "D, " << (sizeof(R) == 4 ? "float" : "double") << ", N = " << n);
  TempDir dir;
  const ParticleSet<D, R> ps = test::make_test_particles<D, R>(n);
  const fs::path path = dir / "frame_000000.vtu";
  write_vtu(path, ps);
  EXPECT_EQ(entries(dir.path()), std::vector<std::string>{"frame_000000.vtu"}) << "no temporaries left";
  const Vtu v = parse_vtu(path, n);
  if (::testing::Test::HasFailure()) return;

  const std::string ft = sizeof(R) == 4 ? "Float32" : "Float64";
  for (const char* name : {"velocity", "initial_position", "position"}) {
    EXPECT_EQ(v.array(name).type(), ft) << name;
    EXPECT_EQ(v.array(name).components(), 3) << name;
  }
  for (const char* name : {"density", "pressure"}) {
    EXPECT_EQ(v.array(name).type(), ft) << name;
    EXPECT_EQ(v.array(name).components(), 1) << name;
  }
  EXPECT_EQ(v.array("id").type(), "UInt64");
  EXPECT_EQ(v.array("connectivity").type(), "Int64");
  EXPECT_EQ(v.array("offsets").type(), "Int64");
  EXPECT_EQ(v.array("types").type(), "UInt8");

  const auto pos = v.values<R>("position");
  const auto vel = v.values<R>("velocity");
  const auto ini = v.values<R>("initial_position");
  const auto den = v.values<R>("density");
  const auto pre = v.values<R>("pressure");
  const auto ids = v.values<std::uint64_t>("id");
  ASSERT_EQ(pos.size(), 3 * n);
  ASSERT_EQ(ids.size(), n);
  for (std::size_t i = 0; i < n; ++i) {
    for (int d = 0; d < 3; ++d) {
      const std::size_t k = 3 * i + static_cast<std::size_t>(d);
      EXPECT_EQ(pos[k], d < D ? ps.position[i][d] : R(0)) << i << "," << d;
      EXPECT_EQ(vel[k], d < D ? ps.velocity[i][d] : R(0)) << i << "," << d;
      EXPECT_EQ(ini[k], d < D ? ps.initial_position[i][d] : R(0)) << i << "," << d;
    }
    EXPECT_EQ(den[i], ps.density[i]);
    EXPECT_EQ(pre[i], ps.pressure[i]);
    EXPECT_EQ(ids[i], ps.id[i]);
  }
  const auto conn = v.values<std::int64_t>("connectivity");
  const auto offs = v.values<std::int64_t>("offsets");
  const auto types = v.values<std::uint8_t>("types");
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_EQ(conn[i], static_cast<std::int64_t>(i));
    EXPECT_EQ(offs[i], static_cast<std::int64_t>(i + 1));
    EXPECT_EQ(types[i], 1) << "VTK_VERTEX";
  }
}

TEST(VtkWriter, Vtu3DDouble) { check_round_trip<3, double>(7); }
TEST(VtkWriter, Vtu2DFloat) { check_round_trip<2, float>(11); }
TEST(VtkWriter, Vtu3DFloat) { check_round_trip<3, float>(5); }
TEST(VtkWriter, Vtu2DDouble) { check_round_trip<2, double>(4); }
TEST(VtkWriter, VtuLarger) { check_round_trip<3, double>(2500); }
TEST(VtkWriter, VtuEmpty) {
  // Emitter scenes start with no particles: frame 0 is empty.
  check_round_trip<3, double>(0);
  check_round_trip<2, float>(0);
}

TEST(VtkWriter, VtuOverwritesAnOlderFrame) {
  TempDir dir;
  const fs::path path = dir / "f.vtu";
  write_vtu(path, test::make_test_particles<3, double>(50));
  write_vtu(path, test::make_test_particles<3, double>(3));
  parse_vtu(path, 3);
  EXPECT_EQ(entries(dir.path()), std::vector<std::string>{"f.vtu"});
}

TEST(VtkWriter, MissingDirectoryThrowsSphError) {
  TempDir dir;
  EXPECT_THROW(write_vtu(dir / "no/frame_000000.vtu", test::make_test_particles<3, double>(2)), Error);
  EXPECT_THROW(write_pvd(dir / "no/frames.pvd", {{0.0, "a.vtu"}}), Error);
  EXPECT_TRUE(entries(dir.path()).empty());
}

TEST(VtkWriter, PvdListsEntriesInOrder) {
  TempDir dir;
  const std::vector<PvdEntry> in{{0.0, "frames/frame_000000.vtu"},
                                 {0.00015, "frames/frame_000001.vtu"},
                                 {0.0003, "frames/frame_000002.vtu"},
                                 {1.5, "frames/frame_000003.vtu"},
                                 {12345.678901, "frames/frame_000004.vtu"}};
  const fs::path path = dir / "frames.pvd";
  write_pvd(path, in);
  const std::string s = slurp(path);
  EXPECT_NE(s.find("<VTKFile type=\"Collection\""), std::string::npos) << s;
  EXPECT_NE(s.find("<Collection>"), std::string::npos);
  EXPECT_NE(s.find("</Collection>"), std::string::npos);
  EXPECT_NE(s.find("</VTKFile>"), std::string::npos);
  static const std::regex ds(R"(<DataSet([^>]*)/>)");
  std::vector<std::map<std::string, std::string>> out;
  for (std::sregex_iterator it(s.begin(), s.end(), ds), end; it != end; ++it) out.push_back(attributes((*it)[1]));
  ASSERT_EQ(out.size(), in.size()) << s;
  for (std::size_t i = 0; i < in.size(); ++i) {
    EXPECT_EQ(out[i]["file"], in[i].file);
    // Times are written with 9 significant digits: plenty to keep frames apart and ordered.
    EXPECT_NEAR(std::stod(out[i]["timestep"]), in[i].time, 1e-8 * in[i].time) << out[i]["timestep"];
    if (i > 0) {
      EXPECT_GT(std::stod(out[i]["timestep"]), std::stod(out[i - 1]["timestep"]));
    }
  }
  // Rewriting with more entries replaces the file (the run rewrites it after every frame).
  std::vector<PvdEntry> more = in;
  more.push_back({20000.0, "frames/frame_000005.vtu"});
  write_pvd(path, more);
  const std::string s2 = slurp(path);
  EXPECT_NE(s2.find("frames/frame_000005.vtu"), s2.npos);
  EXPECT_LT(s2.find("frame_000004.vtu"), s2.find("frame_000005.vtu"));
  EXPECT_EQ(entries(dir.path()), std::vector<std::string>{"frames.pvd"});
}

TEST(VtkWriter, PvdEmpty) {
  TempDir dir;
  write_pvd(dir / "frames.pvd", {});
  const std::string s = slurp(dir / "frames.pvd");
  EXPECT_NE(s.find("<Collection>"), std::string::npos);
  EXPECT_EQ(s.find("<DataSet"), std::string::npos);
}

}  // namespace
}  // namespace sph
