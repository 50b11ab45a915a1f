// Bowyer–Watson insertion in 3D; see insertion.hpp.
#include "insertion.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstring>
#include <memory>
#include <optional>
#include <stdexcept>
#include <utility>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "insertion_order.hpp"
#include "pass.hpp"
#include "tessera/kernels/delaunay_predicates.hpp"
#include "tessera/kernels/filter.hpp"

namespace tessera::front {
namespace {

using kernels::ExactContext;

constexpr std::int32_t infinite = -1;  ///< the vertex every ghost tetrahedron shares

/// A tetrahedron: vertices, and for each k what lies across the face
/// opposite v[k]: 4 u + m for the tetrahedron u whose face m it is (so the
/// way back needs no search). Finite ones are positively oriented; a ghost
/// (one vertex infinite) is oriented as if that vertex were a point beyond
/// its facet.
struct Tet {
  std::int32_t v[4];
  std::int32_t n[4];
};

/// Tetrahedron u's face m, as Tet::n holds it; and back.
inline std::int32_t across(std::int32_t u, int m) { return 4 * u + m; }
inline std::int32_t tet_of(std::int32_t a) { return a >> 2; }
inline int face_of(std::int32_t a) { return a & 3; }

int infinite_slot(const Tet& t) {
  for (int k = 0; k < 4; ++k)
    if (t.v[k] == infinite) return k;
  return 4;
}

// The filters in front of kernels::orientation and kernels::in_sphere,
// written out for 3D and for points that are ids into one array: the walk and
// the cavity search ask tens of them per point. Each returns the exact sign
// when its float evaluation is certain, and 0 otherwise (then the kernels'
// predicates decide, with their exact arithmetic and perturbation). The
// quantities and bounds are those of the kernels' filters
// (delaunay_predicates.hpp), evaluated in another order: the bounds hold for
// any order of the sums.

// Sign of det[b - a, c - a, d - a].
[[gnu::always_inline]] inline int orientation_filter(const double* a, const double* b, const double* c, const double* d) {
  const double r0[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double r1[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const double r2[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
  const double m0 = r1[1] * r2[2], m1 = r1[2] * r2[1];
  const double m2 = r1[2] * r2[0], m3 = r1[0] * r2[2];
  const double m4 = r1[0] * r2[1], m5 = r1[1] * r2[0];
  const double det = r0[0] * (m0 - m1) + r0[1] * (m2 - m3) + r0[2] * (m4 - m5);
  const double perm = std::fabs(r0[0]) * (std::fabs(m0) + std::fabs(m1)) +
                      std::fabs(r0[1]) * (std::fabs(m2) + std::fabs(m3)) +
                      std::fabs(r0[2]) * (std::fabs(m4) + std::fabs(m5));
  const double bound = 16 * kernels::filter::u * perm + kernels::filter::abs_eps;
  return det > bound ? 1 : (det < -bound ? -1 : 0);
}

// For a positively oriented tetrahedron abcd: +1 when q is surely inside its
// circumsphere, -1 surely outside, 0 undecided. With rows r_k = p_k - a and
// s_k = |r_k|^2 (k = b, c, d, q), q is inside iff det[[r_k, s_k]] < 0
// (kernels::in_sphere; det R > 0 here).
[[gnu::always_inline]] inline int in_sphere_filter(const double* a, const double* b, const double* c, const double* d, const double* q) {
  double r[4][3], s[4];
  const double* p[4] = {b, c, d, q};
  for (int k = 0; k < 4; ++k) {
    for (int e = 0; e < 3; ++e) r[k][e] = p[k][e] - a[e];
    s[k] = r[k][0] * r[k][0] + r[k][1] * r[k][1] + r[k][2] * r[k][2];
  }
  // 2x2 minors of the x, y columns for each pair of rows, and their permanents.
  double xy[4][4], axy[4][4];
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) {
      const double u = r[i][0] * r[j][1], v = r[i][1] * r[j][0];
      xy[i][j] = u - v;
      axy[i][j] = std::fabs(u) + std::fabs(v);
    }
  // The 3x3 minor of rows i < j < k (columns x, y, z), expanded along z.
  auto minor = [&](int i, int j, int k, double& perm) {
    perm = std::fabs(r[i][2]) * axy[j][k] + std::fabs(r[j][2]) * axy[i][k] + std::fabs(r[k][2]) * axy[i][j];
    return r[i][2] * xy[j][k] - r[j][2] * xy[i][k] + r[k][2] * xy[i][j];
  };
  double p0, p1, p2, p3;
  const double d0 = minor(1, 2, 3, p0), d1 = minor(0, 2, 3, p1), d2 = minor(0, 1, 3, p2), d3 = minor(0, 1, 2, p3);
  const double det = -s[0] * d0 + s[1] * d1 - s[2] * d2 + s[3] * d3;
  const double perm = s[0] * p0 + s[1] * p1 + s[2] * p2 + s[3] * p3;
  const double bound = 64 * kernels::filter::u * perm + kernels::filter::abs_eps;
  return det < -bound ? 1 : (det > bound ? -1 : 0);
}

// The tetrahedra and their conflict marks, in arrays whose slots are written
// before they are read (allocated without initialising: the capacity
// reserved ahead of a parallel phase costs no page until it is used). Fresh
// slots are claimed in blocks, atomically, so that the parallel phases can
// take them; only the serial code grows the arrays.
class TetStore {
 public:
  Tet* tets() { return tets_.get(); }
  const Tet* tets() const { return tets_.get(); }
  std::uint32_t* state() { return state_.get(); }
  std::size_t size() const { return size_.load(std::memory_order_relaxed); }

  /// Room for `extra` more slots without growing (serial only).
  void reserve(std::size_t extra) {
    const std::size_t need = size() + extra;
    if (need <= cap_) return;
    const std::size_t cap = std::min(std::max(need, 2 * cap_), max_slots);
    if (need > max_slots) throw std::length_error("tessera: insertion: more tetrahedra than Tet::n can number (about 75 million points)");
    std::unique_ptr<Tet[]> t(new Tet[cap]);
    std::unique_ptr<std::uint32_t[]> s(new std::uint32_t[cap]);
    // memcpy: claimed slots not yet written hold indeterminate bytes.
    std::memcpy(t.get(), tets_.get(), size() * sizeof(Tet));
    std::memcpy(s.get(), state_.get(), size() * sizeof(std::uint32_t));
    tets_ = std::move(t);
    state_ = std::move(s);
    cap_ = cap;
  }
  /// The first of `count` fresh slots, or nullopt when the capacity is spent.
  std::optional<std::size_t> claim(std::size_t count) {
    std::size_t s = size_.load(std::memory_order_relaxed);
    do {
      if (s + count > cap_) return std::nullopt;
    } while (!size_.compare_exchange_weak(s, s + count, std::memory_order_relaxed));
    return s;
  }

 private:
  std::unique_ptr<Tet[]> tets_;
  std::unique_ptr<std::uint32_t[]> state_;  // (epoch << 1) | in conflict
  std::size_t cap_ = 0;
  std::atomic<std::size_t> size_{0};
  static constexpr std::size_t max_slots = std::size_t{1} << 29;  // across() fits in int32
};

/// What one thread of insertion keeps: its partition, its conflict-mark
/// epochs, its walk's start, its free and fresh slots and its buffers.
struct Worker {
  std::uint8_t part = 0;      // the partition it inserts in a parallel phase
  std::uint32_t epoch = 0;    // its marks: part + 1, then steps of the worker count
  std::int32_t last = -1;     // a tetrahedron of its last insertion (the next walk's start), or -1
  std::int32_t prev = -1;     // the vertex it inserted last, or -1
  std::size_t guided = 0;     // walks it started by a guide (walk_start)
  std::uint64_t rng = 0x2545F4914F6CDD1Dull;
  std::vector<std::int32_t> free;     // slots of tetrahedra it removed
  std::size_t fresh = 0, fresh_end = 0;  // claimed slots never used
  std::vector<std::int32_t> deferred;  // points a parallel phase left for later
  struct Face {
    std::int32_t v[4];  // the new tetrahedron's vertices (q at k)
    int k;
    std::int32_t outside;  // the tetrahedron across the face, not in conflict
    int back;              // its face towards the cavity
  };
  struct Edge {
    std::uint64_t key = 0;
    std::int32_t tet = -1;
    int slot = 0;
  };
  std::vector<std::int32_t> stack, cavity;
  std::vector<Face> boundary;
  std::vector<Edge> edges;
  std::vector<std::uint64_t> used;
};

class Triangulation {
 public:
  /// Vertices are numbered by `global`, the insertion order: vertex k is
  /// point global[k] of ctx, and its coordinates are copied in that order, so
  /// the points a walk and a cavity meet lie close in memory too.
  Triangulation(const ExactContext& ctx, std::vector<std::int32_t> global, std::vector<std::int32_t> guide, int threads)
      : ctx_(ctx), global_(std::move(global)), guide_(std::move(guide)),
        workers_(static_cast<std::size_t>(std::clamp(threads, 1, max_workers))) {
    vtet_.resize(global_.size());  // written for each vertex as it is inserted
    coords_.resize(3 * global_.size());
    for (std::size_t k = 0; k < global_.size(); ++k)
      for (int e = 0; e < 3; ++e) coords_[3 * k + static_cast<std::size_t>(e)] = ctx.points[static_cast<std::size_t>(global_[k]) * 3 + static_cast<std::size_t>(e)];
    for (std::size_t w = 0; w < workers_.size(); ++w) {
      workers_[w].part = static_cast<std::uint8_t>(w);
      workers_[w].epoch = static_cast<std::uint32_t>(w) + 1;
      workers_[w].rng += 0x9E3779B97F4A7C15ull * w;
    }
    // A Delaunay tetrahedralisation has about 6.5 tetrahedra per point.
    store_.reserve(7 * global_.size() + 64);
  }

  /// Start from the positively oriented tetrahedron s and its four ghosts.
  void start(std::array<std::int32_t, 4> s) {
    const std::size_t first = *store_.claim(5);  // the constructor reserved room
    Tet* const tets = store_.tets() + first;
    Tet t0{{s[0], s[1], s[2], s[3]}, {-1, -1, -1, -1}};
    tets[0] = t0;
    for (int k = 0; k < 4; ++k) {
      Tet g = t0;
      g.v[k] = infinite;
      // With the infinite vertex standing for a point beyond face k (the
      // side away from v[k]) the order is negative: swap two others.
      std::swap(g.v[(k + 1) % 4], g.v[(k + 2) % 4]);
      tets[k + 1] = g;
    }
    // Link the five by their shared faces.
    for (int a = 0; a < 5; ++a) {
      store_.state()[first + static_cast<std::size_t>(a)] = 0;
      for (int ka = 0; ka < 4; ++ka)
        for (int b = 0; b < 5; ++b) {
          if (a == b) continue;
          for (int kb = 0; kb < 4; ++kb)
            if (same_face(tets[a], ka, tets[b], kb)) tets[a].n[ka] = across(static_cast<std::int32_t>(first) + b, kb);
        }
    }
    hint_ = static_cast<std::int32_t>(first);
    for (const std::int32_t v : s) vtet_[static_cast<std::size_t>(v)] = hint_;
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
    int cut_axis = -1;
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
      // have). Smaller phases defer many anyway, as their tetrahedra are
      // large next to the slabs.
      if (tried >= 2048 && 3 * pts.size() > tried) parallel_ = false;
      placed(total - pts.size());
    }
    Worker& w = workers_[0];
    w.last = hint_;
    w.prev = -1;
    const std::size_t before = total - pts.size();
    for (std::size_t k = 0; k < pts.size(); ++k) {
      if (w.epoch >= epoch_limit()) reset_marks();
      if (!insert<false>(w, pts[k])) throw std::logic_error("tessera: insertion: a serial insertion was refused");
      if ((k & 16383) == 16383) {
        hint_ = w.last;  // the state stays whole if placed() throws
        placed(before + k + 1);
      }
    }
    hint_ = w.last;
  }

  /// The finite tetrahedra, in the layout of insertion_delaunay. It
  /// overwrites the store (the triangulation is spent).
  Buffer<std::int32_t> take_rows();
  InsertionStats stats() const {
    InsertionStats s = stats_;
    for (const Worker& w : workers_) s.guided += w.guided;
    return s;
  }

 private:
  using Face = Worker::Face;
  using Edge = Worker::Edge;

  /// One parallel phase (after Marot, Pellerin & Remacle, "One machine, one
  /// minute, three billion tetrahedra", 2019). Space is cut into slabs
  /// across the widest axis of `pts` other than `cut_axis` (the previous
  /// phase's, which is then set to this one's), at quantiles of the points,
  /// so that each worker gets as many; every vertex so far belongs to the
  /// slab it lies in. A worker inserts its slab's points, in their order,
  /// and may only change tetrahedra whose finite vertices all lie in its
  /// slab (`owned`); a point whose walk or cavity meets another one is
  /// deferred and returned. No two workers then touch the same tetrahedron:
  /// * a worker changes a tetrahedron's vertices only if it owns it, and
  ///   its links only across a face whose finite vertices are all its own
  ///   (a face of a cavity it removes), where the new tetrahedron goes;
  /// * it reads and marks only tetrahedra it owns and those across a face of
  ///   one (walk steps, cavity neighbours);
  /// * a tetrahedron with a face all of worker A's (two finite vertices at
  ///   least) and a face all of B's would need two finite vertices of each
  ///   among its four vertices, with one of every face's three left out: no
  ///   such tetrahedron exists (the infinite vertex belongs to everyone).
  /// The triangulation stays the Delaunay triangulation of the points
  /// inserted so far; it is unique (perturbed predicates), so the order of
  /// insertion, and with it the thread count, does not change the result.
  /// Slabs rather than runs of the Morton order: a run's boundary follows
  /// the curve's top bits, which cut a flat input (a torus, a terrain)
  /// along its thin side, where nearly every tetrahedron crosses the cut.
  std::vector<std::int32_t> phase(const std::vector<std::int32_t>& pts, std::size_t end, int& cut_axis) {
    const std::size_t threads = workers_.size();
    double lo[3], hi[3];
    for (int a = 0; a < 3; ++a) lo[a] = hi[a] = at(pts[0])[a];
    for (const std::int32_t q : pts)
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::min(lo[a], at(q)[a]);
        hi[a] = std::max(hi[a], at(q)[a]);
      }
    int axis = -1;
    for (int a = 0; a < 3; ++a)
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
    part_.resize(end);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, end, 1 << 14), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t v = r.begin(); v != r.end(); ++v)
        part_[v] = static_cast<std::uint8_t>(std::upper_bound(cut.begin(), cut.end(), at(static_cast<std::int32_t>(v))[axis]) - cut.begin());
    });
    // Each worker's points, in their order.
    std::vector<std::vector<std::int32_t>> mine(threads);
    for (const std::int32_t q : pts) mine[part_[static_cast<std::size_t>(q)]].push_back(q);
    // A tetrahedron each worker owns, to start its walks from: the one
    // holding one of its points, tried at spread positions of its list, as
    // the first points in Morton order of a slab may all lie along its cut
    // (found serially, each walk starting where the last ended). A worker
    // with none defers its points.
    std::int32_t walk_from = hint_;
    for (std::size_t t = 0; t < threads; ++t) {
      Worker& w = workers_[t];
      w.deferred.clear();
      w.last = -1;
      w.prev = -1;
      const std::size_t tries = std::min<std::size_t>(mine[t].size(), 64);
      for (std::size_t k = 0; k < tries && w.last < 0; ++k) {
        const std::int32_t t0 = locate<false>(w, mine[t][k * mine[t].size() / tries], walk_from);
        walk_from = t0;
        if (owned(store_.tets()[t0], w.part)) w.last = t0;
      }
      if (w.last < 0) w.deferred = mine[t];
    }
    // Room for every fresh slot the phase may claim (claims beyond it defer
    // their points), and marks that cannot wrap within it.
    store_.reserve(8 * pts.size() + threads * fresh_block);
    for (const Worker& w : workers_)
      if (w.epoch + threads * (pts.size() + 1) >= epoch_limit()) reset_marks();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, threads, 1), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t t = r.begin(); t != r.end(); ++t) {
        Worker& w = workers_[t];
        if (w.last < 0) continue;
        for (const std::int32_t q : mine[t])
          if (!insert<true>(w, q)) w.deferred.push_back(q);
      }
    }, tbb::simple_partitioner());
    // A worker's last tetrahedron is its own and alive; with none (nothing
    // inserted) the previous hint was not touched.
    for (const Worker& w : workers_)
      if (w.last >= 0) {
        hint_ = w.last;
        break;
      }
    std::vector<std::int32_t> rest;
    for (const Worker& w : workers_) rest.insert(rest.end(), w.deferred.begin(), w.deferred.end());
    return rest;
  }

  /// Insert point q (not yet in the triangulation, at no vertex's place) by
  /// worker w, starting the walk from w.last. With Check (a parallel phase),
  /// false when the walk or the cavity meets a tetrahedron w does not own,
  /// or no fresh slot is left: nothing has been changed then.
  template <bool Check>
  bool insert(Worker& w, std::int32_t q) {
    const std::int32_t t0 = locate<Check>(w, q, walk_start<Check>(w, q));
    if (t0 < 0) return false;
    w.epoch += static_cast<std::uint32_t>(workers_.size());
    const std::uint32_t mark_out = w.epoch << 1, mark_in = mark_out | 1;
    Tet* tets = store_.tets();
    std::uint32_t* state = store_.state();
    if (!conflicts(t0, q)) throw std::logic_error("tessera: insertion: the located tetrahedron is not in conflict");
    state[t0] = mark_in;
    w.stack.assign(1, t0);
    w.cavity.clear();
    w.boundary.clear();
    while (!w.stack.empty()) {
      const std::int32_t t = w.stack.back();
      w.stack.pop_back();
      w.cavity.push_back(t);
      // The four neighbours' marks and vertices are read below one after
      // the other: ask for all of them first, so their misses overlap.
      for (int k = 0; k < 4; ++k) {
        __builtin_prefetch(state + tet_of(tets[t].n[k]));
        __builtin_prefetch(tets + tet_of(tets[t].n[k]));
      }
      for (int k = 0; k < 4; ++k) {
        const std::int32_t u = tet_of(tets[t].n[k]);
        bool in;
        if ((state[u] | 1) == mark_in) {
          in = state[u] & 1;
        } else {
          in = conflicts(u, q);
          state[u] = in ? mark_in : mark_out;
          if (in) {
            if (Check && !owned(tets[u], w.part)) return false;
            w.stack.push_back(u);
          }
        }
        if (in) continue;
        // A face of the cavity's boundary: the new tetrahedron is t with q
        // in place of v[k] (q sees the face from v[k]'s side).
        Face f;
        for (int m = 0; m < 4; ++m) f.v[m] = tets[t].v[m];
        f.v[k] = q;
        f.k = k;
        f.outside = u;
        f.back = face_of(tets[t].n[k]);
        w.boundary.push_back(f);
      }
    }
    // Slots for the new tetrahedra: the cavity's, the worker's free ones,
    // then fresh ones.
    const std::size_t have = w.cavity.size() + w.free.size() + (w.fresh_end - w.fresh);
    if (w.boundary.size() > have) {
      if (!claim(w, w.boundary.size() - have, Check)) return false;
      tets = store_.tets();  // a serial claim may have moved the arrays
      state = store_.state();
    }
    for (const std::int32_t t : w.cavity) w.free.push_back(t);
    // Each boundary edge bounds two of the new tetrahedra: they meet across
    // the face through it and q.
    const std::size_t need = std::bit_ceil(4 * w.boundary.size() + 16);
    if (w.edges.size() < need) w.edges.assign(need, Edge{});
    const std::uint64_t mask = w.edges.size() - 1;
    const int shift = 64 - std::countr_zero(w.edges.size());
    w.used.clear();
    for (const Face& f : w.boundary) {
      const std::int32_t nt = allocate(w);
      Tet& t = tets[nt];
      for (int m = 0; m < 4; ++m) {
        t.v[m] = f.v[m];
        // Every vertex of a removed tetrahedron lies on the cavity's
        // boundary, so each keeps a live one.
        if (f.v[m] != infinite) vtet_[static_cast<std::size_t>(f.v[m])] = nt;
      }
      t.n[f.k] = across(f.outside, f.back);
      tets[f.outside].n[f.back] = across(nt, f.k);
      for (int j = 0; j < 4; ++j) {
        if (j == f.k) continue;
        std::int32_t a = infinite, b = infinite;
        bool first = true;
        for (int m = 0; m < 4; ++m) {
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
            tets[e.tet].n[e.slot] = across(nt, j);
            e.key = ~std::uint64_t{0};  // matched: keep the probe chain, never match again
            break;
          }
        }
      }
      w.last = nt;
    }
    for (const std::uint64_t h : w.used) w.edges[h] = Edge{};
    w.prev = q;
    return true;
  }

  /// Where q's walk starts: by its last insertion (w.last), or, where q's
  /// guide vertex (an earlier round's point near it in Morton order) is
  /// nearer to q than the last inserted point, by a tetrahedron of the guide.
  /// Consecutive points of a round lie close on the whole, but the Morton
  /// curve jumps now and then; on a surface sample (a torus) those walks
  /// crossed hundreds of long tetrahedra and averaged 68 steps a point. In a
  /// phase the guide must be w's vertex and its tetrahedron w's own.
  template <bool Check>
  std::int32_t walk_start(Worker& w, std::int32_t q) const {
    const std::int32_t g = guide_[static_cast<std::size_t>(q)];
    if (g < 0 || w.prev < 0 || (Check && part_[static_cast<std::size_t>(g)] != w.part)) return w.last;
    auto dist2 = [&](std::int32_t v) {
      double r2 = 0;
      for (int e = 0; e < 3; ++e) r2 += (at(v)[e] - at(q)[e]) * (at(v)[e] - at(q)[e]);
      return r2;
    };
    if (dist2(g) >= dist2(w.prev)) return w.last;
    const std::int32_t t = vtet_[static_cast<std::size_t>(g)];
    if (Check && !owned(store_.tets()[t], w.part)) return w.last;
    ++w.guided;
    return t;
  }

  /// At least `count` more fresh slots for w. Serially the store grows; in
  /// a parallel phase a spent capacity is a refusal (false).
  bool claim(Worker& w, std::size_t count, bool parallel) {
    for (std::size_t s = w.fresh; s < w.fresh_end; ++s) {  // keep the old block's rest as free slots
      store_.state()[s] = 0;
      w.free.push_back(static_cast<std::int32_t>(s));
    }
    w.fresh = w.fresh_end = 0;
    const std::size_t block = std::max(count, fresh_block);
    if (!parallel) store_.reserve(block);
    const std::optional<std::size_t> first = store_.claim(block);
    if (!first) return false;
    w.fresh = *first;
    w.fresh_end = *first + block;
    return true;
  }

  std::int32_t allocate(Worker& w) {
    if (!w.free.empty()) {
      const std::int32_t t = w.free.back();
      w.free.pop_back();
      return t;
    }
    const std::size_t t = w.fresh++;  // insert() made sure there is one
    store_.state()[t] = 0;  // marked by no epoch
    return static_cast<std::int32_t>(t);
  }

  /// Whether worker `part` may change t: its finite vertices all lie in its
  /// partition.
  bool owned(const Tet& t, std::uint8_t part) const {
    for (int k = 0; k < 4; ++k)
      if (t.v[k] != infinite && part_[static_cast<std::size_t>(t.v[k])] != part) return false;
    return true;
  }

  /// Marks are (epoch << 1) | bit in 32 bits; the workers' epochs are
  /// distinct (worker w's are w + 1 modulo the worker count), so a slot
  /// marked by one never reads as marked by another's current insertion.
  static constexpr std::uint32_t epoch_limit() { return 1u << 30; }
  void reset_marks() {
    std::fill(store_.state(), store_.state() + store_.size(), 0u);
    for (std::size_t w = 0; w < workers_.size(); ++w) workers_[w].epoch = static_cast<std::uint32_t>(w) + 1;
  }

  static bool same_face(const Tet& a, int ka, const Tet& b, int kb) {
    std::int32_t fa[3], fb[3];
    for (int m = 0, i = 0, j = 0; m < 4; ++m) {
      if (m != ka) fa[i++] = a.v[m];
      if (m != kb) fb[j++] = b.v[m];
    }
    std::sort(fa, fa + 3);
    std::sort(fb, fb + 3);
    return std::equal(fa, fa + 3, fb);
  }

  /// Is q strictly inside t's (perturbed) circumsphere? For a ghost: is q
  /// beyond its facet, or on the facet's plane within its circumcircle?
  bool conflicts(std::int32_t ti, std::int32_t q) const {
    const Tet& t = store_.tets()[ti];
    const int inf = infinite_slot(t);
    if (inf == 4) return in_sphere(t, q);
    std::int32_t ids[4] = {t.v[0], t.v[1], t.v[2], t.v[3]};
    ids[inf] = q;
    if (const int o = orientation(ids); o != 0) return o > 0;
    return in_sphere(store_.tets()[tet_of(t.n[inf])], q);
  }

  const double* at(std::int32_t k) const { return coords_.data() + static_cast<std::size_t>(k) * 3; }
  std::int32_t global(std::int32_t k) const { return global_[static_cast<std::size_t>(k)]; }

  // kernels::orientation, its filter inline. The exact stages (and the
  // perturbation, by point id) are asked with the input's ids.
  int orientation(const std::int32_t* ks) const {
    if (const int o = orientation_filter(at(ks[0]), at(ks[1]), at(ks[2]), at(ks[3]))) return o;
    const std::int32_t ids[4] = {global(ks[0]), global(ks[1]), global(ks[2]), global(ks[3])};
    return kernels::orientation(ctx_, ids);
  }

  // kernels::in_sphere for a finite tetrahedron, its filter inline.
  bool in_sphere(const Tet& t, std::int32_t q) const {
    if (const int s = in_sphere_filter(at(t.v[0]), at(t.v[1]), at(t.v[2]), at(t.v[3]), at(q))) return s > 0;
    const std::int32_t planes[3] = {global(t.v[1]), global(t.v[2]), global(t.v[3])};
    return kernels::in_sphere(ctx_, global(t.v[0]), planes, global(q));
  }

  /// A tetrahedron whose closure holds q, or a ghost whose facet q lies
  /// strictly beyond: a visibility walk from `from`, which tries the faces
  /// from a varying first one (a stochastic walk terminates; Devillers,
  /// Pion & Teillaud, "Walking in a triangulation", 2002). With Check, -1
  /// once it steps into a tetrahedron w does not own (`from` is w's).
  template <bool Check>
  std::int32_t locate(Worker& w, std::int32_t q, std::int32_t from) {
    const Tet* const tets = store_.tets();
    std::int32_t t = from, came_from = -1;
    if (const int inf = infinite_slot(tets[t]); inf != 4) {
      t = tet_of(tets[t].n[inf]);
      if (Check && !owned(tets[t], w.part)) return -1;
    }
    for (;;) {
      const Tet& tt = tets[t];
      if (infinite_slot(tt) != 4) return t;
      w.rng = w.rng * 6364136223846793005ull + 1442695040888963407ull;
      const int first = static_cast<int>(w.rng >> 62);
      std::int32_t next = -1;
      for (int i = 0; i < 4; ++i) {
        const int k = (first + i) & 3;
        if (tet_of(tt.n[k]) == came_from) continue;  // q lies on this side of the face just crossed
        std::int32_t ids[4] = {tt.v[0], tt.v[1], tt.v[2], tt.v[3]};
        ids[k] = q;
        if (orientation(ids) < 0) {
          next = tet_of(tt.n[k]);
          break;
        }
      }
      if (next < 0) return t;
      if (Check && !owned(tets[next], w.part)) return -1;
      came_from = t;
      t = next;
    }
  }

  /// Partitions are bytes.
  static constexpr int max_workers = 255;
  /// Fresh slots a worker claims at a time.
  static constexpr std::size_t fresh_block = 4096;

  const ExactContext& ctx_;
  std::vector<std::int32_t> global_;  // vertex -> input id
  std::vector<std::int32_t> guide_;   // vertex -> an earlier round's vertex near it, or -1 (walk_start)
  std::vector<std::int32_t> vtet_;    // inserted vertex -> a live tetrahedron of it
  std::vector<double> coords_;        // vertex -> coordinates (3 each)
  TetStore store_;
  std::vector<Worker> workers_;
  std::vector<std::uint8_t> part_;  // vertex -> partition, in a parallel phase
  std::int32_t hint_ = 0;           // a live tetrahedron: the serial walk's start
  bool parallel_ = true;            // whether rounds still try parallel phases
  InsertionStats stats_;
};

