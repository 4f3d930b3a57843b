#include <sph/solver/boundary.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include <sph/core/error.h>
#include <sph/core/parallel.h>
#include <sph/neighbors/list_builder.h>
#include <sph/neighbors/uniform_grid.h>
#include <sph/solver/smoothing.h>

namespace sph {

namespace {

/// The sites along one axis of a box [lo, hi]: `inner` evenly spaced sites (spacing at most
/// dx) half a step inside, and `layers` sites at dx, dx / 2 beyond each end.
struct AxisSites {
  std::vector<double> x;  // low outer layers (outermost first), inner sites, high outer layers
  int layers = 0, inner = 0;
};

AxisSites axis_sites(double lo, double hi, double dx, int layers, bool outer) {
  AxisSites a;
  a.layers = outer ? layers : 0;
  a.inner = std::max(1, static_cast<int>(std::ceil((hi - lo) / dx - 1e-9)));
  const double step = (hi - lo) / a.inner;
  for (int k = a.layers - 1; k >= 0; --k) a.x.push_back(lo - (k + 0.5) * dx);
  for (int i = 0; i < a.inner; ++i) a.x.push_back(lo + (i + 0.5) * step);
  for (int k = 0; k < a.layers; ++k) a.x.push_back(hi + (k + 0.5) * dx);
  return a;
}

/// Visits every lattice site of the axes' product, in order (x fastest), with per axis the
/// site's index.
template <int D, class F>
void for_each_site(const std::array<AxisSites, D>& axes, F&& f) {
  std::array<int, D> idx{};
  for (;;) {
    f(idx);
    int d = 0;
    while (d < D && ++idx[d] == static_cast<int>(axes[d].x.size())) idx[d++] = 0;
    if (d == D) return;
  }
}

/// The shape of obstacle k of a list, or nullptr (a box).
template <int D>
const ObstacleShape<D>* shape_of(std::span<const ObstacleShape<D>* const> shapes, std::size_t k) {
  return k < shapes.size() ? shapes[k] : nullptr;
}

/// The layers first to last - 1 of sites next to a shape's surface: each site of a lattice of
/// spacing dx over the shape's bounds grown by `grow` (x fastest) whose signed distance to the
/// solid s lies between first and last spacings from the surface on the solid's side (`inside`:
/// -last dx <= s < -first dx) or the fluid's (first dx < s <= last dx) is moved along the
/// surface's normal to the middle of its layer, |s| = (k + 1/2) dx, as a box's layers lie, and
/// visited. The first layer is then dx / 2 from the surface everywhere, as on a box, so that the
/// fluid rests a particle radius off the surface wherever the lattice happens to fall.
template <int D, class F>
void for_each_shape_site(const ObstacleShape<D>& shape, double dx, double grow, int first, int last, bool inside,
                         F&& f) {
  const Box<D> b = shape_bounds(shape);
  const double depth = last * dx;
  std::array<AxisSites, D> axes;
  for (int d = 0; d < D; ++d) axes[d] = axis_sites(b.lo[d] - grow, b.hi[d] + grow, dx, 0, false);
  for_each_site<D>(axes, [&](const std::array<int, D>& idx) {
    Vec<D, double> x;
    for (int d = 0; d < D; ++d) x[d] = axes[d].x[static_cast<std::size_t>(idx[d])];
    const SurfaceDistance<D> s = shape.solid_distance(x, depth);
    const double away = inside ? -s.distance : s.distance;  // how far on the wanted side
    if (!(away > first * dx && away <= depth)) return;
    const double layer = std::max(std::min(std::floor(away / dx), last - 1.0), static_cast<double>(first));
    const double target = (layer + 0.5) * dx;
    f(x + s.normal * (inside ? away - target : target - away));
  });
}

/// The sites of the solids' layers first to last - 1 (layer 0 next to the surface): the
/// container's shell outside the box (with_container), then each obstacle's inside it, those
/// outside the container dropped; obstacle_begin as sample_boundary's.
template <int D>
std::vector<Vec<D, double>> solid_layer_sites(const Box<D>& container, const std::vector<Box<D>>& obstacles,
                                              double spacing, int first, int last, bool with_container,
                                              std::vector<std::size_t>* obstacle_begin,
                                              std::span<const ObstacleShape<D>* const> shapes) {
  std::vector<Vec<D, double>> out;
  std::array<AxisSites, D> axes;
  if (with_container) {
    // The container's shell: sites outside the box on at least one axis, in the layer of the
    // axis they are deepest on.
    for (int d = 0; d < D; ++d) axes[d] = axis_sites(container.lo[d], container.hi[d], spacing, last, true);
    for_each_site<D>(axes, [&](const std::array<int, D>& idx) {
      int layer = -1;
      Vec<D, double> x;
      for (int d = 0; d < D; ++d) {
        const int i = idx[d];
        if (i < axes[d].layers) layer = std::max(layer, axes[d].layers - 1 - i);
        if (i >= axes[d].layers + axes[d].inner) layer = std::max(layer, i - axes[d].layers - axes[d].inner);
        x[d] = axes[d].x[static_cast<std::size_t>(i)];
      }
      if (layer >= first) out.push_back(x);
    });
  }
  // Each obstacle: its sites inside it, in the layer of the face they are nearest to.
  if (obstacle_begin) obstacle_begin->assign(1, out.size());
  const auto in_container = [&](const Vec<D, double>& x) {
    for (int d = 0; d < D; ++d)
      if (!(x[d] >= container.lo[d] && x[d] <= container.hi[d])) return false;
    return true;
  };
  for (std::size_t k = 0; k < obstacles.size(); ++k) {
    const Box<D>& b = obstacles[k];
    if (const ObstacleShape<D>* shape = shape_of<D>(shapes, k)) {
      // A shape: the sites of a lattice over its bounds within the layers' depth of its surface
      // on the solid's side (outside the surface too when it is inverted).
      for_each_shape_site<D>(*shape, spacing, shape->inverted ? last * spacing : 0.0, first, last, true,
                             [&](const Vec<D, double>& x) {
                               if (in_container(x)) out.push_back(x);
                             });
      if (obstacle_begin) obstacle_begin->push_back(out.size());
      continue;
    }
    for (int d = 0; d < D; ++d) axes[d] = axis_sites(b.lo[d], b.hi[d], spacing, 0, false);
    for_each_site<D>(axes, [&](const std::array<int, D>& idx) {
      int layer = std::numeric_limits<int>::max();
      Vec<D, double> x;
      for (int d = 0; d < D; ++d) {
        const int i = idx[d];
        layer = std::min({layer, i, axes[d].inner - 1 - i});
        x[d] = axes[d].x[static_cast<std::size_t>(i)];
      }
      if (layer >= first && layer < last && in_container(x)) out.push_back(x);
    });
    if (obstacle_begin) obstacle_begin->push_back(out.size());
  }
  return out;
}

}  // namespace

int boundary_layers(double spacing, double h) {
  SPH_CHECK(spacing > 0 && h > 0 && h / spacing <= 1000, "boundary_layers: h / spacing out of range");
  return std::max(1, static_cast<int>(std::ceil(h / spacing - 1e-9)));
}

template <int D>
std::vector<Vec<D, double>> sample_boundary(const Box<D>& container, const std::vector<Box<D>>& obstacles,
                                            double spacing, double h, std::vector<std::size_t>* obstacle_begin,
                                            std::span<const ObstacleShape<D>* const> shapes) {
  return solid_layer_sites<D>(container, obstacles, spacing, 0, boundary_layers(spacing, h), true, obstacle_begin,
                              shapes);
}

template <int D>
std::vector<Vec<D, double>> solid_sites_beyond_samples(const Box<D>& container, const std::vector<Box<D>>& obstacles,
                                                       double spacing, double h, bool with_container,
                                                       std::span<const ObstacleShape<D>* const> shapes) {
  const int layers = boundary_layers(spacing, h);
  return solid_layer_sites<D>(container, obstacles, spacing, layers, 2 * layers, with_container, nullptr, shapes);
}

template <int D>
std::vector<Vec<D, double>> rest_fluid_sites(const Box<D>& container, const std::vector<Box<D>>& obstacles,
                                             double spacing, double h,
                                             std::span<const ObstacleShape<D>* const> shapes) {
  const int layers = boundary_layers(spacing, h);
  const double depth = layers * spacing;
  const auto in_box = [](const Vec<D, double>& x, const Box<D>& b) {
    for (int d = 0; d < D; ++d)
      if (!(x[d] > b.lo[d] && x[d] < b.hi[d])) return false;
    return true;
  };
  const auto in_obstacle = [&](const Vec<D, double>& x) {
    for (std::size_t k = 0; k < obstacles.size(); ++k) {
      if (const ObstacleShape<D>* shape = shape_of<D>(shapes, k)) {
        if (shape->solid_distance(x, 0).distance < 0) return true;
      } else if (in_box(x, obstacles[k])) {
        return true;
      }
    }
    return false;
  };
  std::vector<Vec<D, double>> out;
  std::array<AxisSites, D> axes;
  for (int d = 0; d < D; ++d) axes[d] = axis_sites(container.lo[d], container.hi[d], spacing, layers, false);
  for_each_site<D>(axes, [&](const std::array<int, D>& idx) {
    bool near_face = false;
    Vec<D, double> x;
    for (int d = 0; d < D; ++d) {
      near_face = near_face || idx[d] < layers || idx[d] >= axes[d].inner - layers;
      x[d] = axes[d].x[static_cast<std::size_t>(idx[d])];
    }
    if (near_face && !in_obstacle(x)) out.push_back(x);
  });
  Box<D> core = container;  // the container's sites cover the depth next to its faces
  for (int d = 0; d < D; ++d) core.lo[d] += depth, core.hi[d] -= depth;
  for (std::size_t k = 0; k < obstacles.size(); ++k) {
    const Box<D>& b = obstacles[k];
    if (const ObstacleShape<D>* shape = shape_of<D>(shapes, k)) {
      // A shape: its lattice's sites within the depth of its surface on the fluid's side.
      for_each_shape_site<D>(*shape, spacing, shape->inverted ? 0.0 : depth, 0, layers, false,
                             [&](const Vec<D, double>& x) {
                               if (in_box(x, core) && !in_obstacle(x)) out.push_back(x);
                             });
      continue;
    }
    for (int d = 0; d < D; ++d) axes[d] = axis_sites(b.lo[d], b.hi[d], spacing, layers, true);
    for_each_site<D>(axes, [&](const std::array<int, D>& idx) {
      Vec<D, double> x;
      for (int d = 0; d < D; ++d) x[d] = axes[d].x[static_cast<std::size_t>(idx[d])];
      if (in_box(x, core) && !in_obstacle(x)) out.push_back(x);
    });
  }
  return out;
}

template <int D, std::floating_point R>
std::vector<R> boundary_psi(std::span<const Vec<D, R>> samples, const FluidParams& fluid, R h,
                            std::span<const Vec<D, R>> rest) {
  std::vector<R> psi(samples.size());
  if (samples.empty()) return psi;
  UniformGrid<D, R> grid;
  grid.build(samples, h);
  ListBuilder<D, R> builder;
  NeighborLists lists, rest_lists;
  builder.build(grid, samples, h, lists);
  if (!rest.empty()) {
    UniformGrid<D, R> rest_grid;
    rest_grid.build(rest, h);
    builder.build_queries(rest_grid, samples, h, rest_lists);
  }
  const SmoothingKernels<D, R> kernels(fluid, h);
  const R rho0 = static_cast<R>(fluid.rest_density);
  parallel_for(samples.size(), [&](std::size_t b) {
    R delta = kernels.w_zero();
    for (const std::uint32_t k : lists.of(b)) delta += kernels.w_r2(norm2(samples[b] - samples[k]));
    if (!rest.empty())
      for (const std::uint32_t k : rest_lists.of(b)) delta += kernels.w_r2(norm2(samples[b] - rest[k]));
    psi[b] = rho0 / delta;
  });
  return psi;
}

template <int D, std::floating_point R>
BoundarySet<D, R> make_boundary(const SimulationParams<D>& params) {
  BoundarySet<D, R> set;
  if (params.boundary.handling != BoundaryHandling::Particles) return set;
  std::vector<const ObstacleShape<D>*> shapes(params.obstacles.size());
  for (std::size_t k = 0; k < shapes.size(); ++k) shapes[k] = obstacle_shape(params, k);
  const std::vector<Vec<D, double>> samples =
      sample_boundary<D>(params.container, params.obstacles, 2.0 * params.particle_radius, params.kernel_radius,
                         &set.obstacle_begin, shapes);
  for (const auto& x : samples) set.position.push_back(vec_cast<R>(x));
  SPH_CHECK(set.position.size() < (std::size_t{1} << 31) / D, "too many boundary samples for 32-bit gather offsets");
  const R h = static_cast<R>(params.kernel_radius);
  const double dx = 2.0 * params.particle_radius;
  const bool rest_fluid = params.boundary.volume == BoundaryVolume::RestFluid;
  // What RestFluid counts beside the samples: the fluid at rest on the solids' fluid side and
  // the solids' own continuation beyond the sampled layers (with the container's shell or not).
  const auto rest_sites = [&](const std::vector<Box<D>>& obstacles, std::span<const ObstacleShape<D>* const> of,
                              bool with_container) {
    std::vector<Vec<D, R>> rest;
    if (!rest_fluid) return rest;
    for (const auto& x : rest_fluid_sites<D>(params.container, obstacles, dx, params.kernel_radius, of))
      rest.push_back(vec_cast<R>(x));
    for (const auto& x :
         solid_sites_beyond_samples<D>(params.container, obstacles, dx, params.kernel_radius, with_container, of))
      rest.push_back(vec_cast<R>(x));
    return rest;
  };
  if (!any_obstacle_moves(params)) {
    set.psi = boundary_psi<D, R>(set.position, params.fluid, h, rest_sites(params.obstacles, shapes, true));
    return set;
  }
  // Moving obstacles: psi counts only what moves with the sample. The container's and the resting
  // obstacles' samples are weighed among themselves; each moving obstacle's among its own (and the
  // rest fluid around it), so that neither keeps the crowding of the other's samples at t = 0
  // once they part (a gate standing on the floor, then lifted).
  set.psi.assign(set.size(), R(0));
  std::vector<Vec<D, R>> still;
  std::vector<std::size_t> still_index;
  std::vector<Box<D>> still_boxes;
  std::vector<const ObstacleShape<D>*> still_shapes;
  for (std::size_t b = 0; b < set.obstacle_begin[0]; ++b) still.push_back(set.position[b]), still_index.push_back(b);
  for (std::size_t k = 0; k < params.obstacles.size(); ++k) {
    const std::size_t b0 = set.obstacle_begin[k], b1 = set.obstacle_begin[k + 1];
    if (obstacle_moves(params, k)) {
      const std::vector<Vec<D, R>> own(set.position.begin() + static_cast<std::ptrdiff_t>(b0),
                                       set.position.begin() + static_cast<std::ptrdiff_t>(b1));
      const ObstacleShape<D>* own_shape[1] = {shapes[k]};
      const std::vector<R> psi =
          boundary_psi<D, R>(own, params.fluid, h, rest_sites({params.obstacles[k]}, own_shape, false));
      std::copy(psi.begin(), psi.end(), set.psi.begin() + static_cast<std::ptrdiff_t>(b0));
      continue;
    }
    still_boxes.push_back(params.obstacles[k]);
    still_shapes.push_back(shapes[k]);
    for (std::size_t b = b0; b < b1; ++b) still.push_back(set.position[b]), still_index.push_back(b);
  }
  const std::vector<R> psi = boundary_psi<D, R>(still, params.fluid, h, rest_sites(still_boxes, still_shapes, true));
  for (std::size_t i = 0; i < still.size(); ++i) set.psi[still_index[i]] = psi[i];
  set.rest_position = samples;
  set.velocity.assign(set.size(), Vec<D, R>{});
  std::vector<RigidPose<D>> poses(params.obstacles.size());
  for (std::size_t k = 0; k < params.obstacles.size(); ++k) poses[k] = pose_at(obstacle_motion(params, k), 0.0);
  place_boundary<D, R>(set, params, poses);
  return set;
}

template <int D, std::floating_point R>
void place_boundary(BoundarySet<D, R>& set, const SimulationParams<D>& params, std::span<const RigidPose<D>> poses) {
  if (!set.moving()) return;
  SPH_CHECK(poses.size() == params.obstacles.size(), "place_boundary: one pose per obstacle");
  for (std::size_t k = 0; k < params.obstacles.size(); ++k) {
    if (!obstacle_moves(params, k)) continue;
    const RigidPose<D>& pose = poses[k];
    const std::size_t b = set.obstacle_begin[k], e = set.obstacle_begin[k + 1];
    parallel_for(e - b, [&](std::size_t s) {
      const Vec<D, double> x = pose.place(set.rest_position[b + s]);
      set.position[b + s] = vec_cast<R>(x);
      set.velocity[b + s] = vec_cast<R>(pose.velocity_at(x));
    });
  }
}

template std::vector<Vec<2, double>> sample_boundary<2>(const Box<2>&, const std::vector<Box<2>>&, double, double,
                                                        std::vector<std::size_t>*,
                                                        std::span<const ObstacleShape<2>* const>);
template std::vector<Vec<3, double>> sample_boundary<3>(const Box<3>&, const std::vector<Box<3>>&, double, double,
                                                        std::vector<std::size_t>*,
                                                        std::span<const ObstacleShape<3>* const>);
template std::vector<Vec<2, double>> solid_sites_beyond_samples<2>(const Box<2>&, const std::vector<Box<2>>&, double,
                                                                   double, bool,
                                                                   std::span<const ObstacleShape<2>* const>);
template std::vector<Vec<3, double>> solid_sites_beyond_samples<3>(const Box<3>&, const std::vector<Box<3>>&, double,
                                                                   double, bool,
                                                                   std::span<const ObstacleShape<3>* const>);
template std::vector<Vec<2, double>> rest_fluid_sites<2>(const Box<2>&, const std::vector<Box<2>>&, double, double,
                                                         std::span<const ObstacleShape<2>* const>);
template std::vector<Vec<3, double>> rest_fluid_sites<3>(const Box<3>&, const std::vector<Box<3>>&, double, double,
                                                         std::span<const ObstacleShape<3>* const>);
#define SPH_INSTANTIATE(D, R)                                                                   \
  template std::vector<R> boundary_psi<D, R>(std::span<const Vec<D, R>>, const FluidParams&, R, \
                                             std::span<const Vec<D, R>>);                       \
  template BoundarySet<D, R> make_boundary<D, R>(const SimulationParams<D>&);                   \
  template void place_boundary<D, R>(BoundarySet<D, R>&, const SimulationParams<D>&, std::span<const RigidPose<D>>);
SPH_INSTANTIATE(2, float)
SPH_INSTANTIATE(2, double)
SPH_INSTANTIATE(3, float)
SPH_INSTANTIATE(3, double)
#undef SPH_INSTANTIATE

}  // namespace sph
