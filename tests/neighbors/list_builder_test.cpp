// The fast neighbor search: the vector and scalar distance kernels give the same lists, chunked
// list storage behaves like plain per-particle vectors, partial rebuilds keep untouched chunks,
// and the Morton order is a stable permutation that keeps neighbors close in memory.

#include <algorithm>
#include <numeric>
#include <random>

#include <gtest/gtest.h>

#include <sph/core/error.h>
#include <sph/core/parallel.h>
#include <sph/neighbors/list_builder.h>
#include <sph/neighbors/reorder.h>
#include <sph/neighbors/standard.h>

namespace sph {
namespace {

template <int D, class R>
std::vector<Vec<D, R>> jittered_lattice(int side, double dx, double jitter, unsigned seed, bool shuffle) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-jitter, jitter);
  std::vector<Vec<D, R>> x;
  const int nz = D == 3 ? side : 1;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < side; ++j)
      for (int i = 0; i < side; ++i) {
        Vec<D, R> p{};
        p[0] = static_cast<R>((i + u(rng)) * dx);
        p[1] = static_cast<R>((j + u(rng)) * dx);
        if constexpr (D == 3) p[2] = static_cast<R>((k + u(rng)) * dx);
        x.push_back(p);
      }
  if (shuffle) std::shuffle(x.begin(), x.end(), rng);
  return x;
}

template <int D, class R>
void expect_kernels_agree(int side, double radius_in_dx, bool shuffle) {
  const auto x = jittered_lattice<D, R>(side, 0.025, 0.1 * 0.025, 7, shuffle);
  const R r = static_cast<R>(radius_in_dx * 0.025);
  UniformGrid<D, R> grid;
  grid.build(x, r);
  ListBuilder<D, R> vec, scalar;
  scalar.use_vector_kernel(false);
  NeighborLists a, b;
  vec.build(grid, x, r, a);
  scalar.build(grid, x, r, b);
  ASSERT_EQ(a.particle_count(), x.size());
  EXPECT_GT(a.entry_count(), x.size());  // the lattice has neighbors
  EXPECT_TRUE(a == b) << "vector and scalar kernels disagree";
  // And both equal brute force, as sets, on a sample of particles.
  for (std::size_t i = 0; i < x.size(); i += 37) {
    std::vector<std::uint32_t> want;
    for (std::size_t j = 0; j < x.size(); ++j)
      if (j != i && norm2(x[i] - x[j]) < r * r) want.push_back(static_cast<std::uint32_t>(j));
    std::vector<std::uint32_t> got(a.of(i).begin(), a.of(i).end());
    std::sort(got.begin(), got.end());
    ASSERT_EQ(got, want) << "particle " << i;
  }
}

TEST(FastLists, VectorAndScalarKernelsAgree3dDouble) { expect_kernels_agree<3, double>(14, 2.0, false); }
TEST(FastLists, VectorAndScalarKernelsAgree3dFloatShuffled) { expect_kernels_agree<3, float>(14, 3.0, true); }
TEST(FastLists, VectorAndScalarKernelsAgree2dDouble) { expect_kernels_agree<2, double>(60, 2.0, true); }
TEST(FastLists, VectorAndScalarKernelsAgree2dFloat) { expect_kernels_agree<2, float>(60, 2.5, false); }

/// Records the lists it is shown and keeps every other entry of each.
struct EveryOtherFilter final : ListFilter {
  mutable std::vector<std::vector<std::uint32_t>> shown;
  std::uint32_t keep(std::size_t i, std::uint32_t* list, std::uint32_t len) const override {
    shown[i].assign(list, list + len);
    std::uint32_t kept = 0;
    for (std::uint32_t k = 0; k < len; k += 2) list[kept++] = list[k];
    return kept;
  }
};

