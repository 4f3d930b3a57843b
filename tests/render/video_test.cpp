// MP4 movies through ffmpeg: checked with ffprobe, Debian's reader (bash scripts/setup.sh
// installs both). Without ffmpeg these tests fail, naming the package.

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include <sph/core/error.h>
#include <sph/render/video.h>

#include "support/expect.h"
#include "support/temp_dir.h"

namespace {

namespace fs = std::filesystem;
using namespace sph;

std::string capture(const std::string& cmd) {
  std::string out;
  FILE* p = ::popen(cmd.c_str(), "r");
  if (!p) return out;
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  ::pclose(p);
  return out;
}

/// A frame with a white square at column `x`, on black.
Image frame(int w, int h, int x) {
  Image img(w, h, Rgb{0, 0, 0});
  img.fill_rect(x, h / 4, 8, 8, Rgb{255, 255, 255});
  return img;
}

class Video : public testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(video_encoder_available())
        << "ffmpeg with libx264 is not installed; bash scripts/setup.sh installs it (Debian package ffmpeg)";
  }
  sph::test::TempDir tmp_;
};

TEST_F(Video, FramesBecomeAnH264MovieOfEvenSize) {
  const fs::path movie = tmp_.path() / "movie.mp4";
  {
    VideoWriter v(movie, 63, 47, 25);  // odd sizes: padded to 64 x 48
    for (int k = 0; k < 12; ++k) v.add(frame(63, 47, 4 * k));
    EXPECT_FALSE(fs::exists(movie));  // only after finish()
    v.finish();
    EXPECT_EQ(v.frames(), 12);
  }
  ASSERT_TRUE(fs::is_regular_file(movie));
  const std::string probe = capture(
      "ffprobe -v error -count_frames -select_streams v:0 -show_entries "
      "stream=codec_name,width,height,nb_read_frames,r_frame_rate -of default=noprint_wrappers=1 '" +
      movie.string() + "'");
  EXPECT_CONTAINS(probe, "codec_name=h264");
  EXPECT_CONTAINS(probe, "width=64");
  EXPECT_CONTAINS(probe, "height=48");
  EXPECT_CONTAINS(probe, "nb_read_frames=12");
  EXPECT_CONTAINS(probe, "r_frame_rate=25/1");
  // Nothing else left in the directory (no temporary movie, no log).
  int files = 0;
  for (const auto& e : fs::directory_iterator(tmp_.path())) files += e.is_regular_file();
  EXPECT_EQ(files, 1);
}

TEST_F(Video, AnAbandonedMovieLeavesNothing) {
  {
    VideoWriter v(tmp_.path() / "movie.mp4", 32, 32, 30);
    v.add(frame(32, 32, 0));
  }
  EXPECT_TRUE(fs::is_empty(tmp_.path()));
}

TEST_F(Video, BadSizesAndRatesAreRefused) {
  EXPECT_THROW(VideoWriter(tmp_.path() / "a.mp4", 0, 10, 30), Error);
  EXPECT_THROW(VideoWriter(tmp_.path() / "a.mp4", 10, 10, 0), Error);
  EXPECT_THROW(VideoWriter(tmp_.path() / "no_such_dir" / "a.mp4", 10, 10, 30), Error);
  EXPECT_TRUE(fs::is_empty(tmp_.path()));
}

TEST(VideoWithFailingFfmpeg, TheErrorHasFfmpegsMessageAndNoMovieIsLeft) {
  // An ffmpeg that claims libx264 but fails at once, as one with a full disk would.
  sph::test::TempDir bin;
  sph::test::spit(bin.path() / "ffmpeg",
                  "#!/bin/sh\ncase \"$*\" in *encoder=libx264*) echo 'Encoder libx264'; exit 0;; esac\n"
                  "echo 'No space left on device' >&2\nexit 1\n");
  fs::permissions(bin.path() / "ffmpeg", fs::perms::owner_all);
  const char* old = std::getenv("PATH");
  const std::string saved = old ? old : "";
  ::setenv("PATH", (bin.path().string() + ":" + saved).c_str(), 1);
  sph::test::TempDir tmp;
  try {
    VideoWriter v(tmp.path() / "movie.mp4", 64, 64, 30);
    for (int k = 0; k < 50; ++k) v.add(frame(64, 64, k));
    v.finish();
    ADD_FAILURE() << "expected sph::Error from a failing ffmpeg";
  } catch (const Error& e) {
    EXPECT_CONTAINS(e.what(), "ffmpeg");
    EXPECT_CONTAINS(e.what(), "No space left on device");
    EXPECT_CONTAINS(e.what(), "movie.mp4");
  }
  ::setenv("PATH", saved.c_str(), 1);
  EXPECT_TRUE(fs::is_empty(tmp.path()));
}

TEST(VideoWithoutFfmpeg, TheErrorNamesThePackage) {
  const char* old = std::getenv("PATH");
  const std::string saved = old ? old : "";
  ::setenv("PATH", "/nonexistent", 1);
  try {
    sph::test::TempDir tmp;
    VideoWriter v(tmp.path() / "movie.mp4", 16, 16, 30);
    ADD_FAILURE() << "expected sph::Error without ffmpeg on PATH";
  } catch (const Error& e) {
    EXPECT_CONTAINS(e.what(), "ffmpeg");
    EXPECT_CONTAINS(e.what(), "apt-get install ffmpeg");
  }
  ::setenv("PATH", saved.c_str(), 1);
}

}  // namespace
