#pragma once
/// \file Growing buffers that are kept between steps: when one must grow, it takes a quarter more
/// than asked, so that sizes that creep up from build to build (clusters, columns, lists) do not
/// allocate at every build (the steady-state steps allocate nothing).

#include <cstddef>
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

}  // namespace sph
