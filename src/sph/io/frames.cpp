#include <sph/io/frames.h>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

#include <fmt/format.h>

#include <sph/core/error.h>
#include <sph/io/atomic_file.h>
#include <sph/io/frame_format.h>
#include <sph/neighbors/strategy.h>
#include <sph/scene/scene_reader.h>

namespace sph {

namespace fs = std::filesystem;

// ---- names ------------------------------------------------------------------------------------

const char* frame_format_name(FrameFormat f) {
  switch (f) {
    case FrameFormat::Vtu:
      return "vtu";
    case FrameFormat::Vtk:
      return "vtk";
    case FrameFormat::Ply:
      return "ply";
  }
  return "?";
}

std::optional<FrameFormat> parse_frame_format(std::string_view name) {
  for (FrameFormat f : {FrameFormat::Vtu, FrameFormat::Vtk, FrameFormat::Ply})
    if (name == frame_format_name(f)) return f;
  return std::nullopt;
}

FrameFieldMask frame_field_mask(const std::vector<std::string>& names) {
  FrameFieldMask mask = 0;
  for (const std::string& name : names) {
    const auto it = std::find(std::begin(kFrameFieldNames), std::end(kFrameFieldNames), name);
    SPH_CHECK(it != std::end(kFrameFieldNames), "unknown frame field \"" + name + "\"");
    mask |= 1u << (it - std::begin(kFrameFieldNames));
  }
  return mask;
}

const FrameField* FrameData::field(std::string_view name) const {
  for (const FrameField& f : fields)
    if (f.name == name) return &f;
  return nullptr;
}

namespace {

/// Components of each point field, in kFrameFieldNames order.
constexpr int kFieldComponents[] = {3, 1, 1, 1, 3};

int field_index(std::string_view name) {
  for (int i = 0; i < static_cast<int>(std::size(kFrameFieldNames)); ++i)
    if (name == kFrameFieldNames[i]) return i;
  return -1;
}

/// The number types frames hold.
enum class Num { F32, F64, U8, U32, I32, U64, I64 };

std::size_t num_size(Num t) {
  switch (t) {
    case Num::U8:
      return 1;
    case Num::F32:
    case Num::U32:
    case Num::I32:
      return 4;
    case Num::F64:
    case Num::U64:
    case Num::I64:
      return 8;
  }
  return 1;
}

/// The value of type `t` at `p`, stored big- or little-endian, as a double.
double load(const char* p, Num t, bool big) {
  unsigned char b[8];
  const std::size_t n = num_size(t);
  for (std::size_t k = 0; k < n; ++k) {
    const bool swap = big == (std::endian::native == std::endian::little);
    b[k] = static_cast<unsigned char>(p[swap ? n - 1 - k : k]);
  }
  switch (t) {
    case Num::F32: {
      float v;
      std::memcpy(&v, b, 4);
      return v;
    }
    case Num::F64: {
      double v;
      std::memcpy(&v, b, 8);
      return v;
    }
    case Num::U8:
      return b[0];
    case Num::U32: {
      std::uint32_t v;
      std::memcpy(&v, b, 4);
      return v;
    }
    case Num::I32: {
      std::int32_t v;
      std::memcpy(&v, b, 4);
      return v;
    }
    case Num::U64: {
      std::uint64_t v;
      std::memcpy(&v, b, 8);
      return static_cast<double>(v);
    }
    case Num::I64: {
      std::int64_t v;
      std::memcpy(&v, b, 8);
      return static_cast<double>(v);
    }
  }
  return 0;
}

/// A whole file in memory, and the error every reader throws: naming the file.
struct Source {
  fs::path path;
  std::string bytes;

  [[noreturn]] void fail(const std::string& message) const { throw Error(message, path.string()); }
};

Source slurp(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw Error("no such frame file", path.string());
  if (!fs::is_regular_file(path, ec)) throw Error("is not a file; expected a frame file", path.string());
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("cannot open the frame file (permissions?)", path.string());
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw Error("cannot read the frame file", path.string());
  return {path, ss.str()};
}

/// A whole unsigned decimal number, or nullopt.
std::optional<std::uint64_t> parse_count(std::string_view s) {
  std::uint64_t v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size() || s.empty()) return std::nullopt;
  return v;
}

/// A whole finite decimal number, or nullopt.
std::optional<double> parse_real(std::string_view s) {
  double v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size() || s.empty() || !std::isfinite(v)) return std::nullopt;
  return v;
}

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    std::size_t j = i;
    while (j < line.size() && line[j] != ' ' && line[j] != '\t' && line[j] != '\r') ++j;
    if (j > i) out.push_back(line.substr(i, j - i));
    i = j;
  }
  return out;
}

