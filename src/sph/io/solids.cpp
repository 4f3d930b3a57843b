#include <sph/io/solids.h>

#include <array>
#include <string>
#include <vector>

#include <fmt/format.h>

#include <sph/io/atomic_file.h>

namespace sph {

namespace {

/// The obstacles placed by their poses as points (each box's corners: corner c has bit d set for
/// the upper end along axis d) and quads (3D: 6 per box, outward and counter-clockwise seen from
/// outside; 2D: one per box, counter-clockwise), with each quad's obstacle index.
template <int D>
struct SolidSurfaces {
  std::vector<std::array<double, 3>> points;
  std::vector<std::array<std::size_t, 4>> quads;
  std::vector<std::size_t> owner;

  SolidSurfaces(const std::vector<Box<D>>& obstacles, std::span<const RigidPose<D>> poses) {
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
                      std::span<const RigidPose<D>> poses, double t) {
  const SolidSurfaces<D> s(obstacles, poses);
  std::string points, connectivity, offsets, ids;
  for (const auto& p : s.points) points += fmt::format("{:.17g} {:.17g} {:.17g}\n", p[0], p[1], p[2]);
  for (std::size_t f = 0; f < s.quads.size(); ++f) {
    const auto& q = s.quads[f];
    connectivity += fmt::format("{} {} {} {}\n", q[0], q[1], q[2], q[3]);
    offsets += fmt::format("{}\n", 4 * (f + 1));
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
                      std::span<const RigidPose<D>> poses, double t) {
  const SolidSurfaces<D> s(obstacles, poses);
  std::string text = fmt::format(
      "ply\nformat ascii 1.0\ncomment sph obstacles\ncomment time {:.17g}\nelement vertex {}\nproperty double "
      "x\nproperty double y\nproperty double z\nelement face {}\nproperty list uchar int vertex_indices\n"
      "end_header\n",
      t, s.points.size(), s.quads.size());
  for (const auto& p : s.points) text += fmt::format("{:.17g} {:.17g} {:.17g}\n", p[0], p[1], p[2]);
  for (const auto& q : s.quads) text += fmt::format("4 {} {} {} {}\n", q[0], q[1], q[2], q[3]);
  write_file_atomic(path, text);
}

template void write_solids_vtp<2>(const std::filesystem::path&, const std::vector<Box<2>>&,
                                  std::span<const RigidPose<2>>, double);
template void write_solids_vtp<3>(const std::filesystem::path&, const std::vector<Box<3>>&,
                                  std::span<const RigidPose<3>>, double);
template void write_solids_ply<2>(const std::filesystem::path&, const std::vector<Box<2>>&,
                                  std::span<const RigidPose<2>>, double);
template void write_solids_ply<3>(const std::filesystem::path&, const std::vector<Box<3>>&,
                                  std::span<const RigidPose<3>>, double);

}  // namespace sph
