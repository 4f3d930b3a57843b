#pragma once
/// \file Building full neighbor lists from a UniformGrid, in parallel and deterministically.

#include <span>
#include <vector>

#include <sph/neighbors/neighbor_lists.h>
#include <sph/neighbors/uniform_grid.h>

namespace sph {

/// Builds the full lists of all points within `radius` (strictly closer) from a grid built on
/// the same points. Each list holds its neighbors in the grid's cell order; the lists depend
/// only on the input, never on the thread count or on which distance kernel ran.
///
/// The distance tests read the grid's sorted coordinate arrays, one contiguous range per row
/// of cells; where the compiler targets AVX-512, 8 (double) or 16 (float) candidates are
/// tested per instruction and the hits compressed into the list. Lists are written in place
/// into their chunk's storage, and storage is kept between builds, so rebuilding allocates
/// nothing in steady state.
/// Told of each list that ListBuilder::rebuild_some() rebuilds in place (lists with room), in the
/// thread that owns the list's chunk, in particle order within the chunk: `before` is the old list
/// (empty for a particle appended since), `after` the new one. Both are valid only during the call.
struct RebuildVisitor {
  virtual ~RebuildVisitor() = default;
  virtual void rebuilt(std::size_t chunk, std::size_t i, std::span<const std::uint32_t> before,
                       std::span<const std::uint32_t> after) = 0;
};

/// Sees each list a ListBuilder gathers (set_filter), before it is stored, and keeps the entries
/// it wants: the tracked modes keep, of the candidates within the builder's radius, the pairs
/// whose paths come close (tracked.h). Called from the thread that builds the list.
struct ListFilter {
  virtual ~ListFilter() = default;
  /// Keeps some of the `len` entries of point i's list, in place and in their order; returns how
  /// many it kept.
  virtual std::uint32_t keep(std::size_t i, std::uint32_t* list, std::uint32_t len) const = 0;
};

/// Sees each list ListBuilder::build() gathers, with the squared distances of its entries (the
/// same values the distance test compared, in the list's order), while they are at hand: the
/// standard mode's density sums are made there (wcsph.h, PairDensity), without gathering the
/// neighbors' positions again. Called from the thread that builds the list: the lists of a chunk
/// of kChunkSize particles (parallel.h) one after the other, in particle order, in one thread.
/// `r2` is readable (stale values) for NeighborLists::kPadding entries past its end.
/// `room`: kRoom reals, 64-byte aligned, that the builder keeps for the visitor through one
/// chunk's visits and gives no one else (the visitor's state across a chunk's particles, on the
/// building thread's stack: a `thread_local` array there cost a call to find it and the vector
/// registers spilled around that call, for every particle).
template <std::floating_point R>
struct PairVisitor {
  static constexpr std::size_t kRoom = 256;
  virtual ~PairVisitor() = default;
  virtual void visit(std::size_t i, std::span<const std::uint32_t> list, std::span<const R> r2, R* room) const = 0;
};

template <int D, std::floating_point R>
class ListBuilder {
 public:
  void build(const UniformGrid<D, R>& grid, std::span<const Vec<D, R>> positions, R radius, NeighborLists& out);

  /// Rebuilds only the lists of the particles with `rebuild[i] != 0` and keeps the others as
  /// they are in `lists`. `lists` may cover fewer particles than `positions` (particles were
  /// appended): every particle beyond it is rebuilt too. The grid must be built on
  /// `positions`. Deterministic for any thread count; chunks without a marked particle are
  /// not touched.
  void rebuild_some(const UniformGrid<D, R>& grid, std::span<const Vec<D, R>> positions, R radius,
                    std::span<const std::uint8_t> rebuild, NeighborLists& lists, RebuildVisitor* visitor = nullptr);

  /// Boundary lists: for each query point i (queries[i], not a point of the grid), every grid
  /// point strictly closer than `radius`, in the grid's cell order. The same kernels, storage and
  /// guarantees as build(); `out` covers the queries (its indices are the grid's points).
  void build_queries(const UniformGrid<D, R>& grid, std::span<const Vec<D, R>> queries, R radius, NeighborLists& out);
  /// rebuild_some() for query lists: rebuilds the lists of the marked queries (and of every
  /// query beyond `lists`), keeps the others.
  void rebuild_some_queries(const UniformGrid<D, R>& grid, std::span<const Vec<D, R>> queries, R radius,
                            std::span<const std::uint8_t> rebuild, NeighborLists& lists);