/// Collects the fields of a frame and checks names, sizes and duplicates.
class FrameBuilder {
 public:
  explicit FrameBuilder(const Source& src) : src_(src) {}
  FrameData data;

  /// Checks that a point count is plausible for the file's size before anything is allocated
  /// for it (`min_bytes` per point at least).
  void set_size(std::uint64_t n, std::size_t min_bytes) {
    if (n > src_.bytes.size() / min_bytes)
      src_.fail(fmt::format("declares {} points, more than its {} bytes can hold: the file is truncated or corrupt", n,
                            src_.bytes.size()));
    data.size = static_cast<std::size_t>(n);
  }
  void add(const std::string& name, int components, std::vector<double> values) {
    const int k = field_index(name);
    if (k < 0)
      src_.fail("holds a point field \"" + name +
                "\" that sph does not write; expected velocity, density, pressure, id or initial_position");
    if (components != kFieldComponents[k])
      src_.fail(fmt::format("the field \"{}\" has {} components; expected {}", name, components, kFieldComponents[k]));
    if (data.field(name)) src_.fail("the field \"" + name + "\" appears twice");
    data.fields.push_back({name, components, std::move(values)});
  }
  FrameData finish(bool have_position) {
    if (!have_position) src_.fail("holds no positions: not a frame written by sph");
    std::sort(data.fields.begin(), data.fields.end(),
              [](const FrameField& a, const FrameField& b) { return field_index(a.name) < field_index(b.name); });
    return std::move(data);
  }

 private:
  const Source& src_;
};

// ---- .vtu -------------------------------------------------------------------------------------

struct XmlTag {
  std::string name;
  bool closing = false;
  std::map<std::string, std::string> attr;
};

/// The tags of an XML header as sph writes it (no comments, CDATA or entities needed).
std::vector<XmlTag> xml_tags(const Source& src, std::string_view xml) {
  std::vector<XmlTag> tags;
  std::size_t i = 0;
  while ((i = xml.find('<', i)) != std::string_view::npos) {
    const std::size_t end = xml.find('>', i);
    if (end == std::string_view::npos) src.fail("its XML header ends inside a tag: not a .vtu file as sph writes it");
    std::string_view body = xml.substr(i + 1, end - i - 1);
    i = end + 1;
    if (!body.empty() && (body.front() == '?' || body.front() == '!')) continue;
    XmlTag t;
    if (!body.empty() && body.front() == '/') t.closing = true, body.remove_prefix(1);
    if (!body.empty() && body.back() == '/') body.remove_suffix(1);
    std::size_t k = 0;
    while (k < body.size() && !std::isspace(static_cast<unsigned char>(body[k]))) ++k;
    t.name = std::string(body.substr(0, k));
    while (k < body.size()) {
      while (k < body.size() && std::isspace(static_cast<unsigned char>(body[k]))) ++k;
      if (k >= body.size()) break;
      const std::size_t eq = body.find('=', k);
      if (eq == std::string_view::npos || eq + 1 >= body.size() || body[eq + 1] != '"')
        src.fail("malformed attribute in the XML tag <" + t.name + ">: not a .vtu file as sph writes it");
      const std::size_t close = body.find('"', eq + 2);
      if (close == std::string_view::npos)
        src.fail("unterminated attribute in the XML tag <" + t.name + ">: not a .vtu file as sph writes it");
      t.attr[std::string(body.substr(k, eq - k))] = std::string(body.substr(eq + 2, close - eq - 2));
      k = close + 1;
    }
    tags.push_back(std::move(t));
  }
  return tags;
}

