#include <sph/neighbors/list_builder.h>

#include <algorithm>

#include <sph/core/error.h>
#include <sph/core/parallel.h>
#include <sph/core/simd.h>  // SPH_SIMD_AVX512 and, where it is 1, <immintrin.h>

namespace sph {

namespace {

/// The candidate ranges of one cell (ChunkStencils keeps a chunk's).
template <int D, std::floating_point R>
struct Stencil {
  static constexpr int kMax = UniformGrid<D, R>::kMaxRanges;
  std::uint32_t cell = ~0u;
  int count = 0;
  std::uint32_t begin[kMax], end[kMax];
  std::uint32_t candidates = 0;

  void set(const UniformGrid<D, R>& grid, std::uint32_t c) {
    cell = c;
    count = grid.stencil_ranges(c, begin, end);
    candidates = 0;
    for (int k = 0; k < count; ++k) candidates += end[k] - begin[k];
  }
};

/// The stencils of one chunk's cells, each found once for the chunk. The Morton order that sorts
/// the particles (reorder.h) has cells of its own, not the grid's, so consecutive particles mostly
/// lie in different grid cells: one cached stencil found each particle's again (13 million
/// stencils in 13 builds of the 1M bench), while a chunk of 256 particles lies in a few dozen.
/// An open-addressing table from cell to stencil, emptied for each chunk.
template <int D, std::floating_point R>
class ChunkStencils {
 public:
  /// The stencil of `cell`, found in the grid the first time the chunk asks for it.
  const Stencil<D, R>& of(const UniformGrid<D, R>& grid, std::uint32_t cell) {
    if (cell == last_->cell) return *last_;
    if (!ready_) {  // (emptied at the first call: a partial rebuild's chunk may ask for none)
      std::fill_n(key_, kSlots, kEmpty);
      ready_ = true;
    }
    std::uint32_t h = (cell * 0x9e3779b1u) >> (32 - kBits);
    while (key_[h] != cell && key_[h] != kEmpty) h = (h + 1) & (kSlots - 1);
    if (key_[h] == kEmpty) {
      SPH_CHECK(used_ < kChunkSize, "a chunk's particles lie in kChunkSize cells at most");
      key_[h] = cell;
      slot_[h] = static_cast<std::uint16_t>(used_);
      stencils_[used_++].set(grid, cell);
    }
    last_ = &stencils_[slot_[h]];
    return *last_;
  }

