// Bowyer–Watson insertion in 2D and 3D; see insertion.hpp. One class
// template over the dimension: a simplex has K = D + 1 vertices, a facet
// (its slot across from a vertex) K - 1. What differs by dimension is the
// float filters (insertion_filters.hpp), how the new simplices around a
// point find their partners (3D: a hash by the edge they share, 2D: an array
// by the vertex), and in 2D the ghosts that two workers of a parallel phase
// may both mark (Triangulation::phase).
#include "insertion.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <optional>
#include <stdexcept>
#include <utility>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "insertion_filters.hpp"
#include "insertion_order.hpp"
#include "insertion_phases.hpp"
#include "pass.hpp"
#include "tessera/kernels/delaunay_predicates.hpp"

namespace tessera::front {
namespace {

using kernels::ExactContext;
using insertion::infinite;

/// A triangle (K = 3) or tetrahedron (K = 4): vertices, and for each k what
/// lies across the facet opposite v[k]: 4 u + m for the simplex u whose facet
/// m it is (so the way back needs no search). Finite ones are positively
/// oriented (triangles counter-clockwise); a ghost (one vertex infinite) is
/// oriented as if that vertex were a point beyond its hull facet.
template <int K>
struct Simplex {
  std::int32_t v[K];
  std::int32_t n[K];
};

/// Simplex u's facet m, as Simplex::n holds it; and back.
inline std::int32_t across(std::int32_t u, int m) { return 4 * u + m; }
inline std::int32_t simplex_of(std::int32_t a) { return a >> 2; }
inline int facet_of(std::int32_t a) { return a & 3; }

/// Thrown out of line, so the walk's loop keeps its registers.
[[noreturn, gnu::noinline, gnu::cold]] void walk_did_not_end() {
  throw std::logic_error("tessera: insertion: a point location walk did not end (inconsistent coordinates?)");
}

/// The slot of t's infinite vertex, or K when t is finite.
template <int K>
int infinite_slot(const Simplex<K>& t) {
  for (int k = 0; k < K; ++k)
    if (t.v[k] == infinite) return k;
  return K;
}

/// A worker (insertion_phases.hpp) with the cavity's buffers.
template <int K>
struct Worker : insertion::Worker {
  struct Facet {
    std::int32_t v[K];  // the new simplex's vertices (q at k)
    int k;
    std::int32_t outside;  // the simplex across the facet, not in conflict
    int back;              // its facet towards the cavity
  };
  struct Edge {
    std::uint64_t key = 0;
    std::int32_t tet = -1;
    int slot = 0;
  };
  std::vector<Facet> boundary;
  std::vector<Edge> edges;          // 3D: new tetrahedra by the edge they share
  std::vector<std::uint64_t> used;  // 3D: the entries of edges in use
  std::int32_t pending_infinite = -1;  // 2D: pending_'s entry for the infinite vertex
};

// Weighted: a regular triangulation (ExactContext::radii): power tests,
// hidden points. A template parameter, so the ordinary insertion's hot loop
// carries none of it.
template <int D, bool Weighted>
class Triangulation {
 public:
  static constexpr int K = D + 1;
  using S = Simplex<K>;
  using W = Worker<K>;

  /// Vertices are numbered by `global`, the insertion order: vertex k is
  /// point global[k] of ctx, with its coordinates at coords[D k], so the
  /// points a walk and a cavity meet lie close in memory too.
  Triangulation(const ExactContext& ctx, std::vector<std::int32_t> global, Buffer<double> coords,
                std::vector<std::int32_t> guide, int threads)
      : ctx_(ctx), underflow_(ctx.may_underflow), global_(std::move(global)),
        guide_(std::move(guide)), coords_(std::move(coords)), workers_(insertion::make_workers<W>(threads)) {
    const std::size_t n = global_.size();
    vsimplex_.resize(n);  // written for each vertex as it is inserted
    if constexpr (Weighted) {
      hidden_.assign(n, 0);
      stamp_.assign(n, 0);
      weight_.resize(n);
      for (std::size_t k = 0; k < n; ++k) {
        const double r = ctx.radii[global_[k]];
        weight_[k] = r * r;
      }
    }
    if constexpr (D == 2) pending_.assign(n, -1);
    // A Delaunay tetrahedralisation of uniform points has about 6.8
    // tetrahedra per point, a triangulation 2 triangles. The capacity is
    // address space until used (the arrays are not initialised), so it is
    // sized for the last round's phases at that rate (reserve_round). Input
    // whose simplices could not be numbered even at the uniform rate fails
    // here, before any work.
    store_.check_limit(static_cast<std::size_t>((D == 3 ? 6.8 : 2.0) * static_cast<double>(n)) + 64);
    store_.grow(static_cast<std::size_t>((D == 3 ? 8.0 : 2.5) * static_cast<double>(n)) + 64);
  }

