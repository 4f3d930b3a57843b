#include <sph/io/frame_source.h>

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace sph::detail {

namespace {

class Cursor {
 public:
  explicit Cursor(const Source& src) : src_(src), f_(src.bytes) {}
  bool at_end() const { return pos_ >= f_.size(); }
  /// The next line (without its '\n'); fails at the end of the file.
  std::string_view line(const char* what) {
    if (pos_ >= f_.size()) src_.fail(std::string("ends before ") + what + ": the file is truncated");
    std::size_t end = f_.find('\n', pos_);
    if (end == std::string::npos) end = f_.size();
    std::string_view l = std::string_view(f_).substr(pos_, end - pos_);
    pos_ = end + 1;
    return l;
  }
  void skip_blank_lines() {
    while (pos_ < f_.size() && (f_[pos_] == '\n' || f_[pos_] == '\r' || f_[pos_] == ' ')) ++pos_;
  }
  /// `count` values of `type`, big-endian, as doubles; then the '\n' sph writes after them.
  std::vector<double> values(std::uint64_t count, Num type, const std::string& what) {
    if (count > (f_.size() - std::min(pos_, f_.size())) / num_size(type))
      src_.fail("ends inside the data of " + what + ": the file is truncated");
    std::vector<double> out(static_cast<std::size_t>(count));
    const std::size_t size = num_size(type);
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = load(f_.data() + pos_ + i * size, type, /*big=*/true);
    pos_ += out.size() * size;
    if (pos_ < f_.size() && f_[pos_] == '\n') ++pos_;
    return out;
  }

 private:
  const Source& src_;
  const std::string& f_;
  std::size_t pos_ = 0;
};

Num legacy_type(const Source& src, std::string_view t, const std::string& what) {
  if (t == "float") return Num::F32;
  if (t == "double") return Num::F64;
  if (t == "unsigned_int") return Num::U32;
  if (t == "int") return Num::I32;
  if (t == "unsigned_char") return Num::U8;
  if (t == "unsigned_long" || t == "vtktypeuint64") return Num::U64;
  if (t == "long" || t == "vtktypeint64") return Num::I64;
  src.fail("the data type \"" + std::string(t) + "\" of " + what + " is not one sph writes");
}

}  // namespace

FrameData read_legacy_vtk(const Source& src) {
  Cursor c(src);
  if (c.line("the header").rfind("# vtk DataFile Version ", 0) != 0)
    src.fail("is not a legacy VTK file (no \"# vtk DataFile Version\" line)");
  c.line("the title");
  if (split(c.line("the format line")) != std::vector<std::string_view>{"BINARY"})
    src.fail("is not a BINARY legacy VTK file, as sph writes them");
  if (split(c.line("the DATASET line")) != std::vector<std::string_view>{"DATASET", "UNSTRUCTURED_GRID"})
    src.fail("is not a legacy VTK UNSTRUCTURED_GRID, as sph writes them");
  FrameBuilder b(src);
  bool have_points = false, in_point_data = false;
  const auto count = [&](std::string_view s, const char* what) {
    const auto n = parse_count(s);
    if (!n) src.fail(std::string("bad count in the ") + what + " line");
    return *n;
  };
  while (true) {
    c.skip_blank_lines();
    if (c.at_end()) break;
    const std::string_view line = c.line("a section");
    const auto w = split(line);
    if (w.empty()) continue;
    const std::string key(w[0]);
    if (key == "FIELD" && w.size() == 3) {
      const std::uint64_t arrays = count(w[2], "FIELD");
      for (std::uint64_t k = 0; k < arrays; ++k) {
        c.skip_blank_lines();
        const auto a = split(c.line("a FIELD array"));
        if (a.size() != 4) src.fail("malformed FIELD array line");
        const std::uint64_t comps = count(a[1], "FIELD array"), tuples = count(a[2], "FIELD array");
        if (comps == 0 || comps > 16 || tuples > src.bytes.size()) src.fail("bad size of a FIELD array");
        const std::string name(a[0]);
        if (in_point_data && tuples != b.data.size)
          src.fail(fmt::format("the point field \"{}\" has {} values; expected one per point ({})", name, tuples,
                               b.data.size));
        auto v = c.values(comps * tuples, legacy_type(src, a[3], name), name);
        if (in_point_data) {
          b.add(name, static_cast<int>(comps), std::move(v));
        } else if (name == "TimeValue") {
          if (v.size() != 1 || !std::isfinite(v[0])) src.fail("its TimeValue is not one finite number");
          b.data.time = v[0];
        }
      }
    } else if (key == "POINTS" && w.size() == 3) {
      if (have_points) src.fail("has two POINTS sections");
      b.set_size(count(w[1], "POINTS"), 12);
      const Num t = legacy_type(src, w[2], "POINTS");
      if (t != Num::F32 && t != Num::F64) src.fail("its POINTS are not float or double");
      b.data.position = c.values(3 * b.data.size, t, "POINTS");
      have_points = true;
    } else if (key == "CELLS" && w.size() == 3) {
      if (!have_points) src.fail("has CELLS before POINTS");
      const std::uint64_t ints = count(w[2], "CELLS");
      c.values(std::min<std::uint64_t>(ints, src.bytes.size()) + (ints > src.bytes.size() ? 1 : 0), Num::I32, "CELLS");
    } else if (key == "CELL_TYPES" && w.size() == 2) {
      const std::uint64_t n = count(w[1], "CELL_TYPES");
      c.values(std::min<std::uint64_t>(n, src.bytes.size()) + (n > src.bytes.size() ? 1 : 0), Num::I32, "CELL_TYPES");
    } else if (key == "POINT_DATA" && w.size() == 2) {
      if (!have_points || count(w[1], "POINT_DATA") != b.data.size)
        src.fail("its POINT_DATA count differs from its POINTS count");
      in_point_data = true;
    } else if (in_point_data && key == "SCALARS" && (w.size() == 3 || w.size() == 4)) {
      const std::string name(w[1]);
      const std::uint64_t comps = w.size() == 4 ? count(w[3], "SCALARS") : 1;
      if (comps < 1 || comps > 4) src.fail("bad component count of the field \"" + name + "\"");
      const Num t = legacy_type(src, w[2], name);
      c.skip_blank_lines();
      if (split(c.line("a LOOKUP_TABLE line")) != std::vector<std::string_view>{"LOOKUP_TABLE", "default"})
        src.fail("the field \"" + name + "\" has no \"LOOKUP_TABLE default\" line");
      auto v = c.values(comps * b.data.size, t, name);
      b.add(name, static_cast<int>(comps), std::move(v));
    } else if (in_point_data && key == "VECTORS" && w.size() == 3) {
      const std::string name(w[1]);
      auto v = c.values(3 * b.data.size, legacy_type(src, w[2], name), name);
      b.add(name, 3, std::move(v));
    } else {
      src.fail("has an unexpected line \"" + std::string(line.substr(0, 40)) +
               "\": not a legacy VTK file as sph writes it");
    }
  }
  return b.finish(have_points);
}

}  // namespace sph::detail