FrameData read_vtu(const Source& src) {
  const std::string& f = src.bytes;
  const std::string open = "<AppendedData encoding=\"raw\">";
  if (f.rfind("<?xml", 0) != 0 || f.find("<VTKFile type=\"UnstructuredGrid\"") == std::string::npos)
    src.fail("is not a VTK XML unstructured grid (.vtu) file");
  const std::size_t ad = f.find(open);
  if (ad == std::string::npos) src.fail("has no raw appended data: not a .vtu file as sph writes it");
  std::size_t data = f.find_first_not_of(" \t\r\n", ad + open.size());
  if (data == std::string::npos || f[data] != '_')
    src.fail("the appended data does not start with '_': the file is truncated or corrupt");
  ++data;
  const std::vector<XmlTag> tags = xml_tags(src, std::string_view(f).substr(0, ad));
  {
    // The file ends with the closing tags sph writes: a file cut short at a block boundary is refused too.
    const std::size_t last = f.find_last_not_of(" \t\r\n");
    const std::string close = "</AppendedData>\n</VTKFile>";
    if (last == std::string::npos || last + 1 < close.size() ||
        f.compare(last + 1 - close.size(), close.size(), close) != 0)
      src.fail("does not end with </VTKFile>: the file is truncated");
  }

  bool big = false, have_piece = false, have_position = false;
  FrameBuilder b(src);
  std::string section;
  const auto array = [&](const XmlTag& t, std::uint64_t tuples, std::vector<double>& out) -> int {
    const auto get = [&](const char* key) -> std::string {
      const auto it = t.attr.find(key);
      return it == t.attr.end() ? std::string() : it->second;
    };
    const std::string type = get("type"), name = get("Name");
    Num num;
    if (type == "Float32")
      num = Num::F32;
    else if (type == "Float64")
      num = Num::F64;
    else if (type == "UInt8")
      num = Num::U8;
    else if (type == "UInt32")
      num = Num::U32;
    else if (type == "Int32")
      num = Num::I32;
    else if (type == "UInt64")
      num = Num::U64;
    else if (type == "Int64")
      num = Num::I64;
    else
      src.fail("the array \"" + name + "\" has type \"" + type + "\", which sph does not write");
    if (get("format") != "appended")
      src.fail("the array \"" + name + "\" is not in the raw appended data, as sph writes it");
    const auto comps = parse_count(get("NumberOfComponents").empty() ? "1" : get("NumberOfComponents"));
    const auto offset = parse_count(get("offset"));
    if (!comps || *comps < 1 || *comps > 3 || !offset)
      src.fail("the array \"" + name + "\" has a bad NumberOfComponents or offset");
    const std::uint64_t avail = f.size() - data;
    if (*offset > avail || avail - *offset < 8)
      src.fail("the array \"" + name + "\" lies beyond the end of the file: the file is truncated");
    std::uint64_t bytes = 0;
    std::memcpy(&bytes, f.data() + data + *offset, 8);
    if (big != (std::endian::native == std::endian::big))
      bytes = static_cast<std::uint64_t>(load(f.data() + data + *offset, Num::U64, big));
    const std::uint64_t want = tuples * *comps * num_size(num);  // tuples <= file size: no overflow
    if (bytes != want)
      src.fail(fmt::format("the array \"{}\" holds {} bytes; expected {} for {} points", name, bytes, want, tuples));
    if (avail - *offset - 8 < bytes)
      src.fail("the array \"" + name + "\" ends beyond the end of the file: the file is truncated");
    const char* p = f.data() + data + *offset + 8;
    const std::size_t count = static_cast<std::size_t>(tuples * *comps);
    out.resize(count);
    for (std::size_t i = 0; i < count; ++i) out[i] = load(p + i * num_size(num), num, big);
    return static_cast<int>(*comps);
  };
  for (const XmlTag& t : tags) {
    if (t.name == "VTKFile" && !t.closing) {
      const auto bo = t.attr.find("byte_order");
      const auto ht = t.attr.find("header_type");
      if (bo == t.attr.end() || (bo->second != "LittleEndian" && bo->second != "BigEndian"))
        src.fail("has no byte_order LittleEndian or BigEndian");
      big = bo->second == "BigEndian";
      if (ht == t.attr.end() || ht->second != "UInt64")
        src.fail("has no header_type=\"UInt64\": not a .vtu file as sph writes it");
      if (t.attr.count("compressor")) src.fail("is compressed: not a .vtu file as sph writes it");
    } else if (t.name == "Piece" && !t.closing) {
      if (have_piece) src.fail("has more than one Piece: not a .vtu file as sph writes it");
      have_piece = true;
      const auto it = t.attr.find("NumberOfPoints");
      const auto n = it == t.attr.end() ? std::nullopt : parse_count(it->second);
      if (!n) src.fail("its Piece has no valid NumberOfPoints");
      b.set_size(*n, 12);
    } else if (t.name == "FieldData" || t.name == "PointData" || t.name == "Points" || t.name == "Cells" ||
               t.name == "CellData") {
      section = t.closing ? "" : t.name;
    } else if (t.name == "DataArray" && !t.closing) {
      const auto nit = t.attr.find("Name");
      const std::string name = nit == t.attr.end() ? "" : nit->second;
      if (section == "FieldData") {
        if (name != "TimeValue") continue;  // (sph writes no other)
        std::vector<double> v;
        if (array(t, 1, v) != 1) src.fail("TimeValue has more than one component");
        if (!std::isfinite(v[0])) src.fail("its TimeValue is not a finite number");
        b.data.time = v[0];
        continue;
      }
      if (!have_piece) src.fail("has a DataArray outside a Piece: not a .vtu file as sph writes it");
      if (section == "Points") {
        if (array(t, b.data.size, b.data.position) != 3) src.fail("its points do not have 3 components");
        have_position = true;
      } else if (section == "PointData") {
        std::vector<double> v;
        const int comps = array(t, b.data.size, v);
        b.add(name, comps, std::move(v));
      }
      // Cells: sph writes one vertex per point; the reader needs nothing from them.
    }
  }
  if (!have_piece) src.fail("has no Piece: not a .vtu file as sph writes it");
  return b.finish(have_position);
}

