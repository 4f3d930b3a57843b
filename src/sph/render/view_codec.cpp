#include <sph/render/view_codec.h>

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <sph/core/error.h>

namespace sph {

namespace {

constexpr char kBase64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

}  // namespace

namespace detail {

void append_base64(std::string& out, std::span<const std::uint8_t> bytes) {
  const std::size_t n = bytes.size();
  out.reserve(out.size() + base64_size(n));
  std::size_t i = 0;
  for (; i + 3 <= n; i += 3) {
    const std::uint32_t v = (bytes[i] << 16) | (bytes[i + 1] << 8) | bytes[i + 2];
    out += kBase64[v >> 18];
    out += kBase64[(v >> 12) & 63];
    out += kBase64[(v >> 6) & 63];
    out += kBase64[v & 63];
  }
  if (i < n) {
    const std::uint32_t v = (bytes[i] << 16) | (i + 1 < n ? bytes[i + 1] << 8 : 0);
    out += kBase64[v >> 18];
    out += kBase64[(v >> 12) & 63];
    out += i + 1 < n ? kBase64[(v >> 6) & 63] : '=';
    out += '=';
  }
}

std::vector<std::uint8_t> little_endian(const std::vector<std::uint16_t>& v) {
  std::vector<std::uint8_t> out(2 * v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    out[2 * i] = static_cast<std::uint8_t>(v[i] & 0xff);
    out[2 * i + 1] = static_cast<std::uint8_t>(v[i] >> 8);
  }
  return out;
}

std::string json_string(const std::string& s) {
  std::string out;
  for (char c : nlohmann::json(s).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace)) {
    if (c == '<')
      out += "\\u003c";
    else
      out += c;
  }
  return out;
}

std::string html_escape(std::string_view s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string json_number(double x) { return std::isfinite(x) ? fmt::format("{}", x) : "0"; }

}  // namespace detail

std::uint16_t quantize_position(double x, double lo, double hi) {
  if (std::isnan(x)) return 0;
  const double t = std::clamp((x - lo) / (hi - lo), 0.0, 1.0);
  return static_cast<std::uint16_t>(std::lround(t * 65535.0));
}

std::uint8_t quantize_scalar(double x, double lo, double hi) {
  if (std::isnan(x)) return 255;
  const double t = std::clamp((x - lo) / (hi - lo), 0.0, 1.0);
  return static_cast<std::uint8_t>(std::lround(t * 254.0));
}

std::string base64_encode(std::span<const std::uint8_t> bytes) {
  std::string out;
  detail::append_base64(out, bytes);
  return out;
}

std::vector<std::uint8_t> base64_decode(std::string_view text) {
  if (text.size() % 4 != 0) throw Error("base64 text of a length that is not a multiple of 4");
  std::vector<std::uint8_t> out;
  out.reserve(text.size() / 4 * 3);
  const auto value = [](char c) -> int {
    const char* p = std::find(std::begin(kBase64), std::end(kBase64) - 1, c);
    return p == std::end(kBase64) - 1 ? -1 : static_cast<int>(p - kBase64);
  };
  for (std::size_t i = 0; i < text.size(); i += 4) {
    int v[4];
    int pad = 0;
    for (int k = 0; k < 4; ++k) {
      const char c = text[i + k];
      if (c == '=' && i + 4 == text.size() && k >= 2) {
        v[k] = 0;
        ++pad;
        continue;
      }
      if (pad > 0 || (v[k] = value(c)) < 0) throw Error(fmt::format("bad base64 character at offset {}", i + k));
    }
    const std::uint32_t w = (v[0] << 18) | (v[1] << 12) | (v[2] << 6) | v[3];
    out.push_back(static_cast<std::uint8_t>(w >> 16));
    if (pad < 2) out.push_back(static_cast<std::uint8_t>((w >> 8) & 0xff));
    if (pad < 1) out.push_back(static_cast<std::uint8_t>(w & 0xff));
  }
  return out;
}

}  // namespace sph
