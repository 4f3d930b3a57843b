#pragma once
/// \file Files that appear whole or not at all: written under a temporary name in the same
/// directory, flushed, then renamed over the final name.

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <string_view>

namespace sph {

class AtomicFile {
 public:
  /// Opens a temporary file next to `path`; throws sph::Error if it cannot be created.
  explicit AtomicFile(std::filesystem::path path);
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  /// Removes the temporary file unless commit() succeeded.
  ~AtomicFile();

  std::ofstream& stream() { return out_; }
  void write(std::string_view bytes) { out_.write(bytes.data(), static_cast<std::streamsize>(bytes.size())); }
  /// Flushes, closes and renames the temporary file to the final path; throws sph::Error on failure.
  /// With `sync`, the data reaches the disk (fsync) before the rename, and the rename before
  /// commit() returns (fsync of the directory): the file survives a power cut whole (checkpoints).
  void commit(bool sync = false);

 private:
  std::filesystem::path path_, tmp_;
  std::ofstream out_;
  bool committed_ = false;
};

/// A set of files that replaces an earlier set in a directory together, or not at all (sph
/// render's images and movie, sph surface's meshes). The new files are written into a hidden
/// directory inside `dir` (path()); commit() moves each of them into `dir`, over its earlier
/// namesake, then removes the earlier set's other files (the regular files whose names
/// `is_member` accepts). Until commit() the earlier files stay as they were: a command that fails
/// half-way leaves them, and the hidden directory is removed with what it held (one left by a
/// killed process is removed by the next StagedFiles in `dir`), as is `dir` if it was made for
/// them. A user's other files are kept.
class StagedFiles {
 public:
  /// Creates `dir` if needed (make_writable_directory, for `purpose`) and the hidden directory.
  StagedFiles(std::filesystem::path dir, std::function<bool(const std::string&)> is_member, std::string_view purpose);
  StagedFiles(const StagedFiles&) = delete;
  StagedFiles& operator=(const StagedFiles&) = delete;
  /// Removes the hidden directory and what is left in it (everything, unless commit() ran), and
  /// `dir` too if this created it and nothing was committed.
  ~StagedFiles();

  /// Where the new files are written.
  const std::filesystem::path& path() const { return stage_; }
  /// Moves the new files into place and removes the earlier set's others; throws sph::Error if
  /// a file cannot be moved.
  void commit();

 private:
  std::filesystem::path dir_, stage_;
  std::function<bool(const std::string&)> is_member_;
  bool created_ = false;  ///< `dir` did not exist: removed again if nothing was committed
  bool committed_ = false;
};

/// Removes the hidden directories of StagedFiles in `dir` whose process no longer runs (a
/// render or surface killed before it finished); nothing else.
void remove_abandoned_stages(const std::filesystem::path& dir);

/// A fresh temporary name next to `path` (".NAME.tmpPID-N"), for files another program writes
/// before they are renamed into place; prepare_output_directory removes such names left behind.
std::filesystem::path temporary_path(const std::filesystem::path& path);

/// Checks that `dir` is an existing directory; throws sph::Error naming it, "no such directory"
/// or "is a file, not a directory" (whichever it is), then "; expected " and `expected`.
void require_directory(const std::filesystem::path& dir, std::string_view expected);

/// Creates `dir` (and its parents) if needed and checks that files can be created in it (a
/// temporary file is made and removed). Throws sph::Error naming `dir` if it exists and is not
/// a directory ("expected a directory for `purpose`") or cannot be created or written.
void make_writable_directory(const std::filesystem::path& dir, std::string_view purpose);

/// Writes `content` to `path` atomically.
void write_file_atomic(const std::filesystem::path& path, std::string_view content);

}  // namespace sph
