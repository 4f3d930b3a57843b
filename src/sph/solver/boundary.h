#pragma once
/// \file Boundary particles (Akinci, Ihmsen, Akinci, Solenthaler and Teschner, "Versatile
/// rigid-fluid coupling for incompressible SPH", SIGGRAPH 2012): the container's walls and the
/// obstacles sampled by static particles that take part in the fluid's density and pressure.
///
/// Sampling (docs/physics.md, "Boundary particles"): each solid is filled, from its surface
/// inwards, with boundary_layers() layers of samples on a lattice of spacing at most the fluid's
/// particle spacing dx, the first layer dx / 2 behind the surface, so that the samples continue
/// the fluid's lattice and a fluid particle at the wall finds its whole kernel support filled.
/// The container's shell is sampled outside the box (faces, edges and corners: every lattice
/// site within the layers' depth of the box on some axis); each obstacle inside its box, in
/// from each face, samples outside the container dropped.
///
/// Each sample b carries psi_b = rho0 V_b with V_b = 1 / sum_k W(x_b - x_k), the sum over the
/// samples within h, b included (Akinci's eq. 4-5): where samples are dense each counts less;
/// with BoundaryVolume::RestFluid (default) the sum also counts the fluid at rest on the
/// solid's fluid side (rest_fluid_sites) and the solid's lattice beyond its sampled layers
/// (solid_sites_beyond_samples), so that every sample weighs what the fluid it stands for would,
/// on any support.

#include <span>
#include <vector>

#include <sph/core/vec.h>
#include <sph/solver/params.h>

namespace sph {

/// Layers of samples behind a surface: ceil(h / spacing), at least 1 (2 at h = 2 spacings).
int boundary_layers(double spacing, double h);

/// The sample positions of the container's shell and the obstacles (in that order, each in a
/// fixed lattice order), m. With `obstacle_begin`, obstacle k's samples are
/// [(*obstacle_begin)[k], (*obstacle_begin)[k + 1]) (obstacles.size() + 1 entries). `shapes[k]`
/// (when given and not null) is obstacle k's shape (shape.h; `obstacles[k]` its bounds): its
/// samples are the sites of a lattice of spacing `spacing` over its bounds that lie within the
/// layers' depth of its surface on the solid's side, each moved along the surface's normal to the
/// middle of its layer (the first dx / 2 behind the surface, as a box's).
template <int D>
std::vector<Vec<D, double>> sample_boundary(const Box<D>& container, const std::vector<Box<D>>& obstacles,
                                            double spacing, double h,
                                            std::vector<std::size_t>* obstacle_begin = nullptr,
                                            std::span<const ObstacleShape<D>* const> shapes = {});

/// The boundary of a run: sample positions and each sample's psi, kg (kg/m in 2D). The samples of
/// moving obstacles (motion.h) are placed at each step's time by place_boundary(); their psi is
/// the one they have at rest (a rigid motion keeps an obstacle's own samples' spacing).
template <int D, std::floating_point R>
struct BoundarySet {
  std::vector<Vec<D, R>> position;  ///< where the samples are now, m
  std::vector<R> psi;
  /// Obstacle k's samples are [obstacle_begin[k], obstacle_begin[k + 1]); the container's come
  /// first, [0, obstacle_begin[0]).
  std::vector<std::size_t> obstacle_begin;
  /// When an obstacle moves: every sample's position at rest, and its velocity now (zero for
  /// the container's and the resting obstacles'). Empty when nothing moves.
  std::vector<Vec<D, double>> rest_position;
  std::vector<Vec<D, R>> velocity;
  std::size_t size() const { return position.size(); }
  bool moving() const { return !velocity.empty(); }
};

/// Places the moving obstacles' samples of `set` (make_boundary's for `params`) where `poses` (one
/// per obstacle: a motion's at a time, or a floating body's) put them, with their velocities.
/// Nothing if no obstacle moves.
template <int D, std::floating_point R>
void place_boundary(BoundarySet<D, R>& set, const SimulationParams<D>& params, std::span<const RigidPose<D>> poses);

/// The lattice sites of fluid at rest next to the solids (BoundaryVolume::RestFluid): the
/// container's interior sites within the layers' depth of a face, and each obstacle's sites
/// within that depth outside it (on its own lattice, continued outwards), leaving out sites in
/// an obstacle and, for an obstacle's, sites the container's already cover (within the depth of
/// a container face), m. A shape's (`shapes` as in sample_boundary) are its lattice's sites within
/// that depth of its surface on the fluid's side.
template <int D>
std::vector<Vec<D, double>> rest_fluid_sites(const Box<D>& container, const std::vector<Box<D>>& obstacles,
                                             double spacing, double h,
                                             std::span<const ObstacleShape<D>* const> shapes = {});

/// The sites of the solids' lattices beyond the sampled layers: the next boundary_layers() layers
/// behind them (the container's shell, when with_container, and each obstacle's inside it, on
/// the lattices and in the layers sample_boundary uses). BoundaryVolume::RestFluid counts them in
/// each sample's delta_b, so that the samples deeper than the first weigh what the solid they
/// stand for would: without them a sample's support reaching past the last layer reads a thin
/// solid, and on supports wider than 2 spacings the fluid next to a wall read above rho0.
template <int D>
std::vector<Vec<D, double>> solid_sites_beyond_samples(const Box<D>& container, const std::vector<Box<D>>& obstacles,
                                                       double spacing, double h, bool with_container,
                                                       std::span<const ObstacleShape<D>* const> shapes = {});

/// psi_b = rho0 / delta_b, delta_b = sum_k W(x_b - x_k) over the samples within h (b included)
/// and the `rest` points within h, W the run's density kernel (FluidParams::kernel).
/// Deterministic for any thread count.
template <int D, std::floating_point R>
std::vector<R> boundary_psi(std::span<const Vec<D, R>> samples, const FluidParams& fluid, R h,
                            std::span<const Vec<D, R>> rest = {});

/// The boundary of `params`: its samples and their psi under BoundaryHandling::Particles, empty
/// otherwise.
template <int D, std::floating_point R>
BoundarySet<D, R> make_boundary(const SimulationParams<D>& params);

}  // namespace sph
