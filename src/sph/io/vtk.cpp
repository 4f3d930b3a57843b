#include <sph/io/vtk.h>

#include <bit>
#include <cstdint>
#include <cstring>
#include <sstream>
#include <type_traits>

#include <fmt/format.h>

#include <sph/core/error.h>
#include <sph/io/atomic_file.h>

namespace sph {

namespace {

static_assert(std::endian::native == std::endian::little || std::endian::native == std::endian::big);
constexpr const char* kByteOrder = std::endian::native == std::endian::little ? "LittleEndian" : "BigEndian";

template <class T>
const char* vtk_type() {
  if constexpr (std::is_same_v<T, float>)
    return "Float32";
  else if constexpr (std::is_same_v<T, double>)
    return "Float64";
  else if constexpr (std::is_same_v<T, std::uint64_t>)
    return "UInt64";
  else if constexpr (std::is_same_v<T, std::int64_t>)
    return "Int64";
  else if constexpr (std::is_same_v<T, std::uint8_t>)
    return "UInt8";
}

/// Collects DataArray headers and their raw appended blocks.
class Appended {
 public:
  template <class T>
  std::string array(const std::string& name, int components, const std::vector<T>& data,
                    const std::string& extra = "") {
    const std::string header =
        fmt::format(R"(<DataArray type="{}"{} NumberOfComponents="{}"{} format="appended" offset="{}"/>)",
                    vtk_type<T>(), name.empty() ? "" : " Name=\"" + name + "\"", components, extra, blob_.size());
    const std::uint64_t bytes = data.size() * sizeof(T);
    blob_.append(reinterpret_cast<const char*>(&bytes), sizeof(bytes));
    blob_.append(reinterpret_cast<const char*>(data.data()), bytes);
    return header;
  }
  const std::string& blob() const { return blob_; }

