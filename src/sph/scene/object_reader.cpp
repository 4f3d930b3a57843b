#include <sph/scene/object_reader.h>

#include <algorithm>

#include <sph/core/error.h>
#include <sph/core/spelling.h>

namespace sph::detail {

void ReadContext::fail(const std::string& path, const std::string& message) const {
  std::string where = source;
  auto within = [](const std::string& a, const std::string& b) {  // a is b or inside b
    return a == b || a.rfind(b + ".", 0) == 0 || a.rfind(b + "[", 0) == 0;
  };
  for (const auto& o : overridden)
    if (within(path, o) || (!path.empty() && within(o, path))) {
      where = source + " (" + override_name(naming, o) + ")";
      break;
    }
  if (!path.empty()) where += ": " + path;
  throw Error(message + note, where);
}

ObjectReader::ObjectReader(const json& j, std::string path, const ReadContext& ctx,
                           const std::vector<std::string>& keys)
    : j_(j), path_(std::move(path)), ctx_(ctx) {
  if (!j_.is_object()) ctx_.fail(path_, "expected an object { ... }, got " + describe(j_));
  for (const auto& k : keys) allowed_.insert(k);
  for (auto it = j_.begin(); it != j_.end(); ++it) {
    if (allowed_.count(it.key())) continue;
    std::string list;
    for (const auto& k : allowed_) list += (list.empty() ? "" : ", ") + k;
    const std::vector<std::string> names(allowed_.begin(), allowed_.end());
    ctx_.fail(child(it.key()), "unknown key" + did_you_mean(it.key(), names) + "; expected one of: " + list);
  }
}

const ObjectReader::json* ObjectReader::find(const std::string& key) {
  SPH_CHECK(allowed_.count(key), "scene key \"" + key + "\" read but not declared for " + path_);
  auto it = j_.find(key);
  return it == j_.end() ? nullptr : &*it;
}

const ObjectReader::json& ObjectReader::require(const std::string& key, const std::string& what) {
  const json* v = find(key);
  if (!v) ctx_.fail(child(key), "missing required key; expected " + what);
  return *v;
}

double ObjectReader::number(const json& v, const std::string& key, const std::string& what) const {
  if (!v.is_number()) ctx_.fail(child(key), "expected " + what + ", got " + describe(v));
  const double x = v.get<double>();
  if (!std::isfinite(x)) ctx_.fail(child(key), "expected a finite number");
  return x;
}

double ObjectReader::positive(const std::string& key, const std::string& what, std::optional<double> def,
                              bool allow_zero) {
  check_file_value(key, [&](ObjectReader& r) { r.positive(key, what, def, allow_zero); });
  const json* v = find(key);
  if (!v) {
    if (def) return *def;
    ctx_.fail(child(key), "missing required key; expected " + what);
  }
  const double x = number(*v, key, what);
  if (allow_zero ? x < 0 : x <= 0) ctx_.fail(child(key), fmt::format("expected {}, got {}", what, x));
  return x;
}

bool ObjectReader::boolean(const std::string& key, const std::string& what, bool def) {
  check_file_value(key, [&](ObjectReader& r) { r.boolean(key, what, def); });
  const json* v = find(key);
  if (!v) return def;
  if (!v->is_boolean()) ctx_.fail(child(key), "expected " + what + " (true or false), got " + describe(*v));
  return v->get<bool>();
}

std::int64_t ObjectReader::integer(const std::string& key, const std::string& what, std::int64_t min, std::int64_t max,
                                   std::optional<std::int64_t> def) {
  check_file_value(key, [&](ObjectReader& r) { r.integer(key, what, min, max, def); });
  const json* v = find(key);
  if (!v) {
    if (def) return *def;
    ctx_.fail(child(key), "missing required key; expected " + what);
  }
  if (!v->is_number_integer()) ctx_.fail(child(key), "expected " + what + ", got " + describe(*v));
  if (v->is_number_unsigned() && v->get<std::uint64_t>() > static_cast<std::uint64_t>(max))
    ctx_.fail(child(key), fmt::format("expected {}, got {}", what, v->get<std::uint64_t>()));
  const auto x = v->get<std::int64_t>();
  if (x < min || x > max) ctx_.fail(child(key), fmt::format("expected {}, got {}", what, x));
  return x;
}

std::string ObjectReader::string(const std::string& key, const std::string& what, std::optional<std::string> def) {
  check_file_value(key, [&](ObjectReader& r) { r.string(key, what, def); });
  const json* v = find(key);
  if (!v) {
    if (def) return *def;
    ctx_.fail(child(key), "missing required key; expected " + what);
  }
  if (!v->is_string()) ctx_.fail(child(key), "expected " + what + ", got " + describe(*v));
  return v->get<std::string>();
}

namespace {
/// "\"a\", \"b\", \"c\"".
std::string quoted_list(const std::vector<std::string>& choices) {
  std::string list;
  for (const auto& c : choices) list += (list.empty() ? "\"" : ", \"") + c + "\"";
  return list;
}
}  // namespace

std::string ObjectReader::choice(const std::string& key, const std::vector<std::string>& choices,
                                 const std::string& def) {
  const std::string list = quoted_list(choices);
  check_file_value(key, [&](ObjectReader& r) { r.choice(key, choices, def); });
  const std::string s = string(key, "one of " + list, def);
  if (std::find(choices.begin(), choices.end(), s) == choices.end())
    ctx_.fail(child(key), "unknown value \"" + s + "\"; expected one of " + list);
  return s;
}

std::optional<std::vector<std::string>> ObjectReader::string_set(const std::string& key,
                                                                 const std::vector<std::string>& choices,
                                                                 const std::string& what) {
  check_file_value(key, [&](ObjectReader& r) { r.string_set(key, choices, what); });
  const json* v = find(key);
  if (!v) return std::nullopt;
  const std::string list = quoted_list(choices);
  if (!v->is_array()) ctx_.fail(child(key), "expected " + what + ": an array of " + list + ", got " + describe(*v));
  std::vector<std::string> out;
  for (std::size_t i = 0; i < v->size(); ++i) {
    const json& e = (*v)[i];
    const std::string at = fmt::format("{}[{}]", child(key), i);
    if (!e.is_string()) ctx_.fail(at, "expected one of " + list + ", got " + describe(e));
    const std::string name = e.get<std::string>();
    if (std::find(choices.begin(), choices.end(), name) == choices.end())
      ctx_.fail(at, "unknown value \"" + name + "\"; expected one of " + list);
    if (std::find(out.begin(), out.end(), name) != out.end())
      ctx_.fail(at, "\"" + name + "\" appears twice; expected each at most once");
    out.push_back(name);
  }
  return out;
}

}  // namespace sph::detail