 private:
  static constexpr int kBits = 9;  // 512 slots for at most 256 cells: short probes
  static constexpr std::uint32_t kSlots = 1u << kBits, kEmpty = ~0u;
  static_assert(kSlots >= 2 * kChunkSize && kChunkSize <= 65536);
  std::uint32_t key_[kSlots];
  std::uint16_t slot_[kSlots];
  std::size_t used_ = 0;
  bool ready_ = false;
  Stencil<D, R> none_;  // (cell ~0u: no grid cell)
  const Stencil<D, R>* last_ = &none_;
  Stencil<D, R> stencils_[kChunkSize];
};

/// Writes the neighbors of point `self` (at query position x; itself excluded)
/// to out and returns how many. out must have room for every candidate plus kPad.
/// The squared distance is computed exactly as norm2(x - x_j) is (same operations, same
/// order, no fused multiply-add), so lists agree bit for bit with a brute-force search.
///
/// With `far` (room for every candidate): the neighbors closer than sqrt(inner2) go to out, the
/// others to far, and the caller appends far's to out's (gather() does: the list then holds its
/// entries closer than the inner radius first, each part in the grid's order).
/// With `dist` (room for every candidate; not with `far`): each neighbor's squared distance, at
/// its place in out.
template <int D, std::floating_point R>
std::uint32_t gather_scalar(const UniformGrid<D, R>& grid, const Stencil<D, R>& st, const Vec<D, R>& x,
                            std::uint32_t self, R r2, std::uint32_t* out, R inner2 = 0, std::uint32_t* far = nullptr,
                            std::uint32_t* far_count = nullptr, R* dist = nullptr) {
  const std::uint32_t* sorted = grid.sorted();
  const R* c[D];
  for (int d = 0; d < D; ++d) c[d] = grid.sorted_coord(d);
  std::uint32_t m = 0;
  for (int q = 0; q < st.count; ++q)
    for (std::uint32_t k = st.begin[q]; k < st.end[q]; ++k) {
      R d2 = 0;
      for (int d = 0; d < D; ++d) {
        const R t = x[d] - c[d][k];
        d2 += t * t;
      }
      const bool hit = (d2 < r2) & (sorted[k] != self);
      if (far && hit && !(d2 < inner2)) {
        far[(*far_count)++] = sorted[k];
        continue;
      }
      out[m] = sorted[k];
      if (dist) dist[m] = d2;
      m += static_cast<std::uint32_t>(hit);
    }
  return m;
}

#if SPH_SIMD_AVX512
template <bool kSplit, bool kDist, int D>
std::uint32_t gather_vector(const UniformGrid<D, double>& grid, const Stencil<D, double>& st, const Vec<D, double>& x,
                            std::uint32_t self, double r2, std::uint32_t* out, double inner2, std::uint32_t* far,
                            std::uint32_t* far_count, double* dist) {
  static_assert(!(kSplit && kDist), "squared distances of whole lists only");
  const std::uint32_t* sorted = grid.sorted();
  const double* c[D];
  __m512d xv[D];
  for (int d = 0; d < D; ++d) c[d] = grid.sorted_coord(d), xv[d] = _mm512_set1_pd(x[d]);
  const __m512d r2v = _mm512_set1_pd(r2), inner2v = _mm512_set1_pd(inner2);
  const __m256i selfv = _mm256_set1_epi32(static_cast<int>(self));
  std::uint32_t m = 0, f = 0;
  for (int q = 0; q < st.count; ++q) {
    const std::uint32_t e = st.end[q];
    for (std::uint32_t k = st.begin[q]; k < e; k += 8) {
      const __m512d t0 = _mm512_sub_pd(xv[0], _mm512_loadu_pd(c[0] + k));
      const __m512d t1 = _mm512_sub_pd(xv[1], _mm512_loadu_pd(c[1] + k));
      __m512d d2 = _mm512_add_pd(_mm512_mul_pd(t0, t0), _mm512_mul_pd(t1, t1));
      if constexpr (D == 3) {
        const __m512d t2 = _mm512_sub_pd(xv[2], _mm512_loadu_pd(c[2] + k));
        d2 = _mm512_add_pd(d2, _mm512_mul_pd(t2, t2));
      }
      const __m256i idx = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(sorted + k));
      const unsigned keep = (e - k < 8 ? (1u << (e - k)) - 1u : 0xffu) & _mm256_cmpneq_epi32_mask(idx, selfv);
      __mmask8 hit = static_cast<__mmask8>(_mm512_cmp_pd_mask(d2, r2v, _CMP_LT_OQ) & keep);
      if constexpr (kSplit) {
        const __mmask8 outer = hit & static_cast<__mmask8>(~_mm512_cmp_pd_mask(d2, inner2v, _CMP_LT_OQ));
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(far + f), _mm256_maskz_compress_epi32(outer, idx));
        f += static_cast<std::uint32_t>(__builtin_popcount(outer));
        hit = hit & static_cast<__mmask8>(~outer);
      }
      // Register compress + plain store: the memory form of vpcompressd is slow on some CPUs.
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + m), _mm256_maskz_compress_epi32(hit, idx));
      if constexpr (kDist) _mm512_storeu_pd(dist + m, _mm512_maskz_compress_pd(hit, d2));
      m += static_cast<std::uint32_t>(__builtin_popcount(hit));
    }
  }
  if constexpr (kSplit) *far_count = f;
  return m;
}

