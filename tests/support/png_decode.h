#pragma once
// Reading PNG files back in tests, with libpng's simplified API (independent of our encoder).

#include <png.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace sph::test {

struct DecodedPng {
  int width = 0, height = 0;
  bool rgb8 = false;              ///< the file itself is 8-bit RGB without alpha
  std::vector<std::uint8_t> rgb;  ///< 3 bytes per pixel, rows top to bottom
};

/// Decodes a PNG file's bytes to 8-bit RGB; throws std::runtime_error if libpng refuses them.
inline DecodedPng decode_png(const std::string& bytes) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_memory(&image, bytes.data(), bytes.size()))
    throw std::runtime_error(std::string("libpng: ") + image.message);
  DecodedPng d;
  d.width = static_cast<int>(image.width);
  d.height = static_cast<int>(image.height);
  d.rgb8 = image.format == PNG_FORMAT_RGB;
  image.format = PNG_FORMAT_RGB;
  d.rgb.resize(PNG_IMAGE_SIZE(image));
  if (!png_image_finish_read(&image, nullptr, d.rgb.data(), 0, nullptr))
    throw std::runtime_error(std::string("libpng: ") + image.message);
  return d;
}

}  // namespace sph::test
