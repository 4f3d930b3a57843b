#include <sph/io/vtk.h>

#include <bit>
#include <cstdint>
#include <sstream>

#include <fmt/format.h>

#include <sph/io/atomic_file.h>

namespace sph {

namespace {

static_assert(std::endian::native == std::endian::little || std::endian::native == std::endian::big);
constexpr const char* kByteOrder = std::endian::native == std::endian::little ? "LittleEndian" : "BigEndian";

template <class T>
const char* vtk_type() {
  if constexpr (std::is_same_v<T, float>) return "Float32";
  else if constexpr (std::is_same_v<T, double>) return "Float64";
  else if constexpr (std::is_same_v<T, std::uint64_t>) return "UInt64";
  else if constexpr (std::is_same_v<T, std::int64_t>) return "Int64";
  else if constexpr (std::is_same_v<T, std::uint8_t>) return "UInt8";
}

/// Collects DataArray headers and their raw appended blocks.
class Appended {
 public:
  template <class T>
  std::string array(const std::string& name, int components, const std::vector<T>& data) {
    const std::string header =
        fmt::format(R"(<DataArray type="{}"{} NumberOfComponents="{}" format="appended" offset="{}"/>)",
                    vtk_type<T>(), name.empty() ? "" : " Name=\"" + name + "\"", components, blob_.size());
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

}  // namespace

template <int D, std::floating_point R>
void write_vtu(const std::filesystem::path& path, const ParticleSet<D, R>& ps) {
  const std::size_t n = ps.size();
  Appended app;
  std::ostringstream xml;
  xml << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"" << kByteOrder
      << "\" header_type=\"UInt64\">\n"
      << "  <UnstructuredGrid>\n"
      << "    <Piece NumberOfPoints=\"" << n << "\" NumberOfCells=\"" << n << "\">\n"
      << "      <PointData Scalars=\"density\" Vectors=\"velocity\">\n";
  xml << "        " << app.array("velocity", 3, as3(ps.velocity)) << "\n";
  xml << "        " << app.array("density", 1, ps.density) << "\n";
  xml << "        " << app.array("pressure", 1, ps.pressure) << "\n";
  xml << "        " << app.array("id", 1, ps.id) << "\n";
  xml << "        " << app.array("initial_position", 3, as3(ps.initial_position)) << "\n";
  xml << "      </PointData>\n      <Points>\n";
  xml << "        " << app.array("position", 3, as3(ps.position)) << "\n";
  xml << "      </Points>\n      <Cells>\n";
  std::vector<std::int64_t> conn(n), offsets(n);
  for (std::size_t i = 0; i < n; ++i) conn[i] = static_cast<std::int64_t>(i), offsets[i] = static_cast<std::int64_t>(i + 1);
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

void write_pvd(const std::filesystem::path& path, const std::vector<PvdEntry>& entries) {
  std::string s = fmt::format("<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"{}\">\n  <Collection>\n",
                              kByteOrder);
  for (const auto& e : entries)
    s += fmt::format("    <DataSet timestep=\"{:.9g}\" group=\"\" part=\"0\" file=\"{}\"/>\n", e.time, e.file);
  s += "  </Collection>\n</VTKFile>\n";
  write_file_atomic(path, s);
}

#define SPH_INSTANTIATE(D, R) template void write_vtu<D, R>(const std::filesystem::path&, const ParticleSet<D, R>&);
SPH_INSTANTIATE(2, float)
SPH_INSTANTIATE(2, double)
SPH_INSTANTIATE(3, float)
SPH_INSTANTIATE(3, double)
#undef SPH_INSTANTIATE

}  // namespace sph
