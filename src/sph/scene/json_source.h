#pragma once
/// \file JSON text as the scene reader takes it: parsed with line and column in syntax errors,
/// duplicate keys and deep nesting refused, UTF-8 checked, values described in messages.

#include <cstddef>
#include <string>

#include <nlohmann/json.hpp>

namespace sph::detail {

/// JSON nested deeper than this is refused: copying, comparing and writing a json value recurse
/// once per level, so a value nested some ten thousand levels deep overflows the stack (a --set
/// value of 20,000 levels did).
inline constexpr int kMaxJsonDepth = 64;

/// Parses a scene's JSON text. Throws sph::Error for text that is not UTF-8 (a UTF-16 or UTF-32
/// byte-order mark, NUL bytes, bytes of another encoding such as Latin-1, each named as such
/// with the advice to save the file as UTF-8), empty text, syntax errors (where:
/// "SOURCE:LINE:COLUMN"), duplicate keys in one object, nesting deeper than kMaxJsonDepth and
/// numbers out of a double's range.
nlohmann::json parse_json(const std::string& text, const std::string& source);

/// The offset of the opening quote of the first key repeated within one object of JSON text, or
/// npos if no key is (keys compared as written).
std::size_t repeated_key_at(const std::string& text);

/// The offset of the first byte of `s` that is not part of well-formed UTF-8 (no overlong
/// forms, no surrogates, nothing above U+10FFFF), or npos if all of `s` is well-formed.
std::size_t invalid_utf8_at(const std::string& s);

/// A short description of a value for messages ("number 3", "an array of 2 elements"): never
/// the whole of a container, at most 40 characters of a scalar.
std::string describe(const nlohmann::json& j);

}  // namespace sph::detail
