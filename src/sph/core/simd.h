#pragma once
/// \file Pack<R>: a fixed number of lanes of R (16 floats or 8 doubles, one 512-bit register)
/// with the few operations the pair loops need. With AVX-512 each operation is one
/// instruction; without it the same operations run lane by lane. Every lane goes through the
/// same IEEE operations in both cases (no fused multiply-add, no reassociation), so results
/// are bitwise the same whichever implementation the build uses.

#include <cmath>
#include <cstdint>
#include <cstring>

#if defined(__AVX512F__) && defined(__AVX512VL__)
#include <immintrin.h>
#define SPH_SIMD_AVX512 1
#else
#define SPH_SIMD_AVX512 0
#endif

namespace sph::simd {

template <class R>
inline constexpr int kLanes = 64 / static_cast<int>(sizeof(R));

/// A set of lanes (bit l for lane l).
using Mask = std::uint32_t;

/// Mask of the first n lanes (all when n >= lanes).
template <class R>
inline Mask first_lanes(std::size_t n) {
  constexpr int W = kLanes<R>;
  return n >= static_cast<std::size_t>(W) ? static_cast<Mask>((std::uint64_t{1} << W) - 1)
                                          : static_cast<Mask>((std::uint64_t{1} << n) - 1);
}

#if SPH_SIMD_AVX512
template <class R>
struct Pack;

template <>
struct Pack<float> {
  __m512 v;
  static Pack set1(float x) { return {_mm512_set1_ps(x)}; }
  /// Lane l = p[l] (contiguous, unaligned).
  static Pack load(const float* p) { return {_mm512_loadu_ps(p)}; }
  /// Lane l = base[stride * idx[l] + offset].
  template <int kStride>
  static Pack gather(const float* base, const std::uint32_t* idx, int offset) {
    __m512i i = _mm512_loadu_si512(idx);
    if constexpr (kStride != 1) i = _mm512_mullo_epi32(i, _mm512_set1_epi32(kStride));
    return {
        _mm512_mask_i32gather_ps(_mm512_setzero_ps(), 0xffff, i, base + offset, 4)};  // (a defined source: no warning)
  }
  friend Pack operator+(Pack a, Pack b) { return {_mm512_add_ps(a.v, b.v)}; }
  friend Pack operator-(Pack a, Pack b) { return {_mm512_sub_ps(a.v, b.v)}; }
  friend Pack operator*(Pack a, Pack b) { return {_mm512_mul_ps(a.v, b.v)}; }
  friend Pack operator/(Pack a, Pack b) { return {_mm512_div_ps(a.v, b.v)}; }
  friend Pack sqrt(Pack a) { return {_mm512_maskz_sqrt_ps(0xffff, a.v)}; }
  friend Mask operator<(Pack a, Pack b) { return _mm512_cmp_ps_mask(a.v, b.v, _CMP_LT_OQ); }
  friend Mask operator>(Pack a, Pack b) { return _mm512_cmp_ps_mask(a.v, b.v, _CMP_GT_OQ); }
  /// Lanes in m from a, the others from b.
  friend Pack select(Mask m, Pack a, Pack b) { return {_mm512_mask_blend_ps(static_cast<__mmask16>(m), b.v, a.v)}; }
  void store(float* out) const { _mm512_storeu_ps(out, v); }
  /// Lane l = p[pattern[l]] for the lane pattern of lane_pattern(); reads p[0..16).
  static Pack permuted(const float* p, __m512i pattern) {  // (maskz: no warning)
    return {_mm512_maskz_permutexvar_ps(0xffff, pattern, _mm512_loadu_ps(p))};
  }
  template <class F>
  static __m512i lane_pattern(F f) {
    alignas(64) std::int32_t idx[16];
    for (int l = 0; l < 16; ++l) idx[l] = f(l);
    return _mm512_load_si512(idx);
  }
};

template <>
struct Pack<double> {
  __m512d v;
  static Pack set1(double x) { return {_mm512_set1_pd(x)}; }
  static Pack load(const double* p) { return {_mm512_loadu_pd(p)}; }
  template <int kStride>
  static Pack gather(const double* base, const std::uint32_t* idx, int offset) {
    __m256i i = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(idx));
    if constexpr (kStride != 1) i = _mm256_mullo_epi32(i, _mm256_set1_epi32(kStride));
    return {_mm512_mask_i32gather_pd(_mm512_setzero_pd(), 0xff, i, base + offset, 8)};
  }
  friend Pack operator+(Pack a, Pack b) { return {_mm512_add_pd(a.v, b.v)}; }
  friend Pack operator-(Pack a, Pack b) { return {_mm512_sub_pd(a.v, b.v)}; }
  friend Pack operator*(Pack a, Pack b) { return {_mm512_mul_pd(a.v, b.v)}; }
  friend Pack operator/(Pack a, Pack b) { return {_mm512_div_pd(a.v, b.v)}; }
  friend Pack sqrt(Pack a) { return {_mm512_maskz_sqrt_pd(0xff, a.v)}; }
  friend Mask operator<(Pack a, Pack b) { return _mm512_cmp_pd_mask(a.v, b.v, _CMP_LT_OQ); }
  friend Mask operator>(Pack a, Pack b) { return _mm512_cmp_pd_mask(a.v, b.v, _CMP_GT_OQ); }
  friend Pack select(Mask m, Pack a, Pack b) { return {_mm512_mask_blend_pd(static_cast<__mmask8>(m), b.v, a.v)}; }
  void store(double* out) const { _mm512_storeu_pd(out, v); }
  static Pack permuted(const double* p, __m512i pattern) {
    return {_mm512_maskz_permutexvar_pd(0xff, pattern, _mm512_loadu_pd(p))};
  }
  template <class F>
  static __m512i lane_pattern(F f) {
    alignas(64) std::int64_t idx[8];
    for (int l = 0; l < 8; ++l) idx[l] = f(l);
    return _mm512_load_si512(idx);
  }
};
#else
template <class R>
struct Pack {
  static constexpr int W = kLanes<R>;
  R v[W];
  static Pack set1(R x) {
    Pack p;
    for (int l = 0; l < W; ++l) p.v[l] = x;
    return p;
  }
  static Pack load(const R* src) {
    Pack p;
    std::memcpy(p.v, src, sizeof(p.v));
    return p;
  }
  template <int kStride>
  static Pack gather(const R* base, const std::uint32_t* idx, int offset) {
    Pack p;
    for (int l = 0; l < W; ++l)
      p.v[l] = base[static_cast<std::size_t>(idx[l]) * kStride + static_cast<std::size_t>(offset)];
    return p;
  }
#define SPH_PACK_BINARY(op)                                \
  friend Pack operator op(const Pack& a, const Pack& b) {  \
    Pack p;                                                \
    for (int l = 0; l < W; ++l) p.v[l] = a.v[l] op b.v[l]; \
    return p;                                              \
  }
  SPH_PACK_BINARY(+)
  SPH_PACK_BINARY(-)
  SPH_PACK_BINARY(*)
  SPH_PACK_BINARY(/)
#undef SPH_PACK_BINARY
  friend Pack sqrt(const Pack& a) {
    Pack p;
    for (int l = 0; l < W; ++l) p.v[l] = std::sqrt(a.v[l]);
    return p;
  }
  friend Mask operator<(const Pack& a, const Pack& b) {
    Mask m = 0;
    for (int l = 0; l < W; ++l) m |= static_cast<Mask>(a.v[l] < b.v[l]) << l;
    return m;
  }
  friend Mask operator>(const Pack& a, const Pack& b) { return b < a; }
  friend Pack select(Mask m, const Pack& a, const Pack& b) {
    Pack p;
    for (int l = 0; l < W; ++l) p.v[l] = (m >> l) & 1u ? a.v[l] : b.v[l];
    return p;
  }
  void store(R* out) const { std::memcpy(out, v, sizeof(v)); }
  struct Pattern {
    int lane[W];
  };
  static Pack permuted(const R* src, const Pattern& pattern) {
    Pack p;
    for (int l = 0; l < W; ++l) p.v[l] = src[pattern.lane[l]];
    return p;
  }
  template <class F>
  static Pattern lane_pattern(F f) {
    Pattern pattern;
    for (int l = 0; l < W; ++l) pattern.lane[l] = f(l);
    return pattern;
  }
};
#endif

/// A fixed lane pattern: with pattern = Pack<R>::lane_pattern(f), Pack<R>::permuted(src, pattern)
/// gives lane l the value src[f(l)], f(l) in [0, kLanes<R>) (src holds kLanes<R> readable
/// values). The cluster-pair loops lay a register out as a small grid of (i, j) pairs this way.
template <class R>
using LanePattern = decltype(Pack<R>::lane_pattern([](int l) { return l; }));

/// Sums of groups of G consecutive lanes, each added in lane order (the same in both
/// implementations): out[g] = lane G g + lane G g + 1 + ... + lane G g + G - 1.
template <int G, class R>
inline void sum_lane_groups(const Pack<R>& p, R* out) {
  static_assert(kLanes<R> % G == 0);
  R lanes[kLanes<R>];
  p.store(lanes);
  for (int g = 0; g < kLanes<R> / G; ++g) {
    R s = 0;
    for (int l = 0; l < G; ++l) s += lanes[G * g + l];
    out[g] = s;
  }
}

/// Sum of the lanes, added in lane order (the same in both implementations).
template <class R>
inline R sum_lanes(const Pack<R>& p) {
  R s;
  sum_lane_groups<kLanes<R>>(p, &s);
  return s;
}

}  // namespace sph::simd
