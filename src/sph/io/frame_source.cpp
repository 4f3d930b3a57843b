#include <sph/io/frame_source.h>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

namespace sph {

namespace fs = std::filesystem;

const FrameField* FrameData::field(std::string_view name) const {
  for (const FrameField& f : fields)
    if (f.name == name) return &f;
  return nullptr;
}

namespace detail {

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

void FrameBuilder::set_size(std::uint64_t n, std::size_t min_bytes) {
  if (n > src_.bytes.size() / min_bytes)
    src_.fail(fmt::format("declares {} points, more than its {} bytes can hold: the file is truncated or corrupt", n,
                          src_.bytes.size()));
  data.size = static_cast<std::size_t>(n);
}

const FieldSpec* find_added(std::span<const FieldSpec> added, std::string_view name) {
  for (const FieldSpec& a : added)
    if (a.name == name) return &a;
  return nullptr;
}

void FrameBuilder::add(const std::string& name, int components, std::vector<double> values) {
  const FieldDesc* f = find_particle_field(name);
  int want = f && f->in_frames ? f->components() : 0;
  if (const FieldSpec* a = find_added(src_.added, name); a && !f) want = a->kind == FieldKind::Vector ? 3 : 1;
  if (want == 0)
    src_.fail("holds a point field \"" + name + "\" that sph does not write; expected " + frame_field_list(" or ") +
              (src_.added.empty() ? "" : " or a field the run added"));
  if (components != want)
    src_.fail(fmt::format("the field \"{}\" has {} components; expected {}", name, components, want));
  if (data.field(name)) src_.fail("the field \"" + name + "\" appears twice");
  data.fields.push_back({name, components, std::move(values)});
}

FrameData FrameBuilder::finish(bool have_position) {
  if (!have_position) src_.fail("holds no positions: not a frame written by sph");
  const auto order = [&](const FrameField& f) {
    const FieldDesc* d = find_particle_field(f.name);
    if (d) return d - std::begin(kParticleFields);
    const FieldSpec* a = find_added(src_.added, f.name);  // (add() accepted only those two kinds)
    return std::ssize(kParticleFields) + (a ? a - src_.added.data() : std::ssize(src_.added));
  };
  std::stable_sort(data.fields.begin(), data.fields.end(),
                   [&](const FrameField& a, const FrameField& b) { return order(a) < order(b); });
  return std::move(data);
}

namespace {

Source slurp(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw Error("no such frame file", path.string());
  if (!fs::is_regular_file(path, ec)) throw Error("is not a file; expected a frame file", path.string());
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("cannot open the frame file (permissions?)", path.string());
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw Error("cannot read the frame file", path.string());
  return {path, ss.str(), {}};
}

}  // namespace

}  // namespace detail

std::span<const FieldSpec> boundary_sample_fields() {
  static const FieldSpec psi{"psi", FieldKind::Real, "kg/m", "kg", "a boundary sample's psi = rho0 V_b"};
  return {&psi, 1};
}

FrameData read_frame(const fs::path& file, std::span<const FieldSpec> added) {
  const std::string ext = file.extension().string();
  if (ext != ".vtu" && ext != ".vtk" && ext != ".ply")
    throw Error("unknown frame file extension \"" + ext + "\"; expected .vtu, .vtk or .ply", file.string());
  detail::Source src = detail::slurp(file);
  src.added = added;
  if (ext == ".vtu") return detail::read_vtu(src);
  if (ext == ".vtk") return detail::read_legacy_vtk(src);
  return detail::read_ply(src);
}

}  // namespace sph
