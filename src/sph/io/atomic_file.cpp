#include <sph/io/atomic_file.h>

#include <atomic>
#include <cstdio>
#include <system_error>

#include <fcntl.h>
#include <unistd.h>

#include <sph/core/error.h>

namespace sph {

std::filesystem::path temporary_path(const std::filesystem::path& path) {
  static std::atomic<unsigned> counter{0};
  return path.parent_path() /
         ("." + path.filename().string() + ".tmp" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
}

AtomicFile::AtomicFile(std::filesystem::path path) : path_(std::move(path)), tmp_(temporary_path(path_)) {
  out_.open(tmp_, std::ios::binary | std::ios::trunc);
  if (!out_) throw Error("cannot create a file in this directory (is it writable?)", tmp_.parent_path().string());
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    out_.close();
    std::error_code ec;
    std::filesystem::remove(tmp_, ec);
  }
}

namespace {
/// fsync of a file or directory by path; false if it failed.
bool sync_path(const std::filesystem::path& path, int flags) {
  const int fd = ::open(path.c_str(), flags | O_CLOEXEC);
  if (fd < 0) return false;
  const bool ok = ::fsync(fd) == 0;
  return ::close(fd) == 0 && ok;
}
}  // namespace

void AtomicFile::commit(bool sync) {
  out_.flush();
  const bool ok = static_cast<bool>(out_);
  out_.close();
  if (!ok || out_.fail()) throw Error("writing failed (disk full?)", path_.string());
  if (sync && !sync_path(tmp_, O_RDONLY)) throw Error("cannot flush the file to disk", path_.string());
  std::error_code ec;
  std::filesystem::rename(tmp_, path_, ec);
  if (ec) throw Error("cannot rename the finished file into place: " + ec.message(), path_.string());
  committed_ = true;
  const std::filesystem::path parent = path_.has_parent_path() ? path_.parent_path() : ".";
  if (sync && !sync_path(parent, O_RDONLY | O_DIRECTORY))
    throw Error("cannot flush the directory to disk", parent.string());
}

void require_directory(const std::filesystem::path& dir, std::string_view expected) {
  std::error_code ec;
  if (std::filesystem::is_directory(dir, ec)) return;
  throw Error(std::string(std::filesystem::exists(dir, ec) ? "is a file, not a directory" : "no such directory") +
                  "; expected " + std::string(expected),
              dir.string());
}

void make_writable_directory(const std::filesystem::path& dir, std::string_view purpose) {
  std::error_code ec;
  if (std::filesystem::exists(dir, ec) && !std::filesystem::is_directory(dir, ec))
    throw Error("exists and is not a directory; expected a directory for " + std::string(purpose), dir.string());
  std::filesystem::create_directories(dir, ec);
  if (ec) throw Error("cannot create the output directory: " + ec.message(), dir.string());
  AtomicFile probe(dir / ".write-test");  // removed unless committed
}

void write_file_atomic(const std::filesystem::path& path, std::string_view content) {
  AtomicFile f(path);
  f.write(content);
  f.commit();
}

}  // namespace sph