  /// Start from the positively oriented simplex s and its K ghosts.
  void start(std::array<std::int32_t, K> s) {
    const std::size_t first = *store_.claim(K + 1);  // the constructor reserved room
    S* const ss = store_.simplices() + first;
    S t0;
    for (int k = 0; k < K; ++k) {
      t0.v[k] = s[static_cast<std::size_t>(k)];
      t0.n[k] = -1;
    }
    ss[0] = t0;
    for (int k = 0; k < K; ++k) {
      S g = t0;
      g.v[k] = infinite;
      // With the infinite vertex standing for a point beyond facet k (the
      // side away from v[k]) the order is negative: swap two others.
      std::swap(g.v[(k + 1) % K], g.v[(k + 2) % K]);
      ss[k + 1] = g;
    }
    // Link them by their shared facets.
    for (int a = 0; a <= K; ++a) {
      store_.state()[first + static_cast<std::size_t>(a)] = 0;
      for (int ka = 0; ka < K; ++ka)
        for (int b = 0; b <= K; ++b) {
          if (a == b) continue;
          for (int kb = 0; kb < K; ++kb)
            if (same_facet(ss[a], ka, ss[b], kb)) ss[a].n[ka] = across(static_cast<std::int32_t>(first) + b, kb);
        }
    }
    hint_ = static_cast<std::int32_t>(first);
    for (const std::int32_t v : s) vsimplex_[static_cast<std::size_t>(v)] = hint_;
  }

  /// Insert the points `pts` (vertex numbers; none in the triangulation yet),
  /// in their order; `end` bounds every vertex number so far. A large set
  /// goes through two parallel phases (see phase), cut across different
  /// axes; what they leave is inserted serially.
  /// `placed(k)` is told, from the calling thread, that k of the round's
  /// points are in (after each phase and every 16,384 serial insertions).
  template <class Placed>
  void insert_round(std::vector<std::int32_t> pts, std::size_t end, std::size_t parallel_min, Placed&& placed) {
    const std::size_t total = pts.size();
    const std::size_t threads = workers_.size();
    reserve_round(total, end - std::min(end, total));
    if (!pts.empty()) update_centre(static_cast<std::size_t>(pts.front()));
    int cut_axis = -1;
    if (!parallel_ && retry_left_ && retry_from_ != 0 && pts.size() >= retry_from_) {
      parallel_ = true;  // the one retry (below)
      retry_left_ = false;
      ++stats_.resumed;
    }
    for (int k = 0; k < 2 && parallel_ && threads > 1 && pts.size() >= parallel_min * threads; ++k) {
      const std::size_t tried = pts.size();
      pts = phase(pts, end, cut_axis);
      ++stats_.phases;
      stats_.phase_points += tried;
      stats_.deferred += pts.size();
      // Points on a surface (a torus, a terrain) have long tetrahedra
      // across the object, so walks and cavities cross the cuts: when a
      // phase of 2048 points or more defers over a third, the later rounds
      // go serially (a failed walk costs about what its insertion would
      // have). Smaller phases defer many anyway, as their simplices are
      // large next to the slabs. Once, a round three times that phase's
      // size tries again: where the early rounds were sparse (a sphere's
      // first few thousand points, a label image sampled around a few
      // labels) the later ones, denser, defer a few percent (200k points on
      // a sphere: 57% of a 3k-point phase, then 7% at 12.5k).
      if (tried >= 2048 && 3 * pts.size() > tried) {
        parallel_ = false;
        ++stats_.stopped;
        retry_from_ = 3 * tried;
      }
      placed(total - pts.size());
    }
    W& w = workers_[0];
    w.last = hint_;
    w.prev = -1;
    w.hull_ghost = -1;
    const std::size_t before = total - pts.size();
    for (std::size_t k = 0; k < pts.size(); ++k) {
      if (w.epoch >= insertion::epoch_limit) insertion::reset_marks(store_, workers_);
      if (!insert<false>(w, pts[k])) throw std::logic_error("tessera: insertion: a serial insertion was refused");
      if ((k & 16383) == 16383) {
        hint_ = w.last;  // the state stays whole if placed() throws
        placed(before + k + 1);
      }
    }
    hint_ = w.last;
  }

  /// The finite simplices, in the layout of insertion_delaunay. It
  /// overwrites the store (the triangulation is spent).
  Buffer<std::int32_t> take_rows() { return insertion::take_rows<K>(store_, global_, workers_); }
  InsertionStats stats() const {
    InsertionStats s = stats_;
    s.store_growths = store_.growths();
    for (const W& w : workers_) {
      s.guided += w.guided;
      s.steps += w.steps;
    }
    return s;
  }

 private:
  using Facet = typename W::Facet;
  using Edge = typename W::Edge;

