#include <sph/render/video.h>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <fstream>
#include <iterator>
#include <vector>

#include <fcntl.h>
#include <pthread.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fmt/format.h>

#include <sph/core/error.h>
#include <sph/io/atomic_file.h>

extern char** environ;

namespace sph {

namespace fs = std::filesystem;

namespace {

/// Runs `args` (args[0] looked up on PATH) with stdin from `stdin_fd` (or /dev/null when -1),
/// stdout and stderr to `log` (or /dev/null when empty). Returns the pid, or -1 if
/// the program could not be started.
int spawn(const std::vector<std::string>& args, int stdin_fd, const fs::path& log) {
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  if (stdin_fd >= 0)
    posix_spawn_file_actions_adddup2(&fa, stdin_fd, STDIN_FILENO);
  else
    posix_spawn_file_actions_addopen(&fa, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  const std::string err = log.empty() ? std::string("/dev/null") : log.string();
  posix_spawn_file_actions_addopen(&fa, STDERR_FILENO, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&fa, STDERR_FILENO, STDOUT_FILENO);
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid = -1;
  const int rc = posix_spawnp(&pid, argv[0], &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  return rc == 0 ? pid : -1;
}

/// Waits for `pid`; its exit status, or -1 if it did not exit normally.
int wait_for(int pid) {
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/// The last non-empty line of a log file ("" if none).
std::string last_line(const fs::path& log) {
  std::ifstream in(log);
  std::string line, last;
  while (std::getline(in, line))
    if (line.find_first_not_of(" \t\r") != std::string::npos) last = line;
  return last;
}

}  // namespace

bool video_encoder_available() {
  // ffmpeg lists its encoders; Debian's ffmpeg has libx264, a custom build may not.
  const fs::path log = temporary_path(fs::temp_directory_path() / "sph-ffmpeg-probe.log");
  const int pid = spawn({"ffmpeg", "-hide_banner", "-loglevel", "error", "-h", "encoder=libx264"}, -1, log);
  bool ok = false;
  if (pid > 0 && wait_for(pid) == 0) {
    std::ifstream in(log);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    ok = text.find("libx264") != std::string::npos;
  }
  std::error_code ec;
  fs::remove(log, ec);
  return ok;
}

VideoWriter::VideoWriter(fs::path path, int width, int height, double fps)
    : path_(std::move(path)),
      tmp_(temporary_path(path_)),
      log_(temporary_path(path_.string() + ".log")),
      width_(width),
      height_(height),
      even_width_(width + width % 2),
      even_height_(height + height % 2) {
  if (width < 1 || height < 1) throw Error(fmt::format("video size {} x {} must be positive", width, height));
  if (!(fps > 0 && fps <= 1000)) throw Error(fmt::format("video frame rate {} is out of range (0, 1000]", fps));
  if (!video_encoder_available()) throw Error(kVideoEncoderMissing);
  {
    std::ofstream probe(log_);
    if (!probe) throw Error("cannot create a file in this directory (is it writable?)", log_.parent_path().string());
  }
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) throw Error(std::string("cannot create a pipe to ffmpeg: ") + std::strerror(errno));
  // The child gets the read end as stdin via dup2, which clears O_CLOEXEC on the copy.
  const std::vector<std::string> args = {"ffmpeg",
                                         "-hide_banner",
                                         "-loglevel",
                                         "error",
                                         "-y",
                                         "-f",
                                         "rawvideo",
                                         "-pix_fmt",
                                         "rgb24",
                                         "-s",
                                         fmt::format("{}x{}", even_width_, even_height_),
                                         "-framerate",
                                         fmt::format("{}", fps),
                                         "-i",
                                         "pipe:0",
                                         "-an",
                                         "-c:v",
                                         "libx264",
                                         "-preset",
                                         "superfast",
                                         "-crf",
                                         "20",
                                         "-pix_fmt",
                                         "yuv420p",
                                         "-movflags",
                                         "+faststart",
                                         "-f",
                                         "mp4",
                                         tmp_.string()};
  pid_ = spawn(args, fds[0], log_);
  ::close(fds[0]);
  if (pid_ < 0) {
    ::close(fds[1]);
    std::error_code ec;
    fs::remove(log_, ec);
    throw Error("cannot start ffmpeg");
  }
  pipe_ = fds[1];
}

VideoWriter::~VideoWriter() {
  if (!finished_) {
    stop_encoder();
    std::error_code ec;
    fs::remove(tmp_, ec);
    fs::remove(log_, ec);
  }
}

void VideoWriter::stop_encoder() {
  {
    std::lock_guard lock(mutex_);
    closing_ = true;
  }
  changed_.notify_all();
  if (feeder_.joinable()) feeder_.join();
  if (pipe_ >= 0) ::close(pipe_), pipe_ = -1;
  if (pid_ > 0) {
    const int pid = pid_;
    pid_ = -1;
    ffmpeg_status_ = wait_for(pid);
  }
}

void VideoWriter::feed() {
  // A dead ffmpeg must give an error, not kill this process with SIGPIPE. The signal a failed
  // write raises is directed at the writing thread; blocked here, it stays pending on this
  // thread (and is discarded when it ends) and write() returns EPIPE.
  sigset_t pipe_only;
  sigemptyset(&pipe_only);
  sigaddset(&pipe_only, SIGPIPE);
  pthread_sigmask(SIG_BLOCK, &pipe_only, nullptr);
  for (;;) {
    std::vector<std::uint8_t> frame;
    {
      std::unique_lock lock(mutex_);
      changed_.wait(lock, [&] { return !queue_.empty() || closing_; });
      if (queue_.empty()) return;  // closing, all written
      frame = std::move(queue_.front());
      queue_.pop_front();
    }
    changed_.notify_all();  // room in the queue
    std::size_t done = 0;
    while (done < frame.size()) {
      const ssize_t n = ::write(pipe_, frame.data() + done, frame.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        std::lock_guard lock(mutex_);
        broken_ = true;
        queue_.clear();
        changed_.notify_all();
        return;
      }
      done += static_cast<std::size_t>(n);
    }
  }
}

void VideoWriter::throw_if_failed() {
  bool broken;
  {
    std::lock_guard lock(mutex_);
    broken = broken_;
  }
  if (!broken) return;
  stop_encoder();
  const std::string why = last_line(log_);
  throw Error("ffmpeg stopped while encoding" + (why.empty() ? std::string() : ": " + why), path_.string());
}

void VideoWriter::add(const Image& image) {
  SPH_CHECK(image.width() == width_ && image.height() == height_, "every video frame must have the first one's size");
  SPH_CHECK(pipe_ >= 0 && !closing_, "add() after finish()");
  throw_if_failed();
  // Padded to even sizes by repeating the last column and row.
  std::vector<std::uint8_t> frame(3 * static_cast<std::size_t>(even_width_) * static_cast<std::size_t>(even_height_));
  std::uint8_t* out = frame.data();
  for (int y = 0; y < even_height_; ++y) {
    const auto src = image.row(std::min(y, height_ - 1));
    for (int x = 0; x < even_width_; ++x, out += 3) {
      const Rgb c = src[std::min(x, width_ - 1)];
      out[0] = c.r, out[1] = c.g, out[2] = c.b;
    }
  }
  {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return queue_.size() < 4 || broken_; });
    if (!broken_) queue_.push_back(std::move(frame));
  }
  changed_.notify_all();
  throw_if_failed();
  if (!feeder_.joinable()) feeder_ = std::thread([this] { feed(); });
  ++frames_;
}

void VideoWriter::finish() {
  SPH_CHECK(!finished_, "finish() twice");
  throw_if_failed();
  stop_encoder();  // writes what is queued, closes the pipe, waits for ffmpeg
  bool broken;
  {
    std::lock_guard lock(mutex_);
    broken = broken_;
  }
  finished_ = true;
  std::error_code ec;
  const int status = ffmpeg_status_;
  if (broken || status != 0) {
    const std::string why = last_line(log_);
    fs::remove(tmp_, ec);
    fs::remove(log_, ec);
    throw Error(fmt::format("ffmpeg failed (exit status {}){}", status, why.empty() ? "" : ": " + why), path_.string());
  }
  fs::remove(log_, ec);
  fs::rename(tmp_, path_, ec);
  if (ec) {
    fs::remove(tmp_, ec);
    throw Error("cannot move the movie into place: " + ec.message(), path_.string());
  }
}

}  // namespace sph