// ---- legacy .vtk ------------------------------------------------------------------------------

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

// ---- .ply -------------------------------------------------------------------------------------

FrameData read_ply(const Source& src) {
  const std::string& f = src.bytes;
  const std::string end_marker = "end_header\n";
  if (f.rfind("ply\n", 0) != 0) src.fail("is not a PLY file (it does not start with \"ply\")");
  const std::size_t he = f.find(end_marker);
  if (he == std::string::npos) src.fail("its PLY header has no end_header line: the file is truncated or corrupt");
  std::istringstream header(f.substr(4, he - 4));
  FrameBuilder b(src);
  bool have_format = false, have_vertex = false;
  struct Prop {
    std::string name;
    Num type;
  };
  std::vector<Prop> props;
  for (std::string line; std::getline(header, line);) {
    const auto w = split(line);
    if (w.empty()) continue;
    if (w[0] == "format") {
      if (w.size() != 3 || w[1] != "binary_little_endian" || w[2] != "1.0")
        src.fail("is not a binary little-endian PLY file, as sph writes them");
      have_format = true;
    } else if (w[0] == "comment" || w[0] == "obj_info") {
      if (w.size() >= 3 && w[1] == "time") {
        const auto t = parse_real(w[2]);
        if (!t) src.fail("its \"comment time\" is not a finite number");
        b.data.time = *t;
      }
    } else if (w[0] == "element") {
      if (have_vertex || w.size() != 3 || w[1] != "vertex")
        src.fail("has an element other than one \"element vertex N\": not a PLY file as sph writes it");
      const auto n = parse_count(w[2]);
      if (!n) src.fail("bad vertex count in its PLY header");
      b.set_size(*n, 1);
      have_vertex = true;
    } else if (w[0] == "property") {
      if (!have_vertex || w.size() != 3) src.fail("has a property that is not a scalar vertex property");
      Num t;
      if (w[1] == "float" || w[1] == "float32")
        t = Num::F32;
      else if (w[1] == "double" || w[1] == "float64")
        t = Num::F64;
      else if (w[1] == "uint" || w[1] == "uint32")
        t = Num::U32;
      else if (w[1] == "int" || w[1] == "int32")
        t = Num::I32;
      else
        src.fail("has a property of type \"" + std::string(w[1]) + "\", which sph does not write");
      for (const Prop& p : props)
        if (p.name == w[2]) src.fail("has the property \"" + p.name + "\" twice");
      props.push_back({std::string(w[2]), t});
    } else {
      src.fail("has an unexpected PLY header line \"" + line.substr(0, 40) + "\"");
    }
  }
  if (!have_format || !have_vertex) src.fail("has no format or no vertex element in its PLY header");
  std::size_t record = 0;
  for (const Prop& p : props) record += num_size(p.type);
  const std::size_t data = he + end_marker.size();
  const std::size_t n = b.data.size;
  if (record == 0 || (f.size() - data) / record != n || (f.size() - data) % record != 0)
    src.fail(fmt::format("holds {} bytes of vertex data; expected {} for {} vertices: the file is truncated or corrupt",
                         f.size() - data, static_cast<std::uint64_t>(record) * n, n));
  // Which field (and component) each property fills: x y z, vx vy vz, density, pressure, id, x0 y0 z0.
  struct Target {
    int field;  // -1: position
    int component;
  };
  static const std::map<std::string, Target> known{
      {"x", {-1, 0}},      {"y", {-1, 1}},       {"z", {-1, 2}}, {"vx", {0, 0}}, {"vy", {0, 1}}, {"vz", {0, 2}},
      {"density", {1, 0}}, {"pressure", {2, 0}}, {"id", {3, 0}}, {"x0", {4, 0}}, {"y0", {4, 1}}, {"z0", {4, 2}}};
  std::vector<Target> targets;
  int seen[6][3] = {};
  for (const Prop& p : props) {
    const auto it = known.find(p.name);
    if (it == known.end()) src.fail("has the vertex property \"" + p.name + "\", which sph does not write");
    targets.push_back(it->second);
    seen[it->second.field + 1][it->second.component] = 1;
  }
  std::vector<std::vector<double>> values(6);
  const auto comps = [](int field) { return field < 0 ? 3 : kFieldComponents[field]; };
  for (int fi = -1; fi < 5; ++fi) {
    int count = 0;
    for (int k = 0; k < 3; ++k) count += seen[fi + 1][k];
    if (count == 0) continue;
    if (count != comps(fi))
      src.fail(fi < 0 ? "does not hold all of x, y and z"
                      : "holds only some of the components of " + std::string(kFrameFieldNames[fi]));
    values[static_cast<std::size_t>(fi + 1)].resize(n * static_cast<std::size_t>(comps(fi)));
  }
  if (!seen[0][0]) src.fail("does not hold x, y and z");
  const char* p = f.data() + data;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t k = 0; k < props.size(); ++k) {
      const Target t = targets[k];
      const std::size_t c = static_cast<std::size_t>(comps(t.field));
      values[static_cast<std::size_t>(t.field + 1)][i * c + static_cast<std::size_t>(t.component)] =
          load(p, props[k].type, /*big=*/false);
      p += num_size(props[k].type);
    }
  b.data.position = std::move(values[0]);
  for (int fi = 0; fi < 5; ++fi)
    if (seen[fi + 1][0])
      b.add(kFrameFieldNames[fi], kFieldComponents[fi], std::move(values[static_cast<std::size_t>(fi + 1)]));
  return b.finish(true);
}

