#pragma once
// Pure colors for the drawing tests.

#include <sph/render/image.h>

namespace sph::test {

inline constexpr Rgb kWhite{255, 255, 255};
inline constexpr Rgb kRed{255, 0, 0};
inline constexpr Rgb kBlue{0, 0, 255};

}  // namespace sph::test
