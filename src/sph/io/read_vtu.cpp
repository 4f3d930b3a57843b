#include <sph/io/frame_source.h>

#include <bit>
#include <cctype>
#include <cmath>
#include <cstring>
#include <map>
#include <utility>

#include <fmt/format.h>

namespace sph::detail {

namespace {

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

/// The raw appended array of DataArray tag `t` (data starts at byte `data` of the file, in the
/// byte order `big`): `tuples` tuples into `out`; returns its components. Fails on anything sph
/// does not write and on sizes that do not fit the file.
int read_array(const Source& src, std::size_t data, bool big, const XmlTag& t, std::uint64_t tuples,
               std::vector<double>& out) {
  const std::string& f = src.bytes;
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
}

/// Checks the frame's envelope (the XML header, the raw appended data, the closing tags) and
/// returns where the appended data starts (after its '_') and where the header ends.
std::pair<std::size_t, std::size_t> appended_data(const Source& src) {
  const std::string& f = src.bytes;
  const std::string open = "<AppendedData encoding=\"raw\">";
  if (f.rfind("<?xml", 0) != 0 || f.find("<VTKFile type=\"UnstructuredGrid\"") == std::string::npos)
    src.fail("is not a VTK XML unstructured grid (.vtu) file");
  const std::size_t ad = f.find(open);
  if (ad == std::string::npos) src.fail("has no raw appended data: not a .vtu file as sph writes it");
  std::size_t data = f.find_first_not_of(" \t\r\n", ad + open.size());
  if (data == std::string::npos || f[data] != '_')
    src.fail("the appended data does not start with '_': the file is truncated or corrupt");
  // The file ends with the closing tags sph writes: a file cut short at a block boundary is refused too.
  const std::size_t last = f.find_last_not_of(" \t\r\n");
  const std::string close = "</AppendedData>\n</VTKFile>";
  if (last == std::string::npos || last + 1 < close.size() ||
      f.compare(last + 1 - close.size(), close.size(), close) != 0)
    src.fail("does not end with </VTKFile>: the file is truncated");
  return {data + 1, ad};
}

}  // namespace

FrameData read_vtu(const Source& src) {
  const std::pair<std::size_t, std::size_t> envelope = appended_data(src);
  const std::size_t data = envelope.first;
  const std::vector<XmlTag> tags = xml_tags(src, std::string_view(src.bytes).substr(0, envelope.second));
  bool big = false, have_piece = false, have_position = false;
  FrameBuilder b(src);
  std::string section;
  const auto array = [&](const XmlTag& t, std::uint64_t tuples, std::vector<double>& out) {
    return read_array(src, data, big, t, tuples, out);
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

}  // namespace sph::detail
