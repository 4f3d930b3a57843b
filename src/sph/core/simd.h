#pragma once
/// \file Pack<R>: a fixed number of lanes of R (16 floats or 8 doubles, one 512-bit register)
/// with the few operations the pair loops need. With AVX-512 each operation is one
/// instruction; without it the same operations run lane by lane. Every lane goes through the
/// same IEEE operations in both cases (no fused multiply-add, no reassociation), so results
/// are bitwise the same whichever implementation the build uses.

#include <cmath>
#include <cstdint>
#include <cstring>
#include <span>

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

#if SPH_SIMD_AVX512
namespace detail {
/// gather_vectors' loads of rows of D scalars (D of 2 or 3): z[a] holds rows idx[a], idx[a + 4],
/// idx[a + 8], idx[a + 12], one per 128-bit block (x y z -); with kMasked each row's D scalars
/// alone, otherwise the block's 4 (what follows the row's D lands in the unused lane).
template <bool kMasked, int D>
[[gnu::always_inline]] inline void load_rows(const float* base, const std::uint32_t* idx, __m512 (&z)[4]) {
  constexpr unsigned kRow = (1u << D) - 1;  // a row's D scalars
  const auto load = [base, idx](int l) {
    const float* row = base + static_cast<std::size_t>(idx[l]) * D;
    return kMasked ? _mm_maskz_loadu_ps(kRow, row) : _mm_loadu_ps(row);
  };
  for (int a = 0; a < 4; ++a) {
    __m512 r = _mm512_castps128_ps512(load(a));
    r = _mm512_maskz_insertf32x4(0xffff, r, load(a + 4), 1);
    r = _mm512_maskz_insertf32x4(0xffff, r, load(a + 8), 2);
    z[a] = _mm512_maskz_insertf32x4(0xffff, r, load(a + 12), 3);
  }
}
/// The same in double, each row masked to its D scalars (plain loads of 4 doubles made the 8,000
/// particle bench's double force pass 0.47 -> 0.54 ms): z[a] holds rows idx[a], idx[a + 4], one per
/// 256-bit half (x y | z 0).
template <int D>
[[gnu::always_inline]] inline void load_rows(const double* base, const std::uint32_t* idx, __m512d (&z)[4]) {
  constexpr unsigned kRow = (1u << D) - 1;
  const auto load = [base, idx](int l) {
    return _mm256_maskz_loadu_pd(kRow, base + static_cast<std::size_t>(idx[l]) * D);
  };
  for (int a = 0; a < 4; ++a) z[a] = _mm512_maskz_insertf64x4(0xff, _mm512_castpd256_pd512(load(a)), load(a + 4), 1);
}
}  // namespace detail
#endif