  /// One parallel phase (after Marot, Pellerin & Remacle, "One machine, one
  /// minute, three billion tetrahedra", 2019). Space is cut into slabs
  /// (insertion::cut_slabs), one per worker, with as many of `pts` each;
  /// every vertex so far belongs to the slab it lies in. A worker inserts
  /// its slab's points, in their order, and may only change simplices it
  /// owns (`owned`: all vertices in its slab); a point whose walk or cavity
  /// meets another one is deferred and returned. No two workers then touch
  /// the same simplex:
  /// * a worker changes a simplex's vertices only if it owns it, and its
  ///   links only across a facet whose finite vertices are all its own (a
  ///   facet of a cavity it removes), where the new simplex goes;
  /// * it reads and marks only simplices it owns and those across a facet
  ///   of one (walk steps, cavity neighbours);
  /// * 3D: a tetrahedron with a face all of worker A's (two finite vertices
  ///   at least) and a face all of B's would need two finite vertices of
  ///   each among its four vertices, with one of every face's three left
  ///   out: no such tetrahedron exists (the infinite vertex belongs to
  ///   everyone).
  /// * 2D: likewise no triangle has an edge of two finite vertices all of
  ///   A's and one all of B's. The exception is a ghost (a, b, ∞) with a in
  ///   A's slab and b in B's: it lies across (a, ∞) from a ghost A may own
  ///   and across (b, ∞) from one B may. Neither owns it, so neither
  ///   changes its vertices; each may test it, mark it (the marks are
  ///   relaxed atomics, and one worker's epochs never match another's) and
  ///   rewrite its own link slot (opposite b, or opposite a: different
  ///   words). The link across (a, b), which a test of it reads, only
  ///   changes serially. Points on a circle are all on the hull: a first
  ///   version that let no worker own a ghost deferred every one of them.
  /// The triangulation stays the Delaunay triangulation of the points
  /// inserted so far; it is unique (perturbed predicates), so the order of
  /// insertion, and with it the thread count, does not change the result.
  /// Slabs rather than runs of the Morton order: a run's boundary follows
  /// the curve's top bits, which cut a flat input (a torus, a terrain)
  /// along its thin side, where nearly every tetrahedron crosses the cut.
  std::vector<std::int32_t> phase(const std::vector<std::int32_t>& pts, std::size_t end, int& cut_axis) {
    const std::size_t threads = workers_.size();
    insertion::cut_slabs<D>(coords_.data(), pts, end, threads, cut_axis, part_);
    // Each worker's points, in their order.
    std::vector<std::vector<std::int32_t>> mine(threads);
    for (const std::int32_t q : pts) mine[part_[static_cast<std::size_t>(q)]].push_back(q);
    // A simplex each worker owns, to start its walks from: the one holding
    // one of its points, tried at spread positions of its list, as the first
    // points in Morton order of a slab may all lie along its cut (found
    // serially, each walk starting where the last ended). A worker with
    // none defers its points.
    std::int32_t walk_from = hint_;
    for (std::size_t t = 0; t < threads; ++t) {
      W& w = workers_[t];
      w.deferred.clear();
      w.last = -1;
      w.prev = -1;
      w.hull_ghost = -1;
      const std::size_t tries = std::min<std::size_t>(mine[t].size(), 64);
      for (std::size_t k = 0; k < tries && w.last < 0; ++k) {
        const std::int32_t t0 = locate<false>(w, mine[t][k * mine[t].size() / tries], walk_from);
        walk_from = t0;
        if (owned(store_.simplices()[t0], w.part)) w.last = t0;
      }
      if (w.last < 0) w.deferred = mine[t];
    }
    // Room for every fresh slot the phase may claim (claims beyond it defer
    // their points; reserve_round made room), and marks that cannot wrap
    // within it.
    store_.reserve(phase_slots(pts.size()));
    for (const W& w : workers_)
      if (w.epoch + threads * (pts.size() + 1) >= insertion::epoch_limit) insertion::reset_marks(store_, workers_);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, threads, 1), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t t = r.begin(); t != r.end(); ++t) {
        W& w = workers_[t];
        if (w.last < 0) continue;
        for (const std::int32_t q : mine[t])
          if (!insert<true>(w, q)) w.deferred.push_back(q);
      }
    }, tbb::simple_partitioner());
    // A worker's last simplex is its own and alive; with none (nothing
    // inserted) the previous hint was not touched.
    for (const W& w : workers_)
      if (w.last >= 0) {
        hint_ = w.last;
        break;
      }
    std::vector<std::int32_t> rest;
    for (const W& w : workers_) rest.insert(rest.end(), w.deferred.begin(), w.deferred.end());
    return rest;
  }

  /// Insert point q (not yet in the triangulation, at no vertex's place) by
  /// worker w, starting the walk from w.last. With Check (a parallel phase),
  /// false when the walk or the cavity meets a simplex w does not own, or no
  /// fresh slot is left: nothing has been changed then.
  template <bool Check>
  bool insert(W& w, std::int32_t q) {
    const bool after_hull = w.hull_ghost >= 0;
    const bool by_hull = after_hull && w.prefers_hull_walk();
    const std::size_t steps_before = w.steps;
    std::int32_t t0 = by_hull ? hull_walk<Check>(w, q, w.hull_ghost) : -1;
    if (t0 < 0) t0 = locate<Check>(w, q, walk_start<Check>(w, q));
    if (after_hull) w.walked(by_hull, w.steps - steps_before);
    if (t0 < 0) return false;
    w.epoch += static_cast<std::uint32_t>(workers_.size());
    const std::uint32_t mark_out = w.epoch << 1, mark_in = mark_out | 1;
    S* ss = store_.simplices();
    std::uint32_t* state = store_.state();
    if (!conflicts(t0, q)) {
      // Regular triangulations: a point in conflict with no simplex (its
      // lift lies above the lower hull) is hidden, for good (later points
      // only lower the hull). Without weights the simplex holding q is
      // always in conflict.
      if constexpr (!Weighted) throw std::logic_error("tessera: insertion: the located simplex is not in conflict");
      hidden_[static_cast<std::size_t>(q)] = 1;
      return true;
    }
    state[t0] = mark_in;
    // The cavity grows breadth first: w.cavity is both the simplices found
    // in conflict and the queue of those whose neighbours are still to be
    // tested. A simplex's neighbours' marks and vertices are read one after
    // the other when its turn comes: ask for them as it joins, so their
    // misses overlap with the work in between.
    auto prefetch_around = [&](std::int32_t t) {
      for (int k = 0; k < K; ++k) {
        __builtin_prefetch(state + simplex_of(ss[t].n[k]));
        __builtin_prefetch(ss + simplex_of(ss[t].n[k]));
      }
    };
    prefetch_around(t0);
    w.cavity.assign(1, t0);
    w.boundary.clear();
    for (std::size_t c = 0; c < w.cavity.size(); ++c) {
      const std::int32_t t = w.cavity[c];
      for (int k = 0; k < K; ++k) {
        const std::int32_t u = simplex_of(ss[t].n[k]);
        // Relaxed atomics (plain moves on x86): in 2D two workers may mark
        // the same ghost (see phase).
        std::atomic_ref<std::uint32_t> mark(state[u]);
        const std::uint32_t m = mark.load(std::memory_order_relaxed);
        bool in;
        if ((m | 1) == mark_in) {
          in = m & 1;
        } else {
          in = conflicts(u, q);
          mark.store(in ? mark_in : mark_out, std::memory_order_relaxed);
          if (in) {
            if (Check && !owned(ss[u], w.part)) return false;
            prefetch_around(u);
            w.cavity.push_back(u);
          }
        }
        if (in) continue;
        // A facet of the cavity's boundary: the new simplex is t with q in
        // place of v[k] (q sees the facet from v[k]'s side).
        Facet f;
        for (int m = 0; m < K; ++m) f.v[m] = ss[t].v[m];
        f.v[k] = q;
        f.k = k;
        f.outside = u;
        f.back = facet_of(ss[t].n[k]);
        w.boundary.push_back(f);
      }
    }
    // Slots for the new simplices: the cavity's, the worker's free ones,
    // then fresh ones.
    const std::size_t have = w.cavity.size() + w.slots_at_hand();
    if (w.boundary.size() > have) {
      if (!w.claim(store_, w.boundary.size() - have, Check)) return false;
      ss = store_.simplices();  // a serial claim may have moved the arrays
      state = store_.state();
    }
    // Regular triangulations: a cavity may swallow a vertex's whole star
    // (its lift now lies above the lower hull). The cavity's vertices that
    // no boundary facet keeps (stamped here) become hidden, and their
    // vsimplex_ entries stale (walk_start skips them). Read once the
    // insertion can no longer give way (a phase's claim, above: a point
    // deferred to a later phase must hide nothing) and before the cavity's
    // slots are reused below. In a phase every vertex here is the
    // worker's own (owned), so the stamps do not race.
    if constexpr (Weighted) {
      for (const Facet& f : w.boundary)
        for (int m = 0; m < K; ++m)
          if (f.v[m] != infinite) stamp_[static_cast<std::size_t>(f.v[m])] = w.epoch;
      for (const std::int32_t t : w.cavity)
        for (int m = 0; m < K; ++m) {
          const std::int32_t v = ss[t].v[m];
          if (v != infinite && stamp_[static_cast<std::size_t>(v)] != w.epoch) hidden_[static_cast<std::size_t>(v)] = 1;
        }
    }
    w.free.insert(w.free.end(), w.cavity.begin(), w.cavity.end());
    // The new simplices fan around q; two of them meet across each facet
    // through q, found by the facet's other vertices. 3D: a hash by the
    // boundary edge they share. 2D: an array by the one boundary vertex
    // they share (pending_; the infinite vertex's entry is the worker's
    // own); in a phase a worker's finite vertices are its own, so no two
    // workers use the same entry.
    std::uint64_t mask = 0;
    int shift = 0;
    if constexpr (D == 3) {
      const std::size_t need = std::bit_ceil(4 * w.boundary.size() + 16);
      if (w.edges.size() < need) w.edges.assign(need, Edge{});
      mask = w.edges.size() - 1;
      shift = 64 - std::countr_zero(w.edges.size());
      w.used.clear();
    }
    std::int32_t ghost = -1;  // a new ghost: q lay outside the hull (the next walk may go along it)
    for (const Facet& f : w.boundary) {
      const std::int32_t nt = w.allocate(store_);
      S& t = ss[nt];
      for (int m = 0; m < K; ++m) {
        t.v[m] = f.v[m];
        // Every vertex of a removed simplex that stays (without weights:
        // all of them) lies on the cavity's boundary, so each keeps a live one.
        if (f.v[m] != infinite) {
          vsimplex_[static_cast<std::size_t>(f.v[m])] = nt;
        } else {
          ghost = nt;
        }
      }
      t.n[f.k] = across(f.outside, f.back);
      ss[f.outside].n[f.back] = across(nt, f.k);
      for (int j = 0; j < K; ++j) {
        if (j == f.k) continue;
        if constexpr (D == 2) {
          const std::int32_t v = f.v[3 - j - f.k];
          std::int32_t& p = v == infinite ? w.pending_infinite : pending_[static_cast<std::size_t>(v)];
          if (p < 0) {
            p = across(nt, j);
          } else {
            t.n[j] = p;
            ss[simplex_of(p)].n[facet_of(p)] = across(nt, j);
            p = -1;
          }
        } else {
          std::int32_t a = infinite, b = infinite;
          bool first = true;
          for (int m = 0; m < K; ++m) {
            if (m == j || m == f.k) continue;
            (first ? a : b) = f.v[m];
            first = false;
          }
          if (a > b) std::swap(a, b);
          const std::uint64_t key = (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) |
                                    static_cast<std::uint32_t>(b);
          std::uint64_t h = (key * 0x9E3779B97F4A7C15ull) >> shift;
          for (;; h = (h + 1) & mask) {
            Edge& e = w.edges[h];
            if (e.tet < 0) {
              e = {key, nt, j};
              w.used.push_back(h);
              break;
            }
            if (e.key == key) {
              t.n[j] = across(e.tet, e.slot);
              ss[e.tet].n[e.slot] = across(nt, j);
              e.key = ~std::uint64_t{0};  // matched: keep the probe chain, never match again
              break;
            }
          }
        }
      }
      w.last = nt;
    }
    if constexpr (D == 3)
      for (const std::uint64_t h : w.used) w.edges[h] = Edge{};
    w.prev = q;
    w.hull_ghost = ghost;
    return true;
  }

  /// Where q's walk starts: by its last insertion (w.last), or, where q's
  /// guide vertex (an earlier round's point near it in Morton order) is
  /// nearer to q than the last inserted point, by a simplex of the guide.
  /// Consecutive points of a round lie close on the whole, but the Morton
  /// curve jumps now and then; on a surface sample (a torus) those walks
  /// crossed hundreds of long tetrahedra and averaged 68 steps a point. In a
  /// phase the guide must be w's vertex and its simplex w's own.
  template <bool Check>
  std::int32_t walk_start(W& w, std::int32_t q) const {
    const std::int32_t g = guide_[static_cast<std::size_t>(q)];
    if (g < 0 || w.prev < 0 || (Check && part_[static_cast<std::size_t>(g)] != w.part)) return w.last;
    if (Weighted && hidden_[static_cast<std::size_t>(g)]) return w.last;  // no live simplex of its own
    auto dist2 = [&](std::int32_t v) {
      double r2 = 0;
      for (int e = 0; e < D; ++e) r2 += (at(v)[e] - at(q)[e]) * (at(v)[e] - at(q)[e]);
      return r2;
    };
    if (dist2(g) >= dist2(w.prev)) return w.last;
    const std::int32_t t = vsimplex_[static_cast<std::size_t>(g)];
    if (Check && !owned(store_.simplices()[t], w.part)) return w.last;
    ++w.guided;
    return t;
  }

  /// Whether worker `part` may change t: its finite vertices all lie in its
  /// partition.
  bool owned(const S& t, std::uint8_t part) const {
    for (int k = 0; k < K; ++k)
      if (t.v[k] != infinite && part_[static_cast<std::size_t>(t.v[k])] != part) return false;
    return true;
  }

  static bool same_facet(const S& a, int ka, const S& b, int kb) {
    std::int32_t fa[K - 1], fb[K - 1];
    for (int m = 0, i = 0, j = 0; m < K; ++m) {
      if (m != ka) fa[i++] = a.v[m];
      if (m != kb) fb[j++] = b.v[m];
    }
    std::sort(fa, fa + K - 1);
    std::sort(fb, fb + K - 1);
    return std::equal(fa, fa + K - 1, fb);
  }

  /// Is q strictly inside t's (perturbed) circumsphere? For a ghost: is q
  /// beyond its facet, or on the facet's hyperplane within the facet's
  /// circumsphere (2D: on the edge's line strictly between its ends)?
  bool conflicts(std::int32_t ti, std::int32_t q) const {
    const S& t = store_.simplices()[ti];
    const int inf = infinite_slot(t);
    if (inf == K) return in_sphere(t, q);
    std::int32_t ids[K];
    for (int k = 0; k < K; ++k) ids[k] = t.v[k];
    ids[inf] = q;
    if (const int o = orientation(ids); o != 0) return o > 0;
    return in_sphere(store_.simplices()[simplex_of(t.n[inf])], q);
  }

  const double* at(std::int32_t k) const { return coords_.data() + static_cast<std::size_t>(k) * D; }
  std::int32_t global(std::int32_t k) const { return global_[static_cast<std::size_t>(k)]; }

  // kernels::orientation, its filter inline. The exact stages (and the
  // perturbation, by point id) are asked with the input's ids.
  int orientation(const std::int32_t* ks) const {
    int o;
    if constexpr (D == 3) o = insertion::orientation_filter(at(ks[0]), at(ks[1]), at(ks[2]), at(ks[3]), underflow_);
    else o = insertion::orientation_filter(at(ks[0]), at(ks[1]), at(ks[2]), underflow_);
    if (o != 0) return o;
    std::int32_t ids[K];
    for (int k = 0; k < K; ++k) ids[k] = global(ks[k]);
    return kernels::orientation(ctx_, ids);
  }

  // kernels::in_sphere for a finite simplex, its filter inline (with
  // weights the power test's, from the vertices' squared radii in insertion
  // order, read beside their coordinates).
  bool in_sphere(const S& t, std::int32_t q) const {
    int s;
    if constexpr (Weighted) {
      double w[K + 1];
      for (int k = 0; k < K; ++k) w[k] = weight_[static_cast<std::size_t>(t.v[k])];
      w[K] = weight_[static_cast<std::size_t>(q)];
      if constexpr (D == 3) s = insertion::in_sphere_filter<true>(at(t.v[0]), at(t.v[1]), at(t.v[2]), at(t.v[3]), at(q), underflow_, w);
      else s = insertion::in_circle_filter<true>(at(t.v[0]), at(t.v[1]), at(t.v[2]), at(q), underflow_, w);
    } else {
      if constexpr (D == 3) s = insertion::in_sphere_filter(at(t.v[0]), at(t.v[1]), at(t.v[2]), at(t.v[3]), at(q), underflow_);
      else s = insertion::in_circle_filter(at(t.v[0]), at(t.v[1]), at(t.v[2]), at(q), underflow_);
    }
    if (s != 0) return s > 0;
    std::int32_t planes[D];
    for (int k = 0; k < D; ++k) planes[k] = global(t.v[k + 1]);
    return kernels::in_sphere_past_filter(ctx_, global(t.v[0]), planes, global(q));
  }

  /// The walk for a point q after one that lay outside the hull: from ghost
  /// g (that point's), over the hull's ghosts, to the one whose facet the
  /// ray from centre_ through q crosses. Such a facet is the one a point
  /// outside the hull sees first, so where that ghost is in conflict with
  /// q (the exact test: q beyond its facet, or on its plane within the
  /// circumcircle), it is returned, as insert needs no more than a simplex
  /// in conflict. Otherwise (q inside the hull, or the walk took too long) -1,
  /// and locate walks as ever; with Check also -1 where the walk would
  /// leave w's ghosts. For surface samples, where every point lies on the
  /// hull when inserted: locate's straight walk between consecutive points
  /// crosses the needle tetrahedra along the chord, 417 steps a point on a
  /// thin cylindrical band (71 on a tall cylinder), where the hull's facets
  /// between them are a few. The steps' sides are float tests, each
  /// against a plane through centre_ and the facet's vertices but one: a
  /// wrong sign only lengthens the walk, as the answer is checked exactly.
  /// (The facets' cones from a point inside the hull tile space, so this is
  /// a visibility walk in a central projection of the hull.)
  template <bool Check>
  [[gnu::noinline]] std::int32_t hull_walk(W& w, std::int32_t q, std::int32_t g) {
    constexpr int step_limit = 256;
    const S* const ss = store_.simplices();
    const double* const x = at(q);
    for (int step = 0; step < step_limit; ++step) {
      const S& t = ss[g];
      const int inf = infinite_slot(t);
      w.rng = w.rng * 6364136223846793005ull + 1442695040888963407ull;
      const unsigned first = static_cast<unsigned>(w.rng >> 33) % K;
      std::int32_t next = -1;
      for (unsigned i = 0; i < K && next < 0; ++i) {
        const int k = static_cast<int>((first + i) % K);
        if (k == inf) continue;
        // The plane through centre_ and the facet's vertices but v[k]:
        // crossing it away from v[k] leads to the ghost across from v[k].
        const double* e[D - 1] = {};
        for (int m = 0, c = 0; m < K; ++m)
          if (m != k && m != inf) e[c++] = at(t.v[m]);
        const double sv = side_of_centre_plane(e, at(t.v[k])), sq = side_of_centre_plane(e, x);
        if ((sv > 0 && sq < 0) || (sv < 0 && sq > 0)) next = simplex_of(t.n[k]);
      }
      if (next < 0) return conflicts(g, q) ? g : -1;
      if (Check && !owned(ss[next], w.part)) return -1;
      ++w.steps;
      g = next;
    }
    return -1;
  }

  // The sign (in floats) of x against the plane (2D: line) through
  // centre_ and e[0..D-1): det(e - centre, ..., x - centre).
  double side_of_centre_plane(const double* const* e, const double* x) const {
    const double* c = centre_;
    if constexpr (D == 2) {
      return (e[0][0] - c[0]) * (x[1] - c[1]) - (e[0][1] - c[1]) * (x[0] - c[0]);
    } else {
      const double a0 = e[0][0] - c[0], a1 = e[0][1] - c[1], a2 = e[0][2] - c[2];
      const double b0 = e[1][0] - c[0], b1 = e[1][1] - c[1], b2 = e[1][2] - c[2];
      const double x0 = x[0] - c[0], x1 = x[1] - c[1], x2 = x[2] - c[2];
      return a0 * (b1 * x2 - b2 * x1) - a1 * (b0 * x2 - b2 * x0) + a2 * (b0 * x1 - b1 * x0);
    }
  }

  // centre_: the mean of vertices [0, end), all inserted, so it lies in
  // their hull (hull_walk's centre of projection), which only grows.
  void update_centre(std::size_t end) {
    for (; centre_count_ < end; ++centre_count_)
      for (int d = 0; d < D; ++d) centre_sum_[d] += at(static_cast<std::int32_t>(centre_count_))[d];
    if (centre_count_ > 0)
      for (int d = 0; d < D; ++d) centre_[d] = centre_sum_[d] / static_cast<double>(centre_count_);
  }

  /// A simplex whose closure holds q, or a ghost whose facet q lies strictly
  /// beyond: a visibility walk from `from`, which tries the facets from a
  /// varying first one (a stochastic walk terminates; Devillers, Pion &
  /// Teillaud, "Walking in a triangulation", 2002). With Check, -1 once it
  /// steps into a simplex w does not own (`from` is w's).
  ///
  /// In a Delaunay triangulation a visibility walk never enters a simplex
  /// twice (Edelsbrunner's acyclicity theorem: the in-front-of relation is
  /// acyclic), so it takes fewer steps than there are slots; past twice that
  /// it throws rather than loop for ever (inconsistent coordinates, a bug).
  template <bool Check>
  std::int32_t locate(W& w, std::int32_t q, std::int32_t from) {
    const S* const ss = store_.simplices();
    std::size_t steps_left = 2 * store_.capacity() + 64;
    std::int32_t t = from, came_from = -1;
    if (const int inf = infinite_slot(ss[t]); inf != K) {
      t = simplex_of(ss[t].n[inf]);
      if (Check && !owned(ss[t], w.part)) return -1;
    }
    for (;;) {
      const S& tt = ss[t];
      if (infinite_slot(tt) != K) return t;
      // The next step is into one of these: ask for them while the
      // orientation tests run (3D surface samples walk ~28 steps a point).
      for (int k = 0; k < K; ++k) __builtin_prefetch(ss + simplex_of(tt.n[k]));
      w.rng = w.rng * 6364136223846793005ull + 1442695040888963407ull;
      const unsigned first = D == 3 ? static_cast<unsigned>(w.rng >> 62) : static_cast<unsigned>((w.rng >> 32) % 3);
      std::int32_t next = -1;
      for (unsigned i = 0; i < K; ++i) {
        const int k = static_cast<int>((first + i) % K);
        if (simplex_of(tt.n[k]) == came_from) continue;  // q lies on this side of the facet just crossed
        std::int32_t ids[K];
        for (int m = 0; m < K; ++m) ids[m] = tt.v[m];
        ids[k] = q;
        if (orientation(ids) < 0) {
          next = simplex_of(tt.n[k]);
          break;
        }
      }
      if (next < 0) return t;
      if (Check && !owned(ss[next], w.part)) return -1;
      if (--steps_left == 0) [[unlikely]]
        walk_did_not_end();
      ++w.steps;
      came_from = t;
      t = next;
    }
  }

  /// Slots per point the store holds so far (its free slots included),
  /// once enough points are in to measure it; before, a uniform input's.
  double slots_per_point(std::size_t inserted) const {
    if (inserted < 1024) return D == 3 ? 6.8 : 2.0;
    return static_cast<double>(store_.size()) / static_cast<double>(inserted);
  }
  /// Fresh slots a parallel phase of `count` points may claim: its points'
  /// share at the rate so far, a tenth more, and a block per worker.
  std::size_t phase_slots(std::size_t count) const {
    const std::size_t inserted = inserted_before_round_;
    return static_cast<std::size_t>(1.1 * slots_per_point(inserted) * static_cast<double>(count)) +
           workers_.size() * W::fresh_block;
  }
  /// Before a round of `count` points with `inserted` in: where its phases
  /// could run out of room, grow the store to what all the points will need
  /// at the rate measured so far, and a quarter more (the capacity costs
  /// address space only), rather than doubling. Surface samples hold far
  /// more simplices than uniform points (200k on a torus: 19 tetrahedra per
  /// point), and their rate still rises as the rounds go (60k on a torus:
  /// by a tenth after the first growth), so the growth's margin exceeds
  /// the phases'; each growth copies the store.
  void reserve_round(std::size_t count, std::size_t inserted) {
    inserted_before_round_ = inserted;
    if (store_.size() + phase_slots(count) <= store_.capacity()) return;
    const double rest = static_cast<double>(global_.size() - std::min(global_.size(), inserted));
    store_.grow(std::max(store_.size() + phase_slots(count),
                         store_.size() + static_cast<std::size_t>(1.25 * slots_per_point(inserted) * rest)));
  }

  const ExactContext& ctx_;
  const bool underflow_;                // ctx_.may_underflow, for the filters (insertion_filters.hpp)
  std::vector<std::int32_t> global_;    // vertex -> input id
  std::vector<std::int32_t> guide_;     // vertex -> an earlier round's vertex near it, or -1 (walk_start)
  Buffer<std::int32_t> vsimplex_;       // inserted vertex -> a live simplex of it
  Buffer<double> coords_;               // vertex -> coordinates (D each)
  Buffer<std::int32_t> pending_;        // 2D: vertex -> a new triangle's link awaiting its partner, or -1
  insertion::SimplexStore<S> store_{D == 3 ? "tessera: insertion: more tetrahedra than Simplex::n can number (about 75 million points)"
                                           : "tessera: insertion: more triangles than Simplex::n can number (about 250 million points)"};
  std::vector<W> workers_;
  std::vector<std::uint8_t> part_;  // vertex -> partition, in a parallel phase
  std::int32_t hint_ = 0;           // a live simplex: the serial walk's start
  double centre_[D] = {};            // hull_walk's centre of projection (update_centre)
  double centre_sum_[D] = {};
  std::size_t centre_count_ = 0;
  bool parallel_ = true;            // whether rounds still try parallel phases
  bool retry_left_ = true;          // whether the phases may still try again once they stopped
  std::size_t retry_from_ = 0;      // the round size that tries again, once they stopped
  std::size_t inserted_before_round_ = 0;  // vertices in before the current round (reserve_round)
  // Weighted only (empty otherwise), after the hot members.
  std::vector<std::uint8_t> hidden_;    // weighted: vertex -> hidden (never a vertex, or removed)
  std::vector<double> weight_;          // weighted: vertex -> its squared radius (the power test's weight)
  std::vector<std::uint32_t> stamp_;    // weighted: vertex -> the last insertion (epoch) whose new simplices hold it
  InsertionStats stats_;
};

