// The one translation unit that includes OpenVDB (its headers take minutes to compile): the
// level set of a surface mesh, written as a .vdb file.

#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include <fmt/format.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>
#include <tbb/global_control.h>

#include <sph/core/error.h>
#include <sph/core/parallel.h>
#include <sph/io/atomic_file.h>
#include <sph/surface/mesh_files.h>

namespace sph {

void write_surface_vdb(const std::filesystem::path& path, const SurfaceMesh& mesh, double time,
                       std::string_view grid_name) {
  if (mesh.dimension != 3) throw Error("an OpenVDB level set needs a 3D surface; 2D surfaces are polylines", "surface");
  SPH_CHECK(mesh.voxel_size > 0, "write_surface_vdb: the mesh has no voxel size");
  openvdb::initialize();
  // OpenVDB runs on TBB: at most as many threads as our parallel loops use.
  const tbb::global_control threads(tbb::global_control::max_allowed_parallelism,
                                    static_cast<std::size_t>(num_threads()));
  const openvdb::math::Transform::Ptr xform = openvdb::math::Transform::createLinearTransform(mesh.voxel_size);
  std::vector<openvdb::Vec3s> points(mesh.vertices.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    points[i] = openvdb::Vec3s(mesh.vertices[i][0], mesh.vertices[i][1], mesh.vertices[i][2]);
  std::vector<openvdb::Vec3I> triangles(mesh.triangles.size());
  for (std::size_t i = 0; i < triangles.size(); ++i)
    triangles[i] = openvdb::Vec3I(mesh.triangles[i][0], mesh.triangles[i][1], mesh.triangles[i][2]);
  openvdb::FloatGrid::Ptr grid;
  if (triangles.empty()) {
    grid = openvdb::createLevelSet<openvdb::FloatGrid>(mesh.voxel_size);
  } else {
    grid = openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(*xform, points, triangles, 3.0f);
  }
  grid->setName(std::string(grid_name));
  grid->setGridClass(openvdb::GRID_LEVEL_SET);
  grid->insertMeta("time", openvdb::DoubleMetadata(time));
  grid->insertMeta("creator", openvdb::StringMetadata("sph surface"));
  // OpenVDB writes by file name: under a temporary name next to the target, renamed when whole.
  const std::filesystem::path tmp = temporary_path(path);
  try {
    openvdb::io::File file(tmp.string());
    file.write({grid});
    file.close();
  } catch (const std::exception& e) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    throw Error(fmt::format("cannot write the level set: {}", e.what()), path.string());
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw Error(fmt::format("cannot write the level set: {}", ec.message()), path.string());
  }
}

}  // namespace sph
