#pragma once
/// \file Coloring particles by a quantity of a frame (speed, kinetic energy, density, pressure,
/// initial position), shared by `sph render` (PNG, MP4) and `sph view` (the browser page).

#include <array>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <sph/io/frames.h>
#include <sph/render/colormap.h>

namespace sph {

enum class ColorBy {
  Speed,            ///< |v|, m/s
  KineticEnergy,    ///< m |v|^2 / 2 per particle, J (J/m in 2D)
  Density,          ///< kg/m^3 (kg/m^2 in 2D)
  Pressure,         ///< Pa (N/m in 2D)
  InitialPosition,  ///< not a scalar: red, green, blue from the initial x, y, z in the container
  None,             ///< not a quantity: every particle in one color (frames that hold positions only)
};

/// Every quantity, in the order above (not None).
inline constexpr ColorBy kColorByAll[] = {ColorBy::Speed, ColorBy::KineticEnergy, ColorBy::Density, ColorBy::Pressure,
                                          ColorBy::InitialPosition};

/// The quantity's name on the command line: "speed", "kinetic_energy", "density", "pressure",
/// "initial_position".
std::string_view color_by_name(ColorBy by);
/// The quantity with this name ("none": ColorBy::None), or nullopt.
std::optional<ColorBy> color_by_from_name(std::string_view name);
/// "speed, kinetic_energy, density, pressure, initial_position" (for messages and --help; not
/// "none").
std::string color_by_names();
/// The same names one by one.
std::vector<std::string> color_by_list();
/// A legend label with the unit for this dimension, e.g. "speed (m/s)", "density (kg/m^2)".
std::string color_by_label(ColorBy by, int dimension);
/// The frame field the quantity is computed from ("velocity", "density", "pressure",
/// "initial_position").
std::string_view color_by_field(ColorBy by);
/// False for InitialPosition (colored by position) and None: no color map, no legend bar.
bool color_by_is_scalar(ColorBy by);
/// The color map that suits the quantity (Turbo for speed and energy, Viridis for density and
/// pressure).
Colormap default_colormap(ColorBy by);

/// The quantity for each particle of `frame` (for InitialPosition: the initial height, y).
/// Throws sph::Error naming the run directory if the frame lacks the field the quantity needs
/// (the run left it out with --fields).
std::vector<double> color_values(const FrameData& frame, ColorBy by, const RunDirectory& run);

/// A range for the color map that suits values over a whole run (every frame's values
/// together), so that a color means the same in every frame: from 0 (speed, energy, pressure)
/// or the 0.5th percentile (density) to the 99.5th percentile, which keeps a few fast spray
/// particles from washing out the rest. NaNs are ignored; no finite value gives [0, 1]; a
/// range of zero width is widened around its value.
std::pair<double, double> color_range(ColorBy by, std::span<const std::vector<double>> values_per_frame);

/// How particles are colored: the quantity, its map and range.
struct ColorSpec {
  ColorBy by = ColorBy::Speed;
  Colormap map = Colormap::Turbo;
  double lo = 0, hi = 1;
};

/// The color of a particle that started at `x0` in the container [lo, hi]: each channel grows
/// with one coordinate (x red, y green, z blue) from a dim 40 to 255, so no particle is black.
Rgb initial_position_color(const std::array<double, 3>& x0, const std::array<double, 3>& lo,
                           const std::array<double, 3>& hi);

/// The color of every particle with ColorBy::None: a water blue.
inline constexpr Rgb kOneColor{60, 125, 205};

/// One color per particle of `frame`: the map over [lo, hi] for scalars; for InitialPosition
/// each channel grows with the initial coordinate across the container (x red, y green, z blue);
/// for None, kOneColor.
/// Throws sph::Error as color_values does.
std::vector<Rgb> particle_colors(const FrameData& frame, const ColorSpec& spec, const RunDirectory& run);

}  // namespace sph
