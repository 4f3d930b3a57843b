#include <sph/io/solids.h>

#include <array>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <sph/io/atomic_file.h>

namespace sph {

namespace {

/// The obstacles placed by their poses as points (each box's corners: corner c has bit d set for
/// the upper end along axis d) and polygons (3D: 6 quads per box, outward and counter-clockwise
/// seen from outside; 2D: one quad per box, counter-clockwise), with each polygon's obstacle
/// index. A shape (shape.h) gives its vertices and faces (3D: its triangles; 2D: one polygon).
template <int D>
struct SolidSurfaces {
  std::vector<std::array<double, 3>> points;
  std::vector<std::vector<std::size_t>> quads;
  std::vector<std::size_t> owner;

  SolidSurfaces(const std::vector<Box<D>>& obstacles, std::span<const RigidPose<D>> poses,
                std::span<const ObstacleShape<D>> shapes) {
    static constexpr std::array<std::array<int, 4>, 6> kFaces3{{{0, 4, 6, 2},    // -x
                                                                {1, 3, 7, 5},    // +x
                                                                {0, 1, 5, 4},    // -y
                                                                {2, 6, 7, 3},    // +y
                                                                {0, 2, 3, 1},    // -z
                                                                {4, 5, 7, 6}}};  // +z
    static constexpr std::array<std::array<int, 4>, 1> kFaces2{{{0, 1, 3, 2}}};
    for (std::size_t k = 0; k < obstacles.size(); ++k) {
      const Box<D>& box = obstacles[k];
      const RigidPose<D> pose = k < poses.size() ? poses[k] : RigidPose<D>{};
      const std::size_t base = points.size();
      if (k < shapes.size() && !shapes[k].empty()) {
        for (const Vec<D, double>& v : shapes[k].vertices) {
          const Vec<D, double> x = pose.place(v);
          points.push_back({x[0], x[1], D == 3 ? x[D - 1] : 0.0});
        }
        if constexpr (D == 3) {
          for (const auto& t : shapes[k].faces) quads.push_back({base + t[0], base + t[1], base + t[2]});
          owner.insert(owner.end(), shapes[k].faces.size(), k);
        } else {
          std::vector<std::size_t> loop;
          for (std::size_t i = 0; i < shapes[k].vertices.size(); ++i) loop.push_back(base + i);
          quads.push_back(std::move(loop));
          owner.push_back(k);
        }
        continue;
      }
      for (int c = 0; c < (1 << D); ++c) {
        const Vec<D, double> x = pose.place(box_corner<D>(box.lo, box.hi, c));
        points.push_back({x[0], x[1], D == 3 ? x[D - 1] : 0.0});
      }
      const auto add = [&](const auto& faces) {
        for (const std::array<int, 4>& q : faces) {
          quads.push_back({base + static_cast<std::size_t>(q[0]), base + static_cast<std::size_t>(q[1]),
                           base + static_cast<std::size_t>(q[2]), base + static_cast<std::size_t>(q[3])});
          owner.push_back(k);
        }
      };
      if constexpr (D == 3)
        add(kFaces3);
      else
        add(kFaces2);
    }
  }
};

}  // namespace

template <int D>
void write_solids_vtp(const std::filesystem::path& path, const std::vector<Box<D>>& obstacles,
                      std::span<const RigidPose<D>> poses, double t, std::span<const ObstacleShape<D>> shapes) {
  const SolidSurfaces<D> s(obstacles, poses, shapes);
  std::string points, connectivity, offsets, ids;
  for (const auto& p : s.points) points += fmt::format("{:.17g} {:.17g} {:.17g}\n", p[0], p[1], p[2]);
  std::size_t offset = 0;
  for (std::size_t f = 0; f < s.quads.size(); ++f) {
    const auto& q = s.quads[f];
    connectivity += fmt::format("{}\n", fmt::join(q, " "));
    offset += q.size();
    offsets += fmt::format("{}\n", offset);
    ids += fmt::format("{}\n", s.owner[f]);
  }
  const std::string xml = fmt::format(
      "<?xml version=\"1.0\"?>\n"
      "<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      "<PolyData>\n"
      "<FieldData><DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" format=\"ascii\">{:.17g}"
      "</DataArray></FieldData>\n"
      "<Piece NumberOfPoints=\"{}\" NumberOfVerts=\"0\" NumberOfLines=\"0\" NumberOfStrips=\"0\" "
      "NumberOfPolys=\"{}\">\n"
      "<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n{}</DataArray></Points>\n"
      "<CellData Scalars=\"obstacle\"><DataArray type=\"Int32\" Name=\"obstacle\" format=\"ascii\">\n{}"
      "</DataArray></CellData>\n"
      "<Polys><DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n{}</DataArray>\n"
      "<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n{}</DataArray></Polys>\n"
      "</Piece>\n</PolyData>\n</VTKFile>\n",
      t, s.points.size(), s.quads.size(), points, ids, connectivity, offsets);
  write_file_atomic(path, xml);
}

template <int D>
void write_solids_ply(const std::filesystem::path& path, const std::vector<Box<D>>& obstacles,
                      std::span<const RigidPose<D>> poses, double t, std::span<const ObstacleShape<D>> shapes) {
  const SolidSurfaces<D> s(obstacles, poses, shapes);
  std::string text = fmt::format(
      "ply\nformat ascii 1.0\ncomment sph obstacles\ncomment time {:.17g}\nelement vertex {}\nproperty double "
      "x\nproperty double y\nproperty double z\nelement face {}\nproperty list uchar int vertex_indices\n"
      "end_header\n",
      t, s.points.size(), s.quads.size());
  for (const auto& p : s.points) text += fmt::format("{:.17g} {:.17g} {:.17g}\n", p[0], p[1], p[2]);
  for (const auto& q : s.quads) text += fmt::format("{} {}\n", q.size(), fmt::join(q, " "));
  write_file_atomic(path, text);
}

template void write_solids_vtp<2>(const std::filesystem::path&, const std::vector<Box<2>>&,
                                  std::span<const RigidPose<2>>, double, std::span<const ObstacleShape<2>>);
template void write_solids_vtp<3>(const std::filesystem::path&, const std::vector<Box<3>>&,
                                  std::span<const RigidPose<3>>, double, std::span<const ObstacleShape<3>>);
template void write_solids_ply<2>(const std::filesystem::path&, const std::vector<Box<2>>&,
                                  std::span<const RigidPose<2>>, double, std::span<const ObstacleShape<2>>);
template void write_solids_ply<3>(const std::filesystem::path&, const std::vector<Box<3>>&,
                                  std::span<const RigidPose<3>>, double, std::span<const ObstacleShape<3>>);

}  // namespace sph