template <int D, class R>
void expect_split_lists(bool vector, bool filtered) {
  const auto x = jittered_lattice<D, R>(D == 3 ? 12 : 40, 0.025, 0.45 * 0.025, 11, true);
  const R r = static_cast<R>(2.6 * 0.025), inner = static_cast<R>(1.9 * 0.025);
  UniformGrid<D, R> grid;
  grid.build(x, r);
  ListBuilder<D, R> plain, split;
  plain.use_vector_kernel(vector);
  split.use_vector_kernel(vector);
  split.split_at(inner);
  EveryOtherFilter filter;
  filter.shown.resize(x.size());
  if (filtered) split.set_filter(&filter);
  NeighborLists a, b;
  plain.build(grid, x, r, a);
  split.build(grid, x, r, b);
  ASSERT_EQ(b.particle_count(), x.size());
  std::size_t inner_entries = 0, outer_entries = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    // The plain list's entries closer than `inner`, then the others, each in the plain list's order.
    std::vector<std::uint32_t> near, far;
    for (const std::uint32_t j : a.of(i)) (norm2(x[i] - x[j]) < inner * inner ? near : far).push_back(j);
    inner_entries += near.size();
    outer_entries += far.size();
    if (filtered) {
      ASSERT_EQ(filter.shown[i], far) << "the filter sees the entries beyond the inner radius, particle " << i;
      std::vector<std::uint32_t> kept;
      for (std::size_t k = 0; k < far.size(); k += 2) kept.push_back(far[k]);
      far = kept;
    }
    std::vector<std::uint32_t> want = near;
    want.insert(want.end(), far.begin(), far.end());
    ASSERT_EQ(std::vector<std::uint32_t>(b.of(i).begin(), b.of(i).end()), want) << "particle " << i;
  }
  EXPECT_GT(inner_entries, x.size());  // both parts are there to order
  EXPECT_GT(outer_entries, x.size());
  EXPECT_TRUE(b.padding_is_valid());
}

TEST(FastLists, SplitListsHoldTheEntriesWithinTheInnerRadiusFirst) {
  for (const bool vector : {true, false})
    for (const bool filtered : {false, true}) {
      SCOPED_TRACE(::testing::Message() << "vector kernel " << vector << ", filtered " << filtered);
      expect_split_lists<3, double>(vector, filtered);
      expect_split_lists<3, float>(vector, filtered);
      expect_split_lists<2, double>(vector, filtered);
      expect_split_lists<2, float>(vector, filtered);
    }
}

TEST(FastLists, ParallelCountingSortGivesTheSerialOrder) {
  // 64,000 points in 8,000 cells: with 2 or more threads the grid sorts in parallel blocks;
  // a stable sort by cell has one result, so lists (which follow the grid order) must not change.
  const int saved = num_threads();
  const auto x = jittered_lattice<3, double>(40, 0.025, 0.0025, 5, true);
  std::vector<NeighborLists> lists;
  for (int threads : {1, 2, 3}) {
    set_num_threads(threads);
    UniformGrid<3, double> grid;
    grid.build(x, 0.05);
    ListBuilder<3, double> b;
    lists.emplace_back();
    b.build(grid, x, 0.05, lists.back());
  }
  set_num_threads(saved);
  EXPECT_TRUE(lists[0] == lists[1]);
  EXPECT_TRUE(lists[0] == lists[2]);
  // And the order inside a list is the cell order, stable in the index: check one list by hand.
  UniformGrid<3, double> grid;
  grid.build(x, 0.05);
  const auto l = lists[0].of(1234);
  for (std::size_t k = 1; k < l.size(); ++k) {
    const auto ca = grid.cell_containing(x[l[k - 1]]), cb = grid.cell_containing(x[l[k]]);
    const bool same_row = ca / grid.dims()[0] == cb / grid.dims()[0];
    if (same_row) {
      EXPECT_TRUE(ca < cb || (ca == cb && l[k - 1] < l[k])) << k;
    }
  }
}

