#pragma once
/// \file The neighbor modes: one descriptor table that names, describes and selects them.
/// Scenes, flags, `sph compare` and `sph bench` take their names and defaults from it.

#include <string>
#include <string_view>
#include <vector>

namespace sph {

/// Neighbor strategies (kNeighborModes describes each).
enum class NeighborMode { Standard, Adaptive, Verlet, Tracked, AdaptiveExact, VerletClusters, BruteForce };

/// One neighbor mode as users name and select it.
struct NeighborModeInfo {
  NeighborMode mode;
  std::string_view name;         ///< in scenes (Configuration.neighbors) and flags
  std::string_view description;  ///< one line: what the mode does
  /// Run by `sph compare` and `sph bench` by default, and accepted by them. The brute-force
  /// oracle of the tests (O(N^2)) is not: it is too slow to time.
  bool compared;
  /// Keeps tracked lists (TrackedNeighbors: h + Configuration.trackedSkin, rebuilt per particle).
  bool tracked = false;
  /// Keeps verlet lists (h + Configuration.verletSkin, all rebuilt once a particle moved half the skin).
  bool verlet = false;
};

/// Every mode, in the enum's order.
inline constexpr NeighborModeInfo kNeighborModes[] = {
    {NeighborMode::Standard, "standard", "rebuilds every list every step (paper Section 4)", true},
    {NeighborMode::Adaptive, "adaptive",
     "the paper's Algorithm 2: rebuilds the lists flagged by the Eq. 7 test, all of them every full-rebuild period",
     true},
    {NeighborMode::Verlet, "verlet", "exact lists of radius h + skin, all rebuilt once a particle moved half the skin",
     true, false, true},
    {NeighborMode::Tracked, "tracked",
     "exact per-particle lists of the pairs whose paths (positions and velocities at their builds) come within h + "
     "skin: a list is rebuilt once its particle is a third of the skin off its path or its path has run 0.1 h, and "
     "inserted into its new neighbors' lists (docs/neighbor-modes.md)",
     true, true},
    {NeighborMode::AdaptiveExact, "adaptive_exact",
     "the paper's Eq. 7 test on tracked lists (a pair predicted to leave the lists' reach flags both): Algorithm 2 "
     "without missed pairs",
     true, true},
    {NeighborMode::VerletClusters, "verlet_clusters",
     "verlet's exact lists (h + skin, all rebuilt once a particle moved half the skin) held as pairs of clusters of 4 "
     "particles, so that the density and force passes load a neighbor cluster instead of gathering each neighbor: "
     "exact as verlet, and slower than it on every scene measured (docs/neighbor-modes.md)",
     true, false, true},
    {NeighborMode::BruteForce, "brute_force", "compares every pair, O(N^2): the tests' oracle, for tiny scenes", false},
};

/// Which modes a list holds: all of them, or those with `compared` set.
enum class NeighborModeSet { All, Compared };

/// The table's entry of `mode`.
const NeighborModeInfo& neighbor_mode_info(NeighborMode mode);
/// The mode's name (the table's).
std::string_view to_string(NeighborMode mode);
/// Parses a mode name of `set`; throws sph::Error naming the accepted values otherwise (for a
/// mode outside `set`, why: the brute-force oracle is too slow to time).
NeighborMode parse_neighbor_mode(std::string_view name, const std::string& where = {},
                                 NeighborModeSet set = NeighborModeSet::All);

/// The names of the modes of `set`, in the table's order.
std::vector<std::string> neighbor_mode_names(NeighborModeSet set = NeighborModeSet::All);
/// The modes of `set`, in the table's order.
std::vector<NeighborMode> neighbor_modes(NeighborModeSet set);
/// The names of the modes of `set` joined for a message or a default value: `separator`
/// between them, `last_separator` before the last one ("standard, adaptive or verlet" with
/// ", " and " or ").
std::string join_neighbor_mode_names(NeighborModeSet set, std::string_view separator, std::string_view last_separator);

}  // namespace sph