/// out[d] = Pack<R>::gather<D>(values.data(), idx, d) for every d < D (lane l of out[d] is
/// values[D idx[l] + d]): a register of D-vectors stored one after another (x0 y0 z0 x1 y1 z1 ...,
/// flat()), the same values. With AVX-512 and D of 2 or 3 each vector is one load, the loads put
/// side by side and transposed into the D registers: a gather instruction per component costs
/// several times as much. In float each load takes 4 scalars, the vector's D and what follows
/// them (unused), except in a register whose lanes include the last vector, which nothing follows:
/// there each is masked to its D (nothing beyond the array is read). The masked loads cost the 1M
/// bench's float density pass a fifth more on the AMD machine of docs/performance.md; in double
/// the plain loads cost more than the masked ones, which it keeps.
template <int D, class R>
[[gnu::always_inline]] inline void gather_vectors(std::span<const R> values, const std::uint32_t* idx,
                                                  Pack<R> (&out)[D]) {
  const R* const base = values.data();
#if SPH_SIMD_AVX512
  if constexpr (D == 2 || D == 3) {
    if constexpr (sizeof(R) == 4) {
      // z[a] holds rows a, a + 4, a + 8, a + 12, one per 128-bit block (x y z -); a 4 x 4
      // transpose within each block then gives lanes 4b..4b+3 of each component.
      __m512 z[4];
      const auto last = static_cast<std::int32_t>(values.size() / D - 1);
      if (_mm512_cmpeq_epi32_mask(_mm512_loadu_si512(idx), _mm512_set1_epi32(last)) == 0)
        detail::load_rows<false, D>(base, idx, z);
      else
        detail::load_rows<true, D>(base, idx, z);
      const __m512 xy01 = _mm512_maskz_unpacklo_ps(0xffff, z[0], z[1]);  // x0 x1 y0 y1 per block
      const __m512 xy23 = _mm512_maskz_unpacklo_ps(0xffff, z[2], z[3]);
      out[0].v = _mm512_maskz_shuffle_ps(0xffff, xy01, xy23, _MM_SHUFFLE(1, 0, 1, 0));
      out[1].v = _mm512_maskz_shuffle_ps(0xffff, xy01, xy23, _MM_SHUFFLE(3, 2, 3, 2));
      if constexpr (D == 3) {
        const __m512 zw01 = _mm512_maskz_unpackhi_ps(0xffff, z[0], z[1]);
        const __m512 zw23 = _mm512_maskz_unpackhi_ps(0xffff, z[2], z[3]);
        out[2].v = _mm512_maskz_shuffle_ps(0xffff, zw01, zw23, _MM_SHUFFLE(1, 0, 1, 0));
      }
    } else {
      // z[a] holds rows a, a + 4, one per 256-bit half (x y | z 0); 64-bit interleaves, then
      // each component's 128-bit pieces put in lane order.
      __m512d z[4];
      detail::load_rows<D>(base, idx, z);
      // lo: (x_a x_a+1) (z_a z_a+1) (x_a+4 x_a+5) (z_a+4 z_a+5); hi: the same of y and the padding
      const __m512d lo01 = _mm512_maskz_unpacklo_pd(0xff, z[0], z[1]),
                    lo23 = _mm512_maskz_unpacklo_pd(0xff, z[2], z[3]);
      const __m512d hi01 = _mm512_maskz_unpackhi_pd(0xff, z[0], z[1]),
                    hi23 = _mm512_maskz_unpackhi_pd(0xff, z[2], z[3]);
      const __m512i first = _mm512_setr_epi64(0, 1, 8, 9, 4, 5, 12, 13);
      out[0].v = _mm512_maskz_permutex2var_pd(0xff, lo01, first, lo23);
      out[1].v = _mm512_maskz_permutex2var_pd(0xff, hi01, first, hi23);
      if constexpr (D == 3) {
        const __m512i second = _mm512_setr_epi64(2, 3, 10, 11, 6, 7, 14, 15);
        out[2].v = _mm512_maskz_permutex2var_pd(0xff, lo01, second, lo23);
      }
    }
    return;
  }
#endif
  for (int d = 0; d < D; ++d) out[d] = Pack<R>::template gather<D>(base, idx, d);
}

