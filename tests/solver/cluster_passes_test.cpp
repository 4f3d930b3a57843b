// The density and force passes over cluster pairs (verlet_clusters) against the same passes over
// per-particle lists: the same terms over the same pairs, added in another order, so they agree to
// rounding for every kernel, pressure form, viscosity and with boundary samples; the same count of
// pairs within h; bitwise the same for any thread count.

#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include <sph/core/parallel.h>
#include <sph/neighbors/verlet.h>
#include <sph/solver/wcsph.h>

#include "support/blob.h"
#include "support/thread_count.h"

namespace sph {
namespace {

using test::Blob;
using test::ThreadCount;

template <int D, class R>
void expect_close(const std::vector<Vec<D, R>>& a, const std::vector<Vec<D, R>>& b, double tol, const char* what) {
  double scale = 0;
  for (const auto& v : a) scale = std::max(scale, static_cast<double>(norm(v)));
  double worst = 0;
  for (std::size_t i = 0; i < a.size(); ++i) worst = std::max(worst, static_cast<double>(norm(a[i] - b[i])));
  EXPECT_LE(worst, tol * scale) << what << ": largest difference " << worst << " of " << scale;
  EXPECT_GT(scale, 0.0) << what;
}

template <class R>
double tolerance() {
  return std::is_same_v<R, float> ? 2e-5 : 1e-12;
}

/// Runs both passes both ways on one blob and compares.
template <int D, class R>
void expect_cluster_passes_match(const FluidParams& fluid, bool boundary, bool pressure_terms = true) {
  SCOPED_TRACE(::testing::Message() << D << "D " << (sizeof(R) == 4 ? "float" : "double") << " kernel "
                                    << static_cast<int>(fluid.kernel) << " form "
                                    << static_cast<int>(fluid.pressure_force) << " viscosity "
                                    << static_cast<int>(fluid.viscosity_model) << (boundary ? " samples" : ""));
  Blob<D, R> blob(D == 3 ? 11 : 30, 3);
  const R h = static_cast<R>(blob.h);
  VerletNeighbors<D, R> verlet(h, h / 10), clusters(h, h / 10, true);
  if (boundary) verlet.set_boundary(blob.samples), clusters.set_boundary(blob.samples);
  verlet.update(blob.ps);
  clusters.update(blob.ps);
  ASSERT_NE(clusters.cluster_pairs(), nullptr);
  BoundaryView<D, R> view;
  if (boundary) {
    view.position = blob.samples;
    view.psi = blob.psi;
    view.lists = &verlet.boundary_lists();
    view.friction = R(0.3);
    view.extrapolate = true;
    view.extrapolation[D - 1] = R(-9.81);
  }
  ParticleSet<D, R> a = blob.ps, b = blob.ps;
  const std::uint64_t within_a = compute_density_pressure<D, R>(a, verlet.lists(), h, fluid, view);
  const NeighborLists none;
  const std::uint64_t within_b = compute_density_pressure<D, R>(b, none, h, fluid, view, clusters.cluster_pairs());
  EXPECT_EQ(within_a, within_b);
  EXPECT_GT(within_a, (D == 3 ? 20 : 8) * a.size());  // (h = 2 spacings: about 28 and 11)
  double worst = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    worst =
        std::max(worst, std::abs(static_cast<double>(a.density[i] - b.density[i])) / static_cast<double>(a.density[i]));
  EXPECT_LE(worst, tolerance<R>()) << "density";
  // The forces from the same densities and pressures.
  b.density = a.density;
  b.pressure = a.pressure;
  const test::FarWalls<D, R> far;
  const WallContact<D, R>& walls = far.walls;
  const Vec<D, R>& g = far.gravity;
  compute_accelerations<D, R>(a, verlet.lists(), h, fluid, g, walls, {}, R(1e-4), view, R(0), pressure_terms);
  compute_accelerations<D, R>(b, verlet.lists(), h, fluid, g, walls, {}, R(1e-4), view, R(0), pressure_terms,
                              clusters.cluster_pairs());
  expect_close<D, R>(a.acceleration, b.acceleration, tolerance<R>(), "acceleration");
}

template <int D, class R>
void expect_every_variant_matches() {
  FluidParams fluid;
  fluid.stiffness = 200;
  fluid.rest_density = 1000;
  fluid.viscosity = 0.5;
  fluid.negative_pressure = NegativePressure::Allow;
  for (KernelKind k : {KernelKind::Paper, KernelKind::Cubic, KernelKind::Wendland}) {
    fluid.kernel = k;
    for (PressureForce f : {PressureForce::Paper, PressureForce::Symmetric, PressureForce::Variational}) {
      fluid.pressure_force = f;
      expect_cluster_passes_match<D, R>(fluid, false);
    }
  }
  fluid.kernel = KernelKind::Paper;
  fluid.pressure_force = PressureForce::Paper;
  expect_cluster_passes_match<D, R>(fluid, true);
  expect_cluster_passes_match<D, R>(fluid, true, false);  // DFSPH's non-pressure accelerations
  fluid.viscosity_model = ViscosityModel::Artificial;
  fluid.alpha = 0.1;
  fluid.kernel = KernelKind::Cubic;
  expect_cluster_passes_match<D, R>(fluid, true);
  fluid.viscosity_model = ViscosityModel::Paper;
  fluid.gradient_correction = GradientCorrection::Renormalize;  // (its pressure pass reads the lists)
  expect_cluster_passes_match<D, R>(fluid, true);
}

TEST(ClusterPasses, MatchThePerParticleListsFor3dFloat) { expect_every_variant_matches<3, float>(); }
TEST(ClusterPasses, MatchThePerParticleListsFor3dDouble) { expect_every_variant_matches<3, double>(); }
TEST(ClusterPasses, MatchThePerParticleListsFor2dFloat) { expect_every_variant_matches<2, float>(); }
TEST(ClusterPasses, MatchThePerParticleListsFor2dDouble) { expect_every_variant_matches<2, double>(); }

TEST(ClusterPasses, AreBitwiseTheSameForAnyThreadCount) {
  ThreadCount restore;
  Blob<3, float> blob(14, 5);  // 2,744 particles: several chunks of clusters
  const float h = static_cast<float>(blob.h);
  VerletNeighbors<3, float> clusters(h, h / 10, true);
  clusters.set_boundary(blob.samples);
  clusters.update(blob.ps);
  BoundaryView<3, float> view{blob.samples, blob.psi, &clusters.boundary_lists(), 0.2f};
  FluidParams fluid;
  fluid.stiffness = 100;
  const std::vector<Box<3>> no_obstacles;
  const WallContact<3, float> walls({Vec<3, double>{-1, -1, -1}, Vec<3, double>{1, 1, 1}}, no_obstacles, 0.01f,
                                    WallParams{});
  const NeighborLists none;
  ParticleSet<3, float> out[2];
  for (int t : {1, 3}) {
    set_num_threads(t);
    ParticleSet<3, float> ps = blob.ps;
    compute_density_pressure<3, float>(ps, none, h, fluid, view, clusters.cluster_pairs());
    compute_accelerations<3, float>(ps, none, h, fluid, Vec<3, float>{0, 0, -9.81f}, walls, {}, 1e-4f, view, 0.0f, true,
                                    clusters.cluster_pairs());
    out[t == 1 ? 0 : 1] = ps;
  }
  EXPECT_TRUE(out[0].density == out[1].density);
  EXPECT_TRUE(out[0].acceleration == out[1].acceleration);
}

}  // namespace
}  // namespace sph
