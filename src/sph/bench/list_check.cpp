#include <sph/bench/list_check.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/format.h>

#include <sph/core/parallel.h>
#include <sph/neighbors/standard.h>

namespace sph {

ListsView view_of(const NeighborLists& lists) {
  return {lists.particle_count(), [&lists](std::size_t k) { return lists.of(k); }};
}

namespace {

/// Lists in the points' own index space, each sorted: list i is idx[off[i] .. off[i+1]).
struct FlatLists {
  std::vector<std::uint64_t> off;
  std::vector<std::uint32_t> idx;
  std::span<const std::uint32_t> of(std::size_t i) const {
    return {idx.data() + off[i], static_cast<std::size_t>(off[i + 1] - off[i])};
  }
};

/// The first problem reported by any chunk, in chunk order (so the message does not depend on
/// the thread count).
class FirstProblem {
 public:
  explicit FirstProblem(std::size_t chunks) : per_chunk_(chunks) {}
  void set(std::size_t chunk, std::string message) {
    if (per_chunk_[chunk].empty()) per_chunk_[chunk] = std::move(message);
  }
  bool has(std::size_t chunk) const { return !per_chunk_[chunk].empty(); }
  std::string first() const {
    for (const auto& m : per_chunk_)
      if (!m.empty()) return m;
    return {};
  }

