#include <sph/neighbors/tracked.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include <sph/core/error.h>
#include <sph/core/parallel.h>
#include <sph/core/simd.h>
#include <sph/core/state_stream.h>
#include <sph/core/timer.h>

namespace sph {

double tracked_skin(double h, double mean_speed, double dt, int dimension) {
  const double s = std::sqrt(3.0 * kTrackedRebuildCost * std::max(mean_speed, 0.0) * std::max(dt, 0.0) * h /
                             static_cast<double>(dimension));
  return std::clamp(s, 0.02 * h, 0.5 * h);
}

template <int D, std::floating_point R>
TrackedNeighbors<D, R>::TrackedNeighbors(R radius, R skin, int full_rebuild_period, R time_step, bool exit_test)
    : radius_(radius),
      fixed_skin_(skin),
      skin_(skin > R(0) ? skin : static_cast<R>(tracked_skin(radius, 0.0, time_step, D))),
      dt_(time_step),
      period_(full_rebuild_period),
      exit_test_(exit_test) {
  SPH_CHECK(radius > R(0), "neighbor radius must be positive");
  SPH_CHECK(skin >= R(0), "tracked skin must not be negative");
  SPH_CHECK(full_rebuild_period >= 1, "full rebuild period must be at least 1");
  builder_.keep_room(true);
  builder_.split_at(sure_radius());
}

template <int D, std::floating_point R>
R TrackedNeighbors<D, R>::window(const Vec<D, R>& v) const {
  const double speed = std::sqrt(static_cast<double>(norm2(v)));
  return speed > 0 ? static_cast<R>(kTrackedReach * static_cast<double>(radius_) / speed)
                   : std::numeric_limits<R>::infinity();
}

template <int D, std::floating_point R>
void TrackedNeighbors<D, R>::size_paths(std::size_t n) {
  for (auto* v : {&built_at_, &built_velocity_, &path_now_}) v->resize(n);
  built_time_.resize(n);
  window_end_.resize(n);
  left_.resize(n);
  filter_.self = this;  // (set before each build: the strategy may have been moved)
  builder_.set_filter(&filter_);
}

template <int D, std::floating_point R>
void TrackedNeighbors<D, R>::start_path(const ParticleSet<D, R>& ps, std::size_t i) {
  built_at_[i] = path_now_[i] = ps.position[i];
  built_velocity_[i] = ps.velocity[i];
  built_time_[i] = time_;
  left_[i] = window(ps.velocity[i]);
  window_end_[i] = time_ + static_cast<double>(left_[i]);
}

template <int D, std::floating_point R>
std::uint32_t TrackedNeighbors<D, R>::PathFilter::keep(std::size_t i, std::uint32_t* list, std::uint32_t len) const {
  // The closest approach of the two paths over [now, the first window's end]: the relative path
  // r0 + dw t, 0 <= t <= min(left_i, left_j); receding or parallel paths are closest now. Lanes
  // of simd::Pack (the portable Pack where AVX-512 is missing: the same operations in the same
  // order, so the same lists), and symmetric bit for bit when both particles are rebuilt now:
  // r0 and dw change sign, and j's path is where j is.
  using P = simd::Pack<R>;
  constexpr int kW = simd::kLanes<R>;
  const TrackedNeighbors& t = *self;
  const std::span<const R> path = flat(t.path_now_), w = flat(t.built_velocity_);
  const R* left = t.left_.data();
  const R reach = t.radius_ + t.skin_;
  const P reach2 = P::set1(reach * reach), zero = P::set1(R(0)), li = P::set1(t.left_[i]);
  P xi[D], wi[D];
  for (int d = 0; d < D; ++d) xi[d] = P::set1(t.built_at_[i][d]), wi[d] = P::set1(t.built_velocity_[i][d]);
  std::uint32_t kept = 0;
  alignas(64) std::uint32_t idx[kW];
  for (std::uint32_t k = 0; k < len; k += kW) {
    const std::uint32_t lanes = std::min<std::uint32_t>(kW, len - k);
    for (int l = 0; l < kW; ++l) idx[l] = list[k + std::min<std::uint32_t>(static_cast<std::uint32_t>(l), lanes - 1)];
    P r0[D], dw[D];
    simd::gather_vectors<D>(path, idx, r0);
    simd::gather_vectors<D>(w, idx, dw);
    for (int d = 0; d < D; ++d) {
      r0[d] = xi[d] - r0[d];
      dw[d] = wi[d] - dw[d];
    }
    P d2 = r0[0] * r0[0], b = r0[0] * dw[0], a = dw[0] * dw[0];
    for (int d = 1; d < D; ++d) d2 = d2 + r0[d] * r0[d], b = b + r0[d] * dw[d], a = a + dw[d] * dw[d];
    // (only lanes with b < 0 use t; there a > 0)
    const simd::Mask approach = (b < zero) & (d2 > reach2);
    if (approach != 0) {
      const P lj = P::template gather<1>(left, idx, 0);
      const P span = select(lj < li, lj, li);
      P tm = (zero - b) / select(approach, a, P::set1(R(1)));
      tm = select(span < tm, span, tm);
      P e2 = zero;
      for (int d = 0; d < D; ++d) {
        const P e = r0[d] + dw[d] * tm;
        e2 = e2 + e * e;
      }
      d2 = select(approach, e2, d2);
    }
    simd::Mask meet = ~(d2 > reach2) & simd::first_lanes<R>(lanes);
    for (; meet != 0; meet &= meet - 1) list[kept++] = idx[__builtin_ctz(meet)];
  }
  return kept;
}

template <int D, std::floating_point R>
void TrackedNeighbors<D, R>::choose_skin(const ParticleSet<D, R>& particles) {
  if (fixed_skin_ > R(0)) return;
  const std::size_t n = particles.size();
  chunk_speed_.assign(chunk_count<kSumBlock>(n), R(0));
  parallel_chunks<kSumBlock>(n, [&](std::size_t c, std::size_t b, std::size_t e) {
    R sum = 0;
    for (std::size_t i = b; i < e; ++i) sum += std::sqrt(norm2(particles.velocity[i]));
    chunk_speed_[c] = sum;
  });
  double sum = 0;  // in block order: the same for any thread count
  for (R s : chunk_speed_) sum += static_cast<double>(s);
  const double mean = n > 0 ? sum / static_cast<double>(n) : 0.0;
  const R skin = static_cast<R>(tracked_skin(radius_, mean, dt_, D));
  if (skin == skin_) return;
  set_skin(skin);
}

template <int D, std::floating_point R>
void TrackedNeighbors<D, R>::set_skin(R skin) {
  skin_ = skin;
  builder_.split_at(sure_radius());
  // The samples' grid is indexed for the lists' radius.
  samples_copy_.assign(this->boundary_.samples().begin(), this->boundary_.samples().end());
  if (!samples_copy_.empty()) this->boundary_.set_samples(samples_copy_, boundary_radius());
}

template <int D, std::floating_point R>
void TrackedNeighbors<D, R>::full_build(const ParticleSet<D, R>& particles) {
  Stopwatch watch;
  choose_skin(particles);
  const R r = candidate_radius();
  grid_.build(particles.position, r);
  counters_.grid_seconds = watch.lap();
  const std::size_t n = particles.size();
  size_paths(n);
  parallel_for(n, [&](std::size_t i) { start_path(particles, i); });
  builder_.build(grid_, particles.position, r, lists_);
  this->boundary_.build(particles.position);
  // Room for the changes a step's rebuilds make to other lists: two per particle of a chunk
  // covers steady flows many times over (a vector grows past it only in a violent step).
  changes_.resize(chunk_count(particles.size()));
  for (auto& c : changes_) c.reserve(2 * kChunkSize);
  counters_.lists_rebuilt = particles.size();
  counters_.entries_rebuilt = builder_.entries_written();
}

template <int D, std::floating_point R>
void TrackedNeighbors<D, R>::update(const ParticleSet<D, R>& particles) {
  Stopwatch watch;
  const std::size_t n = particles.size();
  const std::size_t old_n = lists_.particle_count();
  SPH_CHECK(n < kRemove, "too many particles for the tracked lists");
  const bool full = invalid_ || old_n == 0 || built_at_.size() != old_n || built_velocity_.size() != old_n ||
                    built_time_.size() != old_n || window_end_.size() != old_n || updates_ % period_ == 0;
  invalid_ = false;
  ++updates_;
  counters_ = {};
  if (exit_test_) flags_.resize(n, 0);
  if (full) {
    full_build(particles);
  } else {
    // 1. Marks: more than the trigger off its path, its path's window closed, emitted since the
    // last update, or (exit test) flagged by Eq. 7.
    const R t2 = trigger() * trigger();
    marks_.assign(n, 0);
    size_paths(n);
    const std::size_t chunks = chunk_count(n);
    chunk_counts_.assign(chunks, 0);
    parallel_chunks(n, [&](std::size_t c, std::size_t b, std::size_t e) {
      std::uint32_t count = 0;
      for (std::size_t i = b; i < e; ++i) {
        bool mark = i >= old_n || (exit_test_ && flags_[i] != 0) || time_ > window_end_[i];
        if (!mark) {
          path_now_[i] = built_at_[i] + built_velocity_[i] * static_cast<R>(time_ - built_time_[i]);
          left_[i] = static_cast<R>(window_end_[i] - time_);
          mark = !(norm2(particles.position[i] - path_now_[i]) <= t2);  // NaN: rebuilt
        }
        // A marked particle's path starts again here, before any list is built (the path test
        // reads the new paths of the particles rebuilt with it).
        if (mark) start_path(particles, i);
        marks_[i] = mark ? 1 : 0;
        count += mark ? 1 : 0;
      }
      chunk_counts_[c] = count;
    });
    std::size_t marked = 0;
    for (std::size_t c = 0; c < chunks; ++c) marked += chunk_counts_[c];
    counters_.lists_rebuilt = marked;
    if (marked > 0) {
      // 2. The marked lists, from a fresh grid (boundary lists with them). Each rebuild tells
      // what it changes in the lists of unmarked particles (a marked pair is in both new lists
      // or in neither: the distance test is symmetric, bit for bit). Old and new lists are
      // compared through per-thread stamps, one per particle: the old entries get one value, the
      // new ones the next.
      const R r = candidate_radius();
      grid_.build(particles.position, r);
      counters_.grid_seconds = watch.lap();
      changes_.resize(chunks);
      for (std::size_t c = 0; c < chunks; ++c) changes_[c].clear();
      stamps_.resize(static_cast<std::size_t>(num_threads()));
      next_stamp_.resize(stamps_.size(), 0);
      for (std::size_t t = 0; t < stamps_.size(); ++t) {
        if (stamps_[t].size() < n) {
          stamps_[t].reserve(particles.position.capacity());
          stamps_[t].resize(n, 0);
        }
        // An update gives each thread at most two stamps per particle; if that could wrap, start
        // again from clean stamps (an old stamp equal to a new one would hide a change).
        if (next_stamp_[t] > std::numeric_limits<std::uint32_t>::max() - 2 * n - 2) {
          std::fill(stamps_[t].begin(), stamps_[t].end(), 0u);
          next_stamp_[t] = 0;
        }
      }
      struct Diff final : RebuildVisitor {
        TrackedNeighbors& self;
        const ParticleSet<D, R>& ps;
        Diff(TrackedNeighbors& s, const ParticleSet<D, R>& p) : self(s), ps(p) {}
        void rebuilt(std::size_t c, std::size_t i, std::span<const std::uint32_t> before,
                     std::span<const std::uint32_t> after) override {
          std::vector<Change>& out = self.changes_[c];
          const auto me = static_cast<std::uint32_t>(i);
          const std::uint8_t* marks = self.marks_.data();
          if (before.empty()) {  // emitted (or an empty list): enters every new neighbor's list
            for (const std::uint32_t j : after)
              if (!marks[j]) out.push_back({j, me});
            return;
          }
          const auto t = static_cast<std::size_t>(thread_index());
          std::uint32_t* stamp = self.stamps_[t].data();
          const std::uint32_t was = ++self.next_stamp_[t], is = ++self.next_stamp_[t];
          for (const std::uint32_t k : before) stamp[k] = was;
          for (const std::uint32_t j : after) {
            if (stamp[j] != was && !marks[j]) out.push_back({j, me});
            stamp[j] = is;
          }
          for (const std::uint32_t k : before)
            if (stamp[k] != is && !marks[k]) out.push_back({k, me | kRemove});
        }
      } diff(*this, particles);
      builder_.rebuild_some(grid_, particles.position, r, marks_, lists_, &diff);
      this->boundary_.rebuild_some(particles.position, marks_);
      counters_.entries_rebuilt = builder_.entries_written();
      // 3. Applied in chunk order: the same lists for any thread count.
      apply_changes();
      counters_.entries_rebuilt += counters_.insertions;
    }
  }
  if (exit_test_) std::fill(flags_.begin(), flags_.end(), std::uint8_t{0});  // rebuilt lists start clean
  counters_.lists_seconds = watch.lap();
  counters_.pairs_stored = lists_.entry_count();
  counters_.boundary_pairs_stored = this->boundary_.lists().entry_count();
  counters_.skin = static_cast<double>(skin_);
}

template <int D, std::floating_point R>
void TrackedNeighbors<D, R>::apply_changes() {
  NeighborLists& l = lists_;
  for (const std::vector<Change>& changes : changes_)
    for (const Change& ch : changes) {
      const std::size_t j = ch.target;
      const std::uint32_t i = ch.source & ~kRemove;
      std::vector<std::uint32_t>* buf = &l.chunks_[j / kChunkSize];
      if ((ch.source & kRemove) == 0) {
        if (l.end_[j] - l.begin_[j] == l.cap_[j]) {
          const std::uint32_t want = ListBuilder<D, R>::list_capacity(l.cap_[j] + 1);
          l.relayout_chunk(j / kChunkSize, relayout_scratch_,
                           [&](std::size_t q) { return q == j ? want : std::uint32_t{0}; });
          ++counters_.overflows;
        }
        (*buf)[l.end_[j]++] = i;
        ++l.entries_;
        ++counters_.insertions;
      } else {
        std::uint32_t* first = buf->data() + l.begin_[j];
        std::uint32_t* last = buf->data() + l.end_[j];
        std::uint32_t* at = std::find(first, last, i);
        SPH_CHECK(at != last, "tracked lists lost their symmetry");
        *at = *(last - 1);
        *(last - 1) = 0;  // unused room holds valid indices
        --l.end_[j];
        --l.entries_;
        ++counters_.removals;
      }
    }
}

template <int D, std::floating_point R>
void TrackedNeighbors<D, R>::save_state(StateWriter& out) const {
  out.put(updates_);
  out.put(static_cast<std::uint8_t>(invalid_));
  out.put(skin_);
  out.put(flags_);
  out.put(built_at_);
  out.put(built_velocity_);
  out.put(built_time_);
  out.put(window_end_);
  lists_.save(out);
  this->boundary_.save(out);
}

template <int D, std::floating_point R>
void TrackedNeighbors<D, R>::load_state(StateReader& in, std::size_t particles) {
  in.get(updates_);
  invalid_ = in.get<std::uint8_t>() != 0;
  R skin = 0;
  in.get(skin);
  in.expect(skin > R(0) && (fixed_skin_ <= R(0) || skin == fixed_skin_), "tracked neighbor state has another skin");
  if (skin != skin_) set_skin(skin);
  in.get(flags_);
  in.get(built_at_);
  in.get(built_velocity_);
  in.get(built_time_);
  in.get(window_end_);
  lists_.load(in);
  this->boundary_.load(in, particles);
  in.expect(updates_ >= 0 && built_at_.size() == lists_.particle_count() && built_at_.size() <= particles &&
                built_velocity_.size() == built_at_.size() && built_time_.size() == built_at_.size() &&
                window_end_.size() == built_at_.size() && flags_.size() <= particles &&
                (lists_.particle_count() == 0 || lists_.has_room()),
            "tracked neighbor state does not match the particles");
}

template class TrackedNeighbors<2, float>;
template class TrackedNeighbors<2, double>;
template class TrackedNeighbors<3, float>;
template class TrackedNeighbors<3, double>;

}  // namespace sph
