#pragma once
/// \file MP4 movies (H.264) from images, encoded by the ffmpeg program, which is optional: it is
/// looked up on PATH when a movie is asked for.

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <sph/render/image.h>

namespace sph {

/// True if an `ffmpeg` program that can encode H.264 (libx264) runs.
bool video_encoder_available();

/// The message for a missing encoder (VideoWriter throws it; `sph render --mp4` checks
/// video_encoder_available() before it writes any image).
inline constexpr const char* kVideoEncoderMissing =
    "making an MP4 needs ffmpeg with its H.264 encoder (libx264), which was not found on PATH; install it with "
    "`apt-get install ffmpeg` (bash scripts/setup.sh does), or leave out --mp4";

/// Writes images as the frames of an MP4 file, by piping raw RGB to ffmpeg from a thread of its
/// own, so that the caller renders the next frames while ffmpeg encodes. The movie appears
/// at `path` only when finish() succeeds (it is encoded under a temporary name and renamed);
/// destroying the writer without finish() removes the temporary file.
class VideoWriter {
 public:
  /// Starts ffmpeg for width x height frames (rounded up to even sizes, as H.264's 4:2:0 color
  /// needs; the extra column or row is the image's edge repeated) at `fps` frames per second.
  /// Throws sph::Error if ffmpeg is not installed (naming the package to install), the size is
  /// not positive, fps is not in (0, 1000], or the directory of `path` cannot be written.
  VideoWriter(std::filesystem::path path, int width, int height, double fps);
  ~VideoWriter();
  VideoWriter(const VideoWriter&) = delete;
  VideoWriter& operator=(const VideoWriter&) = delete;

  /// Queues a frame (waits while a few frames are already queued). Precondition: the image has
  /// the size given to the constructor. Throws sph::Error if ffmpeg stopped.
  void add(const Image& image);
  /// Closes the stream, waits for ffmpeg and moves the movie into place. Throws sph::Error with
  /// ffmpeg's last message if it failed.
  void finish();

  int frames() const { return frames_; }

 private:
  void stop_encoder();
  void feed();  ///< the thread that writes queued frames to ffmpeg
  void throw_if_failed();

  std::filesystem::path path_, tmp_, log_;
  int width_, height_, even_width_, even_height_;
  int pipe_ = -1;
  int pid_ = -1;
  int ffmpeg_status_ = -1;  ///< ffmpeg's exit status once it ended
  int frames_ = 0;
  bool finished_ = false;

  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<std::vector<std::uint8_t>> queue_;  ///< padded RGB frames not yet written
  bool closing_ = false;                         ///< no more frames will come
  bool broken_ = false;                          ///< a write to ffmpeg failed
  std::thread feeder_;
};

}  // namespace sph
