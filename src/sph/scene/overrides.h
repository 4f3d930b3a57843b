#pragma once
/// \file --set overrides: "KEY.PATH=VALUE" strings applied to a scene's JSON before it is read.

#include <map>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace sph {

/// How messages name an override: as the sph program's flag (--set Fluid.stiffness) or as the
/// Python module's argument (overrides["Fluid.stiffness"]).
enum class OverrideNaming { Flag, Python };

}  // namespace sph

namespace sph::detail {

/// The name of the override of `key` ("--set KEY", or overrides["KEY"]); of the overrides as a
/// whole for an empty key ("--set", or overrides).
std::string override_name(OverrideNaming naming, const std::string& key = {});

/// Applies "a.b[2].c=VALUE" overrides to `doc` in order; VALUE is JSON if it parses as JSON,
/// else a string. A missing object on the path is created; a missing array element is an error.
/// Returns the key paths set (as "a.b[2].c"); `replaced` (if given) receives, for each path
/// whose value the document had before its first override, that value (so that the reader can
/// check the file's own value too). Throws sph::Error (where: override_name(naming) or
/// override_name(naming, KEY))
/// for text that is not UTF-8, no "=", an empty or malformed path, a path through a value of
/// another type, an index out of range, a number out of range and nesting deeper than
/// kMaxJsonDepth.
std::set<std::string> apply_overrides(nlohmann::json& doc, const std::vector<std::string>& overrides,
                                      std::map<std::string, nlohmann::json>* replaced = nullptr,
                                      OverrideNaming naming = OverrideNaming::Flag);

}  // namespace sph::detail