TEST(FastLists, PaddingHoldsValidIndicesAfterALargerSetOnTheSameThread) {
  // Vector loops read up to 16 entries past a list: they must be indices of this particle set,
  // never stale ones left by an earlier, larger set (thread-local merge buffers, reused lists).
  const auto big = jittered_lattice<3, double>(18, 0.025, 0.0025, 1, false);   // 5,832 points
  const auto small = jittered_lattice<3, double>(3, 0.025, 0.0025, 2, false);  // 27 points
  UniformGrid<3, double> grid;
  ListBuilder<3, double> builder;
  NeighborLists reused;
  grid.build(big, 0.05);
  builder.build(grid, big, 0.05, reused);
  std::vector<std::uint8_t> all(big.size(), 1);
  builder.rebuild_some(grid, big, 0.05, all, reused);  // fills the merge buffers with big indices
  ASSERT_TRUE(reused.padding_is_valid());
  grid.build(small, 0.05);
  builder.build(grid, small, 0.05, reused);  // the same lists object, now for 27 points
  EXPECT_TRUE(reused.padding_is_valid());
  NeighborLists fresh;
  builder.build(grid, small, 0.05, fresh);
  std::vector<std::uint8_t> some(small.size(), 0);
  some[3] = some[20] = 1;
  builder.rebuild_some(grid, small, 0.05, some, fresh);
  EXPECT_TRUE(fresh.padding_is_valid());
  EXPECT_TRUE(NeighborLists::from({{1}, {0}}).padding_is_valid());
}

TEST(FastLists, ListsThatOutgrowTheirChunksBufferAreExact) {
  // A chunk's buffer keeps no room for one more particle's candidates: a list that may not fit
  // is gathered aside and copied, and the buffer grows only by what the lists take. Lists built
  // again, the same objects, on points compressed to 0.7 of their spacing (each list about
  // three times as long) equal a brute-force search's, in every build path.
  const auto x = jittered_lattice<3, double>(14, 0.025, 0.0025, 9, true);  // 2,744 points: 11 chunks
  auto squeezed = x;
  for (auto& p : squeezed) p = 0.7 * p;
  const NeighborLists expected = brute_force_lists<3, double>(squeezed, 0.05);
  for (bool room : {false, true}) {
    UniformGrid<3, double> grid;
    ListBuilder<3, double> builder;
    builder.keep_room(room);
    NeighborLists built, rebuilt;
    grid.build(x, 0.05);
    builder.build(grid, x, 0.05, built);
    builder.build(grid, x, 0.05, rebuilt);
    grid.build(squeezed, 0.05);
    builder.build(grid, squeezed, 0.05, built);
    const std::vector<std::uint8_t> all(x.size(), 1);
    builder.rebuild_some(grid, squeezed, 0.05, all, rebuilt);
    for (const NeighborLists* l : {&built, &rebuilt}) {
      ASSERT_EQ(l->particle_count(), x.size());
      EXPECT_TRUE(l->padding_is_valid()) << room;
      for (std::size_t i = 0; i < x.size(); ++i) {
        auto got = l->of(i), want = expected.of(i);
        std::vector<std::uint32_t> a(got.begin(), got.end()), b(want.begin(), want.end());
        std::sort(a.begin(), a.end());
        std::sort(b.begin(), b.end());
        ASSERT_EQ(a, b) << "point " << i << (room ? ", lists with room" : "");
      }
    }
  }
}

TEST(FastLists, PairsExactlyAtRadiusAreExcluded) {
  // Points on an exact lattice at spacing 1 with r = 2: the neighbors at distance exactly 2
  // are not strictly closer and must be left out by both kernels.
  std::vector<Vec<3, double>> x;
  for (int k = 0; k < 6; ++k)
    for (int j = 0; j < 6; ++j)
      for (int i = 0; i < 6; ++i) x.push_back({double(i), double(j), double(k)});
  UniformGrid<3, double> grid;
  grid.build(x, 2.0);
  for (bool vector : {true, false}) {
    ListBuilder<3, double> b;
    b.use_vector_kernel(vector);
    NeighborLists l;
    b.build(grid, x, 2.0, l);
    const NeighborLists bf = brute_force_lists<3, double>(x, 2.0);
    for (std::size_t i = 0; i < x.size(); ++i) {
      std::vector<std::uint32_t> got(l.of(i).begin(), l.of(i).end());
      std::sort(got.begin(), got.end());
      ASSERT_TRUE(std::equal(got.begin(), got.end(), bf.of(i).begin(), bf.of(i).end())) << "particle " << i;
    }
    // An interior point: 6 at 1, 12 at sqrt 2, 8 at sqrt 3, none at 2: 26 neighbors.
    EXPECT_EQ(l.of(2 + 6 * 2 + 36 * 2).size(), 26u);
  }
}

