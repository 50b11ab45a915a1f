// What the Bowyer–Watson insertion (insertion.cpp) needs beside its
// triangulation, in 2D and 3D alike, for its parallel phases and its output: the store
// of simplices whose fresh slots workers claim in blocks, a worker's slots
// and conflict-mark epochs, the slabs a phase cuts space into, and the rows
// laid out by lowest id. A simplex type S has `std::int32_t v[K], n[K]`:
// its vertices (the infinite one is -1) and, for each k, 4 u + m for the
// simplex u whose slot m lies across from v[k].
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <stdexcept>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "tessera/buffer.hpp"

namespace tessera::front::insertion {

constexpr std::int32_t infinite = -1;  ///< the vertex every ghost simplex shares

/// The simplices and their conflict marks, in arrays whose slots are written
/// before they are read (Buffers sized without initialising: the capacity
/// reserved ahead of a parallel phase costs no page until it is used, and
/// from 2 MiB up they lie on transparent huge pages, which the walks and
/// cavities read at random). Fresh slots are claimed in blocks, atomically,
/// so that the parallel phases can take them; only the serial code grows
/// the arrays.
template <class S>
class SimplexStore {
 public:
  /// `too_many`: the error when the slots would not fit S::n's numbering.
  explicit SimplexStore(const char* too_many) : too_many_(too_many) {}

  S* simplices() { return simplices_.data(); }
  const S* simplices() const { return simplices_.data(); }
  std::uint32_t* state() { return state_.data(); }
  std::size_t size() const { return size_.load(std::memory_order_relaxed); }
  /// Slots reserved; it changes only serially, so phases read it freely.
  std::size_t capacity() const { return simplices_.size(); }

  /// Throws the store's error where `slots` would not fit S::n's numbering.
  void check_limit(std::size_t slots) const {
    if (slots > max_slots) throw std::length_error(too_many_);
  }
  /// Room for `extra` more slots without growing (serial only); a growth
  /// at least doubles the capacity.
  void reserve(std::size_t extra) {
    const std::size_t need = size() + extra;
    if (need <= capacity()) return;
    check_limit(need);
    grow(std::max(need, 2 * capacity()));
  }
  /// A capacity of at least `cap` slots (at most the numbering's limit),
  /// exactly that where it grows (serial only). Growing copies the slots in
  /// use into new arrays, so the pages of both are touched: callers grow to
  /// what they expect to need, once, rather than doubling again and again.
  void grow(std::size_t cap) {
    cap = std::min(cap, max_slots);
    if (cap <= capacity()) return;
    Buffer<S> t;
    Buffer<std::uint32_t> s;
    t.resize(cap);  // not initialised (Buffer)
    s.resize(cap);
    // memcpy rather than the vectors' own growth: claimed slots not yet
    // written hold indeterminate bytes.
    if (size() > 0) {
      std::memcpy(t.data(), simplices_.data(), size() * sizeof(S));
      std::memcpy(s.data(), state_.data(), size() * sizeof(std::uint32_t));
    }
    if (capacity() != 0) ++growths_;
    simplices_ = std::move(t);
    state_ = std::move(s);
  }
  /// Times the capacity grew after the first allocation.
  std::size_t growths() const { return growths_; }
  /// The first of `count` fresh slots, or nullopt when the capacity is spent.
  std::optional<std::size_t> claim(std::size_t count) {
    std::size_t s = size_.load(std::memory_order_relaxed);
    do {
      if (s + count > capacity()) return std::nullopt;
    } while (!size_.compare_exchange_weak(s, s + count, std::memory_order_relaxed));
    return s;
  }

 private:
  static constexpr std::size_t max_slots = std::size_t{1} << 29;  // 4 u + m fits in int32
  const char* too_many_;
  Buffer<S> simplices_;
  Buffer<std::uint32_t> state_;  // (epoch << 1) | in conflict
  std::size_t growths_ = 0;
  std::atomic<std::size_t> size_{0};
};

/// What one thread of insertion keeps: its partition, its conflict-mark
/// epochs, its walk's start, its free and fresh slots and its buffers.
struct Worker {
  std::uint8_t part = 0;      // the partition it inserts in a parallel phase
  std::uint32_t epoch = 0;    // its marks: part + 1, then steps of the worker count
  std::int32_t last = -1;     // a simplex of its last insertion (the next walk's start), or -1
  std::int32_t prev = -1;     // the vertex it inserted last, or -1
  std::int32_t hull_ghost = -1;  // a ghost of its last insertion when that point lay outside the hull (hull_walk), or -1
  // After a point outside the hull, the next is located by the hull walk or
  // by the plain one, whichever took fewer steps there lately (a moving
  // average of each); every 64th such choice is the other one, to follow
  // a change. The hull walk wins on a thin band of a cylinder (10 steps a
  // point against 417), the plain one on a parabolic cylinder, whose hull
  // facets are strips along its rulings (16 against 78).
  double hull_walk_steps = 0, plain_walk_steps = 0;
  std::uint32_t walk_choices = 0;
  bool prefers_hull_walk() {
    const bool hull = hull_walk_steps <= plain_walk_steps;
    return ++walk_choices % 64 == 0 ? !hull : hull;
  }
  void walked(bool by_hull, std::size_t steps) {
    double& average = by_hull ? hull_walk_steps : plain_walk_steps;
    average += (static_cast<double>(steps) - average) / 8;
  }
  std::size_t guided = 0;     // walks it started by a guide (walk_start)
  std::size_t steps = 0;      // steps its walks took (locate)
  std::uint64_t rng = 0x2545F4914F6CDD1Dull;
  std::vector<std::int32_t> free;        // slots of simplices it removed
  std::size_t fresh = 0, fresh_end = 0;  // claimed slots never used
  std::vector<std::int32_t> deferred;    // points a parallel phase left for later
  std::vector<std::int32_t> cavity;      // the simplices in conflict with the point being inserted

