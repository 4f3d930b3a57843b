#pragma once
/// \file Growing buffers that are kept between steps: when one must grow, it takes a quarter more
/// than asked, so that sizes that creep up from build to build (clusters, columns, lists) do not
/// allocate at every build (the steady-state steps allocate nothing).

#include <cstddef>
#include <memory>
#include <new>
#include <type_traits>
#include <vector>

namespace sph {

/// v.resize(n), reserving n + n / 4 + 64 first when its capacity is short.
template <class T>
void resize_with_room(std::vector<T>& v, std::size_t n) {
  if (v.capacity() < n) v.reserve(n + n / 4 + 64);
  v.resize(n);
}

/// v.assign(n, value), with the same room.
template <class T>
void assign_with_room(std::vector<T>& v, std::size_t n, const T& value) {
  if (v.capacity() < n) v.reserve(n + n / 4 + 64);
  v.assign(n, value);
}

/// Raw memory, 64-byte aligned, kept between steps, that holds arrays of trivial types one use
/// at a time: place<T>(offset, n) ends the lifetime of whatever those bytes held and begins that
/// of n T's there, with indeterminate values (written before they are read). One block serves
/// uses that never overlap in time (a grid's sorted coordinates, then a sort's keys), so they
/// share its bytes instead of each keeping its own.
class ScratchBuffer {
 public:
  static constexpr std::size_t kAlign = 64;

  /// Bytes held.
  std::size_t capacity() const { return bytes_; }
  /// Makes capacity() at least `bytes`, a sixteenth more when it must grow. What it held is
  /// lost when it grows.
  void reserve(std::size_t bytes) {
    if (bytes <= bytes_) return;
    const std::size_t want = round_up(bytes + bytes / 16);
    data_.reset(static_cast<std::byte*>(::operator new (want, std::align_val_t{kAlign})));
    bytes_ = want;
  }
  /// n T's at byte `offset` (a multiple of alignof(T)), within capacity().
  template <class T>
  T* place(std::size_t offset, std::size_t n) {
    static_assert(std::is_trivially_default_constructible_v<T> && std::is_trivially_destructible_v<T>);
    return n == 0 ? reinterpret_cast<T*>(data_.get() + offset) : ::new (data_.get() + offset) T[n];
  }
  /// The T's placed at `offset` last.
  template <class T>
  T* at(std::size_t offset) {
    return std::launder(reinterpret_cast<T*>(data_.get() + offset));
  }
  template <class T>
  const T* at(std::size_t offset) const {
    return std::launder(reinterpret_cast<const T*>(data_.get() + offset));
  }
  /// `bytes` rounded up to a multiple of kAlign (where the next array may start).
  static constexpr std::size_t round_up(std::size_t bytes) { return (bytes + kAlign - 1) / kAlign * kAlign; }

 private:
  struct Free {
    void operator()(std::byte* p) const { ::operator delete (p, std::align_val_t{kAlign}); }
  };
  std::unique_ptr<std::byte, Free> data_;
  std::size_t bytes_ = 0;
};

}  // namespace sph