 private:
  std::vector<std::string> per_chunk_;
};

template <int D, std::floating_point R>
std::string where(std::span<const Vec<D, R>> x, std::size_t i) {
  std::string s = fmt::format("particle {} at (", i);
  for (int d = 0; d < D; ++d) s += fmt::format("{}{:.6g}", d ? ", " : "", static_cast<double>(x[i][d]));
  return s + ")";
}

template <int D, std::floating_point R>
double distance_in_radii(std::span<const Vec<D, R>> x, std::size_t i, std::size_t j, R radius) {
  double d2 = 0;
  for (int d = 0; d < D; ++d) {
    const double t = static_cast<double>(x[i][d]) - static_cast<double>(x[j][d]);
    d2 += t * t;
  }
  return std::sqrt(d2) / static_cast<double>(radius);
}

/// Describes how `got` (sorted) differs from `want` (sorted) for particle i, or "" if equal.
template <int D, std::floating_point R>
std::string set_difference(std::span<const Vec<D, R>> x, R radius, std::size_t i, std::span<const std::uint32_t> got,
                           std::span<const std::uint32_t> want, const char* exact_name) {
  if (std::equal(got.begin(), got.end(), want.begin(), want.end())) return {};
  std::vector<std::uint32_t> missing, extra;
  std::set_difference(want.begin(), want.end(), got.begin(), got.end(), std::back_inserter(missing));
  std::set_difference(got.begin(), got.end(), want.begin(), want.end(), std::back_inserter(extra));
  const auto names = [&](const std::vector<std::uint32_t>& v) {
    if (v.empty()) return std::string("none");
    std::string s;
    for (std::size_t k = 0; k < v.size() && k < 3; ++k)
      s += fmt::format("{}{} (at {:.6f} r)", k ? ", " : "", v[k], distance_in_radii<D, R>(x, i, v[k], radius));
    if (v.size() > 3) s += fmt::format(" and {} more", v.size() - 3);
    return s;
  };
  return fmt::format("{}: the lists give {} neighbors, {} finds {}; missing: {}; not neighbors: {}", where<D, R>(x, i),
                     got.size(), exact_name, want.size(), names(missing), names(extra));
}

/// Whether `perm` (if not empty) is a permutation of 0..n-1: "" if so, else the problem.
std::string check_order(std::span<const std::uint32_t> perm, std::size_t n) {
  if (perm.empty()) return {};
  if (perm.size() != n) return fmt::format("the order has {} entries, expected {}", perm.size(), n);
  std::vector<std::uint8_t> seen(n, 0);
  for (std::size_t k = 0; k < n; ++k) {
    if (perm[k] >= n || seen[perm[k]]) return fmt::format("the order is not a permutation (entry {})", k);
    seen[perm[k]] = 1;
  }
  return {};
}

/// Step 1: the lists in the points' own index space, sorted, into `flat`; indices out of range
/// are refused first (the problem is returned, "" if none).
template <int D, std::floating_point R>
std::string flatten_lists(std::span<const Vec<D, R>> positions, const ListsView& lists,
                          std::span<const std::uint32_t> perm, FlatLists& flat) {
  const std::size_t n = positions.size();
  const auto original = [&](std::size_t k) -> std::size_t { return perm.empty() ? k : perm[k]; };
  flat.off.assign(n + 1, 0);
  for (std::size_t k = 0; k < n; ++k) {
    const auto list = lists.of(k);
    for (std::uint32_t j : list)
      if (j >= n)
        return fmt::format("{}: the list holds index {}, but there are {} particles",
                           where<D, R>(positions, original(k)), j, n);
    flat.off[original(k) + 1] = list.size();
  }
  for (std::size_t i = 0; i < n; ++i) flat.off[i + 1] += flat.off[i];
  flat.idx.resize(flat.off[n]);
  parallel_for(n, [&](std::size_t k) {
    const auto list = lists.of(k);
    std::uint32_t* out = flat.idx.data() + flat.off[original(k)];
    for (std::size_t e = 0; e < list.size(); ++e) out[e] = static_cast<std::uint32_t>(original(list[e]));
    std::sort(out, out + list.size());
  });
  return {};
}

/// The first entry (i, j) with j < i whose partner (j, i) is missing, described.
template <int D, std::floating_point R>
std::string first_unpartnered(std::span<const Vec<D, R>> positions, R radius, const FlatLists& flat) {
  for (std::size_t i = 0; i < positions.size(); ++i)
    for (std::uint32_t j : flat.of(i)) {
      const auto back = flat.of(j);
      if (j < i && !std::binary_search(back.begin(), back.end(), static_cast<std::uint32_t>(i)))
        return fmt::format("{}: lists {} at {:.6f} r but {} does not list {} (lists are not symmetric)",
                           where<D, R>(positions, i), j, distance_in_radii<D, R>(positions, i, j, radius), j, i);
    }
  return "lists are not symmetric";  // unreachable: the counts differ only if a partner is missing
}

/// Step 2: every entry is not the particle itself, listed once, within the radius, and
/// symmetric. Distances are symmetric bit for bit ((a - b)^2 == (b - a)^2), so the pairs (i, j)
/// with j > i are looked up in list j; if every one is found there and there are as many
/// entries with j < i as with j > i, the partners are all there (no duplicates: the map is one
/// to one).
template <int D, std::floating_point R>
std::string check_entries(std::span<const Vec<D, R>> positions, R radius, const FlatLists& flat) {
  const std::size_t n = positions.size();
  const R r2 = radius * radius;
  const std::size_t chunks = chunk_count(n);
  FirstProblem problems(chunks);
  std::vector<std::uint64_t> upper(chunks, 0), lower(chunks, 0);
  parallel_chunks(n, [&](std::size_t c, std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end && !problems.has(c); ++i) {
      const auto list = flat.of(i);
      for (std::size_t e = 0; e < list.size(); ++e) {
        const std::uint32_t j = list[e];
        if (j == i) {
          problems.set(c, fmt::format("{}: lists itself", where<D, R>(positions, i)));
        } else if (e > 0 && list[e - 1] == j) {
          problems.set(c, fmt::format("{}: lists {} twice", where<D, R>(positions, i), j));
        } else if (j < i) {
          ++lower[c];
        } else if (!(norm2(positions[i] - positions[j]) < r2)) {
          problems.set(c, fmt::format("{}: lists {} at {:.6f} r, not closer than r", where<D, R>(positions, i), j,
                                      distance_in_radii<D, R>(positions, i, j, radius)));
        } else {
          ++upper[c];
          const auto back = flat.of(j);
          if (!std::binary_search(back.begin(), back.end(), static_cast<std::uint32_t>(i)))
            problems.set(c, fmt::format("{}: lists {} but {} does not list {} (lists are not symmetric)",
                                        where<D, R>(positions, i), j, j, i));
        }
        if (problems.has(c)) break;
      }
    }
  });
  if (auto p = problems.first(); !p.empty()) return p;
  std::uint64_t up = 0, low = 0;
  for (std::size_t c = 0; c < chunks; ++c) up += upper[c], low += lower[c];
  return up == low ? std::string() : first_unpartnered<D, R>(positions, radius, flat);
}

/// Step 3 for small sets: every list against brute_force_lists.
template <int D, std::floating_point R>
std::string compare_all_lists(std::span<const Vec<D, R>> positions, R radius, const FlatLists& flat) {
  const std::size_t n = positions.size();
  const NeighborLists exact = brute_force_lists<D, R>(positions, radius);
  FirstProblem problems(chunk_count(n));
  parallel_chunks(n, [&](std::size_t c, std::size_t begin, std::size_t end) {
    std::vector<std::uint32_t> want;
    for (std::size_t i = begin; i < end && !problems.has(c); ++i) {
      const auto e = exact.of(i);
      want.assign(e.begin(), e.end());
      std::sort(want.begin(), want.end());
      problems.set(c, set_difference<D, R>(positions, radius, i, flat.of(i), want, "brute force"));
    }
  });
  return problems.first();
}

/// Step 3 for large sets: `samples` lists, spread evenly over the index range, against an exact
/// search by a sweep over the points sorted by x (no grid involved).
template <int D, std::floating_point R>
std::string compare_sampled_lists(std::span<const Vec<D, R>> positions, R radius, const FlatLists& flat,
                                  std::size_t samples) {
  const std::size_t n = positions.size();
  const R r2 = radius * radius;
  // The points sorted by x, coordinates alongside, so that a slab is one sequential scan.
  struct Point {
    Vec<D, R> x;
    std::uint32_t index;
  };
  std::vector<Point> by_x(n);
  for (std::size_t i = 0; i < n; ++i) by_x[i] = {positions[i], static_cast<std::uint32_t>(i)};
  std::sort(by_x.begin(), by_x.end(),
            [](const Point& a, const Point& b) { return a.x[0] < b.x[0] || (a.x[0] == b.x[0] && a.index < b.index); });
  FirstProblem problems(chunk_count(samples));
  parallel_chunks(samples, [&](std::size_t c, std::size_t begin, std::size_t end) {
    std::vector<std::uint32_t> want;
    for (std::size_t s = begin; s < end && !problems.has(c); ++s) {
      const std::size_t i = samples == 1 ? 0 : s * (n - 1) / (samples - 1);
      const Vec<D, R>& x = positions[i];
      // A point farther than the radius in x is no neighbor: its computed squared distance is
      // at least radius^2 (rounding is monotone). The slab is a little wider than 2 radius so
      // that rounding of its bounds cannot cut a neighbor off.
      const R margin = R(0.01) * radius + R(1e-5) * std::abs(x[0]);
      const R lo = x[0] - radius - margin, hi = x[0] + radius + margin;
      auto it = std::lower_bound(by_x.begin(), by_x.end(), lo, [](const Point& p, R v) { return p.x[0] < v; });
      want.clear();
      for (; it != by_x.end() && it->x[0] <= hi; ++it)
        if (it->index != i && norm2(x - it->x) < r2) want.push_back(it->index);
      std::sort(want.begin(), want.end());
      problems.set(c, set_difference<D, R>(positions, radius, i, flat.of(i), want, "an exact search"));
    }
  });
  return problems.first();
}

}  // namespace

