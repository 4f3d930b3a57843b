// Mesh files (mesh_reader.h): the same cube read from OBJ (quads), binary STL (separate triangles)
// and binary PLY is one closed surface of 8 vertices and 12 triangles, and the files a user can get
// wrong are refused with what is wrong.

#include <string>

#include <gtest/gtest.h>

#include <sph/core/error.h>
#include <sph/scene/mesh_reader.h>
#include <sph/solver/shape.h>

#include "support/temp_dir.h"

namespace sph {
namespace {

const std::string kData = SPH_SOURCE_DIR "/tests/data/meshes/";
const std::string kBad = SPH_SOURCE_DIR "/tests/scene/bad/meshes/";

TEST(MeshReader, EachFormatGivesTheSameClosedCube) {
  for (const char* file : {"cube.obj", "cube.stl", "cube.ply"}) {
    SCOPED_TRACE(file);
    TriangleMesh m = read_mesh_file(kData + file);
    EXPECT_EQ(m.vertices.size(), 8u);  // (the STL's 36 corners merged)
    EXPECT_EQ(m.triangles.size(), 12u);
    const ObstacleShape<3> s = make_shape<3>(m.vertices, m.triangles, false);
    EXPECT_NEAR(s.field->volume(), 1.0, 1e-6);
    EXPECT_NEAR(s.field->distance(Vec<3, double>{{0.5, 0.5, 0.5}}).distance, -0.5, 1e-6);
  }
}

/// The message read_mesh_file throws ("" if it reads the file).
std::string refusal(const std::string& path) {
  try {
    read_mesh_file(path);
  } catch (const Error& e) {
    return e.message();
  }
  return "";
}

TEST(MeshReader, FilesItCannotUseAreRefusedWithWhy) {
  EXPECT_NE(refusal(kData + "missing.obj").find("not found"), std::string::npos);
  EXPECT_NE(refusal(kData + "cube.3ds").find("expected a .obj, .stl or .ply file"), std::string::npos);
  EXPECT_NE(refusal(kData).find("expected a .obj"), std::string::npos);  // a directory, no extension
  EXPECT_NE(refusal(kBad + "not_a_mesh.stl").find("cannot be read as an STL file (the reader says: "),
            std::string::npos);
  EXPECT_NE(refusal(kBad + "empty.obj").find("empty.obj"), std::string::npos);
  // OBJ faults the importer reports without a line ("vertex index out of range"): named with it.
  sph::test::TempDir tmp;
  sph::test::spit(tmp / "flat.obj", "v 0 0 0\nv 1 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_NE(refusal((tmp / "flat.obj").string()).find("line 2: a vertex (\"v\") needs three coordinates"),
            std::string::npos);
  sph::test::spit(tmp / "far.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 -4\n");
  EXPECT_NE(refusal((tmp / "far.obj").string()).find("line 5: the face names vertex -4, but 3 vertices"),
            std::string::npos);
  EXPECT_EQ(refusal(kData + "CUBE.OBJ").find("expected"), std::string::npos);  // (extensions in any case)
}

}  // namespace
}  // namespace sph
