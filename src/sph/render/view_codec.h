#pragma once
/// \file The encodings of the `sph view` page: positions and scalars quantized to integers,
/// bytes as base64, and text escaped for the page's JSON data block and its HTML.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace sph {

/// A coordinate as 0..65535 over [lo, hi] (clamped; NaN gives 0). Precondition: lo < hi.
std::uint16_t quantize_position(double x, double lo, double hi);
/// A scalar as 0..254 over [lo, hi] (clamped); NaN gives 255 ("no value"). Precondition: lo < hi.
std::uint8_t quantize_scalar(double x, double lo, double hi);

/// Standard base64 (RFC 4648, with padding).
std::string base64_encode(std::span<const std::uint8_t> bytes);
/// The bytes of standard base64 text; throws sph::Error on a character outside the alphabet or
/// a length that is not a multiple of 4.
std::vector<std::uint8_t> base64_decode(std::string_view text);

namespace detail {

/// Base64 length of n bytes.
constexpr std::size_t base64_size(std::size_t n) { return 4 * ((n + 2) / 3); }
/// Appends the base64 text of `bytes` (as base64_encode writes it) to `out`.
void append_base64(std::string& out, std::span<const std::uint8_t> bytes);
/// The uint16 values as little-endian bytes (what the page reads whatever this machine is).
std::vector<std::uint8_t> little_endian(const std::vector<std::uint16_t>& v);
/// JSON text of a string, safe inside a <script> element: "</" would end the element, so '<' is
/// written as its escape.
std::string json_string(const std::string& s);
/// Text for HTML (element content or a quoted attribute).
std::string html_escape(std::string_view s);
/// The number as JSON (finite values only; JSON has no NaN: others give 0).
std::string json_number(double x);

}  // namespace detail

}  // namespace sph
