// Hull completion: the Delaunay simplices the cells pass cannot see.
//
// The cells pass finds exactly the simplices whose circumcentre lies in the
// domain box. Near the convex hull, thin simplices have circumcentres far
// outside any padded box (arbitrarily far for nearly coplanar hull points).
// They are recovered by gift wrapping restricted to the thin hull shell:
//
//  * Open facets of the found complex (a facet in one found simplex, whose
//    Voronoi edge runs to the box) are closed one by one: the simplex on the
//    far side is {facet, p} for the point p strictly beyond the facet whose
//    sphere through the facet is empty of every other point beyond it (the
//    first point swept as the sphere through the facet grows away from the
//    found simplex). No point beyond the facet: it is a hull facet.
//  * Every vertex of a missing simplex has a cell that reaches the box (its
//    circumcentre lies outside the box and inside all those cells), so the
//    candidates are those points only, in a small bounding-volume tree with
//    tight boxes (candidate_tree.hpp). The region a better point must lie in
//    (the current best sphere beyond the facet) is a huge, thin lens for the
//    thin simplices near the hull; tight boxes around a shell of points prune
//    it far better than a uniform grid, whose bins the lens cuts by hundreds.
//  * Comparisons use in_sphere(), the clip predicate with its symbolic
//    perturbation, so the added simplices are those of the same perturbed
//    triangulation the cells pass computed: together they are one
//    triangulation of the convex hull, exactly CGAL's on points in general
//    position.
// The same wrapping closes the cavities that skipped cells leave (simplices
// of skipped points only; docs/design.md, "Skipped cells"): the skipped
// points are candidates too, and the open facets around a cavity come from
// the compositor like the hull's.
// Closing a facet can open new ones; rounds repeat until every open facet is
// a hull facet. Each round's gift wraps run in parallel, each first trying
// the vertices of the round's other open facets across its ridges (seeds:
// often the answer, which then only has to be proved empty).
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <stdexcept>
#include <vector>

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include "delaunay_compositor.hpp"
#include "tessera/engine/thread_arena.hpp"
#include "tessera/kernels/delaunay_predicates.hpp"
#include "candidate_tree.hpp"
#include "facet_table.hpp"

namespace tessera::front {

template <int D>
class HullCompletion {
 public:
  using Facet = std::array<std::int32_t, D>;
  using Simplex = std::array<std::int32_t, D + 1>;

  /// `candidates` holds the points whose cells reach the box; `diameter` is
  /// the domain's diagonal (the scale for float margins).
  HullCompletion(const kernels::ExactContext& ctx, const CandidateTree<D>& candidates, double diameter)
      : ctx_(ctx), tree_(candidates), diam_(diameter) {}

  /// Stop once the wraps have done more than `work` in all, counting each
  /// candidate considered once and each side test that needs the exact
  /// orientation (tens of times a float test) exact_weight times: run() then returns what it has, and over_budget() says so. The
  /// wraps consider a few candidates per input point on most inputs (1.6 at
  /// 1M uniform points, 5.5 on the benchmark's clustered set), with next to
  /// no exact tests; near-coplanar hull faces (a rotated or slightly
  /// jittered lattice) make every wrap scan a whole face, hundreds per point
  /// and growing with the face, most of them exact.
  void set_budget(std::uint64_t work) { budget_ = work; }
  static constexpr std::uint64_t exact_weight = 32;
  bool over_budget() const { return over_.load(std::memory_order_relaxed); }

  /// The point beyond `f` (away from `apex`) that closes it, or -1 for a
  /// hull facet. `seeds` are likely answers, tried before the search (see
  /// wrap_toward).
  std::int32_t wrap(const Facet& f, std::int32_t apex, std::span<const std::int32_t> seeds = {}) const {
    std::array<std::int32_t, D + 1> ids;
    std::copy(f.begin(), f.end(), ids.begin());
    ids[D] = apex;
    const int apex_side = kernels::orientation(ctx_, ids.data());
    if (apex_side == 0) throw std::logic_error("tessera: hull completion met a flat simplex");
    return wrap_toward(f, -apex_side, apex, seeds);
  }