TEST(NeighborListsStorage, FromAndEqualityCompareListsInOrder) {
  std::vector<std::vector<std::uint32_t>> v(2500);
  for (std::size_t i = 0; i < v.size(); ++i)
    for (std::uint32_t k = 0; k < i % 7; ++k) v[i].push_back(static_cast<std::uint32_t>((i * 31 + k) % 2500));
  const NeighborLists a = NeighborLists::from(v);
  ASSERT_EQ(a.particle_count(), v.size());
  std::size_t entries = 0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    entries += v[i].size();
    ASSERT_TRUE(std::equal(a.of(i).begin(), a.of(i).end(), v[i].begin(), v[i].end())) << i;
  }
  EXPECT_EQ(a.entry_count(), entries);
  EXPECT_TRUE(a == NeighborLists::from(v));
  auto w = v;
  std::swap(w[1500][0], w[1500][1]);  // same set, other order
  EXPECT_FALSE(a == NeighborLists::from(w));
  EXPECT_GT(a.memory_bytes(), entries * sizeof(std::uint32_t));
}

TEST(FastLists, RebuildSomeLeavesUnmarkedChunksUntouchedAndAppends) {
  auto x = jittered_lattice<3, double>(16, 0.025, 0.0025, 3, false);  // 4096 points: 4 chunks
  const double r = 0.05;
  UniformGrid<3, double> grid;
  grid.build(x, r);
  ListBuilder<3, double> b;
  NeighborLists lists;
  b.build(grid, x, r, lists);
  const std::uint32_t* chunk0 = lists.of(0).data();
  // Move one particle of chunk 2, append 100 particles, rebuild the moved one only.
  x[2100][0] += 0.01;
  for (int k = 0; k < 100; ++k) x.push_back(Vec<3, double>{0.2 + 0.001 * k, 0.2, 0.2});
  std::vector<std::uint8_t> flags(x.size(), 0);
  flags[2100] = 1;
  grid.build(x, r);
  b.rebuild_some(grid, x, r, flags, lists);
  ASSERT_EQ(lists.particle_count(), x.size());
  EXPECT_EQ(lists.of(0).data(), chunk0) << "an unmarked chunk was copied";
  const NeighborLists exact = brute_force_lists<3, double>(x, r);
  for (std::size_t i : {std::size_t{2100}, x.size() - 1, x.size() - 100}) {
    std::vector<std::uint32_t> got(lists.of(i).begin(), lists.of(i).end()),
        want(exact.of(i).begin(), exact.of(i).end());
    std::sort(got.begin(), got.end());
    EXPECT_EQ(got, want) << "particle " << i;
  }
}

// The builds find each chunk's stencils once per cell (a table of the chunk's cells). On particles
// in random order, whose chunks each lie in up to 256 cells (the table's limit) with colliding
// slots, every list is the one read from the grid particle by particle: the candidates of the
// particle's cell's stencil ranges, in their order, closer than r.
template <int D, class R>
void expect_lists_read_from_each_particles_stencil(const std::vector<Vec<D, R>>& x, R r) {
  UniformGrid<D, R> grid;
  grid.build(x, r);
  ListBuilder<D, R> b;
  NeighborLists whole, each;
  b.build(grid, x, r, whole);
  b.rebuild_some(grid, x, r, std::vector<std::uint8_t>(x.size(), 1), each);  // every list, from none
  EXPECT_GT(whole.entry_count(), x.size());
  std::vector<std::vector<std::uint32_t>> want(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    std::uint32_t begin[UniformGrid<D, R>::kMaxRanges], end[UniformGrid<D, R>::kMaxRanges];
    const int ranges = grid.stencil_ranges(grid.cell_containing(x[i]), begin, end);
    for (int q = 0; q < ranges; ++q)
      for (std::uint32_t k = begin[q]; k < end[q]; ++k) {
        const std::uint32_t j = grid.sorted()[k];
        if (j != i && norm2(x[i] - x[j]) < r * r) want[i].push_back(j);
      }
  }
  EXPECT_TRUE(whole == NeighborLists::from(want)) << D << "D: build()";
  EXPECT_TRUE(each == NeighborLists::from(want)) << D << "D: rebuild_some()";
}