Buffer<std::int32_t> Triangulation::take_rows() {
  using Row = std::array<std::int32_t, 4>;
  const std::size_t size = store_.size();
  const Tet* const tets = store_.tets();
  std::vector<std::uint8_t> is_free(size, 0);
  for (const Worker& w : workers_) {
    for (const std::int32_t t : w.free) is_free[static_cast<std::size_t>(t)] = 1;
    for (std::size_t t = w.fresh; t < w.fresh_end; ++t) is_free[t] = 1;
  }
  auto live = [&](std::size_t i) { return !is_free[i] && infinite_slot(tets[i]) == 4; };
  // Slot i's row, its ids ascending except that the last two are swapped
  // where that order is negative (an odd permutation of the positive one).
  auto row_of = [&](std::size_t i) {
    Row r{global(tets[i].v[0]), global(tets[i].v[1]), global(tets[i].v[2]), global(tets[i].v[3])};
    // The permutation's parity from its inversions, then a sorting network
    // of min/max: no branch on the ids' order (they are random here).
    const int inversions = (r[0] > r[1]) + (r[0] > r[2]) + (r[0] > r[3]) + (r[1] > r[2]) + (r[1] > r[3]) + (r[2] > r[3]);
    auto order = [&](int a, int b) {
      const std::int32_t lo = std::min(r[a], r[b]), hi = std::max(r[a], r[b]);
      r[a] = lo;
      r[b] = hi;
    };
    order(0, 1);
    order(2, 3);
    order(0, 2);
    order(1, 3);
    order(1, 2);
    if (inversions & 1) std::swap(r[2], r[3]);
    return r;
  };
  // Rows ordered by lowest id in two counting passes, each of whose writes
  // stay within a cache-sized region (one scatter to a million ids wrote a
  // cache line per row, at random: 0.7 s of one thread at 1M points).
  // Pass 1, per fixed chunk of slots: its rows, grouped by coarse bucket
  // (the lowest id's top bits), written over the chunk's own tetrahedra
  // once it has read them (a row takes half a tetrahedron's room; a fresh
  // array faulted in 115 MB at 1M points). Pass 2,
  // per bucket: its groups from every chunk, counting-sorted by lowest id
  // straight into the output, then each id's few rows sorted by the rest,
  // which makes the result the same for any slot layout. The tetrahedra are
  // read once, each row is written twice.
  static_assert(2 * sizeof(Row) == sizeof(Tet));
  std::size_t n_ids = 1;
  for (const std::int32_t g : global_) n_ids = std::max(n_ids, static_cast<std::size_t>(g) + 1);
  const int shift = std::max(0, static_cast<int>(std::bit_width(n_ids - 1)) - 10);
  const std::size_t buckets = ((n_ids - 1) >> shift) + 1;
  constexpr std::size_t chunk = 1 << 14;
  const std::size_t chunks = (size + chunk - 1) / chunk;
  // group[c * (buckets + 1) + b]: where chunk c's rows of bucket b start, in
  // rows from grouped(c).
  std::vector<std::uint32_t> group(chunks * (buckets + 1));
  auto grouped = [&](std::size_t c) { return reinterpret_cast<unsigned char*>(store_.tets() + c * chunk); };
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, chunks, 1), [&](const tbb::blocked_range<std::size_t>& range) {
    std::vector<Row> rows;
    rows.reserve(chunk);
    for (std::size_t c = range.begin(); c != range.end(); ++c) {
      rows.clear();
      std::uint32_t* const start = group.data() + c * (buckets + 1);
      std::fill(start, start + buckets + 1, 0u);
      const std::size_t end = std::min(size, (c + 1) * chunk);
      for (std::size_t i = c * chunk; i < end; ++i) {
        // The vertices' ids lie anywhere in global_: ask for them ahead.
        if (i + 16 < end)
          for (int k = 0; k < 4; ++k) __builtin_prefetch(global_.data() + std::max(tets[i + 16].v[k], 0));
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
  auto key_less = [](const Row& a, const Row& b) {  // row[0] is shared
    if (a[1] != b[1]) return a[1] < b[1];
    const std::int32_t a2 = std::min(a[2], a[3]), b2 = std::min(b[2], b[3]);
    if (a2 != b2) return a2 < b2;
    return std::max(a[2], a[3]) < std::max(b[2], b[3]);
  };
  Buffer<std::int32_t> out(4 * bucket_start[buckets]);  // every entry is written below
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
      each_row([&](const Row& r) { std::memcpy(dst + 4 * start[static_cast<std::size_t>(r[0]) - id0]++, r.data(), sizeof(Row)); });
      // start[g] is now where id g's rows end.
      for (std::size_t g = 0, from = bucket_start[b]; g < ids; from = start[g++])
        if (const std::size_t n = start[g] - from; n > 1) {  // sorted as Rows, copied in and out (no aliasing)
          few.resize(n);
          std::memcpy(few.data(), dst + 4 * from, n * sizeof(Row));
          if (n > 32) {
            std::sort(few.begin(), few.end(), key_less);
          } else {  // an id has 7 rows on average
            for (std::size_t a = 1; a < n; ++a)
              for (std::size_t k = a; k > 0 && key_less(few[k], few[k - 1]); --k) std::swap(few[k], few[k - 1]);
          }
          std::memcpy(dst + 4 * from, few.data(), n * sizeof(Row));
        }
    }
  });
  return out;
}

}  // namespace

