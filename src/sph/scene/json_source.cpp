#include <sph/scene/json_source.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <set>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include <sph/core/error.h>

namespace sph::detail {

using json = nlohmann::json;

std::string describe(const json& j) {
  // Never dump containers whole: a deeply nested value would recurse without bound.
  if (j.is_array()) return fmt::format("an array of {} element{}", j.size(), j.size() == 1 ? "" : "s");
  if (j.is_object()) return fmt::format("an object with {} key{}", j.size(), j.size() == 1 ? "" : "s");
  if (j.is_null()) return "null";
  std::string text = j.dump();
  if (text.size() > 40) text = text.substr(0, 37) + "...";
  return std::string(j.type_name()) + " " + text;
}

namespace {

/// "LINE:COLUMN" (1-based) of byte `at` of `text`.
std::string line_column(const std::string& text, std::size_t at) {
  std::size_t line = 1, col = 1;
  for (std::size_t k = 0; k < at && k < text.size(); ++k) {
    if (text[k] == '\n')
      ++line, col = 1;
    else
      ++col;
  }
  return fmt::format("{}:{}", line, col);
}

/// Refuses text that is not UTF-8, naming the encoding it looks like.
void check_utf8(const std::string& text, const std::string& source) {
  const auto byte = [&](std::size_t k) { return k < text.size() ? static_cast<unsigned char>(text[k]) : 0x100u; };
  if ((byte(0) == 0xFF && byte(1) == 0xFE) || (byte(0) == 0xFE && byte(1) == 0xFF))
    throw Error("the scene file is UTF-16 (it starts with a UTF-16 byte-order mark); save it as UTF-8", source);
  if (byte(0) == 0 && byte(1) == 0 && byte(2) == 0xFE && byte(3) == 0xFF)
    throw Error("the scene file is UTF-32 (it starts with a UTF-32 byte-order mark); save it as UTF-8", source);
  if (const std::size_t nul = text.find('\0'); nul != std::string::npos)
    throw Error(fmt::format("the scene file holds NUL bytes (the first at line {}), as UTF-16 text does; save it as "
                            "UTF-8",
                            line_column(text, nul)),
                source);
  if (const std::size_t bad = invalid_utf8_at(text); bad != std::string::npos)
    throw Error(fmt::format("the scene file is not UTF-8 text: byte 0x{:02X} at line {} is not valid UTF-8 (is it "
                            "Latin-1 or Windows-1252?); save it as UTF-8",
                            static_cast<unsigned char>(text[bad]), line_column(text, bad)),
                source);
}

/// Where in JSON text the parser's position-less refusals are: the first key repeated within one
/// object, and the first number beyond a double's range (strtod gives an infinity, as the parser
/// finds "number overflow"). npos where there is none. One walk over the tokens that matter
/// (strings, numbers, brackets, commas), run only after the parser refused the text.
struct JsonSpots {
  std::size_t repeated_key = std::string::npos;
  std::size_t overflow = std::string::npos, overflow_end = std::string::npos;  // [overflow, overflow_end)
};

JsonSpots find_spots(const std::string& text) {
  JsonSpots spots;
  struct Level {
    bool object;
    std::set<std::string> keys;  // as written, quotes and escapes included
  };
  std::vector<Level> levels;
  bool key_next = false;  // the next string is a key: after '{' or a comma in an object
  const std::size_t n = text.size();
  for (std::size_t k = 0; k < n;) {
    const char c = text[k];
    if (c == '"') {
      const std::size_t begin = k++;
      while (k < n && text[k] != '"') k += text[k] == '\\' ? 2 : 1;
      k = std::min(k + 1, n);
      if (key_next && !levels.empty() && !levels.back().keys.insert(text.substr(begin, k - begin)).second &&
          spots.repeated_key == std::string::npos)
        spots.repeated_key = begin;
      key_next = false;
      continue;
    }
    if (c == '-' || (c >= '0' && c <= '9')) {
      const std::size_t begin = k;
      while (k < n && std::string_view("+-.eE0123456789").find(text[k]) != std::string_view::npos) ++k;
      if (!std::isfinite(std::strtod(text.substr(begin, k - begin).c_str(), nullptr)) &&
          spots.overflow == std::string::npos)
        spots.overflow = begin, spots.overflow_end = k;
      continue;
    }
    if (c == '{' || c == '[')
      levels.push_back({c == '{', {}}), key_next = c == '{';
    else if (c == '}' || c == ']') {
      if (!levels.empty()) levels.pop_back();
      key_next = false;
    } else if (c == ',')
      key_next = !levels.empty() && levels.back().object;
    ++k;
  }
  return spots;
}

}  // namespace

std::size_t repeated_key_at(const std::string& text) { return find_spots(text).repeated_key; }

namespace {

/// "SOURCE:LINE:COLUMN" of byte `at` of `text`, or `source` alone when `at` is npos.
std::string where(const std::string& text, const std::string& source, std::size_t at) {
  return at == std::string::npos ? source : source + ":" + line_column(text, at);
}

}  // namespace

json parse_json(const std::string& text, const std::string& source) {
  check_utf8(text, source);
  if (text.find_first_not_of(" \t\r\n") == std::string::npos)
    throw Error("the scene file is empty; expected a JSON object (see docs/scene-format.md)", source);
  // Duplicate keys would silently keep the last value: refuse them.
  std::vector<std::set<std::string>> keys;
  std::string duplicate;
  json::parser_callback_t cb = [&](int depth, json::parse_event_t event, json& parsed) {
    if (depth > kMaxJsonDepth)
      throw Error(fmt::format("the JSON is nested more than {} levels deep", kMaxJsonDepth), source);
    if (event == json::parse_event_t::object_start)
      keys.emplace_back();
    else if (event == json::parse_event_t::object_end)
      keys.pop_back();
    else if (event == json::parse_event_t::key && !keys.empty() && duplicate.empty()) {
      const auto k = parsed.get<std::string>();
      if (!keys.back().insert(k).second) duplicate = k;
    }
    return true;
  };
  try {
    json j = json::parse(text, cb, /*allow_exceptions=*/true, /*ignore_comments=*/false);
    if (!duplicate.empty())
      throw Error("key \"" + duplicate + "\" appears twice in the same object; expected each key once",
                  where(text, source, find_spots(text).repeated_key));
    return j;
  } catch (const json::parse_error& e) {
    // e.byte is the 1-based offset of the offending character.
    std::size_t line = 1, col = 1;
    const std::size_t end = std::min<std::size_t>(e.byte > 0 ? e.byte - 1 : 0, text.size());
    for (std::size_t k = 0; k < end; ++k) {
      if (text[k] == '\n')
        ++line, col = 1;
      else
        ++col;
    }
    std::string what = e.what();
    const auto pos = what.find("syntax error");
    if (pos != std::string::npos) what = what.substr(pos);
    // A comment (// or /*) where the error is: JSON has none, and the parser's words do not say so.
    const std::size_t near = end >= 2 ? end - 2 : 0;
    const std::string around = text.substr(near, end + 2 - near);
    if (around.find("//") != std::string::npos || around.find("/*") != std::string::npos)
      what += " (JSON has no comments: remove the // or /* */ text, or put a note in the scene's \"description\")";
    throw Error("JSON syntax error: " + what, fmt::format("{}:{}:{}", source, line, col));
  } catch (const json::exception& e) {
    // For example a number too large for a double (1e999).
    std::string what = e.what();
    const auto pos = what.find("] ");
    const JsonSpots spots = find_spots(text);
    if (what.find("number overflow") != std::string::npos && spots.overflow != std::string::npos)
      throw Error(
          fmt::format("the number {} is beyond a double's range; expected a magnitude below 1.8e308",
                      text.substr(spots.overflow, std::min<std::size_t>(spots.overflow_end - spots.overflow, 40))),
          where(text, source, spots.overflow));
    throw Error("invalid JSON: " + (pos == std::string::npos ? what : what.substr(pos + 2)), source);
  }
}

std::size_t invalid_utf8_at(const std::string& s) {
  std::size_t i = 0;
  while (i < s.size()) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c < 0x80) {
      ++i;
      continue;
    }
    // The length of the sequence a lead byte starts, and the range its second byte must be in
    // (narrower after E0, ED, F0 and F4: no overlong forms, surrogates or code points > 10FFFF).
    std::size_t len = 0;
    unsigned char lo = 0x80, hi = 0xBF;
    if (c >= 0xC2 && c <= 0xDF) {
      len = 2;
    } else if (c >= 0xE0 && c <= 0xEF) {
      len = 3;
      if (c == 0xE0) lo = 0xA0;
      if (c == 0xED) hi = 0x9F;
    } else if (c >= 0xF0 && c <= 0xF4) {
      len = 4;
      if (c == 0xF0) lo = 0x90;
      if (c == 0xF4) hi = 0x8F;
    } else {
      return i;
    }
    if (len > s.size() - i) return i;
    for (std::size_t k = 1; k < len; ++k) {
      const auto b = static_cast<unsigned char>(s[i + k]);
      if (b < (k == 1 ? lo : 0x80) || b > (k == 1 ? hi : 0xBF)) return i;
    }
    i += len;
  }
  return std::string::npos;
}

}  // namespace sph::detail
