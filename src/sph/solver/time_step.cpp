#include <sph/solver/time_step.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include <sph/core/error.h>

namespace sph {

template <int D>
std::vector<TimeStepLimit> time_step_limits(const SimulationParams<D>& p) {
  std::vector<TimeStepLimit> out;
  const double dt = p.time_step;
  const double h = p.kernel_radius;
  auto add = [&](const char* name, double warn, double refuse, const char* keys) {
    out.push_back({name, dt / warn, warn, refuse, false, keys});
  };
  const double c = std::sqrt(p.fluid.stiffness);
  // DFSPH solves for its pressure: there is no sound speed to resolve.
  if (c > 0 && p.method == SimulationMethod::Wcsph) {
    add("acoustic CFL (dt <= 0.4 h / sqrt(stiffness))", 0.4 * h / c, 1.0 * h / c, "a lower Fluid.stiffness");
    out.back().acoustic = true;
  }
  const double nu = p.fluid.viscosity / p.fluid.rest_density;
  // Forward Euler is stable while dt lambda_max <= 2, lambda_max the viscosity operator's largest
  // eigenvalue; on a lattice (scripts/viscous_limit.py) that is dt <= 0.127-0.147 h^2 / nu for Eq. 6's
  // Laplacian and 0.078-0.095 h^2 / nu for Morris's (the cubic spline and Wendland C2 at 2 to 3
  // spacings). The warning levels stay below: 0.125 and 0.0625. (Integrated implicitly, the
  // viscosity has no step limit.)
  if (p.fluid.viscosity_model == ViscosityModel::Paper && p.fluid.viscosity_solve == ViscositySolve::Explicit &&
      nu > 0) {
    if (p.fluid.kernel == KernelKind::Paper)
      add("viscous diffusion (dt <= 0.125 h^2 rho0 / viscosity)", 0.125 * h * h / nu, 0.5 * h * h / nu,
          "a lower Fluid.viscosity, or Fluid.viscositySolver \"implicit\" (no step limit)");
    else
      add("viscous diffusion (dt <= 0.0625 h^2 rho0 / viscosity with the cubic spline and Wendland C2)",
          0.0625 * h * h / nu, 0.25 * h * h / nu,
          "a lower Fluid.viscosity, or Fluid.viscositySolver \"implicit\" (no step limit)");
  }
  // Artificial viscosity's diffusion, nu = alpha h c / (2 (D + 2)) (Monaghan 2005), is below the
  // acoustic limit's for alpha < 1; it is checked the same way.
  const double nu_art = p.fluid.alpha * h * c / (2.0 * (D + 2));
  if (p.fluid.viscosity_model == ViscosityModel::Artificial && nu_art > 0)
    add("artificial viscosity's diffusion (dt <= 0.125 h^2 / nu, nu = alpha h c0 / (2 (D + 2)))",
        0.125 * h * h / nu_art, 0.5 * h * h / nu_art, "a lower Fluid.artificialViscosityAlpha or Fluid.stiffness");
  // Boundary particles' friction (Akinci et al. 2012) is an artificial viscosity at the walls
  // with nu = sigma h c0 / (2 (D + 2)): the same diffusion limit.
  const double nu_wall = p.boundary.friction * h * c / (2.0 * (D + 2));
  if (p.boundary.handling == BoundaryHandling::Particles && nu_wall > 0)
    add("boundary friction's diffusion (dt <= 0.125 h^2 / nu, nu = boundaryFriction h c0 / (2 (D + 2)))",
        0.125 * h * h / nu_wall, 0.5 * h * h / nu_wall, "a lower Configuration.boundaryFriction or Fluid.stiffness");
  // Penalty walls only: boundary particles act through the pressure (the acoustic limit).
  const bool springs = p.boundary.handling == BoundaryHandling::Penalty;
  if (springs && p.walls.stiffness > 0) {
    const double w = std::sqrt(p.walls.stiffness);
    add("wall spring (dt <= 0.5 / sqrt(wall stiffness))", 0.5 / w, 1.5 / w, "a lower Container.wallStiffness");
  }
  if (springs && p.walls.damping > 0)
    add("wall damping (dt <= 0.5 / wall damping)", 0.5 / p.walls.damping, 1.5 / p.walls.damping,
        "a lower Container.wallDamping");
  const double g = norm(p.gravity);
  if (g > 0)
    add("gravity (dt <= 0.25 sqrt(h / |g|))", 0.25 * std::sqrt(h / g), std::sqrt(h / g),
        "a larger Configuration.kernelRadius or a weaker Configuration.gravitation");
  return out;
}

template <int D>
double auto_time_step(const SimulationParams<D>& p) {
  double smallest = std::numeric_limits<double>::infinity();
  for (const auto& l : time_step_limits(p)) smallest = std::min(smallest, l.dt_warn);
  SPH_CHECK(std::isfinite(smallest), "auto_time_step: no stability limit applies (stiffness not positive)");
  return kAutoTimeStepFraction * smallest;
}

template <int D>
std::vector<std::string> check_time_step(const SimulationParams<D>& p) {
  std::vector<std::string> warnings;
  for (const auto& l : time_step_limits(p)) {
    if (p.time_step > l.dt_refuse)
      throw Error(fmt::format("time step {:.4g} s is unstable by the {} criterion, which gives {:.4g} s here; a "
                              "step above {:.4g} s is refused (and one above {:.4g} s warned of). Lower "
                              "Configuration.timeStepSize (or give \"auto\"), or allow a longer step with {}",
                              p.time_step, l.name, l.dt_warn, l.dt_refuse, l.dt_warn, l.keys),
                  "Configuration.timeStepSize");
    if (p.time_step > l.dt_warn)
      warnings.push_back(fmt::format("time step {:.4g} s exceeds the {} limit of {:.4g} s; the run may be unstable",
                                     p.time_step, l.name, l.dt_warn));
  }
  return warnings;
}

template std::vector<TimeStepLimit> time_step_limits<2>(const SimulationParams<2>&);
template std::vector<TimeStepLimit> time_step_limits<3>(const SimulationParams<3>&);
template double auto_time_step<2>(const SimulationParams<2>&);
template double auto_time_step<3>(const SimulationParams<3>&);
template std::vector<std::string> check_time_step<2>(const SimulationParams<2>&);
template std::vector<std::string> check_time_step<3>(const SimulationParams<3>&);

}  // namespace sph