std::optional<Buffer<std::int32_t>> insertion_delaunay(const ExactContext& ctx, std::span<const std::int32_t> ids,
                                                       const double* lo, const double* hi,
                                                       const InsertionOptions& options) {
  if (ctx.dim != 3) throw std::logic_error("tessera: insertion_delaunay is 3D only");
  BrioOrder order = brio_order(ctx, ids, lo, hi);
  // The first tetrahedron: the first two points, the first point off their
  // line, the first off their plane (in insertion order).
  const std::size_t m = order.ids.size();
  if (m < 4) return std::nullopt;
  std::size_t c = 2;
  auto at = [&](std::size_t k) { return ctx.points + static_cast<std::size_t>(order.ids[k]) * 3; };
  while (c < m && kernels::collinear3(at(0), at(1), at(c))) ++c;
  if (c == m) return std::nullopt;
  std::size_t d = c + 1;
  std::array<std::int32_t, 4> s{order.ids[0], order.ids[1], order.ids[c], -1};
  int o = 0;
  for (; d < m; ++d) {
    s[3] = order.ids[d];
    if ((o = kernels::orientation(ctx, s.data())) != 0) break;
  }
  if (d == m) return std::nullopt;
  std::array<std::int32_t, 4> local{0, 1, static_cast<std::int32_t>(c), static_cast<std::int32_t>(d)};
  if (o < 0) std::swap(local[2], local[3]);
  std::vector<std::int32_t> guide = brio_guides(ctx, order);
  order.codes = {};
  Triangulation tri(ctx, std::move(order.ids), std::move(guide), options.threads);
  tri.start(local);
  for (std::size_t r = 0; r + 1 < order.rounds.size(); ++r) {
    const std::size_t a = order.rounds[r], b = order.rounds[r + 1];
    std::vector<std::int32_t> pts;
    pts.reserve(b - a);
    for (std::size_t i = std::max<std::size_t>(a, 2); i < b; ++i)
      if (i != c && i != d) pts.push_back(static_cast<std::int32_t>(i));
    // Every vertex so far: the round's points, those before, and c and d.
    auto placed = [&](std::size_t k) {
      if (options.progress) options.progress(static_cast<double>(a + k) / static_cast<double>(m));
    };
    tri.insert_round(std::move(pts), std::max(b, d + 1), options.parallel_min, placed);
    if (options.progress) options.progress(static_cast<double>(b) / static_cast<double>(m));
  }
  if (options.stats != nullptr) *options.stats = tri.stats();
  return tri.take_rows();
}

template <int D>
LocatedInsertion insert_located(const Pass<D>& pass, const std::function<void(double)>& progress) {
  // Exact duplicates, bin by bin (BinLocator::lowest_coincident): sorting
  // every id by its coordinates gathered a cache line per comparison.
  const auto& loc = *pass.locator;
  LocatedInsertion out;
  out.lowest = loc.lowest_coincident();
  std::vector<std::int32_t> distinct;
  distinct.reserve(loc.size());
  for (std::size_t k = 0; k < loc.size(); ++k)
    if (out.lowest[k] < 0) distinct.push_back(loc.id(k));
  if constexpr (D == 2) {
    out.rows = insertion_delaunay_2d(pass.exact, distinct, pass.gens.lo.data(), pass.gens.hi.data(), progress);
  } else {
    InsertionOptions io;
    io.threads = pass.engine_options.threads;
    io.progress = progress;
    out.rows = insertion_delaunay(pass.exact, distinct, pass.gens.lo.data(), pass.gens.hi.data(), io);
  }
  return out;
}

template LocatedInsertion insert_located(const Pass<2>&, const std::function<void(double)>&);
template LocatedInsertion insert_located(const Pass<3>&, const std::function<void(double)>&);

}  // namespace tessera::front