template <bool kSplit, bool kDist, int D>
std::uint32_t gather_vector(const UniformGrid<D, float>& grid, const Stencil<D, float>& st, const Vec<D, float>& x,
                            std::uint32_t self, float r2, std::uint32_t* out, float inner2, std::uint32_t* far,
                            std::uint32_t* far_count, float* dist) {
  static_assert(!(kSplit && kDist), "squared distances of whole lists only");
  const std::uint32_t* sorted = grid.sorted();
  const float* c[D];
  __m512 xv[D];
  for (int d = 0; d < D; ++d) c[d] = grid.sorted_coord(d), xv[d] = _mm512_set1_ps(x[d]);
  const __m512 r2v = _mm512_set1_ps(r2), inner2v = _mm512_set1_ps(inner2);
  const __m512i selfv = _mm512_set1_epi32(static_cast<int>(self));
  std::uint32_t m = 0, f = 0;
  for (int q = 0; q < st.count; ++q) {
    const std::uint32_t e = st.end[q];
    for (std::uint32_t k = st.begin[q]; k < e; k += 16) {
      const __m512 t0 = _mm512_sub_ps(xv[0], _mm512_loadu_ps(c[0] + k));
      const __m512 t1 = _mm512_sub_ps(xv[1], _mm512_loadu_ps(c[1] + k));
      __m512 d2 = _mm512_add_ps(_mm512_mul_ps(t0, t0), _mm512_mul_ps(t1, t1));
      if constexpr (D == 3) {
        const __m512 t2 = _mm512_sub_ps(xv[2], _mm512_loadu_ps(c[2] + k));
        d2 = _mm512_add_ps(d2, _mm512_mul_ps(t2, t2));
      }
      const __m512i idx = _mm512_loadu_si512(sorted + k);
      const unsigned keep = (e - k < 16 ? (1u << (e - k)) - 1u : 0xffffu) & _mm512_cmpneq_epi32_mask(idx, selfv);
      __mmask16 hit = static_cast<__mmask16>(_mm512_cmp_ps_mask(d2, r2v, _CMP_LT_OQ) & keep);
      if constexpr (kSplit) {
        const __mmask16 outer = hit & static_cast<__mmask16>(~_mm512_cmp_ps_mask(d2, inner2v, _CMP_LT_OQ));
        _mm512_storeu_si512(far + f, _mm512_maskz_compress_epi32(outer, idx));
        f += static_cast<std::uint32_t>(__builtin_popcount(outer));
        hit = hit & static_cast<__mmask16>(~outer);
      }
      _mm512_storeu_si512(out + m, _mm512_maskz_compress_epi32(hit, idx));
      if constexpr (kDist) _mm512_storeu_ps(dist + m, _mm512_maskz_compress_ps(hit, d2));
      m += static_cast<std::uint32_t>(__builtin_popcount(hit));
    }
  }
  if constexpr (kSplit) *far_count = f;
  return m;
}
#endif

/// List i: the neighbors of point `self` (at x) into out, as gather_scalar, and returns how many.
/// With `far` (room for every candidate and a register), those closer than sqrt(inner2) first,
/// then the others; `filter` (if any) keeps what it wants of the others (of all, without `far`).
/// With `dist` (room for every candidate and a register; neither `far` nor `filter`), the
/// entries' squared distances too.
template <int D, std::floating_point R>
std::uint32_t gather(bool vector, const UniformGrid<D, R>& grid, const Stencil<D, R>& st, const Vec<D, R>& x,
                     std::uint32_t self, R r2, std::uint32_t* out, R inner2, std::uint32_t* far,
                     const ListFilter* filter, std::size_t i, R* dist = nullptr) {
  std::uint32_t m = 0, f = 0;
#if SPH_SIMD_AVX512
  if (vector)
    m = far    ? gather_vector<true, false, D>(grid, st, x, self, r2, out, inner2, far, &f, dist)
        : dist ? gather_vector<false, true, D>(grid, st, x, self, r2, out, inner2, far, &f, dist)
               : gather_vector<false, false, D>(grid, st, x, self, r2, out, inner2, far, &f, dist);
  else
    m = gather_scalar<D, R>(grid, st, x, self, r2, out, inner2, far, &f, dist);
#else
  (void)vector;
  m = gather_scalar<D, R>(grid, st, x, self, r2, out, inner2, far, &f, dist);
#endif
  if (f > 0) std::copy_n(far, f, out + m);
  const std::uint32_t inner = far ? m : 0;
  return filter ? inner + filter->keep(i, out + inner, m + f - inner) : m + f;
}

/// Makes buf at least `need` long, growing by a thirty-second and 256 entries at least: few
/// reallocations while the lists grow, little spare room once they are stable (a chunk's lists
/// keep a thirty-second more, about 3.6 bytes a particle at 1M in float).
void ensure_room(std::vector<std::uint32_t>& buf, std::size_t need) {
  if (buf.size() >= need) return;
  std::size_t size = std::max(need, buf.size() + buf.size() / 32 + 256);
  if (need <= buf.capacity()) size = std::min(size, buf.capacity());  // (no reallocation while it fits)
  buf.resize(size);
}