/// The first simplex, in positions of `order`: the first two points, then
/// the first point off their line, and in 3D the first off their plane;
/// positively oriented. nullopt when the points are all on one line (2D) or
/// plane (3D).
template <int D>
std::optional<std::array<std::int32_t, D + 1>> first_simplex(const ExactContext& ctx, const BrioOrder& order) {
  const std::size_t m = order.ids.size();
  if (m < D + 1) return std::nullopt;
  std::array<std::int32_t, D + 1> local{0, 1};
  std::array<std::int32_t, D + 1> s{order.ids[0], order.ids[1]};
  std::size_t c = 2;
  if constexpr (D == 3) {
    auto at = [&](std::size_t k) { return ctx.points + static_cast<std::size_t>(order.ids[k]) * 3; };
    while (c < m && kernels::collinear3(at(0), at(1), at(c))) ++c;
    if (c == m) return std::nullopt;
    local[2] = static_cast<std::int32_t>(c);
    s[2] = order.ids[c];
    ++c;
  }
  int o = 0;
  for (; c < m; ++c) {
    s[D] = order.ids[c];
    if ((o = kernels::orientation(ctx, s.data())) != 0) break;
  }
  if (c == m) return std::nullopt;
  local[D] = static_cast<std::int32_t>(c);
  if (o < 0) std::swap(local[D - 1], local[D]);
  return local;
}