  /// At least `count` more fresh slots. Serially the store grows; in a
  /// parallel phase a spent capacity is a refusal (false).
  template <class S>
  bool claim(SimplexStore<S>& store, std::size_t count, bool parallel) {
    for (std::size_t s = fresh; s < fresh_end; ++s) {  // keep the old block's rest as free slots
      store.state()[s] = 0;
      free.push_back(static_cast<std::int32_t>(s));
    }
    fresh = fresh_end = 0;
    const std::size_t block = std::max(count, fresh_block);
    if (!parallel) store.reserve(block);
    const std::optional<std::size_t> first = store.claim(block);
    if (!first) return false;
    fresh = *first;
    fresh_end = *first + block;
    return true;
  }
  /// Slots this worker has for new simplices without claiming.
  std::size_t slots_at_hand() const { return free.size() + (fresh_end - fresh); }
  /// A slot for a new simplex: a free one, else a fresh one (claim made sure
  /// there is one).
  template <class S>
  std::int32_t allocate(SimplexStore<S>& store) {
    if (!free.empty()) {
      const std::int32_t t = free.back();
      free.pop_back();
      return t;
    }
    const std::size_t t = fresh++;
    store.state()[t] = 0;  // marked by no epoch
    return static_cast<std::int32_t>(t);
  }

  /// Fresh slots a worker claims at a time.
  static constexpr std::size_t fresh_block = 4096;
};

/// Partitions are bytes.
inline constexpr int max_workers = 255;

/// `threads` workers (W derives from Worker), each with its partition and
/// its residue class of epochs, and a walk's random stream of its own.
template <class W>
std::vector<W> make_workers(int threads) {
  std::vector<W> workers(static_cast<std::size_t>(std::clamp(threads, 1, max_workers)));
  for (std::size_t w = 0; w < workers.size(); ++w) {
    workers[w].part = static_cast<std::uint8_t>(w);
    workers[w].epoch = static_cast<std::uint32_t>(w) + 1;
    workers[w].rng += 0x9E3779B97F4A7C15ull * w;
  }
  return workers;
}

/// Marks are (epoch << 1) | bit in 32 bits; the workers' epochs are distinct
/// (worker w's are w + 1 modulo the worker count), so a slot marked by one
/// never reads as marked by another's current insertion.
inline constexpr std::uint32_t epoch_limit = 1u << 30;
template <class S, class W>
void reset_marks(SimplexStore<S>& store, std::vector<W>& workers) {
  std::fill(store.state(), store.state() + store.size(), 0u);
  for (std::size_t w = 0; w < workers.size(); ++w) workers[w].epoch = static_cast<std::uint32_t>(w) + 1;
}

/// A parallel phase's slabs (Triangulation::phase in insertion.cpp): space
/// cut across the widest axis of `pts` other than `cut_axis` (which is then
/// set to this one), at quantiles of the points, one slab per worker, so
/// that each gets as many. part[v] is set to vertex v's slab for every
/// vertex below `end`; `coords` holds D coordinates per vertex.
template <int D>
void cut_slabs(const double* coords, const std::vector<std::int32_t>& pts, std::size_t end, std::size_t threads,
               int& cut_axis, std::vector<std::uint8_t>& part) {
  auto at = [&](std::int32_t v) { return coords + static_cast<std::size_t>(v) * D; };
  double lo[D], hi[D];
  for (int a = 0; a < D; ++a) lo[a] = hi[a] = at(pts[0])[a];
  for (const std::int32_t q : pts)
    for (int a = 0; a < D; ++a) {
      lo[a] = std::min(lo[a], at(q)[a]);
      hi[a] = std::max(hi[a], at(q)[a]);
    }
  int axis = -1;
  for (int a = 0; a < D; ++a)
    if (a != cut_axis && (axis < 0 || hi[a] - lo[a] > hi[axis] - lo[axis])) axis = a;
  cut_axis = axis;
  std::vector<double> x(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) x[i] = at(pts[i])[axis];
  std::vector<double> cut(threads - 1);
  for (std::size_t t = threads - 1; t >= 1; --t) {  // descending: each nth_element narrows the next
    const auto nth = x.begin() + static_cast<std::ptrdiff_t>(t * pts.size() / threads);
    std::nth_element(x.begin(), nth, x.end());
    cut[t - 1] = *nth;
    x.resize(static_cast<std::size_t>(nth - x.begin()) + 1);
  }
  part.resize(end);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, end, 1 << 14), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t v = r.begin(); v != r.end(); ++v)
      part[v] = static_cast<std::uint8_t>(std::upper_bound(cut.begin(), cut.end(), at(static_cast<std::int32_t>(v))[axis]) - cut.begin());
  });
}