  /// The point on `side` of `f` (the sign of orientation(f, x)) whose
  /// simplex with f is Delaunay, or -1 when no point lies strictly there.
  /// `skip` (an apex already known) is not considered. Precondition: f is a
  /// facet of the (perturbed) triangulation.
  ///
  /// `seeds` (point ids; negative entries are ignored) are considered
  /// first. They change the work, never the answer: the answer is the point
  /// of least pencil parameter beyond f, and a point is inside the sphere
  /// through f and the current best exactly when its parameter is smaller,
  /// so whatever the order, every better point is inside every ball the
  /// search prunes by. A right seed makes the first ball the final one: the
  /// search then only proves it empty (on a terrain's completion, ~10
  /// points tested instead of ~43, and one ball solved instead of ~13).
  std::int32_t wrap_toward(const Facet& f, int side, std::int32_t skip = -1,
                           std::span<const std::int32_t> seeds = {}) const {
    std::array<std::int32_t, D + 1> ids;
    std::copy(f.begin(), f.end(), ids.begin());
    // The facet's fixed rows of orientation(f, x): its value is the dot of
    // x - a with their cofactors c, the filter's error bound the dot of |x - a|
    // with the cofactors' absolute products cp. The same terms as
    // orientation()'s own filter, so a certain sign here is its sign.
    const double* a = pt(f[0]);
    double c[D], cp[D];
    if constexpr (D == 3) {
      const double* b = pt(f[1]);
      const double* e = pt(f[2]);
      double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {e[0] - a[0], e[1] - a[1], e[2] - a[2]};
      for (int d = 0; d < 3; ++d) {
        const int d1 = (d + 1) % 3, d2 = (d + 2) % 3;
        c[d] = u[d1] * v[d2] - u[d2] * v[d1];
        cp[d] = std::fabs(u[d1] * v[d2]) + std::fabs(u[d2] * v[d1]);
      }
    } else {
      const double* b = pt(f[1]);
      c[0] = -(b[1] - a[1]);
      c[1] = b[0] - a[0];
      cp[0] = std::fabs(c[0]);
      cp[1] = std::fabs(c[1]);
    }
    // The side of x (an input point or a box corner): the float filter, then
    // the facet's integer plane (grids, where coplanar points are common),
    // built on first need, then `exact`.
    std::optional<IntegerPlane> plane;
    std::uint64_t tested = 0;  // candidates considered, and exact side tests (set_budget)
    auto side_of = [&](const double* x, auto&& exact) {
      double det = 0, perm = 0, growth = 3;
      for (int d = 0; d < D; ++d) {
        const double r = x[d] - a[d];
        det += r * c[d];
        perm += std::fabs(r) * cp[d];
        growth += 2 * std::fabs(r);
      }
      // Underflow: each c[d] errs by 2 eta at most, times |r|, and each
      // product by eta (filter::underflow_bound).
      const double bound = 16 * kernels::filter::u * perm + kernels::filter::underflow_bound(growth);
      if (det > bound) return 1;
      if (det < -bound) return -1;
      if (!plane) plane.emplace(f, *this);
      int side;
      if (plane->side(x, side)) return side;
      tested += exact_weight;
      return exact();
    };
    // Float normal n with n.(x - a) > 0 beyond the facet, for pruning only.
    double n[D];
    double nn = 0;
    for (int d = 0; d < D; ++d) {
      n[d] = side * c[d];
      nn += n[d] * n[d];
    }
    typename CandidateTree<D>::Query q;
    for (int d = 0; d < D; ++d) {
      q.normal[d] = n[d];
      q.origin[d] = a[d];
      q.near[d] = 0;
      for (int k = 0; k < D; ++k) q.near[d] += pt(f[static_cast<std::size_t>(k)])[d] / D;
    }
    // The margin covers the float plane test's rounding, n's included: n
    // is the facet's float cofactors, whose absolute error is a few ulp of
    // the products behind them (cp), not of |n|. Where the facet is nearly
    // degenerate (three almost collinear points of a rotated lattice's hull)
    // n is small and mostly rounding, and a margin of |n| pruned points that
    // lay beyond.
    double cp_sum = 0;
    for (int d = 0; d < D; ++d) cp_sum += cp[d];
    q.margin = 1e-9 * (std::sqrt(nn) + cp_sum) * diam_;
    // True when no corner of the box is strictly on `side`: the orientation
    // is affine in x, so then no point of the box is beyond.
    auto box_not_beyond = [&](const double* lo, const double* hi) {
      const double* pts[D + 1];
      for (int k = 0; k < D; ++k) pts[k] = pt(f[static_cast<std::size_t>(k)]);
      double corner[D];
      pts[D] = corner;
      for (int k = 0; k < (1 << D); ++k) {
        for (int d = 0; d < D; ++d) corner[d] = (k >> d) & 1 ? hi[d] : lo[d];
        // A corner at a facet vertex (a tight box holding it) is on the plane.
        auto exact = [&] {
          for (int v = 0; v < D; ++v)
            if (std::equal(corner, corner + D, pts[v])) return 0;
          return kernels::orientation(D, pts);
        };
        if (side_of(corner, exact) == side) return false;
      }
      return true;
    };
    std::int32_t best = -1;
    auto consider = [&](std::int32_t p) {
      ++tested;
      // best itself: a seed the search meets again (in_sphere is not asked
      // about a sphere's own point).
      if (p == skip || p == best || std::find(f.begin(), f.end(), p) != f.end()) return;
      ids[D] = p;
      if (side_of(pt(p), [&] { return kernels::orientation(ctx_, ids.data()); }) != side) return;  // not strictly beyond
      if (best >= 0) {
        std::array<std::int32_t, D> planes;
        std::copy(f.begin() + 1, f.end(), planes.begin());
        planes[D - 1] = best;
        if (!kernels::in_sphere(ctx_, f[0], planes.data(), p)) return;
      }
      best = p;
      circumball(f, best, q);
    };
    for (std::int32_t p : seeds)
      if (p >= 0) consider(p);
    tree_.search(q, consider, box_not_beyond);
    if (considered_.fetch_add(tested, std::memory_order_relaxed) + tested > budget_) over_.store(true, std::memory_order_relaxed);
    return best;
  }