template <int D, bool Weighted>
std::optional<Buffer<std::int32_t>> insert_all(const ExactContext& ctx, std::span<const std::int32_t> ids,
                                               const double* coords, const double* lo, const double* hi,
                                               const InsertionOptions& options) {
  BrioOrder order = brio_order(ctx, ids, coords, lo, hi);
  const std::optional<std::array<std::int32_t, D + 1>> first = first_simplex<D>(ctx, order);
  if (!first) return std::nullopt;
  // Positions 0 and 1 start the first round; the simplex's later points
  // are skipped where their rounds reach them.
  std::int32_t later[2] = {-1, -1};
  std::size_t end_min = 0, n_later = 0;
  for (const std::int32_t v : *first)
    if (v >= 2) {
      later[n_later++] = v;
      end_min = std::max(end_min, static_cast<std::size_t>(v) + 1);
    }
  const std::size_t m = order.ids.size();
  std::vector<std::int32_t> guide = brio_guides(D, order);
  order.codes = {};
  Triangulation<D, Weighted> tri(ctx, std::move(order.ids), std::move(order.coords), std::move(guide), options.threads);
  tri.start(*first);
  for (std::size_t r = 0; r + 1 < order.rounds.size(); ++r) {
    const std::size_t a = order.rounds[r], b = order.rounds[r + 1];
    std::vector<std::int32_t> pts;
    pts.reserve(b - a);
    for (std::size_t i = std::max<std::size_t>(a, 2); i < b; ++i)
      if (static_cast<std::int32_t>(i) != later[0] && static_cast<std::int32_t>(i) != later[1]) pts.push_back(static_cast<std::int32_t>(i));
    // Every vertex so far: the round's points, those before, and the first simplex's.
    auto placed = [&](std::size_t k) {
      if (options.progress) options.progress(static_cast<double>(a + k) / static_cast<double>(m));
    };
    tri.insert_round(std::move(pts), std::max(b, end_min), options.parallel_min, placed);
    if (options.progress) options.progress(static_cast<double>(b) / static_cast<double>(m));
  }
  if (options.stats != nullptr) *options.stats = tri.stats();
  return tri.take_rows();
}

}  // namespace

