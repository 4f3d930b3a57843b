#pragma once
/// \file What one iterative solve of a step did: DFSPH's two pressure solves (dfsph.h) and the
/// implicit viscosity solve (viscosity.h).

namespace sph {

struct SolveStats {
  int iterations = 0;  ///< iterations (each one applies the solve's operator once)
  /// The error after them: the average compression, % (DFSPH's density solve), the average
  /// divergence, % per second (its divergence solve), or the residual as a % of the starting
  /// one (the viscosity solve).
  double error = 0;
  bool converged = true;  ///< the error reached the tolerance
};

}  // namespace sph