// Room after the last list: a vector store may write this far past the last hit, and readers
// may load NeighborLists::kPadding entries past a list's end.
constexpr std::size_t kRoom = 16;

static_assert(kRoom >= NeighborLists::kPadding);

/// Gathers point i's list (gather()'s arguments) into buf at `at` and returns its length. buf
/// grows only by what the list needs, not by room for every candidate: when it lacks that room,
/// the list is gathered into `spill` (the thread's) first and copied. So a chunk's buffer keeps
/// no room for one more particle's candidates (3.6 bytes a particle at 1M in float).
/// (Inlined: the build's inner loop, where gather() was called directly before.)
template <int D, std::floating_point R>
[[gnu::always_inline]] inline std::uint32_t gather_into(std::vector<std::uint32_t>& buf, std::size_t at,
                                                        std::vector<std::uint32_t>& spill, bool vector,
                                                        const UniformGrid<D, R>& grid, const Stencil<D, R>& st,
                                                        const Vec<D, R>& x, std::uint32_t self, R r2, R inner2,
                                                        std::uint32_t* far, const ListFilter* filter, std::size_t i,
                                                        R* dist = nullptr) {
  const bool fits = buf.size() >= at + st.candidates + kRoom;
  if (!fits) ensure_room(spill, st.candidates + kRoom);
  std::uint32_t* const out = fits ? buf.data() + at : spill.data();
  const std::uint32_t m = gather(vector, grid, st, x, self, r2, out, inner2, far, filter, i, dist);
  if (!fits) {
    ensure_room(buf, at + m + kRoom);
    std::copy_n(spill.data(), m, buf.data() + at);
  }
  return m;
}

/// Query points and their cells (UniformGrid::cell_containing: for the grid's own points, the
/// cell the build put each in). kOwn: the grid's own points, each left out of its own list;
/// otherwise points that are not the grid's (fluid particles against the boundary samples' grid),
/// nothing left out (no grid index is ~0).
template <int D, std::floating_point R, bool kOwn>
struct Points {
  const UniformGrid<D, R>& grid;
  std::span<const Vec<D, R>> positions;
  std::uint32_t cell(std::size_t i) const { return grid.cell_containing(positions[i]); }
  void cells(std::size_t b, std::size_t e, std::uint32_t* out) const {
    grid.cells_containing(positions.data() + b, e - b, out);
  }
  const Vec<D, R>& x(std::size_t i) const { return positions[i]; }
  static std::uint32_t self(std::size_t i) { return kOwn ? static_cast<std::uint32_t>(i) : ~0u; }
};
template <int D, std::floating_point R>
using GridPoints = Points<D, R, true>;
template <int D, std::floating_point R>
using QueryPoints = Points<D, R, false>;

}  // namespace

template <int D, std::floating_point R>
void ListBuilder<D, R>::size_thread_buffers() {
  old_copy_.resize(static_cast<std::size_t>(num_threads()));
  far_.resize(old_copy_.size());
  spill_.resize(old_copy_.size());
  for (auto& spill : spill_) ensure_room(spill, 4096);  // (grown once, on every thread)
}

template <int D, std::floating_point R>
std::uint32_t* ListBuilder<D, R>::far_room(std::size_t candidates) {
  if (!(inner_ > R(0))) return nullptr;
  std::vector<std::uint32_t>& far = far_[static_cast<std::size_t>(thread_index())];
  ensure_room(far, candidates + kRoom);
  return far.data();
}

template <int D, std::floating_point R>
void ListBuilder<D, R>::build(const UniformGrid<D, R>& grid, std::span<const Vec<D, R>> positions, R radius,
                              NeighborLists& out) {
  build_with(grid, positions.size(), GridPoints<D, R>{grid, positions}, radius, out);
}

template <int D, std::floating_point R>
void ListBuilder<D, R>::build_queries(const UniformGrid<D, R>& grid, std::span<const Vec<D, R>> queries, R radius,
                                      NeighborLists& out) {
  build_with(grid, queries.size(), QueryPoints<D, R>{grid, queries}, radius, out);
}

template <int D, std::floating_point R>
void ListBuilder<D, R>::rebuild_some(const UniformGrid<D, R>& grid, std::span<const Vec<D, R>> positions, R radius,
                                     std::span<const std::uint8_t> rebuild, NeighborLists& lists,
                                     RebuildVisitor* visitor) {
  rebuild_some_with(grid, positions.size(), GridPoints<D, R>{grid, positions}, radius, rebuild, lists, visitor);
}

