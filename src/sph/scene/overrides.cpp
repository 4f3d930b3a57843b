#include <sph/scene/overrides.h>

#include <fmt/format.h>

#include <sph/core/error.h>
#include <sph/scene/json_source.h>

namespace sph::detail {

namespace {

using json = nlohmann::json;

/// The value of one override: JSON if it parses, else the text as a string (such as adaptive).
/// `name`: the override's, for messages (override_name).
json parse_value(const std::string& name, const std::string& value_text) {
  try {
    const json::parser_callback_t depth_limit = [&](int depth, json::parse_event_t, json&) {
      if (depth > kMaxJsonDepth)
        throw Error(fmt::format("the value is nested more than {} levels deep", kMaxJsonDepth), name);
      return true;
    };
    json value = json::parse(value_text, depth_limit);
    if (const std::size_t at = repeated_key_at(value_text); at != std::string::npos) {
      const std::size_t end = value_text.find(':', at);
      throw Error(fmt::format("key {} appears twice in the same object of the value; expected each key once",
                              value_text.substr(at, end == std::string::npos ? 40 : end - at)),
                  name);
    }
    return value;
  } catch (const json::parse_error&) {
    return value_text;
  } catch (const json::exception& e) {
    throw Error("the value \"" + value_text + "\" is not a usable number (out of range)", name);
  }
}

/// "a.b[2].c" as its object keys and "[index]" parts: {"a", "b", "[2]", "c"}.
std::vector<std::string> split_path(const std::string& key) {
  std::vector<std::string> parts;
  std::string cur;
  for (const char c : key) {
    if (c == '.' || c == '[') {
      if (!cur.empty()) parts.push_back(cur);
      cur.clear();
      if (c == '[') cur = "[";
    } else if (c == ']') {
      parts.push_back(cur + "]");
      cur.clear();
    } else {
      cur += c;
    }
  }
  if (!cur.empty()) parts.push_back(cur);
  return parts;
}

/// The node at `parts` in `doc`, creating missing objects on the way; `path` receives the
/// canonical path walked.
json& walk(json& doc, const std::vector<std::string>& parts, const std::string& name, std::string& path) {
  json* node = &doc;
  for (std::size_t k = 0; k < parts.size(); ++k) {
    const std::string& p = parts[k];
    if (p.front() == '[') {
      const std::string digits = p.substr(1, p.size() - 2);
      if (node->is_null()) throw Error("\"" + path + "\" is not in the scene, so it has no element " + p, name);
      if (!node->is_array()) throw Error("\"" + path + "\" is not an array, so it has no element " + p, name);
      if (digits.empty() || digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos)
        throw Error("bad array index " + p + "; expected [0], [1], ...", name);
      const std::size_t idx = std::stoul(digits);
      if (idx >= node->size())
        throw Error(fmt::format("\"{}\" has {} element{}; index {} does not exist", path, node->size(),
                                node->size() == 1 ? "" : "s", idx),
                    name);
      path += p;
      node = &(*node)[idx];
    } else {
      if (!node->is_object()) throw Error("\"" + path + "\" is not an object, so it has no key \"" + p + "\"", name);
      path += (path.empty() ? "" : ".") + p;
      if (k + 1 < parts.size() && !node->contains(p)) {
        if (parts[k + 1].front() == '[')
          throw Error("\"" + path + "\" is not in the scene, so it has no element " + parts[k + 1], name);
        (*node)[p] = json::object();
      }
      node = &(*node)[p];
    }
  }
  return *node;
}

}  // namespace

std::string override_name(OverrideNaming naming, const std::string& key) {
  if (naming == OverrideNaming::Python) return key.empty() ? "overrides" : "overrides[\"" + key + "\"]";
  return key.empty() ? "--set" : "--set " + key;
}

std::set<std::string> apply_overrides(json& doc, const std::vector<std::string>& overrides,
                                      std::map<std::string, json>* replaced, OverrideNaming naming) {
  std::set<std::string> overridden;
  for (const std::string& o : overrides) {
    // JSON text is UTF-8: a key or a plain-string value with other bytes could never be written
    // back out (scene.json, checkpoints), so it is refused here, without echoing the bytes.
    if (const std::size_t bad = invalid_utf8_at(o); bad != std::string::npos)
      throw Error(fmt::format("expected KEY=VALUE as UTF-8 text; byte {} (0x{:02X}) is not valid UTF-8", bad,
                              static_cast<unsigned char>(o[bad])),
                  override_name(naming));
    const auto eq = o.find('=');
    if (eq == std::string::npos || eq == 0)
      throw Error("expected KEY=VALUE with KEY a key path such as Fluid.stiffness, got \"" + o + "\"",
                  override_name(naming));
    const std::string key = o.substr(0, eq);
    json value = parse_value(override_name(naming, key), o.substr(eq + 1));
    const std::vector<std::string> parts = split_path(key);
    std::string path;
    json& node = walk(doc, parts, override_name(naming, key), path);
    if (parts.empty()) throw Error("empty key path", override_name(naming));
    if (replaced && !node.is_null() && !overridden.count(path)) replaced->emplace(path, node);
    node = std::move(value);
    overridden.insert(path);
  }
  return overridden;
}

}  // namespace sph::detail
