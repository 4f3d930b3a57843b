#pragma once
/// \file Binary state streams for checkpoints: each component writes and reads its own state
/// (ParticleSet, NeighborLists, the neighbor strategies, Simulation, RunOutput) through
/// StateWriter and StateReader, which keep a running checksum of every byte.
///
/// Values are stored in the machine's byte order (the checkpoint header records it); vectors
/// as a 64-bit count followed by their elements. A reader never trusts a count: it refuses any
/// count larger than the bytes left in the stream, so a corrupt file cannot make it allocate
/// without bound.

#include <concepts>
#include <cstdint>
#include <cstring>
#include <istream>
#include <ostream>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

namespace sph {

/// A 64-bit checksum of a byte stream, the same however the stream is split into calls of
/// add(): bytes are taken eight at a time as little words, each mixed by a multiply and a
/// shift (a 64-bit FNV-style hash over words; it detects corruption, it is not cryptographic).
class Checksum {
 public:
  void add(const void* data, std::size_t size);
  /// The checksum of everything added so far (add() may continue afterwards).
  std::uint64_t value() const;

 private:
  void mix(std::uint64_t word) {
    h_ = (h_ ^ word) * 0x100000001B3ull;
    h_ ^= h_ >> 29;
  }
  std::uint64_t h_ = 0xCBF29CE484222325ull;
  std::uint64_t bytes_ = 0;
  unsigned char pending_[8] = {};
  std::size_t npending_ = 0;
};

/// Writes values to a stream and checksums them. Errors of the stream are the caller's to check.
class StateWriter {
 public:
  explicit StateWriter(std::ostream& out) : out_(out) {}

  void bytes(const void* data, std::size_t size) {
    out_.write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
    sum_.add(data, size);
    written_ += size;
  }
  template <class T>
  requires std::is_trivially_copyable_v<T>
  void put(const T& value) { bytes(&value, sizeof(T)); }
  template <class T>
  requires std::is_trivially_copyable_v<T>
  void put(std::span<const T> values) {
    put(static_cast<std::uint64_t>(values.size()));
    bytes(values.data(), values.size_bytes());
  }
  template <class T>
  void put(const std::vector<T>& values) {
    put(std::span<const T>(values));
  }
  void put(const std::string& s) { put(std::span<const char>(s.data(), s.size())); }

  const Checksum& checksum() const { return sum_; }
  std::uint64_t written() const { return written_; }

 private:
  std::ostream& out_;
  Checksum sum_;
  std::uint64_t written_ = 0;
};

/// Reads what a StateWriter wrote. Every failure (end of data, a count that cannot fit,
/// a value out of range) throws sph::Error naming `source` and saying the file is corrupt.
class StateReader {
 public:
  /// Reads at most `limit` bytes from `in`.
  StateReader(std::istream& in, std::uint64_t limit, std::string source)
      : in_(in), left_(limit), source_(std::move(source)) {}

  void bytes(void* data, std::size_t size);
  template <class T>
  requires std::is_trivially_copyable_v<T> T get() {
    T value;
    bytes(&value, sizeof(T));
    return value;
  }
  template <class T>
  requires std::is_trivially_copyable_v<T>
  void get(T& value) { bytes(&value, sizeof(T)); }
  template <class T>
  requires std::is_trivially_copyable_v<T>
  void get(std::vector<T>& values) {
    values.resize(count(sizeof(T)));
    bytes(values.data(), values.size() * sizeof(T));
  }
  void get(std::string& s) {
    s.resize(count(1));
    bytes(s.data(), s.size());
  }
  /// Reads a vector count and checks that `element_size` bytes each can still be in the data.
  std::size_t count(std::size_t element_size);
  /// Throws the corrupt-file error with `what` unless `ok`.
  void expect(bool ok, const std::string& what) const {
    if (!ok) fail(what);
  }
  [[noreturn]] void fail(const std::string& what) const;

  const Checksum& checksum() const { return sum_; }
  std::uint64_t left() const { return left_; }

 private:
  std::istream& in_;
  std::uint64_t left_;
  std::string source_;
  Checksum sum_;
};

}  // namespace sph