/// "frame_NNNNNN.EXT" -> NNNNNN (6 digits or more), or nullopt.
std::optional<std::uint64_t> frame_number(const std::string& name, const std::string& ext) {
  if (name.rfind("frame_", 0) != 0 || name.size() < 6 + 6 + 1 + ext.size()) return std::nullopt;
  const std::string tail = "." + ext;
  if (name.compare(name.size() - tail.size(), tail.size(), tail) != 0) return std::nullopt;
  const std::string digits = name.substr(6, name.size() - 6 - tail.size());
  if (digits.size() < 6 || digits.size() > 12) return std::nullopt;
  return parse_count(digits);
}

}  // namespace

FrameData read_frame(const fs::path& file) {
  const std::string ext = file.extension().string();
  if (ext != ".vtu" && ext != ".vtk" && ext != ".ply")
    throw Error("unknown frame file extension \"" + ext + "\"; expected .vtu, .vtk or .ply", file.string());
  const Source src = slurp(file);
  if (ext == ".vtu") return read_vtu(src);
  if (ext == ".vtk") return read_legacy_vtk(src);
  return read_ply(src);
}

std::vector<fs::path> list_frames(const fs::path& dir, FrameFormat format) {
  const std::string ext = frame_format_name(format);
  std::map<std::uint64_t, fs::path> found;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir / "frames", ec)) {
    const auto k = frame_number(entry.path().filename().string(), ext);
    if (!k) continue;  // other files (temporaries of a killed run, notes) are not frames
    if (!found.emplace(*k, entry.path()).second)
      throw Error("two files hold frame " + std::to_string(*k), (dir / "frames").string());
  }
  std::vector<fs::path> frames;
  for (const auto& [k, path] : found) {
    if (k != frames.size())
      throw Error(fmt::format("frame {} is missing (frames/frame_{:06d}.{} not found, frame {} is there): the run "
                              "directory is incomplete",
                              frames.size(), frames.size(), ext, k),
                  dir.string());
    frames.push_back(path);
  }
  return frames;
}

