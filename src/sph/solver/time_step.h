#pragma once
/// \file Time-step checks: warn when dt is close to a stability limit, refuse it past one.

#include <string>
#include <vector>

#include <sph/solver/params.h>

namespace sph {

/// One stability criterion evaluated for a scene.
struct TimeStepLimit {
  std::string name;       ///< what limits the step, e.g. "acoustic CFL"
  double ratio;           ///< dt relative to the limit: dt / dt_limit
  double dt_warn;         ///< largest dt that passes without a warning, s
  double dt_refuse;       ///< dt above this is refused, s
  bool acoustic = false;  ///< the acoustic CFL limit (CFL steps take it with the flow's speed)
  std::string keys;       ///< the scene keys that set the limit, for the refusal's advice
};

/// Evaluates the stability limits of explicit WCSPH with penalty walls for these params:
///  - acoustic CFL: dt <= 0.4 h / c (warn), 1.0 h / c (refuse), with sound speed c = sqrt(k);
///  - viscous diffusion: dt <= 0.125 h^2 / nu (warn), 0.5 h^2 / nu (refuse), nu = mu / rho0;
///  - wall springs: dt sqrt(k_w) <= 0.5 (warn), 1.5 (refuse); dt c_w <= 0.5 (warn), 1.5 (refuse);
///  - gravity: dt <= 0.25 sqrt(h / |g|) (warn), 1.0 sqrt(h / |g|) (refuse).
template <int D>
std::vector<TimeStepLimit> time_step_limits(const SimulationParams<D>& p);

/// The fraction of the tightest warning limit that `timeStepSize: "auto"` takes: a margin
/// below the limits above (the acoustic CFL number of an auto step is 0.8 * 0.4 = 0.32).
inline constexpr double kAutoTimeStepFraction = 0.8;

/// The time step `timeStepSize: "auto"` gives: kAutoTimeStepFraction times the smallest dt_warn
/// of time_step_limits(p) (p.time_step is not used); fixed for the run, so that runs stay
/// deterministic. SPH_CHECK: some limit applies (a positive stiffness always gives one).
template <int D>
double auto_time_step(const SimulationParams<D>& p);

/// Returns warning lines for limits exceeded; throws sph::Error naming the criterion, the
/// largest acceptable dt and the key to change when a hard limit is exceeded.
template <int D>
std::vector<std::string> check_time_step(const SimulationParams<D>& p);

}  // namespace sph
