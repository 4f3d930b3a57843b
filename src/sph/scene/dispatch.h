#pragma once
/// \file The one switch from a scene's runtime dimension and precision to the template
/// parameters of the code that runs it.

#include <utility>

#include <sph/core/error.h>
#include <sph/scene/scene_desc.h>

namespace sph {

/// Calls `f.template operator()<D, R>()` with D = `dimension` (2 or 3) and R = float or double as
/// `precision` says, and returns what it returns. For example
///
///   return dispatch(desc, [&]<int D, class R>() { return run_scene<D, R>(desc); });
///
/// Every variant is instantiated, so each must compile. SPH_CHECK: dimension is 2 or 3 (the scene
/// reader and the checkpoint reader refuse anything else).
template <class F>
decltype(auto) dispatch(int dimension, Precision precision, F&& f) {
  SPH_CHECK(dimension == 2 || dimension == 3, "dispatch: a dimension other than 2 or 3");
  const bool single = precision == Precision::Float;
  if (dimension == 2) {
    if (single) return std::forward<F>(f).template operator()<2, float>();
    return std::forward<F>(f).template operator()<2, double>();
  }
  if (single) return std::forward<F>(f).template operator()<3, float>();
  return std::forward<F>(f).template operator()<3, double>();
}

/// dispatch() on a scene's own dimension and precision.
template <class F>
decltype(auto) dispatch(const SceneDesc& desc, F&& f) {
  return dispatch(desc.dimension, desc.precision, std::forward<F>(f));
}

}  // namespace sph
