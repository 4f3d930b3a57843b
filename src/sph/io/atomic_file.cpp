#include <sph/io/atomic_file.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdio>
#include <system_error>
#include <vector>

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <fmt/format.h>
#include <sph/core/error.h>

namespace sph {

std::filesystem::path temporary_path(const std::filesystem::path& path) {
  static std::atomic<unsigned> counter{0};
  return path.parent_path() /
         ("." + path.filename().string() + ".tmp" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
}

AtomicFile::AtomicFile(std::filesystem::path path) : path_(std::move(path)), tmp_(temporary_path(path_)) {
  out_.open(tmp_, std::ios::binary | std::ios::trunc);
  if (!out_) {
    // (the cause a user can act on: a directory that is not there, or one that takes no files)
    const std::filesystem::path dir = tmp_.parent_path().empty() ? std::filesystem::path(".") : tmp_.parent_path();
    std::error_code ec;
    if (!std::filesystem::exists(dir, ec))
      throw Error("the directory does not exist; create it first, or write the file into an existing one",
                  dir.string());
    if (!std::filesystem::is_directory(dir, ec))
      throw Error("is not a directory; expected a directory to hold the file", dir.string());
    throw Error("cannot create a file in this directory (is it writable?)", dir.string());
  }
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
  if (ec) {
    // Name the part of the path that stops it: "Not a directory" alone does not say which.
    for (std::filesystem::path up = dir.parent_path(); !up.empty() && up != up.parent_path(); up = up.parent_path()) {
      std::error_code probe_ec;
      if (!std::filesystem::exists(up, probe_ec)) continue;
      if (!std::filesystem::is_directory(up, probe_ec))
        throw Error(fmt::format("cannot create the output directory: {} is a file, not a directory; expected a "
                                "directory path for {}",
                                up.string(), purpose),
                    dir.string());
      break;
    }
    throw Error(
        fmt::format("cannot create the output directory: {}; expected a writable place for {}", ec.message(), purpose),
        dir.string());
  }
  AtomicFile probe(dir / ".write-test");  // removed unless committed
}

namespace {
constexpr std::string_view kStagePrefix = ".sph-staging-";
}  // namespace

void remove_abandoned_stages(const std::filesystem::path& dir) {
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(kStagePrefix, 0) != 0 || !entry.is_directory(ec)) continue;
    const std::string digits = name.substr(kStagePrefix.size());
    if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos || digits.size() > 9) continue;
    const auto pid = static_cast<pid_t>(std::stol(digits));
    if (pid != ::getpid() && ::kill(pid, 0) != 0 && errno == ESRCH) std::filesystem::remove_all(entry.path(), ec);
  }
}

StagedFiles::StagedFiles(std::filesystem::path dir, std::function<bool(const std::string&)> is_member,
                         std::string_view purpose)
    : dir_(std::move(dir)), is_member_(std::move(is_member)) {
  std::error_code ec;
  created_ = !std::filesystem::exists(dir_, ec);
  make_writable_directory(dir_, purpose);
  remove_abandoned_stages(dir_);
  stage_ = dir_ / (std::string(kStagePrefix) + std::to_string(::getpid()));
  std::filesystem::remove_all(stage_, ec);
  std::filesystem::create_directory(stage_, ec);
  if (ec) throw Error("cannot create a directory in this directory: " + ec.message(), dir_.string());
}

StagedFiles::~StagedFiles() {
  std::error_code ec;
  std::filesystem::remove_all(stage_, ec);
  if (!committed_ && created_ && std::filesystem::is_empty(dir_, ec)) std::filesystem::remove(dir_, ec);
}

void StagedFiles::commit() {
  std::error_code ec;
  std::vector<std::filesystem::path> staged;
  for (const auto& entry : std::filesystem::directory_iterator(stage_, ec)) staged.push_back(entry.path());
  if (ec) throw Error("cannot list the finished files: " + ec.message(), stage_.string());
  std::sort(staged.begin(), staged.end());
  std::vector<std::string> names;
  for (const std::filesystem::path& p : staged) {
    std::filesystem::rename(p, dir_ / p.filename(), ec);
    if (ec) throw Error("cannot move the finished file into place: " + ec.message(), (dir_ / p.filename()).string());
    names.push_back(p.filename().string());
  }
  committed_ = true;
  std::sort(names.begin(), names.end());
  std::vector<std::filesystem::path> earlier;
  for (const auto& entry : std::filesystem::directory_iterator(dir_, ec)) {
    const std::string name = entry.path().filename().string();
    if (is_member_(name) && entry.is_regular_file(ec) && !std::binary_search(names.begin(), names.end(), name))
      earlier.push_back(entry.path());
  }
  for (const std::filesystem::path& p : earlier) std::filesystem::remove(p, ec);
  std::filesystem::remove(stage_, ec);
}

void write_file_atomic(const std::filesystem::path& path, std::string_view content) {
  AtomicFile f(path);
  f.write(content);
  f.commit();
}

}  // namespace sph