template <int D, std::floating_point R>
void ListBuilder<D, R>::rebuild_some_queries(const UniformGrid<D, R>& grid, std::span<const Vec<D, R>> queries,
                                             R radius, std::span<const std::uint8_t> rebuild, NeighborLists& lists) {
  rebuild_some_with(grid, queries.size(), QueryPoints<D, R>{grid, queries}, radius, rebuild, lists);
}

template <int D, std::floating_point R>
template <class Query>
void ListBuilder<D, R>::build_with(const UniformGrid<D, R>& grid, std::size_t n, const Query& query, R radius,
                                   NeighborLists& out) {
  const R r2 = radius * radius;
  const std::size_t chunks = chunk_count(n);
  out.chunks_.resize(chunks);
  out.end_.resize(n);
  if (room_) {
    out.begin_.resize(n);
    out.cap_.resize(n);
  } else {
    out.begin_.clear();
    out.cap_.clear();
  }
  chunk_entries_.resize(chunks);
  size_thread_buffers();
  SPH_CHECK(!visitor_ || (!filter_ && !(inner_ > R(0)) && !room_), "a pair visitor sees whole, compact lists");
  if (visitor_) {
    dist_.resize(old_copy_.size());
    for (auto& dist : dist_)
      if (dist.size() < 4096) dist.resize(4096);  // (grown once, on every thread)
  }

  parallel_chunks(n, [&](std::size_t c, std::size_t b, std::size_t e) {
    // A chunk's first build goes to its thread's scratch, then into a buffer allocated once, at
    // its size and a thirty-second more: grown from nothing in place, the buffer would be allocated
    // several times over, and the blocks freed on the way stay with the process (resident).
    std::vector<std::uint32_t>& own = out.chunks_[c];
    const bool first = own.capacity() == 0;
    const auto thread = static_cast<std::size_t>(thread_index());  // (once per chunk: a call into the runtime)
    std::vector<std::uint32_t>& buf = first ? old_copy_[thread] : own;
    std::vector<std::uint32_t>& spill = spill_[thread];
    std::vector<R>* const dist = visitor_ ? &dist_[thread] : nullptr;
    ChunkStencils<D, R> stencils;
    std::size_t used = 0, entries = 0;
    std::uint32_t cells[kChunkSize];  // the chunk's cells, in one loop
    alignas(64) R visitor_room[PairVisitor<R>::kRoom];
    SPH_CHECK(e - b <= kChunkSize, "parallel_chunks gives chunks of kChunkSize points at most");
    query.cells(b, e, cells);
    for (std::size_t i = b; i < e; ++i) {
      const Stencil<D, R>& st = stencils.of(grid, cells[i - b]);
      if (dist && dist->size() < st.candidates + kRoom) dist->resize(st.candidates + kRoom);
      const std::uint32_t m = gather_into(buf, used, spill, vector_, grid, st, query.x(i), query.self(i), r2, inner2(),
                                          far_room(st.candidates), filter_, i, dist ? dist->data() : nullptr);
      if (dist) visitor_->visit(i, {buf.data() + used, m}, {dist->data(), m}, visitor_room);
      if (room_) out.begin_[i] = static_cast<std::uint32_t>(used);
      out.end_[i] = static_cast<std::uint32_t>(used + m);
      entries += m;
      used += m;
      if (room_) {
        const std::uint32_t cap = list_capacity(m);
        ensure_room(buf, used - m + cap + kRoom);
        std::fill_n(buf.data() + used, cap - m, 0u);
        out.cap_[i] = cap;
        used += cap - m;
      }
    }
    std::fill_n(buf.data() + used, kRoom, 0u);  // readable padding, valid indices (not stale ones)
    if (first) {
      own.reserve(used + used / 32 + kRoom);
      own.assign(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(used + kRoom));
    }
    chunk_entries_[c] = entries;
  });
  out.entries_ = 0;
  for (std::size_t c = 0; c < chunks; ++c) out.entries_ += chunk_entries_[c];
  written_ = out.entries_;
}