TEST(FastLists, ChunksStencilTableGivesEachParticlesOwnStencilsLists) {
  // 2D: 1,024 cells of 2 spacings, so a chunk of 256 shuffled particles lies in about 200.
  expect_lists_read_from_each_particles_stencil<2, float>(jittered_lattice<2, float>(64, 0.025, 0.0025, 5, true),
                                                          0.05f);
  expect_lists_read_from_each_particles_stencil<3, double>(jittered_lattice<3, double>(20, 0.025, 0.0025, 9, true),
                                                           0.05);
}

// balance_loops' work: each chunk's entries, counted for lists laid one after the other (from
// their chunk's last end) and for lists with room of their own (list by list), after a build and
// after a partial rebuild that appends particles (a last chunk that is not full).
TEST(NeighborListsStorage, ChunkEntriesAreEachChunksListSizes) {
  for (bool room : {false, true}) {
    SCOPED_TRACE(room ? "with room" : "without room");
    auto x = jittered_lattice<3, double>(12, 0.025, 0.0025, 5, true);  // 1,728 points: 7 chunks
    const double r = 0.05;
    UniformGrid<3, double> grid;
    grid.build(x, r);
    ListBuilder<3, double> b;
    b.keep_room(room);
    NeighborLists lists;
    b.build(grid, x, r, lists);
    const auto expect_sizes = [&] {
      std::vector<std::uint64_t> work(chunk_count(lists.particle_count()), 5), want(work);
      for (std::size_t i = 0; i < lists.particle_count(); ++i) want[i / kChunkSize] += lists.of(i).size();
      lists.add_chunk_entries(work);
      EXPECT_EQ(work, want);
      EXPECT_EQ(std::accumulate(want.begin(), want.end(), std::uint64_t{0}), 5 * want.size() + lists.entry_count());
    };
    expect_sizes();
    for (int k = 0; k < 40; ++k) x.push_back(Vec<3, double>{0.1 + 0.01 * k, 0.1, 0.1});
    std::vector<std::uint8_t> flags(x.size(), 0);
    flags[300] = flags[1000] = 1;
    x[300][0] += 0.01;
    grid.build(x, r);
    b.rebuild_some(grid, x, r, flags, lists);
    ASSERT_EQ(lists.particle_count(), x.size());
    expect_sizes();
  }
}

