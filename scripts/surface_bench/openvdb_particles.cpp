// OpenVDB's own particle surfacing, timed: ParticlesToLevelSet (spheres of radius
// RADIUS spacings), one Gaussian pass of LevelSetFilter, volumeToMesh; on an N^3 lattice of
// spacing 0.01 at RES voxels per spacing, with THREADS TBB threads. Prints the phases' seconds
// and particles per second. Usage: openvdb_particles N RES RADIUS THREADS
// (scripts/surface_speed.sh runs it beside sph surface; docs/performance.md, "Surfaces").
#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetFilter.h>
#include <openvdb/tools/ParticlesToLevelSet.h>
#include <openvdb/tools/VolumeToMesh.h>
#include <tbb/global_control.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

struct PL {
  using PosType = openvdb::Vec3R;
  std::vector<openvdb::Vec3R> p;
  double r;
  size_t size() const { return p.size(); }
  void getPos(size_t n, openvdb::Vec3R& x) const { x = p[n]; }
  void getPosRad(size_t n, openvdb::Vec3R& x, openvdb::Real& rad) const {
    x = p[n];
    rad = r;
  }
};
int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: openvdb_particles N RES RADIUS THREADS\n");
    return 2;
  }
  openvdb::initialize();
  const tbb::global_control threads(tbb::global_control::max_allowed_parallelism, std::atoi(argv[4]));
  int n = std::atoi(argv[1]);
  double s = 0.01;
  double res = std::atof(argv[2]);
  PL pl;
  pl.r = s * std::atof(argv[3]);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) pl.p.push_back({i * s, j * s, k * s});
  auto t0 = std::chrono::steady_clock::now();
  double vox = s / res;
  auto grid = openvdb::createLevelSet<openvdb::FloatGrid>(vox, 3.0);
  openvdb::tools::ParticlesToLevelSet<openvdb::FloatGrid> raster(*grid);
  raster.setRmin(0.1);
  raster.rasterizeSpheres(pl);
  raster.finalize(true);
  auto t1 = std::chrono::steady_clock::now();
  openvdb::tools::LevelSetFilter<openvdb::FloatGrid> f(*grid);
  f.gaussian(1);
  auto t2 = std::chrono::steady_clock::now();
  std::vector<openvdb::Vec3s> pts;
  std::vector<openvdb::Vec3I> tri;
  std::vector<openvdb::Vec4I> quad;
  openvdb::tools::volumeToMesh(*grid, pts, tri, quad, 0.0, 0.0);
  auto t3 = std::chrono::steady_clock::now();
  auto d = [](auto a, auto b) { return std::chrono::duration<double>(b - a).count(); };
  std::printf("N=%zu raster %.3f filter %.3f mesh %.3f  pts %zu tris %zu quads %zu  -> %.2f Mp/s\n", pl.p.size(),
              d(t0, t1), d(t1, t2), d(t2, t3), pts.size(), tri.size(), quad.size(), pl.p.size() / d(t0, t3) / 1e6);
}