/// The finite simplices of `store` (K vertices each), as input ids through
/// `global` (vertex -> id), in the layout of tessera::Delaunay::simplices:
/// each row's ids ascending, except that the last two are swapped where
/// that order is an odd permutation of the stored (positive) one; rows
/// ascending by their sorted ids. Slots in `workers`' free lists and fresh
/// blocks are not simplices. It overwrites the store (the triangulation is
/// spent).
template <int K, class S, class W>
Buffer<std::int32_t> take_rows(SimplexStore<S>& store, const std::vector<std::int32_t>& global,
                               const std::vector<W>& workers) {
  using Row = std::array<std::int32_t, K>;
  const std::size_t size = store.size();
  const S* const simplices = store.simplices();
  std::vector<std::uint8_t> is_free(size, 0);
  for (const W& w : workers) {
    for (const std::int32_t t : w.free) is_free[static_cast<std::size_t>(t)] = 1;
    for (std::size_t t = w.fresh; t < w.fresh_end; ++t) is_free[t] = 1;
  }
  auto live = [&](std::size_t i) {
    if (is_free[i]) return false;
    for (int k = 0; k < K; ++k)
      if (simplices[i].v[k] == infinite) return false;
    return true;
  };
  auto id = [&](std::int32_t v) { return global[static_cast<std::size_t>(v)]; };
  // Slot i's row. The permutation's parity from its inversions, then a
  // sorting network of min/max: no branch on the ids' order (they are random
  // here).
  auto row_of = [&](std::size_t i) {
    Row r;
    int inversions = 0;
    for (int a = 0; a < K; ++a) {
      r[a] = id(simplices[i].v[a]);
      for (int b = 0; b < a; ++b) inversions += r[b] > r[a];
    }
    auto order = [&](int a, int b) {
      const std::int32_t lo = std::min(r[a], r[b]), hi = std::max(r[a], r[b]);
      r[a] = lo;
      r[b] = hi;
    };
    if constexpr (K == 4) {
      order(0, 1);
      order(2, 3);
      order(0, 2);
      order(1, 3);
      order(1, 2);
    } else {
      static_assert(K == 3);
      order(0, 1);
      order(1, 2);
      order(0, 1);
    }
    if (inversions & 1) std::swap(r[K - 2], r[K - 1]);
    return r;
  };
  // Rows ordered by lowest id in two counting passes, each of whose writes
  // stay within a cache-sized region (one scatter to a million ids wrote a
  // cache line per row, at random: 0.7 s of one thread at 1M 3D points).
  // Pass 1, per fixed chunk of slots: its rows, grouped by coarse bucket
  // (the lowest id's top bits), written over the chunk's own simplices
  // once it has read them (a row takes half a simplex's room; a fresh
  // array faulted in 115 MB at 1M 3D points). Pass 2, per bucket: its
  // groups from every chunk, counting-sorted by lowest id straight into the
  // output, then each id's few rows sorted by the rest, which makes the
  // result the same for any slot layout. The simplices are read once, each
  // row is written twice.
  static_assert(2 * sizeof(Row) == sizeof(S));
  std::size_t n_ids = 1;
  for (const std::int32_t g : global) n_ids = std::max(n_ids, static_cast<std::size_t>(g) + 1);
  const int shift = std::max(0, static_cast<int>(std::bit_width(n_ids - 1)) - 10);
  const std::size_t buckets = ((n_ids - 1) >> shift) + 1;
  constexpr std::size_t chunk = 1 << 14;
  const std::size_t chunks = (size + chunk - 1) / chunk;
  // group[c * (buckets + 1) + b]: where chunk c's rows of bucket b start, in
  // rows from grouped(c).
  std::vector<std::uint32_t> group(chunks * (buckets + 1));
  auto grouped = [&](std::size_t c) { return reinterpret_cast<unsigned char*>(store.simplices() + c * chunk); };
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, chunks, 1), [&](const tbb::blocked_range<std::size_t>& range) {
    std::vector<Row> rows;
    rows.reserve(chunk);
    for (std::size_t c = range.begin(); c != range.end(); ++c) {
      rows.clear();
      std::uint32_t* const start = group.data() + c * (buckets + 1);
      std::fill(start, start + buckets + 1, 0u);
      const std::size_t end = std::min(size, (c + 1) * chunk);
      for (std::size_t i = c * chunk; i < end; ++i) {
        // The vertices' ids lie anywhere in global: ask for them ahead.
        if (i + 16 < end)
          for (int k = 0; k < K; ++k) __builtin_prefetch(global.data() + std::max(simplices[i + 16].v[k], 0));
        if (live(i)) {
          rows.push_back(row_of(i));
          ++start[(static_cast<std::size_t>(rows.back()[0]) >> shift) + 1];
        }
      }
      for (std::size_t b = 0; b < buckets; ++b) start[b + 1] += start[b];
      unsigned char* const dst = grouped(c);
      for (const Row& r : rows) std::memcpy(dst + sizeof(Row) * start[static_cast<std::size_t>(r[0]) >> shift]++, r.data(), sizeof(Row));
      // start[b] is now where bucket b ends: shift back to where it starts.
      for (std::size_t b = buckets; b > 0; --b) start[b] = start[b - 1];
      start[0] = 0;
    }
  });
  std::vector<std::size_t> bucket_start(buckets + 1, 0);
  for (std::size_t c = 0; c < chunks; ++c) {
    const std::uint32_t* const start = group.data() + c * (buckets + 1);
    for (std::size_t b = 0; b < buckets; ++b) bucket_start[b + 1] += start[b + 1] - start[b];
  }
  for (std::size_t b = 0; b < buckets; ++b) bucket_start[b + 1] += bucket_start[b];
  auto key_less = [](const Row& a, const Row& b) {  // row[0] is shared; the last two may be swapped
    for (int k = 1; k < K - 2; ++k)
      if (a[k] != b[k]) return a[k] < b[k];
    const std::int32_t a2 = std::min(a[K - 2], a[K - 1]), b2 = std::min(b[K - 2], b[K - 1]);
    if (a2 != b2) return a2 < b2;
    return std::max(a[K - 2], a[K - 1]) < std::max(b[K - 2], b[K - 1]);
  };
  Buffer<std::int32_t> out(K * bucket_start[buckets]);  // every entry is written below
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, buckets, 1), [&](const tbb::blocked_range<std::size_t>& range) {
    std::vector<std::size_t> start;
    std::vector<Row> few;
    for (std::size_t b = range.begin(); b != range.end(); ++b) {
      const std::size_t id0 = b << shift, ids = std::min(n_ids - id0, std::size_t{1} << shift);
      auto each_row = [&](auto&& f) {
        for (std::size_t c = 0; c < chunks; ++c) {
          const std::uint32_t* const g = group.data() + c * (buckets + 1) + b;
          const unsigned char* const rows = grouped(c);
          for (std::uint32_t k = g[0]; k < g[1]; ++k) {
            Row r;
            std::memcpy(r.data(), rows + sizeof(Row) * k, sizeof(Row));
            f(r);
          }
        }
      };
      start.assign(ids + 1, bucket_start[b]);
      each_row([&](const Row& r) { ++start[static_cast<std::size_t>(r[0]) - id0 + 1]; });
      for (std::size_t g = 0; g < ids; ++g) start[g + 1] += start[g] - bucket_start[b];
      std::int32_t* const dst = out.data();
      each_row([&](const Row& r) { std::memcpy(dst + K * start[static_cast<std::size_t>(r[0]) - id0]++, r.data(), sizeof(Row)); });
      // start[g] is now where id g's rows end.
      for (std::size_t g = 0, from = bucket_start[b]; g < ids; from = start[g++])
        if (const std::size_t n = start[g] - from; n > 1) {  // sorted as Rows, copied in and out (no aliasing)
          few.resize(n);
          std::memcpy(few.data(), dst + K * from, n * sizeof(Row));
          if (n > 32) {
            std::sort(few.begin(), few.end(), key_less);
          } else {  // an id has a few rows (3D: 7 on average, 2D: 2)
            for (std::size_t a = 1; a < n; ++a)
              for (std::size_t k = a; k > 0 && key_less(few[k], few[k - 1]); --k) std::swap(few[k], few[k - 1]);
          }
          std::memcpy(dst + K * from, few.data(), n * sizeof(Row));
        }
    }
  });
  return out;
}

}  // namespace tessera::front::insertion