std::optional<Buffer<std::int32_t>> insertion_delaunay(const ExactContext& ctx, std::span<const std::int32_t> ids,
                                                       const double* coords, const double* lo, const double* hi,
                                                       const InsertionOptions& options) {
  const bool weighted = ctx.radii != nullptr;
  if (ctx.dim == 2)
    return weighted ? insert_all<2, true>(ctx, ids, coords, lo, hi, options) : insert_all<2, false>(ctx, ids, coords, lo, hi, options);
  if (ctx.dim == 3)
    return weighted ? insert_all<3, true>(ctx, ids, coords, lo, hi, options) : insert_all<3, false>(ctx, ids, coords, lo, hi, options);
  throw std::logic_error("tessera: insertion_delaunay: dimension must be 2 or 3");
}

template <int D>
LocatedInsertion insert_located(const Pass<D>& pass, const std::function<void(double)>& progress) {
  // The located points are distinct (the pass left exact duplicates out),
  // in slot order with the locator's own coordinates.
  const auto& loc = *pass.locator;
  LocatedInsertion out;
  std::vector<std::int32_t> ids(loc.size());
  for (std::size_t k = 0; k < loc.size(); ++k) ids[k] = loc.id(k);
  const double* coords = loc.size() == 0 ? nullptr : loc.point(0).data();
  InsertionOptions io;
  io.threads = pass.engine_options.threads;
  io.progress = progress;
  // The Morton order over the grid's box, which spans the bulk where a few
  // points lie far out (the far ones clamp to its edges): over the domain
  // box, 1M points beside one at 1e200 all had one code, were inserted in
  // random order, and every walk crossed the triangulation (2D: 52.9 s).
  const auto glo = loc.grid_lo(), ghi = loc.grid_hi();
  out.rows = insertion_delaunay(pass.exact, ids, coords, glo.data(), ghi.data(), io);
  return out;
}

template LocatedInsertion insert_located(const Pass<2>&, const std::function<void(double)>&);
template LocatedInsertion insert_located(const Pass<3>&, const std::function<void(double)>&);

}  // namespace tessera::front
