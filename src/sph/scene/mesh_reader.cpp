#include <sph/scene/mesh_reader.h>

#include <algorithm>
#include <cctype>
#include <exception>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <system_error>

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>
#include <assimp/Importer.hpp>

#include <sph/core/error.h>

namespace sph {

namespace {

/// The first fault of an OBJ file that the importer would report without a line (its "vertex
/// index out of range" for a vertex line with two coordinates): a "v" line that does not hold
/// at least three numbers, or an "f" line with an index (1-based, or negative from the end) of a
/// vertex not defined above it. Throws sph::Error naming the file and the line.
void check_obj_lines(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::size_t vertices = 0;
  for (std::size_t number = 1; std::getline(in, line); ++number) {
    std::istringstream ss(line);
    std::string tag;
    ss >> tag;
    if (tag == "v") {
      int coordinates = 0;
      for (double x = 0; coordinates < 3 && ss >> x; ++coordinates) {
      }
      if (coordinates < 3)
        throw Error(fmt::format("mesh file '{}', line {}: a vertex (\"v\") needs three coordinates x y z, got \"{}\"",
                                path, number, line));
      ++vertices;
    } else if (tag == "f") {
      for (std::string corner; ss >> corner;) {
        long long k = 0;
        try {
          k = std::stoll(corner.substr(0, corner.find('/')));
        } catch (const std::exception&) {
          throw Error(
              fmt::format("mesh file '{}', line {}: \"{}\" is not a face's vertex number", path, number, corner));
        }
        const long long n = static_cast<long long>(vertices);
        if (k == 0 || k > n || k < -n)
          throw Error(
              fmt::format("mesh file '{}', line {}: the face names vertex {}, but {} vertices are defined "
                          "above it (numbered from 1, or from -1 backwards)",
                          path, number, k, n));
      }
    }
  }
}

}  // namespace

TriangleMesh read_mesh_file(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path p(path);
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (std::find_if(kMeshExtensions.begin(), kMeshExtensions.end(), [&](const char* e) { return ext == e; }) ==
      kMeshExtensions.end())
    throw Error(fmt::format("'{}' is not a mesh file this program reads: expected a .obj, .stl or .ply file", path));
  if (!fs::exists(p, ec)) throw Error(fmt::format("mesh file '{}' not found", path));
  if (!fs::is_regular_file(p, ec)) throw Error(fmt::format("mesh file '{}' is not a regular file", path));
  const std::uintmax_t size = fs::file_size(p, ec);
  if (ec) throw Error(fmt::format("cannot read mesh file '{}': {}", path, ec.message()));
  if (size > (std::uintmax_t{1} << 31))
    throw Error(fmt::format("mesh file '{}' is {:.3g} GB; at most 2 GB is read (simplify the mesh first)", path,
                            static_cast<double>(size) / 1e9));
  if (ext == ".obj") check_obj_lines(path);
  Assimp::Importer importer;
  // Only the triangles are wanted: points and lines are dropped, polygons split.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* scene =
      importer.ReadFile(path, aiProcess_Triangulate | aiProcess_SortByPType | aiProcess_PreTransformVertices);
  std::string format = ext.substr(1);
  std::transform(format.begin(), format.end(), format.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  if (scene == nullptr)
    throw Error(
        fmt::format("mesh file '{}' cannot be read as an {} file (the reader says: {}); expected a triangle "
                    "mesh written by a modeller",
                    path, format, importer.GetErrorString()));
  TriangleMesh mesh;
  // Vertices merged by exact position, numbered in order of first use.
  std::map<std::array<double, 3>, std::uint32_t> index;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* am = scene->mMeshes[m];
    if (!(am->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices != 3) continue;
      std::array<std::uint32_t, 3> t{};
      for (unsigned k = 0; k < 3; ++k) {
        const unsigned v = face.mIndices[k];
        if (v >= am->mNumVertices) throw Error(fmt::format("mesh file '{}' has a face with a bad vertex index", path));
        const aiVector3D& a = am->mVertices[v];
        const std::array<double, 3> x{a.x, a.y, a.z};
        const auto [it, added] = index.try_emplace(x, static_cast<std::uint32_t>(mesh.vertices.size()));
        if (added) mesh.vertices.push_back(Vec<3, double>{x});
        t[k] = it->second;
      }
      mesh.triangles.push_back(t);
    }
  }
  if (mesh.triangles.empty()) throw Error(fmt::format("mesh file '{}' holds no triangles", path));
  return mesh;
}

}  // namespace sph
