#include <sph/surface/mesh_files.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>
#include <string>

#include <fmt/format.h>

#include <sph/core/error.h>
#include <sph/io/atomic_file.h>

namespace sph {

namespace {

template <class T>
void put_le(std::string& out, T v) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  if constexpr (std::endian::native != std::endian::little)
    for (std::size_t k = 0; k < sizeof(T) / 2; ++k) std::swap(b[k], b[sizeof(T) - 1 - k]);
  out.append(reinterpret_cast<const char*>(b), sizeof(T));
}

void check_indices(const SurfaceMesh& mesh) {
  if (mesh.vertices.size() > static_cast<std::size_t>(INT32_MAX))
    throw Error(fmt::format("{} vertices: more than PLY's and OBJ's int indices hold; lower --resolution",
                            mesh.vertices.size()),
                "surface");
}

}  // namespace

void write_surface_ply(const std::filesystem::path& path, const SurfaceMesh& mesh, double time) {
  check_indices(mesh);
  const bool three = mesh.dimension == 3;
  std::string out = fmt::format(
      "ply\nformat binary_little_endian 1.0\ncomment sph surface\ncomment time {}\ncomment voxel_size {}\n"
      "element vertex {}\nproperty float x\nproperty float y\nproperty float z\n",
      time, mesh.voxel_size, mesh.vertices.size());
  if (three) out += "property float nx\nproperty float ny\nproperty float nz\n";
  // 2D segments are two-vertex faces, as meshio writes and reads lines.
  out += fmt::format("element face {}\nproperty list uchar int vertex_indices\n",
                     three ? mesh.triangles.size() : mesh.segments.size());
  out += "end_header\n";
  out.reserve(out.size() + mesh.vertices.size() * (three ? 24 : 12) +
              (three ? mesh.triangles.size() * 13 : mesh.segments.size() * 9));
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    for (float c : mesh.vertices[i]) put_le(out, c);
    if (three)
      for (float c : mesh.normals[i]) put_le(out, c);
  }
  if (three) {
    for (const auto& t : mesh.triangles) {
      put_le(out, std::uint8_t{3});
      for (std::uint32_t v : t) put_le(out, static_cast<std::int32_t>(v));
    }
  } else {
    for (const auto& s : mesh.segments) {
      put_le(out, std::uint8_t{2});
      for (std::uint32_t v : s) put_le(out, static_cast<std::int32_t>(v));
    }
  }
  AtomicFile f(path);
  f.write(out);
  f.commit();
}

void write_surface_obj(const std::filesystem::path& path, const SurfaceMesh& mesh, double time) {
  check_indices(mesh);
  fmt::memory_buffer out;
  fmt::format_to(std::back_inserter(out), "# sph surface\n# time {}\n# voxel_size {}\n", time, mesh.voxel_size);
  for (const auto& v : mesh.vertices) fmt::format_to(std::back_inserter(out), "v {} {} {}\n", v[0], v[1], v[2]);
  if (mesh.dimension == 3) {
    for (const auto& n : mesh.normals) fmt::format_to(std::back_inserter(out), "vn {} {} {}\n", n[0], n[1], n[2]);
    for (const auto& t : mesh.triangles)
      fmt::format_to(std::back_inserter(out), "f {0}//{0} {1}//{1} {2}//{2}\n", t[0] + 1, t[1] + 1, t[2] + 1);
  } else {
    for (const auto& line : surface_polylines(mesh)) {
      out.push_back('l');
      for (std::uint32_t v : line) fmt::format_to(std::back_inserter(out), " {}", v + 1);
      out.push_back('\n');
    }
  }
  AtomicFile f(path);
  f.write(std::string_view(out.data(), out.size()));
  f.commit();
}

SurfaceFormats parse_surface_formats(std::string_view list, const std::string& flag) {
  if (list == "all") return {};
  SurfaceFormats f{false, false, false};
  const std::string expected = "expected all or a comma list of ply, obj and vdb, e.g. ply,vdb";
  std::size_t begin = 0;
  while (true) {
    const std::size_t end = std::min(list.find(',', begin), list.size());
    const std::string_view item = list.substr(begin, end - begin);
    bool* slot = item == "ply" ? &f.ply : item == "obj" ? &f.obj : item == "vdb" ? &f.vdb : nullptr;
    if (!slot) throw Error(fmt::format("unknown surface format \"{}\"; {}", item, expected), flag);
    if (*slot) throw Error(fmt::format("surface format \"{}\" is given twice; {}", item, expected), flag);
    *slot = true;
    if (end == list.size()) break;
    begin = end + 1;
  }
  return f;
}

std::vector<std::filesystem::path> write_surface_frame(const std::filesystem::path& dir, std::size_t index,
                                                       const SurfaceMesh& mesh, double time,
                                                       const SurfaceFormats& formats) {
  std::vector<std::filesystem::path> written;
  auto path = [&](const char* ext) { return dir / fmt::format("surface_{:06d}.{}", index, ext); };
  if (formats.ply) write_surface_ply(written.emplace_back(path("ply")), mesh, time);
  if (formats.obj) write_surface_obj(written.emplace_back(path("obj")), mesh, time);
  if (formats.vdb && mesh.dimension == 3) write_surface_vdb(written.emplace_back(path("vdb")), mesh, time);
  return written;
}

}  // namespace sph