template <int D, std::floating_point R>
ListCheck check_neighbor_lists(std::span<const Vec<D, R>> positions, R radius, const ListsView& lists,
                               std::span<const std::uint32_t> perm, const ListCheckOptions& options) {
  ListCheck res;
  const std::size_t n = positions.size();
  const auto fail = [&](std::string problem) {
    res.ok = false;
    res.problem = std::move(problem);
    return res;
  };
  if (lists.count != n) return fail(fmt::format("the lists cover {} particles, expected {}", lists.count, n));
  if (auto p = check_order(perm, n); !p.empty()) return fail(p);
  FlatLists flat;
  if (auto p = flatten_lists<D, R>(positions, lists, perm, flat); !p.empty()) return fail(p);
  res.entries = flat.off[n];
  if (auto p = check_entries<D, R>(positions, radius, flat); !p.empty()) return fail(p);

  if (n <= options.full_limit) {
    res.method = "every list against brute_force_lists, plus radius and symmetry of every entry";
    res.lists_compared = n;
    if (auto p = compare_all_lists<D, R>(positions, radius, flat); !p.empty()) return fail(p);
    return res;
  }
  const std::size_t samples = std::min(n, std::max<std::size_t>(options.samples, 2));
  res.method = fmt::format(
      "{} sampled lists against an exact search (points sorted by x), plus radius and symmetry of every entry",
      samples);
  res.lists_compared = samples;
  if (auto p = compare_sampled_lists<D, R>(positions, radius, flat, samples); !p.empty()) return fail(p);
  return res;
}

#define SPH_INSTANTIATE(D, R)                                                                    \
  template ListCheck check_neighbor_lists<D, R>(std::span<const Vec<D, R>>, R, const ListsView&, \
                                                std::span<const std::uint32_t>, const ListCheckOptions&);
SPH_INSTANTIATE(2, float)
SPH_INSTANTIATE(2, double)
SPH_INSTANTIATE(3, float)
SPH_INSTANTIATE(3, double)
#undef SPH_INSTANTIATE

}  // namespace sph