  /// Uses the vector kernel where the build has one (SPH_SIMD_AVX512, default) or the portable
  /// scalar one (tests check that both give the same lists).
  void use_vector_kernel(bool on) { vector_ = on; }

  /// Entries the last build() or rebuild_some() gathered: every list's for build(), the
  /// rebuilt lists' for rebuild_some() (the kept ones are not counted).
  std::size_t entries_written() const { return written_; }

  /// Lists built from now on keep room of their own (NeighborLists::capacity), list_capacity()
  /// slots for a list of that size, so that other lists' particles can be inserted (the tracked
  /// modes); rebuild_some() keeps a kept list's capacity. Off by default (compact lists).
  void keep_room(bool on) { room_ = on; }
  /// Every list built from now on is passed through `filter` (null: none) before it is stored
  /// (beyond split_at's radius); capacities and counts are those of the filtered lists.
  void set_filter(const ListFilter* filter) { filter_ = filter; }
  /// Lists built from now on hold their entries closer than `inner` first, then the others, each
  /// part in the grid's order, and only the others go through the filter (set_filter): the
  /// entries closer than `inner` are kept as they are. 0 (the default): every list in the grid's
  /// order, all of it filtered.
  void split_at(R inner) { inner_ = inner; }
  /// Every list build() makes from now on is shown to `visitor` (null: none) with its squared
  /// distances. Not with a filter, split lists or room (the tracked modes'), nor in rebuild_some().
  void set_pair_visitor(const PairVisitor<R>* visitor) { visitor_ = visitor; }
  /// The capacity a list of `size` entries is built with when lists keep room: a quarter more and 4.
  static std::uint32_t list_capacity(std::uint32_t size) { return size + size / 4 + 4; }

 private:
  template <class Query>
  void build_with(const UniformGrid<D, R>& grid, std::size_t n, const Query& query, R radius, NeighborLists& out);
  template <class Query>
  void rebuild_some_with(const UniformGrid<D, R>& grid, std::size_t n, const Query& query, R radius,
                         std::span<const std::uint8_t> rebuild, NeighborLists& lists,
                         RebuildVisitor* visitor = nullptr);

  template <class Query>
  void rebuild_in_place(const UniformGrid<D, R>& grid, std::size_t n, const Query& query, R radius,
                        std::span<const std::uint8_t> rebuild, NeighborLists& lists, RebuildVisitor* visitor);

  /// One merge, far and spill buffer per thread (the spill buffers with room for 4,096 entries).
  void size_thread_buffers();
  /// The calling thread's buffer for the entries beyond the inner radius (room for `candidates`),
  /// or null when lists are not split.
  std::uint32_t* far_room(std::size_t candidates);
  R inner2() const { return inner_ * inner_; }

  bool vector_ = true;
  bool room_ = false;
  R inner_ = 0;
  std::vector<std::vector<std::uint32_t>> far_;  // one per thread: split_at's outer entries
  const ListFilter* filter_ = nullptr;
  const PairVisitor<R>* visitor_ = nullptr;
  std::vector<std::vector<R>> dist_;  // one per thread: the squared distances of the list visitor_ sees
  std::vector<std::size_t> chunk_entries_;
  std::vector<std::int64_t> chunk_delta_;
  std::vector<std::size_t> chunk_written_;
  std::size_t written_ = 0;
  std::vector<std::vector<std::uint32_t>> old_copy_;       // one per thread: rebuild_some's old lists, a first build
  std::vector<std::vector<std::uint32_t>> relayout_copy_;  // rebuild_some in place: one per thread
  std::vector<std::vector<std::uint32_t>> spill_;  // one per thread: a list whose chunk lacked room for its candidates
};

extern template class ListBuilder<2, float>;
extern template class ListBuilder<2, double>;
extern template class ListBuilder<3, float>;
extern template class ListBuilder<3, double>;

}  // namespace sph
