#pragma once
/// \file PNG output (libpng): 8-bit RGB, no interlacing, encoded in memory and written atomically.

#include <filesystem>
#include <string>

#include <sph/render/image.h>

namespace sph {

/// The image encoded as a complete PNG file (8-bit RGB). Throws sph::Error for an empty image.
std::string encode_png(const Image& image);

/// Writes the image as a PNG file at `path`, atomically (the file appears whole or not at all).
/// Throws sph::Error naming `path` if it cannot be written.
void write_png(const std::filesystem::path& path, const Image& image);

}  // namespace sph
