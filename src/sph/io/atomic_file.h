#pragma once
/// \file Files that appear whole or not at all: written under a temporary name in the same
/// directory, flushed, then renamed over the final name.

#include <filesystem>
#include <fstream>
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
