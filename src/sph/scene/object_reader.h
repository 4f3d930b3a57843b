#pragma once
/// \file ObjectReader: reads the keys of one JSON object of a scene, each checked for its type
/// and range, with messages that name the key path and what is expected.

#include <cmath>
#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <sph/core/vec.h>
#include <sph/scene/json_source.h>
#include <sph/scene/overrides.h>

namespace sph::detail {

/// Where values come from: the file, or --set flags for overridden key paths.
struct ReadContext {
  std::string source;
  std::set<std::string> overridden;
  /// The scene file's own values at overridden paths (apply_overrides' `replaced`): each is
  /// checked as the reader checks the key, before the flag's value is read.
  std::map<std::string, nlohmann::json> replaced;
  /// Appended to every message (set for the check of a replaced value).
  std::string note;
  /// How the overrides are named in messages (--set KEY, or the Python module's overrides).
  OverrideNaming naming = OverrideNaming::Flag;

  /// Throws sph::Error(message) whose where() names the source, the --set flag that gave the
  /// value (if `path` is, or is within or around, an overridden path) and `path`.
  [[noreturn]] void fail(const std::string& path, const std::string& message) const;
};

/// Reads the keys of one JSON object, whose allowed keys are declared up front.
class ObjectReader {
 public:
  using json = nlohmann::json;

  /// `keys` are all the keys this object may have; any other key is reported at once, before
  /// a missing-key error that a misspelt key would otherwise cause.
  ObjectReader(const json& j, std::string path, const ReadContext& ctx, const std::vector<std::string>& keys);

  std::string child(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }
  const ReadContext& ctx() const { return ctx_; }

  /// The value at `key` or nullptr; SPH_CHECK: `key` was declared.
  const json* find(const std::string& key);
  const json& require(const std::string& key, const std::string& what);

  double number(const json& v, const std::string& key, const std::string& what) const;
  /// A number > 0 (or >= 0 if allow_zero).
  double positive(const std::string& key, const std::string& what, std::optional<double> def = {},
                  bool allow_zero = false);
  std::int64_t integer(const std::string& key, const std::string& what, std::int64_t min, std::int64_t max,
                       std::optional<std::int64_t> def = {});
  std::string string(const std::string& key, const std::string& what, std::optional<std::string> def = {});
  /// true or false.
  bool boolean(const std::string& key, const std::string& what, bool def);
  /// One of `choices` (strings).
  std::string choice(const std::string& key, const std::vector<std::string>& choices, const std::string& def);
  /// An optional array of distinct strings, each one of `choices`; nullopt if absent.
  std::optional<std::vector<std::string>> string_set(const std::string& key, const std::vector<std::string>& choices,
                                                     const std::string& what);

  template <int D>
  Vec<D, double> vec(const std::string& key, const std::string& what, std::optional<Vec<D, double>> def = {}) {
    check_file_value(key, [&](ObjectReader& r) { r.vec<D>(key, what, def); });
    const json* v = find(key);
    const std::string expect = fmt::format("{} as an array of {} numbers", what, D);
    if (!v) {
      if (def) return *def;
      ctx_.fail(child(key), "missing required key; expected " + expect);
    }
    if (!v->is_array() || v->size() != static_cast<std::size_t>(D))
      ctx_.fail(child(key), "expected " + expect + ", got " + describe(*v));
    Vec<D, double> out;
    for (int d = 0; d < D; ++d) {
      const json& e = (*v)[static_cast<std::size_t>(d)];
      if (!e.is_number() || !std::isfinite(e.get<double>()))
        ctx_.fail(child(key), fmt::format("expected {}, got {} in [{}]", expect, describe(e), d));
      out[d] = e.get<double>();
    }
    return out;
  }
  /// If a flag replaced the scene file's own value at `key` (ReadContext::replaced), reads that
  /// value with `read` (the same check as the flag's value gets): a bad value in the file is
  /// refused even when a flag overrides it, naming the file's value.
  template <class F>
  void check_file_value(const std::string& key, F&& read) const {
    const auto it = ctx_.replaced.find(child(key));
    if (it == ctx_.replaced.end()) return;
    ReadContext file;
    file.source = ctx_.source;
    file.naming = ctx_.naming;
    file.note = ctx_.naming == OverrideNaming::Flag
                    ? " (the value in the scene file, which a flag overrides; it must be valid too)"
                    : " (the value in the scene, which an override replaces; it must be valid too)";
    const json one = {{key, it->second}};
    ObjectReader r(one, path_, file, {key});
    read(r);
  }

  /// An optional array of objects; calls f(reader, index) for each.
  template <class F>
  void array_of_objects(const std::string& key, const std::vector<std::string>& keys, F&& f) {
    const json* v = find(key);
    if (!v) return;
    if (!v->is_array()) ctx_.fail(child(key), "expected an array of objects [ {...}, ... ], got " + describe(*v));
    for (std::size_t i = 0; i < v->size(); ++i) {
      ObjectReader r((*v)[i], fmt::format("{}[{}]", child(key), i), ctx_, keys);
      f(r, i);
    }
  }
  /// A sub-object; an absent one reads as empty (its required keys are then reported missing).
  template <class F>
  void object(const std::string& key, const std::vector<std::string>& keys, F&& f) {
    static const json empty = json::object();
    const json* v = find(key);
    ObjectReader r(v ? *v : empty, child(key), ctx_, keys);
    f(r);
  }

 private:
  const json& j_;
  std::string path_;
  const ReadContext& ctx_;
  std::set<std::string> allowed_;
};

}  // namespace sph::detail
