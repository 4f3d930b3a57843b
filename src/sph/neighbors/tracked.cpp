#include <sph/neighbors/tracked.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include <sph/core/error.h>
#include <sph/core/parallel.h>
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
}

template <int D, std::floating_point R>
void TrackedNeighbors<D, R>::choose_skin(const ParticleSet<D, R>& particles) {
  if (fixed_skin_ > R(0)) return;
  const std::size_t n = particles.size();
  chunk_speed_.assign(chunk_count(n), R(0));
  parallel_chunks(n, [&](std::size_t c, std::size_t b, std::size_t e) {
    R sum = 0;
    for (std::size_t i = b; i < e; ++i) sum += std::sqrt(norm2(particles.velocity[i]));
    chunk_speed_[c] = sum;
  });
  double sum = 0;  // in chunk order: the same for any thread count
  for (R s : chunk_speed_) sum += static_cast<double>(s);
  const double mean = n > 0 ? sum / static_cast<double>(n) : 0.0;
  const R skin = static_cast<R>(tracked_skin(radius_, mean, dt_, D));
  if (skin == skin_) return;
  set_skin(skin);
}

template <int D, std::floating_point R>
void TrackedNeighbors<D, R>::set_skin(R skin) {
  skin_ = skin;
  // The samples' grid is indexed for the lists' radius.
  samples_copy_.assign(this->boundary_.samples().begin(), this->boundary_.samples().end());
  if (!samples_copy_.empty()) this->boundary_.set_samples(samples_copy_, radius_ + skin_);
}

template <int D, std::floating_point R>
void TrackedNeighbors<D, R>::full_build(const ParticleSet<D, R>& particles) {
  Stopwatch watch;
  choose_skin(particles);
  const R r = radius_ + skin_;
  grid_.build(particles.position, r);
  counters_.grid_seconds = watch.lap();
  builder_.build(grid_, particles.position, r, lists_);
  this->boundary_.build(particles.position);
  built_at_.assign(particles.position.begin(), particles.position.end());
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
  const bool full = invalid_ || old_n == 0 || built_at_.size() != old_n || updates_ % period_ == 0;
  invalid_ = false;
  ++updates_;
  counters_ = {};
  if (exit_test_) flags_.resize(n, 0);
  if (full) {
    full_build(particles);
  } else {
    // 1. Marks: moved more than the trigger since its own build, emitted since the last update, or
    // (exit test) flagged by Eq. 7.
    const R t2 = trigger() * trigger();
    marks_.assign(n, 0);
    const std::size_t chunks = chunk_count(n);
    chunk_counts_.assign(chunks, 0);
    parallel_chunks(n, [&](std::size_t c, std::size_t b, std::size_t e) {
      std::uint32_t count = 0;
      for (std::size_t i = b; i < e; ++i) {
        const bool mark = i >= old_n || !(norm2(particles.position[i] - built_at_[i]) <= t2) ||  // NaN: rebuilt
                          (exit_test_ && flags_[i] != 0);
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
      const R r = radius_ + skin_;
      grid_.build(particles.position, r);
      counters_.grid_seconds = watch.lap();
      built_at_.resize(n);
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
          self.built_at_[i] = ps.position[i];
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
  lists_.load(in);
  this->boundary_.load(in, particles);
  in.expect(updates_ >= 0 && built_at_.size() == lists_.particle_count() && built_at_.size() <= particles &&
                flags_.size() <= particles && (lists_.particle_count() == 0 || lists_.has_room()),
            "tracked neighbor state does not match the particles");
}

template class TrackedNeighbors<2, float>;
template class TrackedNeighbors<2, double>;
template class TrackedNeighbors<3, float>;
template class TrackedNeighbors<3, double>;

}  // namespace sph