 private:
  std::string blob_;
};

template <int D, std::floating_point R>
std::vector<R> as3(const std::vector<Vec<D, R>>& v) {
  std::vector<R> out(v.size() * 3, R(0));
  for (std::size_t i = 0; i < v.size(); ++i)
    for (int d = 0; d < D; ++d) out[3 * i + static_cast<std::size_t>(d)] = v[i][d];
  return out;
}

/// A field's values as a frame stores them: vectors padded to 3 components, others as they are.
template <int D, std::floating_point R>
std::vector<R> frame_values(const std::vector<Vec<D, R>>& v) {
  return as3(v);
}
template <class T>
const std::vector<T>& frame_values(const std::vector<T>& v) {
  return v;
}
/// Ids: 32 bits in memory, UInt64 in VTU frames (as they always were written).
std::vector<std::uint64_t> frame_values(const std::vector<std::uint32_t>& v) { return {v.begin(), v.end()}; }

/// PointData's Scalars= and Vectors= attributes: the fields ParaView shows first.
template <int D, std::floating_point R>
std::string active_arrays(const ParticleSet<D, R>& ps, const FrameFields& fields) {
  std::string scalars, vectors;
  for_each_frame_field(ps, fields, [&](const FieldDesc& f, const auto&) {
    if (!f.vtk_active) return;
    std::string& attr = f.kind == FieldKind::Vector ? vectors : scalars;
    if (attr.empty()) attr = std::string(f.name);
  });
  return (scalars.empty() ? "" : " Scalars=\"" + scalars + "\"") +
         (vectors.empty() ? "" : " Vectors=\"" + vectors + "\"");
}

/// Appends `values` to `out` in big-endian byte order (the legacy VTK format's only one).
template <class T>
void append_big_endian(std::string& out, const std::vector<T>& values) {
  const std::size_t at = out.size();
  out.resize(at + values.size() * sizeof(T));
  char* p = out.data() + at;
  for (const T& v : values) {
    unsigned char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    if constexpr (std::endian::native == std::endian::little)
      for (std::size_t k = 0; k < sizeof(T); ++k) *p++ = static_cast<char>(b[sizeof(T) - 1 - k]);
    else
      for (std::size_t k = 0; k < sizeof(T); ++k) *p++ = static_cast<char>(b[k]);
  }
}

}  // namespace

template <int D, std::floating_point R>
void write_vtu(const std::filesystem::path& path, const ParticleSet<D, R>& ps, double time, const FrameFields& fields) {
  const std::size_t n = ps.size();
  Appended app;
  std::ostringstream xml;
  xml << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"" << kByteOrder
      << "\" header_type=\"UInt64\">\n"
      << "  <UnstructuredGrid>\n"
      << "    <FieldData>\n"
      << "      " << app.array("TimeValue", 1, std::vector<double>{time}, " NumberOfTuples=\"1\"") << "\n"
      << "    </FieldData>\n"
      << "    <Piece NumberOfPoints=\"" << n << "\" NumberOfCells=\"" << n << "\">\n"
      << "      <PointData" << active_arrays(ps, fields) << ">\n";
  for_each_frame_field(ps, fields, [&](const FieldDesc& f, const auto& column) {
    xml << "        " << app.array(std::string(f.name), f.components(), frame_values(column)) << "\n";
  });
  xml << "      </PointData>\n      <Points>\n";
  xml << "        " << app.array("position", 3, as3(ps.position)) << "\n";
  xml << "      </Points>\n      <Cells>\n";
  std::vector<std::int64_t> conn(n), offsets(n);
  for (std::size_t i = 0; i < n; ++i)
    conn[i] = static_cast<std::int64_t>(i), offsets[i] = static_cast<std::int64_t>(i + 1);
  const std::vector<std::uint8_t> types(n, 1);  // VTK_VERTEX
  xml << "        " << app.array("connectivity", 1, conn) << "\n";
  xml << "        " << app.array("offsets", 1, offsets) << "\n";
  xml << "        " << app.array("types", 1, types) << "\n";
  xml << "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n"
      << "  <AppendedData encoding=\"raw\">\n_";
  AtomicFile f(path);
  f.write(xml.str());
  f.write(app.blob());
  f.write("\n  </AppendedData>\n</VTKFile>\n");
  f.commit();
}

template <int D, std::floating_point R>
void write_legacy_vtk(const std::filesystem::path& path, const ParticleSet<D, R>& ps, double time,
                      const FrameFields& fields) {
  const std::size_t n = ps.size();
  // Cells hold 32-bit indices in this format.
  if (n > 0x7fffffffu) throw Error("too many particles for a legacy VTK file (at most 2^31 - 1)", path.string());
  constexpr const char* real = std::is_same_v<R, float> ? "float" : "double";
  std::string s;
  s.reserve(64 + n * (3 * sizeof(R) + 12));
  s += fmt::format("# vtk DataFile Version 4.2\nsph frame, time {} s\nBINARY\nDATASET UNSTRUCTURED_GRID\n", time);
  s += "FIELD FieldData 1\nTimeValue 1 1 double\n";
  append_big_endian(s, std::vector<double>{time});
  s += fmt::format("\nPOINTS {} {}\n", n, real);
  append_big_endian(s, as3(ps.position));
  s += fmt::format("\nCELLS {} {}\n", n, 2 * n);
  std::vector<std::int32_t> cells(2 * n);
  for (std::size_t i = 0; i < n; ++i) cells[2 * i] = 1, cells[2 * i + 1] = static_cast<std::int32_t>(i);
  append_big_endian(s, cells);
  s += fmt::format("\nCELL_TYPES {}\n", n);
  append_big_endian(s, std::vector<std::int32_t>(n, 1));  // VTK_VERTEX
  // The point fields as one FIELD block: readers load every array of it, whereas of SCALARS
  // and VECTORS sections VTK's reader loads only the first of each unless asked for all.
  int arrays = 0;
  for_each_frame_field(ps, fields, [&](const FieldDesc&, const auto&) { ++arrays; });
  s += fmt::format("\nPOINT_DATA {}\nFIELD FieldData {}\n", n, arrays);
  for_each_frame_field(ps, fields, [&](const FieldDesc& f, const auto& column) {
    using T = typename std::decay_t<decltype(column)>::value_type;
    if constexpr (std::is_same_v<T, std::uint32_t>) {
      // 32 bits, as the particles keep them (ids stay below the 2e9 particles a scene may
      // hold), and every reader knows unsigned_int (64-bit types are spelt differently by VTK
      // versions).
      s += fmt::format("{} {} {} {}\n", f.name, 1, n, "unsigned_int");
      append_big_endian(s, column);
    } else {
      s += fmt::format("{} {} {} {}\n", f.name, f.components(), n, real);
      append_big_endian(s, frame_values(column));
    }
    s += "\n";
  });
  write_file_atomic(path, s);
}

void write_pvd(const std::filesystem::path& path, const std::vector<PvdEntry>& entries) {
  std::string s = fmt::format(
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"{}\">\n  <Collection>\n",
      kByteOrder);
  for (const auto& e : entries)
    s += fmt::format("    <DataSet timestep=\"{:.9g}\" group=\"\" part=\"0\" file=\"{}\"/>\n", e.time, e.file);
  s += "  </Collection>\n</VTKFile>\n";
  write_file_atomic(path, s);
}

#define SPH_INSTANTIATE(D, R)                                                                                        \
  template void write_vtu<D, R>(const std::filesystem::path&, const ParticleSet<D, R>&, double, const FrameFields&); \
  template void write_legacy_vtk<D, R>(const std::filesystem::path&, const ParticleSet<D, R>&, double,               \
                                       const FrameFields&);
SPH_INSTANTIATE(2, float)
SPH_INSTANTIATE(2, double)
SPH_INSTANTIATE(3, float)
SPH_INSTANTIATE(3, double)
#undef SPH_INSTANTIATE

}  // namespace sph