template <int D, std::floating_point R>
template <class Query>
void ListBuilder<D, R>::rebuild_some_with(const UniformGrid<D, R>& grid, std::size_t n, const Query& query, R radius,
                                          std::span<const std::uint8_t> rebuild, NeighborLists& lists,
                                          RebuildVisitor* visitor) {
  const std::size_t old_n = lists.particle_count();
  SPH_CHECK(rebuild.size() == n && old_n <= n, "rebuild flags must cover every particle");
  SPH_CHECK(room_ == lists.has_room() || old_n == 0, "lists with room are rebuilt with room");
  SPH_CHECK(visitor == nullptr || room_, "only lists with room are rebuilt in place");
  const R r2 = radius * radius;
  const std::size_t chunks = chunk_count(n);
  lists.chunks_.resize(chunks);
  lists.end_.resize(n);
  if (room_) {
    lists.begin_.resize(n);
    lists.cap_.resize(n);
  }
  chunk_entries_.resize(chunks);
  chunk_written_.assign(chunks, 0);

  // Each thread copies a chunk's old lists aside before merging. The copy buffers are grown
  // here, before the loop, to the largest old chunk: their size depends only on the lists, not
  // on which thread meets which chunk, so a steady state allocates nothing for any schedule.
  std::size_t largest_old = 0;
  for (std::size_t c = 0; c * kChunkSize < old_n; ++c) {
    const std::size_t last = std::min(old_n, (c + 1) * kChunkSize) - 1;
    largest_old = std::max<std::size_t>(largest_old, lists.begin(last) + lists.capacity(last));
  }
  size_thread_buffers();
  for (auto& copy : old_copy_) ensure_room(copy, largest_old);

  if (room_ && lists.has_room()) {
    rebuild_in_place(grid, n, query, radius, rebuild, lists, visitor);
    return;
  }
  parallel_chunks(n, [&](std::size_t c, std::size_t b, std::size_t e) {
    const auto marked = [&](std::size_t i) { return rebuild[i] != 0 || i >= old_n; };
    std::size_t kept = 0;
    bool any = false;
    for (std::size_t i = b; i < e; ++i) {
      if (marked(i))
        any = true;
      else
        kept += lists.of(i).size();
    }
    if (!any) {
      chunk_entries_[c] = kept;
      return;
    }
    // The chunk's old lists are copied aside, then the chunk's buffer is rewritten in order:
    // kept lists (with their room) from the copy, marked ones gathered in place. The buffer
    // belongs to the chunk and keeps its room, so it grows only when the chunk's lists do.
    std::vector<std::uint32_t>& buf = lists.chunks_[c];
    const std::size_t last_old = std::min(e, old_n);  // particles [b, last_old) had lists
    const std::size_t old_size = last_old > b ? lists.begin(last_old - 1) + lists.capacity(last_old - 1) : 0;
    const auto thread = static_cast<std::size_t>(thread_index());
    std::vector<std::uint32_t>& old_copy = old_copy_[thread];
    std::vector<std::uint32_t>& spill = spill_[thread];
    std::copy_n(buf.data(), old_size, old_copy.data());
    ChunkStencils<D, R> stencils;
    std::size_t at = 0, entries = 0, written = 0;
    // (the old lists have no room of their own here, so each started at the end of the one
    // before it: that old end, read before list i - 1's is rewritten)
    std::uint32_t old_end = 0;
    for (std::size_t i = b; i < e; ++i) {
      std::uint32_t len = 0, cap = 0;
      if (marked(i)) {
        const Stencil<D, R>& st = stencils.of(grid, query.cell(i));
        len = gather_into(buf, at, spill, vector_, grid, st, query.x(i), query.self(i), r2, inner2(),
                          far_room(st.candidates), filter_, i);
        written += len;
        cap = room_ ? list_capacity(len) : len;
        ensure_room(buf, at + cap + kRoom);
      } else {
        len = lists.end_[i] - old_end;
        cap = len;
        ensure_room(buf, at + cap + kRoom);
        std::copy_n(old_copy.data() + old_end, len, buf.data() + at);
      }
      std::fill_n(buf.data() + at + len, cap - len, 0u);  // a list's room holds valid indices
      if (i < old_n) old_end = lists.end_[i];
      if (room_) lists.begin_[i] = static_cast<std::uint32_t>(at);
      lists.end_[i] = static_cast<std::uint32_t>(at + len);
      if (room_) lists.cap_[i] = cap;
      at += cap;
      entries += len;
    }
    std::fill_n(buf.data() + at, kRoom, 0u);  // readable padding, valid indices
    chunk_entries_[c] = entries;
    chunk_written_[c] = written;
  });
  lists.entries_ = 0;
  written_ = 0;
  for (std::size_t c = 0; c < chunks; ++c) lists.entries_ += chunk_entries_[c], written_ += chunk_written_[c];
}

