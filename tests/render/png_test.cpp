// PNG output read back with libpng: size, format and every pixel survive; failures name the path.

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <png.h>

#include <gtest/gtest.h>

#include <sph/core/error.h>
#include <sph/render/png.h>

#include "support/png_decode.h"

namespace sph {
namespace {

namespace fs = std::filesystem;

using Decoded = sph::test::DecodedPng;
Decoded decode(const std::string& bytes) { return sph::test::decode_png(bytes); }

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

class TempDir {
 public:
  TempDir() {
    std::string tmpl = (fs::temp_directory_path() / "sph_render_test_XXXXXX").string();
    if (!::mkdtemp(tmpl.data())) throw std::runtime_error("mkdtemp failed");
    path_ = tmpl;
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  fs::path operator/(const std::string& name) const { return path_ / name; }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

/// An image where every pixel differs from its neighbors in every channel.
Image pattern(int w, int h) {
  Image img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      img.set(x, y,
              Rgb{static_cast<std::uint8_t>(x * 7 + y), static_cast<std::uint8_t>(255 - x * 3 - y * 5),
                  static_cast<std::uint8_t>((x * y) % 256)});
  return img;
}

TEST(Png, RoundTripKeepsSizeAndEveryPixel) {
  const Image img = pattern(37, 21);  // odd sizes: no accidental row alignment
  const std::string bytes = encode_png(img);
  ASSERT_GE(bytes.size(), 8u);
  EXPECT_EQ(bytes.substr(1, 3), "PNG");
  const Decoded d = decode(bytes);
  EXPECT_EQ(d.width, 37);
  EXPECT_EQ(d.height, 21);
  EXPECT_TRUE(d.rgb8);
  ASSERT_EQ(d.rgb.size(), img.bytes().size());
  for (std::size_t i = 0; i < d.rgb.size(); ++i) ASSERT_EQ(d.rgb[i], img.bytes()[i]) << "byte " << i;
}

TEST(Png, SinglePixel) {
  Image img(1, 1, Rgb{10, 20, 30});
  const Decoded d = decode(encode_png(img));
  EXPECT_EQ(d.width, 1);
  EXPECT_EQ(d.height, 1);
  EXPECT_EQ(d.rgb, (std::vector<std::uint8_t>{10, 20, 30}));
}

TEST(Png, EmptyImageIsRefused) { EXPECT_THROW(encode_png(Image()), Error); }

TEST(Png, WritePngWritesTheEncodedFileAndNothingElse) {
  TempDir dir;
  const Image img = pattern(16, 9);
  write_png(dir / "out.png", img);
  EXPECT_EQ(slurp(dir / "out.png"), encode_png(img));
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir.path())) names.push_back(e.path().filename().string());
  EXPECT_EQ(names, std::vector<std::string>{"out.png"});
}

TEST(Png, WritePngToAMissingDirectoryThrowsNamingThePath) {
  TempDir dir;
  const fs::path target = dir / "no_such_dir" / "frame.png";
  try {
    write_png(target, pattern(4, 4));
    FAIL() << "expected sph::Error";
  } catch (const Error& e) {
    EXPECT_EQ(e.where(), target.string());
    EXPECT_NE(std::string(e.what()).find(target.string()), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(target));
}

TEST(Png, WritePngOverADirectoryThrowsNamingThePathAndLeavesNoTemporary) {
  TempDir dir;
  const fs::path target = dir / "taken";
  fs::create_directory(target);
  try {
    write_png(target, pattern(4, 4));
    FAIL() << "expected sph::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(target.string()), std::string::npos) << e.what();
  }
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir.path())) names.push_back(e.path().filename().string());
  EXPECT_EQ(names, std::vector<std::string>{"taken"});
}

}  // namespace
}  // namespace sph
