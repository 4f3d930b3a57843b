#pragma once
/// \file Fixed-size vector Vec<D,R> used for positions, velocities and accelerations.

#include <array>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <limits>
#include <span>
#include <vector>

namespace sph {

/// A quiet NaN: what the analyses report for a quantity that was not measured.
inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// A D-dimensional vector of floating-point type R. Plain value type (trivially copyable).
template <int D, std::floating_point R>
struct Vec {
  static_assert(D == 2 || D == 3, "only 2D and 3D are supported");
  std::array<R, D> c{};

  constexpr R& operator[](int i) { return c[static_cast<std::size_t>(i)]; }
  constexpr const R& operator[](int i) const { return c[static_cast<std::size_t>(i)]; }

  static constexpr Vec zero() { return Vec{}; }
  static constexpr Vec filled(R v) {
    Vec r;
    for (int i = 0; i < D; ++i) r[i] = v;
    return r;
  }

  constexpr Vec& operator+=(const Vec& o) {
    for (int i = 0; i < D; ++i) c[i] += o.c[i];
    return *this;
  }
  constexpr Vec& operator-=(const Vec& o) {
    for (int i = 0; i < D; ++i) c[i] -= o.c[i];
    return *this;
  }
  constexpr Vec& operator*=(R s) {
    for (int i = 0; i < D; ++i) c[i] *= s;
    return *this;
  }
  friend constexpr Vec operator+(Vec a, const Vec& b) { return a += b; }
  friend constexpr Vec operator-(Vec a, const Vec& b) { return a -= b; }
  friend constexpr Vec operator*(Vec a, R s) { return a *= s; }
  friend constexpr Vec operator*(R s, Vec a) { return a *= s; }
  friend constexpr Vec operator-(Vec a) {
    for (int i = 0; i < D; ++i) a.c[i] = -a.c[i];
    return a;
  }
  friend constexpr bool operator==(const Vec&, const Vec&) = default;
};

template <int D, std::floating_point R>
constexpr R dot(const Vec<D, R>& a, const Vec<D, R>& b) {
  R s = 0;
  for (int i = 0; i < D; ++i) s += a[i] * b[i];
  return s;
}

template <int D, std::floating_point R>
constexpr R norm2(const Vec<D, R>& a) {
  return dot(a, a);
}

/// The cross product a x b of two 3D vectors.
template <std::floating_point R>
constexpr Vec<3, R> cross(const Vec<3, R>& a, const Vec<3, R>& b) {
  return {{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]}};
}

template <int D, std::floating_point R>
R norm(const Vec<D, R>& a) {
  return std::sqrt(norm2(a));
}

template <int D, std::floating_point R>
bool all_finite(const Vec<D, R>& a) {
  for (int i = 0; i < D; ++i)
    if (!std::isfinite(a[i])) return false;
  return true;
}

/// The scalars of a vector field, x0 y0 z0 x1 y1 z1 ... (D times as many), so that pair loops
/// load or gather lanes of them (simd::gather_vectors).
template <int D, std::floating_point R>
std::span<const R> flat(std::span<const Vec<D, R>> v) {
  static_assert(sizeof(Vec<D, R>) == D * sizeof(R));
  return {reinterpret_cast<const R*>(v.data()), v.size() * D};
}
template <int D, std::floating_point R>
std::span<const R> flat(const std::vector<Vec<D, R>>& v) {
  return flat(std::span<const Vec<D, R>>(v));
}

/// Converts between precisions (and from double scene values to the simulation's R).
template <std::floating_point To, int D, std::floating_point From>
constexpr Vec<D, To> vec_cast(const Vec<D, From>& v) {
  Vec<D, To> r;
  for (int i = 0; i < D; ++i) r[i] = static_cast<To>(v[i]);
  return r;
}

}  // namespace sph