template <int D, std::floating_point R>
template <class Query>
void ListBuilder<D, R>::rebuild_in_place(const UniformGrid<D, R>& grid, std::size_t n, const Query& query, R radius,
                                         std::span<const std::uint8_t> rebuild, NeighborLists& lists,
                                         RebuildVisitor* visitor) {
  // Lists with room of their own: a marked list is gathered aside and copied into its slot, and
  // only a list that no longer fits has its chunk laid out again; the others are not touched.
  const std::size_t old_n = lists.particle_count();
  const R r2 = radius * radius;
  const std::size_t chunks = chunk_count(n);
  lists.chunks_.resize(chunks);
  lists.begin_.resize(n);
  lists.end_.resize(n);
  lists.cap_.resize(n);
  chunk_delta_.assign(chunks, 0);
  chunk_written_.assign(chunks, 0);
  old_copy_.resize(static_cast<std::size_t>(num_threads()));
  relayout_copy_.resize(old_copy_.size());
  parallel_chunks(n, [&](std::size_t c, std::size_t b, std::size_t e) {
    std::vector<std::uint32_t>& buf = lists.chunks_[c];
    const auto thread = static_cast<std::size_t>(thread_index());
    std::vector<std::uint32_t>& scratch = old_copy_[thread];
    std::vector<std::uint32_t>& spill = spill_[thread];
    std::int64_t delta = 0;
    std::size_t written = 0;
    ChunkStencils<D, R> stencils;
    for (std::size_t i = b; i < e; ++i) {
      if (rebuild[i] == 0 && i < old_n) continue;
      const Stencil<D, R>& st = stencils.of(grid, query.cell(i));
      if (i >= old_n) {  // appended: its list goes after the chunk's last one
        const std::size_t at = i == b ? 0 : lists.begin_[i - 1] + lists.cap_[i - 1];
        const std::uint32_t len = gather_into(buf, at, spill, vector_, grid, st, query.x(i), query.self(i), r2,
                                              inner2(), far_room(st.candidates), filter_, i);
        const std::uint32_t cap = list_capacity(len);
        ensure_room(buf, at + cap + kRoom);
        std::fill_n(buf.data() + at + len, cap - len + kRoom, 0u);
        lists.begin_[i] = static_cast<std::uint32_t>(at);
        lists.end_[i] = static_cast<std::uint32_t>(at + len);
        lists.cap_[i] = cap;
        delta += len;
        written += len;
        if (visitor) visitor->rebuilt(c, i, {}, {buf.data() + at, len});
        continue;
      }
      ensure_room(scratch, st.candidates + kRoom);
      const std::uint32_t len = gather(vector_, grid, st, query.x(i), query.self(i), r2, scratch.data(), inner2(),
                                       far_room(st.candidates), filter_, i);
      written += len;
      if (len > lists.cap_[i]) {
        const std::uint32_t want = list_capacity(len);
        lists.relayout_chunk(c, relayout_copy_[static_cast<std::size_t>(thread_index())],
                             [&](std::size_t q) { return q == i ? want : std::uint32_t{0}; });
      }
      delta += static_cast<std::int64_t>(len) - static_cast<std::int64_t>(lists.end_[i] - lists.begin_[i]);
      if (visitor) visitor->rebuilt(c, i, lists.of(i), {scratch.data(), len});
      std::copy_n(scratch.data(), len, buf.data() + lists.begin_[i]);
      // Entries past the new end keep old, valid indices (below the old particle count).
      lists.end_[i] = lists.begin_[i] + len;
    }
    chunk_delta_[c] = delta;
    chunk_written_[c] = written;
  });
  std::int64_t total = static_cast<std::int64_t>(lists.entries_);
  written_ = 0;
  for (std::size_t c = 0; c < chunks; ++c) total += chunk_delta_[c], written_ += chunk_written_[c];
  lists.entries_ = static_cast<std::size_t>(total);
}

template class ListBuilder<2, float>;
template class ListBuilder<2, double>;
template class ListBuilder<3, float>;
template class ListBuilder<3, double>;

}  // namespace sph
