#include <sph/solver/wcsph.h>

#include <algorithm>
#include <atomic>
#include <cmath>

#include <sph/core/error.h>
#include <sph/core/kernels.h>
#include <sph/core/parallel.h>

namespace sph {

namespace {
template <bool kExitTest, int D, std::floating_point R>
std::uint64_t density_pass(ParticleSet<D, R>& ps, const NeighborLists& lists, R h, const FluidParams& fluid,
                           std::span<std::uint8_t> flags, R dt) {
  const Poly6Kernel<D, R> poly6(h);
  const R w0 = poly6.w_zero();
  const R h2 = h * h;
  const R rho0 = static_cast<R>(fluid.rest_density);
  const R k = static_cast<R>(fluid.stiffness);
  const bool clamp = fluid.negative_pressure == NegativePressure::Clamp;
  const auto set_flag = [&](std::size_t q) {
    std::atomic_ref<std::uint8_t>(flags[q]).store(1, std::memory_order_relaxed);
  };
  std::vector<std::uint64_t> within(chunk_count(ps.size()), 0);
  parallel_chunks(ps.size(), [&](std::size_t c, std::size_t b, std::size_t e) {
    std::uint64_t count = 0;
    for (std::size_t i = b; i < e; ++i) {
      const Vec<D, R> xi = ps.position[i];
      R rho = ps.mass[i] * w0;
      bool flag_i = false;
      for (std::uint32_t j : lists.of(i)) {
        const Vec<D, R> rij = xi - ps.position[j];
        const R r2 = norm2(rij);
        rho += ps.mass[j] * poly6.w_r2(r2);
        count += r2 < h2 ? 1 : 0;
        if constexpr (kExitTest) {
          // Paper Eq. 7: the pair's distance after the step, predicted with today's velocities.
          if (norm2(rij + (ps.velocity[i] - ps.velocity[j]) * dt) > h2) {
            flag_i = true;
            set_flag(j);
          }
        }
      }
      if constexpr (kExitTest)
        if (flag_i) set_flag(i);
      ps.density[i] = rho;
      const R p = k * (rho - rho0);
      ps.pressure[i] = clamp ? std::max(p, R(0)) : p;
    }
    within[c] = count;
  });
  std::uint64_t total = 0;
  for (std::uint64_t w : within) total += w;
  return total;
}
}  // namespace

template <int D, std::floating_point R>
std::uint64_t compute_density_pressure(ParticleSet<D, R>& ps, const NeighborLists& lists, R h, const FluidParams& fluid,
                                       std::span<std::uint8_t> exit_flags, R dt) {
  if (exit_flags.empty()) return density_pass<false>(ps, lists, h, fluid, exit_flags, dt);
  SPH_CHECK(exit_flags.size() == ps.size(), "one exit flag per particle");
  return density_pass<true>(ps, lists, h, fluid, exit_flags, dt);
}

template <int D, std::floating_point R>
void compute_fluid_accelerations(ParticleSet<D, R>& ps, const NeighborLists& lists, R h, const FluidParams& fluid,
                                 const Vec<D, R>& gravity) {
  const SpikyKernel<D, R> spiky(h);
  const ViscosityKernel<D, R> visc(h);
  const R mu = static_cast<R>(fluid.viscosity);
  const bool paper = fluid.pressure_force == PressureForce::Paper;
  parallel_for(ps.size(), [&](std::size_t i) {
    const Vec<D, R> xi = ps.position[i];
    const Vec<D, R> vi = ps.velocity[i];
    const R inv_rhoi = R(1) / ps.density[i];
    // Pressure term P_ij, symmetric in i and j, so that each pair's contributions are equal
    // and opposite: the paper's (p_i + p_j) / (2 rho_i rho_j), or p_i / rho_i^2 + p_j / rho_j^2.
    const R pi_half = R(0.5) * ps.pressure[i] * inv_rhoi;
    const R pi_sym = ps.pressure[i] * inv_rhoi * inv_rhoi;
    Vec<D, R> a{};
    for (std::uint32_t j : lists.of(i)) {
      const Vec<D, R> rij = xi - ps.position[j];
      const R r = norm(rij);
      if (r >= h) continue;
      const R inv_rhoj = R(1) / ps.density[j];
      const R pij = paper ? (pi_half + R(0.5) * ps.pressure[j] * inv_rhoi) * inv_rhoj
                          : pi_sym + ps.pressure[j] * inv_rhoj * inv_rhoj;
      a += spiky.gradient(rij, r) * (-ps.mass[j] * pij);
      a += (ps.velocity[j] - vi) * (mu * ps.mass[j] * inv_rhoi * inv_rhoj * visc.laplacian(r));
    }
    ps.acceleration[i] = gravity + a;
  });
}

namespace {
/// Acceleration of a penalty contact along unit axis normal sign*e_d: never attractive.
template <std::floating_point R>
R contact(R penetration, R normal_velocity, R ks, R kd) {
  return std::max(R(0), ks * penetration - kd * normal_velocity);
}
}  // namespace

template <int D, std::floating_point R>
void add_wall_accelerations(ParticleSet<D, R>& ps, const Box<D>& container, const std::vector<Box<D>>& obstacles,
                            R particle_radius, const WallParams& walls) {
  const R ks = static_cast<R>(walls.stiffness);
  const R kd = static_cast<R>(walls.damping);
  const Vec<D, R> lo = vec_cast<R>(container.lo), hi = vec_cast<R>(container.hi);
  std::vector<Box<D>> const& obs = obstacles;
  parallel_for(ps.size(), [&](std::size_t i) {
    const Vec<D, R> x = ps.position[i];
    const Vec<D, R> v = ps.velocity[i];
    Vec<D, R> a{};
    // Container: particles inside the box, pushed back from each of its 2D faces.
    for (int d = 0; d < D; ++d) {
      const R pen_lo = lo[d] + particle_radius - x[d];
      if (pen_lo > 0) a[d] += contact(pen_lo, v[d], ks, kd);
      const R pen_hi = x[d] - (hi[d] - particle_radius);
      if (pen_hi > 0) a[d] -= contact(pen_hi, -v[d], ks, kd);
    }
    // Obstacles: a particle inside the box grown by one radius is pushed out through the
    // nearest face.
    for (const Box<D>& b : obs) {
      R best = std::numeric_limits<R>::max();
      int best_d = -1;
      R best_sign = 0;
      bool inside = true;
      for (int d = 0; d < D && inside; ++d) {
        const R to_lo = x[d] - (static_cast<R>(b.lo[d]) - particle_radius);
        const R to_hi = (static_cast<R>(b.hi[d]) + particle_radius) - x[d];
        if (to_lo <= 0 || to_hi <= 0) {
          inside = false;
          break;
        }
        if (to_lo < best) best = to_lo, best_d = d, best_sign = R(-1);
        if (to_hi < best) best = to_hi, best_d = d, best_sign = R(1);
      }
      if (!inside) continue;
      a[best_d] += best_sign * contact(best, best_sign * v[best_d], ks, kd);
    }
    ps.acceleration[i] += a;
  });
}

template <int D, std::floating_point R>
void integrate_symplectic_euler(ParticleSet<D, R>& ps, R dt) {
  parallel_for(ps.size(), [&](std::size_t i) {
    ps.velocity[i] += ps.acceleration[i] * dt;
    ps.position[i] += ps.velocity[i] * dt;
  });
}

template <int D>
double lattice_mass(double rest_density, double spacing, double h) {
  const Poly6Kernel<D, double> poly6(h);
  const int n = static_cast<int>(std::ceil(h / spacing)) + 1;
  double sum = 0;
  if constexpr (D == 2) {
    for (int a = -n; a <= n; ++a)
      for (int b = -n; b <= n; ++b) sum += poly6.w(spacing * std::sqrt(double(a * a + b * b)));
  } else {
    for (int a = -n; a <= n; ++a)
      for (int b = -n; b <= n; ++b)
        for (int c = -n; c <= n; ++c) sum += poly6.w(spacing * std::sqrt(double(a * a + b * b + c * c)));
  }
  return rest_density / sum;
}

#define SPH_INSTANTIATE(D, R)                                                                                      \
  template std::uint64_t compute_density_pressure<D, R>(ParticleSet<D, R>&, const NeighborLists&, R,               \
                                                        const FluidParams&, std::span<std::uint8_t>, R);           \
  template void compute_fluid_accelerations<D, R>(ParticleSet<D, R>&, const NeighborLists&, R, const FluidParams&, \
                                                  const Vec<D, R>&);                                               \
  template void add_wall_accelerations<D, R>(ParticleSet<D, R>&, const Box<D>&, const std::vector<Box<D>>&, R,     \
                                             const WallParams&);                                                   \
  template void integrate_symplectic_euler<D, R>(ParticleSet<D, R>&, R);
SPH_INSTANTIATE(2, float)
SPH_INSTANTIATE(2, double)
SPH_INSTANTIATE(3, float)
SPH_INSTANTIATE(3, double)
#undef SPH_INSTANTIATE
template double lattice_mass<2>(double, double, double);
template double lattice_mass<3>(double, double, double);

}  // namespace sph