/// sum_lanes of a register's worth of packs at once: out[k] = sum_lanes(p[k]) for k < count, bit
/// for bit (the same additions in the same order), p holding kLanes<R> packs (those from count on
/// are read, their sums not written). With AVX-512 the packs are transposed, so that lane k of
/// the j-th register holds lane j of p[k], and the registers are added in lane order: a register's
/// sums in kLanes<R> vector additions instead of one chain of scalar ones per pack.
template <class R>
inline void sum_lanes_each(const Pack<R>* p, int count, R* out) {
#if SPH_SIMD_AVX512
  // (maskz forms throughout: GCC 12's plain ones start from an undefined register, and warn)
  R sums[kLanes<R>];
  if constexpr (sizeof(R) == 4) {
    // r_k = p[k]. Within each 128-bit block j: 32-bit, then 64-bit interleaves (u[4g + m] holds
    // rows 4g..4g+3 of element 4j + m), then the blocks gathered across four registers.
    __m512 t[16], u[16];
    for (int g = 0; g < 8; ++g) {
      t[2 * g] = _mm512_maskz_unpacklo_ps(0xffff, p[2 * g].v, p[2 * g + 1].v);
      t[2 * g + 1] = _mm512_maskz_unpackhi_ps(0xffff, p[2 * g].v, p[2 * g + 1].v);
    }
    for (int g = 0; g < 4; ++g) {
      const __m512d a = _mm512_castps_pd(t[4 * g]), b = _mm512_castps_pd(t[4 * g + 2]);
      const __m512d c = _mm512_castps_pd(t[4 * g + 1]), d = _mm512_castps_pd(t[4 * g + 3]);
      u[4 * g] = _mm512_castpd_ps(_mm512_maskz_unpacklo_pd(0xff, a, b));
      u[4 * g + 1] = _mm512_castpd_ps(_mm512_maskz_unpackhi_pd(0xff, a, b));
      u[4 * g + 2] = _mm512_castpd_ps(_mm512_maskz_unpacklo_pd(0xff, c, d));
      u[4 * g + 3] = _mm512_castpd_ps(_mm512_maskz_unpackhi_pd(0xff, c, d));
    }
    __m512 f[16];  // f[e]: lane k = element e of row k
    for (int m = 0; m < 4; ++m) {
      const __m512 p0 = _mm512_maskz_shuffle_f32x4(0xffff, u[m], u[4 + m], _MM_SHUFFLE(2, 0, 2, 0));
      const __m512 p1 = _mm512_maskz_shuffle_f32x4(0xffff, u[m], u[4 + m], _MM_SHUFFLE(3, 1, 3, 1));
      const __m512 q0 = _mm512_maskz_shuffle_f32x4(0xffff, u[8 + m], u[12 + m], _MM_SHUFFLE(2, 0, 2, 0));
      const __m512 q1 = _mm512_maskz_shuffle_f32x4(0xffff, u[8 + m], u[12 + m], _MM_SHUFFLE(3, 1, 3, 1));
      f[m] = _mm512_maskz_shuffle_f32x4(0xffff, p0, q0, _MM_SHUFFLE(2, 0, 2, 0));
      f[8 + m] = _mm512_maskz_shuffle_f32x4(0xffff, p0, q0, _MM_SHUFFLE(3, 1, 3, 1));
      f[4 + m] = _mm512_maskz_shuffle_f32x4(0xffff, p1, q1, _MM_SHUFFLE(2, 0, 2, 0));
      f[12 + m] = _mm512_maskz_shuffle_f32x4(0xffff, p1, q1, _MM_SHUFFLE(3, 1, 3, 1));
    }
    __m512 s = _mm512_setzero_ps();
    for (int e = 0; e < 16; ++e) s = _mm512_add_ps(s, f[e]);
    _mm512_storeu_ps(sums, s);
  } else {
    // Within each 128-bit block j: a 64-bit interleave (t[2g + m] holds rows 2g, 2g + 1 of
    // element 2j + m), then the blocks gathered across four registers.
    __m512d t[8];
    for (int g = 0; g < 4; ++g) {
      t[2 * g] = _mm512_maskz_unpacklo_pd(0xff, p[2 * g].v, p[2 * g + 1].v);
      t[2 * g + 1] = _mm512_maskz_unpackhi_pd(0xff, p[2 * g].v, p[2 * g + 1].v);
    }
    __m512d f[8];
    for (int m = 0; m < 2; ++m) {
      const __m512d p0 = _mm512_maskz_shuffle_f64x2(0xff, t[m], t[2 + m], _MM_SHUFFLE(2, 0, 2, 0));
      const __m512d p1 = _mm512_maskz_shuffle_f64x2(0xff, t[m], t[2 + m], _MM_SHUFFLE(3, 1, 3, 1));
      const __m512d q0 = _mm512_maskz_shuffle_f64x2(0xff, t[4 + m], t[6 + m], _MM_SHUFFLE(2, 0, 2, 0));
      const __m512d q1 = _mm512_maskz_shuffle_f64x2(0xff, t[4 + m], t[6 + m], _MM_SHUFFLE(3, 1, 3, 1));
      f[m] = _mm512_maskz_shuffle_f64x2(0xff, p0, q0, _MM_SHUFFLE(2, 0, 2, 0));
      f[4 + m] = _mm512_maskz_shuffle_f64x2(0xff, p0, q0, _MM_SHUFFLE(3, 1, 3, 1));
      f[2 + m] = _mm512_maskz_shuffle_f64x2(0xff, p1, q1, _MM_SHUFFLE(2, 0, 2, 0));
      f[6 + m] = _mm512_maskz_shuffle_f64x2(0xff, p1, q1, _MM_SHUFFLE(3, 1, 3, 1));
    }
    __m512d s = _mm512_setzero_pd();
    for (int e = 0; e < 8; ++e) s = _mm512_add_pd(s, f[e]);
    _mm512_storeu_pd(sums, s);
  }
  for (int k = 0; k < count; ++k) out[k] = sums[k];
#else
  for (int k = 0; k < count; ++k) out[k] = sum_lanes(p[k]);
#endif
}

}  // namespace sph::simd