RunDirectory open_run_directory(const fs::path& dir, std::optional<FrameFormat> format) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw Error("no such directory; expected a run directory (sph run -o DIR)", dir.string());
  const fs::path scene_file = dir / "scene.json";
  if (!fs::is_regular_file(scene_file, ec))
    throw Error("is not a run directory: it has no scene.json (expected the output directory of sph run)",
                dir.string());
  RunDirectory run;
  run.dir = dir;
  run.scene = read_scene_file(scene_file.string());
  run.dimension = run.scene.dimension;
  run.scene.visit_body([&]<int D>(const SceneBody<D>& body) {
    const SimulationParams<D>& sim = body.sim;
    run.particle_radius = sim.particle_radius;
    run.kernel_radius = sim.kernel_radius;
    run.particle_mass = sim.particle_mass;
    run.rest_density = sim.fluid.rest_density;
    for (int d = 0; d < D; ++d)
      run.box_lo[static_cast<std::size_t>(d)] = sim.container.lo[d],
      run.box_hi[static_cast<std::size_t>(d)] = sim.container.hi[d];
    run.label = run.scene.name;
    // A run of a compare directory is named by its neighbor mode.
    fs::path full = fs::absolute(dir, ec).lexically_normal();
    if (!full.has_filename()) full = full.parent_path();  // "DIR/" -> "DIR"
    if (fs::is_regular_file(full.parent_path() / kRunListFile, ec)) run.label = std::string(to_string(sim.neighbors));
  });

  if (format) {
    run.format = *format;
    run.frames = list_frames(dir, *format);
    if (run.frames.empty())
      throw Error(std::string("holds no .") + frame_format_name(*format) + " frames (frames/frame_000000." +
                      frame_format_name(*format) + " ...)",
                  dir.string());
    return run;
  }
  for (FrameFormat f : {FrameFormat::Vtu, FrameFormat::Vtk, FrameFormat::Ply}) {
    run.frames = list_frames(dir, f);
    if (!run.frames.empty()) {
      run.format = f;
      return run;
    }
  }
  throw Error("holds no frames (frames/frame_000000.vtu, .vtk or .ply); was it run with outputEveryNSteps = 0?",
              dir.string());
}

std::vector<std::string> read_run_list(const fs::path& dir) {
  const fs::path file = dir / kRunListFile;
  std::ifstream in(file);
  if (!in) throw Error("cannot read the list of runs", file.string());
  std::vector<std::string> names;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '\t')) line.pop_back();
    if (line.empty()) continue;
    if (line.find('/') != std::string::npos || line == "." || line == ".." ||
        std::find(names.begin(), names.end(), line) != names.end())
      throw Error(
          fmt::format("line {}: \"{}\" is not a new subdirectory name; expected one run directory name per line",
                      number, line),
          file.string());
    names.push_back(line);
  }
  if (names.empty()) throw Error("lists no runs; expected one run directory name per line", file.string());
  return names;
}

void write_run_list(const fs::path& dir, const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) {
    SPH_CHECK(!name.empty() && name.find_first_of("/\n\r") == std::string::npos, "bad run directory name " + name);
    text += name + "\n";
  }
  write_file_atomic(dir / kRunListFile, text);
}

std::vector<fs::path> run_directories(const fs::path& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw Error(
        "no such directory; expected a run directory (sph run -o DIR) or a compare directory (sph compare -o DIR)",
        dir.string());
  if (fs::is_regular_file(dir / "scene.json", ec)) return {dir};
  if (!fs::is_regular_file(dir / kRunListFile, ec))
    throw Error(
        std::string("is neither a run directory (no scene.json) nor a compare directory (no ") + kRunListFile + ")",
        dir.string());
  std::vector<fs::path> runs;
  for (const std::string& name : read_run_list(dir)) {
    if (!fs::is_regular_file(dir / name / "scene.json", ec))
      throw Error("lists \"" + name + "\", which is not a run directory here (no " + name + "/scene.json)",
                  (dir / kRunListFile).string());
    runs.push_back(dir / name);
  }
  return runs;
}

}  // namespace sph