  /// The facets of simplex s (ids ascending), each with its opposite vertex as apex.
  static std::array<OpenFacet<D>, D + 1> facets_of(const Simplex& s) {
    std::array<OpenFacet<D>, D + 1> out;
    for (int k = 0; k <= D; ++k) {
      OpenFacet<D>& o = out[static_cast<std::size_t>(k)];
      for (int m = 0, j = 0; m <= D; ++m)
        if (m != k) o.facet[static_cast<std::size_t>(j++)] = s[static_cast<std::size_t>(m)];
      o.apex = s[static_cast<std::size_t>(k)];
    }
    return out;
  }

  /// The whole triangulation grown from one of its simplices, `seed` (ids
  /// ascending): run() on the seed's facets, with the seed itself among the
  /// simplices returned.
  std::vector<Simplex> run_from(const Simplex& seed, int threads) {
    const auto open = facets_of(seed);
    std::vector<Simplex> added = run(std::vector<OpenFacet<D>>(open.begin(), open.end()), threads);
    added.insert(std::lower_bound(added.begin(), added.end(), seed), seed);
    return added;
  }

  /// Close the complex whose open facets are `open`; returns the added
  /// simplices (ascending ids), in ascending order. Terminates: a simplex is
  /// never added twice (its facets would then be in three simplices, which
  /// throws), and there are finitely many.
  std::vector<Simplex> run(const std::vector<OpenFacet<D>>& open, int threads) {
    // Facets on the current boundary and those closed by completion, with
    // the number of simplices holding each (found ones count once: the
    // other side of an open facet is what completion looks for).
    engine::ThreadArena arena(threads);  // below 1: one thread
    FacetTable<D> facets(2 * open.size());
    std::vector<OpenFacet<D>> queue = open;
    std::vector<std::uint8_t> counts;
    arena.execute([&] { facets.bump_all(queue.size(), [&](std::size_t i) { return queue[i].facet; }, counts); });
    std::vector<Simplex> added;
    std::vector<Ridge> ridges;
    std::vector<std::int32_t> seeds;
    while (!queue.empty()) {
      // A thin hull simplex usually closes two open facets of the same
      // round. The simplex beyond a facet is unique (the perturbed
      // triangulation is), so once a wrap finds one, the round's other
      // facets of it are closed by it and skip their own wrap (over a third
      // of all wraps at 1M uniform points). Which wrap finds it depends on timing; the simplices
      // found do not. The queue is sorted by facet for the lookup.
      std::vector<std::int32_t> hit(queue.size(), -1);
      std::vector<std::atomic<std::uint8_t>> closed(queue.size());
      // Wraps run in spatial order (the tree's leaf order of the facet's
      // lowest point): the searches of one thread's range then share warm
      // branches of the tree. Key: rank above, queue index below.
      std::vector<std::uint64_t> order(queue.size());
      arena.execute([&] {
        tbb::parallel_sort(queue.begin(), queue.end());
        tbb::parallel_for(std::size_t{0}, queue.size(), [&](std::size_t i) {
          order[i] = std::uint64_t{tree_.rank(queue[i].facet[0])} << 32 | i;
        });
        tbb::parallel_sort(order.begin(), order.end());
        find_seeds(queue, ridges, seeds);
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, queue.size()), [&](const tbb::blocked_range<std::size_t>& r) {
          for (std::size_t o = r.begin(); o != r.end(); ++o) {
            const std::size_t i = order[o] & 0xffffffffu;
            if (closed[i].load(std::memory_order_relaxed) || over_budget()) continue;
            const Facet& f = queue[i].facet;
            const std::int32_t p = hit[i] = wrap(f, queue[i].apex, seeds_at(seeds, i));
            if (p < 0) continue;
            for (int k = 0; k < D; ++k) {  // the new simplex's other facets: f with f[k] replaced by p
              OpenFacet<D> g;
              g.facet = f;
              g.facet[static_cast<std::size_t>(k)] = p;
              std::sort(g.facet.begin(), g.facet.end());
              g.apex = std::numeric_limits<std::int32_t>::min();  // below every apex: the first entry of g
              const auto at = std::lower_bound(queue.begin(), queue.end(), g);
              if (at != queue.end() && at->facet == g.facet)
                closed[static_cast<std::size_t>(at - queue.begin())].store(1, std::memory_order_relaxed);
            }
          }
        });
      });
      std::vector<Simplex> fresh;
      for (std::size_t i = 0; i < queue.size(); ++i) {
        if (hit[i] < 0) continue;
        Simplex s;
        std::copy(queue[i].facet.begin(), queue[i].facet.end(), s.begin());
        s[D] = hit[i];
        std::sort(s.begin(), s.end());
        fresh.push_back(s);
      }
      arena.execute([&] { tbb::parallel_sort(fresh.begin(), fresh.end()); });
      fresh.erase(std::unique(fresh.begin(), fresh.end()), fresh.end());
      // The new simplices' facets, counted with all of them in: a facet
      // held once is open (the next round wraps it), twice closed.
      added.insert(added.end(), fresh.begin(), fresh.end());
      std::vector<OpenFacet<D>> held(fresh.size() * (D + 1));
      arena.execute([&] {
        tbb::parallel_for(std::size_t{0}, fresh.size(), [&](std::size_t j) {
          const auto f = facets_of(fresh[j]);
          std::copy(f.begin(), f.end(), held.begin() + static_cast<std::ptrdiff_t>(j * (D + 1)));
        });
        facets.bump_all(held.size(), [&](std::size_t i) { return held[i].facet; }, counts);
      });
      queue.clear();
      if (over_budget()) break;
      for (std::size_t i = 0; i < held.size(); ++i) {
        if (counts[i] > 2) throw std::logic_error("tessera: hull completion put a facet in three simplices");
        if (counts[i] == 1) queue.push_back(held[i]);
      }
    }
    arena.execute([&] { tbb::parallel_sort(added.begin(), added.end()); });
    return added;
  }

 private:
  // Seeds from the front (the round's open facets). The simplex beyond an
  // open facet f often has another facet on the front: then its apex is
  // the far vertex of an open facet that shares a ridge (D - 1 points) with
  // f, as the fan around that ridge closes. Each open facet keeps, per
  // ridge, up to kSeedsPerRidge such vertices. On a terrain's completion
  // (50k points, 379k wraps) a seed was the answer in 35% of the wraps,
  // which then tested ~10 points each instead of ~43, and the Delaunay run
  // took 2.8 -> 1.85 s on two threads (with the slack below).
  static constexpr std::size_t kSeedsPerRidge = 2;
  static constexpr std::size_t kSeeds = D * kSeedsPerRidge;

  // An open facet's ridge: the facet without its vertex `k` (ids ascending,
  // packed), the facet's place in the queue, and the vertex left out.
  struct Ridge {
    std::uint64_t key;
    std::uint32_t facet;
    std::int32_t other;
    auto operator<=>(const Ridge&) const = default;
  };

  static std::uint64_t ridge_key(const Facet& f, int k) {
    std::uint64_t key = 0;
    for (int m = 0; m < D; ++m)
      if (m != k) key = key << 32 | static_cast<std::uint32_t>(f[static_cast<std::size_t>(m)]);
    return key;
  }

  // seeds[i * kSeeds + k * kSeedsPerRidge + j]: the j-th front vertex
  // across ridge k of queue[i], or -1. Call within the arena.
  static void find_seeds(const std::vector<OpenFacet<D>>& queue, std::vector<Ridge>& ridges,
                         std::vector<std::int32_t>& seeds) {
    const std::size_t n = queue.size();
    ridges.resize(n * D);
    seeds.assign(n * kSeeds, -1);
    tbb::parallel_for(std::size_t{0}, n, [&](std::size_t i) {
      for (int k = 0; k < D; ++k)
        ridges[i * D + static_cast<std::size_t>(k)] = {ridge_key(queue[i].facet, k), static_cast<std::uint32_t>(i),
                                                       queue[i].facet[static_cast<std::size_t>(k)]};
    });
    tbb::parallel_sort(ridges.begin(), ridges.end());
    // Each entry fills its own facet's slots for its own ridge: no two
    // entries write the same slot. (Two ridges of one facet have different keys.)
    tbb::parallel_for(std::size_t{0}, ridges.size(), [&](std::size_t e) {
      const Ridge& r = ridges[e];
      const Facet& f = queue[r.facet].facet;
      const auto k = static_cast<std::size_t>(std::find(f.begin(), f.end(), r.other) - f.begin());
      std::int32_t* out = seeds.data() + r.facet * kSeeds + k * kSeedsPerRidge;
      std::size_t m = 0;
      for (std::size_t a = e; a-- > 0 && ridges[a].key == r.key && m < kSeedsPerRidge;) out[m++] = ridges[a].other;
      for (std::size_t a = e + 1; a < ridges.size() && ridges[a].key == r.key && m < kSeedsPerRidge; ++a)
        out[m++] = ridges[a].other;
    });
  }

  static std::span<const std::int32_t> seeds_at(const std::vector<std::int32_t>& seeds, std::size_t i) {
    return {seeds.data() + i * kSeeds, kSeeds};
  }

  const double* pt(std::int32_t id) const { return ctx_.points + static_cast<std::size_t>(id) * D; }

  // The facet's plane in exact 128-bit integers when its coordinates are
  // 25-bit integers times a common power of two (lattices, voxel centres):
  // there, whole hull faces are coplanar with the facet and every one of their
  // points would otherwise go through the slow exact orientation path.
  // side() gives sign(det[f1-f0, (f2-f0,) x-f0]) = orientation(f, x) for a
  // point on the same grid, and false when the point is not.
  struct IntegerPlane {
    bool ok = false;
    kernels::GridScale grid;
    __int128 n[D] = {}, a[D] = {};

    IntegerPlane(const Facet& f, const HullCompletion& hc) {
      for (std::int32_t id : f)
        for (int d = 0; d < D; ++d) grid.see(hc.pt(id)[d]);
      std::int64_t c[D][D];
      for (int k = 0; k < D; ++k)
        for (int d = 0; d < D; ++d)
          if (!grid.scaled(hc.pt(f[static_cast<std::size_t>(k)])[d], 25, c[k][d])) return;
      __int128 r[D][D];
      for (int d = 0; d < D; ++d) a[d] = c[0][d];
      for (int k = 1; k < D; ++k)
        for (int d = 0; d < D; ++d) r[k][d] = c[k][d] - a[d];
      if constexpr (D == 3) {
        n[0] = r[1][1] * r[2][2] - r[1][2] * r[2][1];
        n[1] = r[1][2] * r[2][0] - r[1][0] * r[2][2];
        n[2] = r[1][0] * r[2][1] - r[1][1] * r[2][0];
      } else {
        n[0] = -r[1][1];
        n[1] = r[1][0];
      }
      ok = true;
    }

    bool side(const double* x, int& out) const {
      if (!ok) return false;
      __int128 s = 0;
      for (int d = 0; d < D; ++d) {
        std::int64_t v;
        if (!grid.scaled(x[d], 25, v)) return false;
        s += n[d] * (static_cast<__int128>(v) - a[d]);
      }
      out = s > 0 ? 1 : (s < 0 ? -1 : 0);
      return true;
    }
  };

  // The circumball of the facet and `best`, inflated: a better point lies in
  // it (and beyond the facet). Float, with a margin, where the simplex is
  // well-conditioned; its centre solved exactly where it is flat. Flatness is
  // what matters, not the radius: a nearly flat simplex whose fourth point is
  // also nearly on the facet's circle has a circumcentre of ordinary size
  // that the float solve can put anywhere (found on a rotated lattice, whose
  // hull faces are coplanar up to rounding: the ball pruned the true best).
  // Forward error analysis of the solve (cofactors, determinant and
  // numerators, and the rounding of r and s) bounds the centre's error by
  // about 50 u cond (|y| + max |r_k|), cond = |r_0|...|r_{D-1}| / |det r|
  // (the permanents behind each rounding are at most 5.2 |r_0|...|r_{D-1}|).
  // With cond <= 1e7 that is below 1e-7 (|y| + diam), inside the margin.
  // A cutoff of 1e4 sent the common thin hull simplices to the exact solve:
  // hull completion of 1M uniform points took 0.3 s longer.
  //
  // Beyond the cutoff the centre comes from exact_vertex (the Voronoi vertex
  // of f[0] with the others' bisectors, in rationals, rounded once per
  // coordinate). These balls used to be unbounded, and an unbounded search
  // visits every candidate beyond the facet: on a height field (a terrain),
  // whose nearly flat stretches make such simplices by the hundred, that
  // made hull completion quadratic (100k points: 752 such searches, each
  // over ~50k candidates, more work than all the other 760k searches
  // together). Slow (GMP), but rare: ~0.5% of the balls there.
  //
  // Power cells (ExactContext::radii): the ball is the orthoball's reach. A
  // point q of weight w_q = r_q^2 is in conflict with the orthosphere (centre
  // c, power R^2 = |c - a|^2 - w_a) when |q - c|^2 < R^2 + w_q, so every
  // better point lies within sqrt(R^2 + w_max) of c. The centre solves
  // 2 r_k . y = s_k - (w_k - w_a); the error analysis above holds with
  // max |r_k| read as max (s_k + w_k + w_a) / |r_k| (a numerator's term
  // s_k c_k / det is at most that times cond / 2).
  void circumball(const Facet& f, std::int32_t best, typename CandidateTree<D>::Query& q) const {
    const double* a = pt(f[0]);
    const double* radii = ctx_.radii;
    const double wa = radii != nullptr ? radii[f[0]] * radii[f[0]] : 0.0;
    double r[D][D], s[D];
    double lengths = 1, longest = 0;
    for (int k = 0; k < D; ++k) {
      const std::int32_t id = k + 1 < D ? f[static_cast<std::size_t>(k + 1)] : best;
      const double* p = pt(id);
      s[k] = 0;
      for (int d = 0; d < D; ++d) {
        r[k][d] = p[d] - a[d];
        s[k] += r[k][d] * r[k][d];
      }
      lengths *= std::sqrt(s[k]);
      longest = std::max(longest, std::sqrt(s[k]));
      // An edge shorter than 2^-300 (input whose coordinates span more than
      // 2^347, ExactContext::may_underflow): its squared length, and the
      // products below, may have underflowed, which the bound above does
      // not cover. Found by fuzzing: two points 2^-1022 apart made s = 0,
      // lengths = 0, and a garbage ball pruned the true next point (a facet
      // then sat in three simplices). No ball: the search is exhaustive.
      if (!(s[k] >= 0x1p-600)) {
        q.ball_r2 = std::numeric_limits<double>::infinity();
        return;
      }
      if (radii != nullptr) {
        const double wk = radii[id] * radii[id];
        longest = std::max(longest, (s[k] + wk + wa) / std::sqrt(s[k]));
        s[k] -= wk - wa;
      }
    }
    // Centre y relative to a: 2 r_k . y = s_k (Cramer).
    double y[D];
    double det;
    if constexpr (D == 2) {
      det = 2 * (r[0][0] * r[1][1] - r[0][1] * r[1][0]);
      y[0] = (s[0] * r[1][1] - s[1] * r[0][1]) / det;
      y[1] = (r[0][0] * s[1] - r[1][0] * s[0]) / det;
    } else {
      double c0[3], c1[3], c2[3];
      auto cross = [](const double* u, const double* v, double* o) {
        o[0] = u[1] * v[2] - u[2] * v[1];
        o[1] = u[2] * v[0] - u[0] * v[2];
        o[2] = u[0] * v[1] - u[1] * v[0];
      };
      cross(r[1], r[2], c0);
      cross(r[2], r[0], c1);
      cross(r[0], r[1], c2);
      det = 2 * (r[0][0] * c0[0] + r[0][1] * c0[1] + r[0][2] * c0[2]);
      for (int d = 0; d < 3; ++d) y[d] = (s[0] * c0[d] + s[1] * c1[d] + s[2] * c2[d]) / det;
    }
    double rad2 = 0;
    for (int d = 0; d < D; ++d) rad2 += y[d] * y[d];
    double rad = std::sqrt(rad2);
    double slack;  // the inflation: the centre's error, the radius's rounding, the margin
    if (std::fabs(det) * 1e7 >= 2 * lengths && std::isfinite(rad) && rad <= 1e6 * diam_) {
      // The centre's error E (above; a point of the true ball is within
      // rad + 2E of the computed centre), taken 40 times over, plus 1e-12
      // of the sizes for the radius's and the tree's own roundings. It was
      // 1e-6 (rad + diam) whatever the conditioning, ~1e6 times the error
      // of a typical ball: on a terrain, whose leaves grow thinner than
      // that as points are added, the inflated balls opened leaves all along
      // their contact with the surface (200k terrain Delaunay 10.9-11.1 ->
      // 10.5-10.6 s). Neither the test suite nor a fuzz of 900 nearly
      // degenerate hulls (jittered rotated lattices, shallow caps, jittered
      // spheres) found a wrong simplex even with no slack at all: the margin
      // rests on the analysis, as the old one did.
      const double cond = 2 * lengths / std::fabs(det);
      slack = (4096 * kernels::filter::u * cond + 1e-12) * (rad + longest);
    } else {
      // best is strictly beyond the facet, so the simplex is not flat and
      // its planes are independent. Each coordinate is within 2 ulp: the
      // centre within 4 u |y|, the radius computed from it within a few
      // more u; 1e-9 rad is far above both (and above the rounding of the
      // tree's squared distances to a centre this far away).
      std::int32_t planes[D];
      for (int k = 0; k + 1 < D; ++k) planes[k] = f[static_cast<std::size_t>(k + 1)];
      planes[D - 1] = best;
      kernels::exact_vertex(ctx_, f[0], planes, y);
      rad2 = 0;
      for (int d = 0; d < D; ++d) rad2 += y[d] * y[d];
      rad = std::sqrt(rad2);
      if (!(rad <= 1e100 * diam_)) {  // squares would overflow: no ball
        q.ball_r2 = std::numeric_limits<double>::infinity();
        return;
      }
      slack = 1e-9 * rad;
    }
    // The centre is stored in absolute coordinates: a[d] + y[d] rounds to
    // the ulp of the larger, which on points far from the origin (a cloud of
    // extent 1e-10 around 1000, where an ulp is 1e-13) dwarfs the relative
    // margins; the tree's point distances round likewise.
    double big = 0;
    for (int d = 0; d < D; ++d) {
      q.ball_centre[d] = a[d] + y[d];
      big = std::max({big, std::fabs(a[d]), std::fabs(q.ball_centre[d])});
    }
    double reach = rad + slack + 64 * kernels::filter::u * big;
    if (radii != nullptr) {
      // A conflicting point lies within E + sqrt((|y| + E)^2 + w_max - w_a)
      // of the computed centre (E: its error, within slack); the weights'
      // rounding is covered by 1e-12 of the magnitudes under the root.
      const double wmax = ctx_.max_radius * ctx_.max_radius;
      const double extra = wmax - wa + 1e-12 * (rad2 + wa + wmax);
      reach = std::sqrt(reach * reach + std::max(extra, 0.0)) + slack;
    }
    q.ball_r2 = reach * reach;
  }

  const kernels::ExactContext& ctx_;
  const CandidateTree<D>& tree_;
  double diam_;
  std::uint64_t budget_ = std::numeric_limits<std::uint64_t>::max();  // set_budget
  mutable std::atomic<std::uint64_t> considered_{0};                  // by every wrap so far
  mutable std::atomic<bool> over_{false};
};

}  // namespace tessera::front
