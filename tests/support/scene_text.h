#pragma once
// Reading a scene given as JSON in a test, as sph run reads a file named test.json: the scene,
// or the message that refuses it.

#include <exception>
#include <string>
#include <typeinfo>
#include <vector>

#include <gtest/gtest.h>
#include <sph/core/error.h>
#include <sph/scene/scene_reader.h>
#include <nlohmann/json.hpp>

namespace sph::test {

/// The scene `j` describes, with the `--set` overrides.
inline SceneDesc parse(const nlohmann::json& j, const std::vector<std::string>& overrides = {}) {
  return parse_scene(j.dump(2), "test.json", overrides);
}

/// The what() of the sph::Error that reading `text` throws; a test failure if it throws
/// nothing or another exception type.
inline std::string error_of(const std::string& text, const std::vector<std::string>& overrides = {}) {
  try {
    parse_scene(text, "test.json", overrides);
  } catch (const Error& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "threw a " << typeid(e).name() << " instead of sph::Error: " << e.what();
    return {};
  }
  ADD_FAILURE() << "no error for scene:\n" << text;
  return {};
}
inline std::string error_of(const nlohmann::json& j, const std::vector<std::string>& overrides = {}) {
  return error_of(j.dump(2), overrides);
}

}  // namespace sph::test
