#include <sph/neighbors/neighbor_mode.h>

#include <sph/core/error.h>
#include <sph/core/spelling.h>

namespace sph {

namespace {

constexpr bool table_in_enum_order() {
  for (std::size_t k = 0; k < std::size(kNeighborModes); ++k)
    if (static_cast<std::size_t>(kNeighborModes[k].mode) != k) return false;
  return true;
}
static_assert(table_in_enum_order(), "kNeighborModes must list the modes in the enum's order");

bool in_set(const NeighborModeInfo& info, NeighborModeSet set) { return set == NeighborModeSet::All || info.compared; }

}  // namespace

const NeighborModeInfo& neighbor_mode_info(NeighborMode mode) {
  const auto k = static_cast<std::size_t>(mode);
  SPH_CHECK(k < std::size(kNeighborModes), "not a neighbor mode");
  return kNeighborModes[k];
}

std::string_view to_string(NeighborMode mode) { return neighbor_mode_info(mode).name; }

NeighborMode parse_neighbor_mode(std::string_view name, const std::string& where, NeighborModeSet set) {
  std::string expected;
  for (const NeighborModeInfo& info : kNeighborModes)
    if (in_set(info, set)) expected += (expected.empty() ? "\"" : ", \"") + std::string(info.name) + "\"";
  for (const NeighborModeInfo& info : kNeighborModes) {
    if (info.name != name) continue;
    if (in_set(info, set)) return info.mode;
    throw Error("\"" + std::string(name) + "\" is the tests' oracle (every pair, O(N^2)), too slow to time here; " +
                    "expected one of " + expected,
                where);
  }
  throw Error("unknown neighbor mode \"" + std::string(name) + "\"" + did_you_mean(name, neighbor_mode_names(set)) +
                  "; expected one of " + expected,
              where);
}

std::vector<std::string> neighbor_mode_names(NeighborModeSet set) {
  std::vector<std::string> names;
  for (const NeighborModeInfo& info : kNeighborModes)
    if (in_set(info, set)) names.emplace_back(info.name);
  return names;
}

std::vector<NeighborMode> neighbor_modes(NeighborModeSet set) {
  std::vector<NeighborMode> modes;
  for (const NeighborModeInfo& info : kNeighborModes)
    if (in_set(info, set)) modes.push_back(info.mode);
  return modes;
}

std::string join_neighbor_mode_names(NeighborModeSet set, std::string_view separator, std::string_view last_separator) {
  const std::vector<std::string> names = neighbor_mode_names(set);
  std::string out;
  for (std::size_t k = 0; k < names.size(); ++k) {
    if (k > 0) out += k + 1 == names.size() ? last_separator : separator;
    out += names[k];
  }
  return out;
}

}  // namespace sph