template <int D>
void expect_morton_is_stable_permutation() {
  auto x = jittered_lattice<D, double>(D == 3 ? 20 : 90, 0.025, 0.0025, 11, true);
  x.push_back(x[5]);  // a duplicate: same cell, must keep index order
  MortonOrder<D, double> order;
  const std::span<const std::uint32_t> result = order.compute(x, 0.05);
  const std::vector<std::uint32_t> perm(result.begin(), result.end());
  ASSERT_EQ(perm.size(), x.size());
  std::vector<std::uint32_t> seen(perm);
  std::sort(seen.begin(), seen.end());
  for (std::size_t k = 0; k < seen.size(); ++k) ASSERT_EQ(seen[k], k);
  const auto at5 = std::find(perm.begin(), perm.end(), 5u), at_dup = std::find(perm.begin(), perm.end(), x.size() - 1);
  EXPECT_LT(at5, at_dup);
  // Locality: consecutive points along the curve are close; in shuffled input order they are not.
  const auto mean_step = [&](auto index) {
    double s = 0;
    for (std::size_t k = 1; k < x.size(); ++k) s += std::sqrt(norm2(x[index(k)] - x[index(k - 1)]));
    return s / static_cast<double>(x.size() - 1);
  };
  const double along = mean_step([&](std::size_t k) { return perm[k]; });
  const double input = mean_step([](std::size_t k) { return k; });
  EXPECT_LT(along, 0.1);        // about two spacings
  EXPECT_GT(input, 5 * along);  // the shuffle scattered them
  // Same input, same permutation.
  const std::span<const std::uint32_t> again = order.compute(x, 0.05);
  EXPECT_TRUE(std::equal(perm.begin(), perm.end(), again.begin(), again.end()));
  // And with a grid's memory lent for the sort's arrays: the same permutation, the grid built
  // afterwards as without the loan, and the lent memory keeps its block (none new).
  // Cells of 0.05 take 2 radix passes, of 0.004 3 (the result in the second copy), and 3D cells
  // of 0.0002 need 64-bit keys (in 2D, 16 bytes a point: more than a 2D grid lends).
  for (const double cell : {0.05, 0.004, 0.0002}) {
    MortonOrder<D, double> alone;
    const std::span<const std::uint32_t> own_result = alone.compute(x, cell);
    const std::vector<std::uint32_t> own(own_result.begin(), own_result.end());
    // (the reference: a stable sort of the indices by their Morton keys, computed here)
    Vec<D, double> lo = x[0];
    for (const auto& p : x)
      for (int d = 0; d < D; ++d) lo[d] = std::min(lo[d], p[d]);
    const double inv = 1.0 / cell;
    std::vector<std::uint64_t> key(x.size());
    for (std::size_t i = 0; i < x.size(); ++i) {
      std::uint32_t c[3] = {0, 0, 0};
      for (int d = 0; d < D; ++d) c[d] = static_cast<std::uint32_t>((x[i][d] - lo[d]) * inv);
      key[i] = D == 2 ? morton_key(c[0], c[1]) : morton_key(c[0], c[1], c[2]);
    }
    std::vector<std::uint32_t> reference(x.size());
    std::iota(reference.begin(), reference.end(), 0u);
    std::stable_sort(reference.begin(), reference.end(),
                     [&](std::uint32_t a, std::uint32_t b) { return key[a] < key[b]; });
    EXPECT_EQ(own, reference) << cell;
    UniformGrid<D, double> grid, plain;
    grid.build(x, 0.05);
    ScratchBuffer& lent = grid.lend_scratch(x.size());
    const std::size_t room = lent.capacity();
    const std::byte* block = lent.at<std::byte>(0);
    MortonOrder<D, double> borrowing;
    const std::span<const std::uint32_t> with_loan = borrowing.compute(x, cell, &lent);
    EXPECT_TRUE(std::equal(own.begin(), own.end(), with_loan.begin(), with_loan.end())) << cell;
    // (the result lies in the lent memory: a double grid lends 4 + 8 D bytes a point, and the
    // sort needs 16 with 32-bit keys, 24 with 64-bit ones)
    const auto* first = reinterpret_cast<const std::byte*>(with_loan.data());
    EXPECT_TRUE(first >= block && first < block + room) << cell;
    EXPECT_EQ(lent.capacity(), room);
    EXPECT_EQ(lent.at<std::byte>(0), block);
    grid.build(x, 0.05);
    plain.build(x, 0.05);
    for (std::size_t i = 0; i < x.size(); ++i) ASSERT_EQ(grid.sorted()[i], plain.sorted()[i]) << cell;
    for (int d = 0; d < D; ++d)
      for (std::size_t i = 0; i < x.size(); ++i) ASSERT_EQ(grid.sorted_coord(d)[i], plain.sorted_coord(d)[i]) << cell;
    EXPECT_EQ(lent.at<std::byte>(0), block);  // (the build found its room)
  }
}

TEST(MortonOrder, StablePermutationWithLocality3d) { expect_morton_is_stable_permutation<3>(); }
TEST(MortonOrder, StablePermutationWithLocality2d) { expect_morton_is_stable_permutation<2>(); }

TEST(MortonOrder, KeysInterleaveBits) {
  EXPECT_EQ(morton_key(1u, 0u, 0u), 1u);
  EXPECT_EQ(morton_key(0u, 1u, 0u), 2u);
  EXPECT_EQ(morton_key(0u, 0u, 1u), 4u);
  EXPECT_EQ(morton_key(3u, 3u, 3u), 63u);
  EXPECT_EQ(morton_key(1u, 1u), 3u);
  EXPECT_EQ(morton_key(2u, 0u), 4u);
  EXPECT_EQ(morton_key((1u << 21) - 1, 0u, 0u), 0x1249249249249249ull);
}

TEST(MortonOrder, RefusesNonFinitePositions) {
  std::vector<Vec<2, double>> x{{0, 0}, {std::nan(""), 1}};
  MortonOrder<2, double> order;
  EXPECT_THROW(order.compute(x, 0.1), std::logic_error);  // a bug upstream: the solver stops first
}

}  // namespace
}  // namespace sph
