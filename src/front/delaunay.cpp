// tessera::delaunay: the cells pass with the Delaunay compositor (simplices
// oriented by the cells' topology), hull completion (oriented by the exact
// predicate), and one layout of both.
#include "tessera/delaunay.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <numbers>
#include <numeric>
#include <optional>
#include <span>
#include <stdexcept>

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include "delaunay_compositor.hpp"
#include "hull_completion.hpp"
#include "id_hash.hpp"
#include "insertion.hpp"
#include "pass.hpp"
#include "periodic.hpp"
#include "pilot.hpp"
#include "point_buckets.hpp"
#include "simplex_facets.hpp"
#include "tessera/engine/tessellate.hpp"
#include "tessera/engine/thread_arena.hpp"
#include "tessera/kernels/delaunay_predicates.hpp"
#include "tessera/kernels/hull.hpp"
#include "tessera/kernels/tile.hpp"

namespace tessera {
namespace {

using front::pilot_estimate;
using front::pilot_min_points;
using front::PilotEstimate;

// Whether every point inside the domain lies on one hyperplane (a plane in
// 3D, a line in 2D), decided exactly. Such input has no simplex at all. It is
// asked only when the cells pass found none, so on other input it costs
// nothing; on flat input, one filtered orientation per point.
template <int D>
bool exactly_flat(std::span<const double> points, std::span<const std::uint8_t> in_box) {
  auto at = [&](std::size_t i) { return points.data() + i * D; };
  // Affinely independent points met so far; once D of them span the
  // hyperplane, every later point must lie on it (earlier ones were
  // dependent on the basis, so they lie on every hyperplane through it).
  std::array<const double*, D> basis{};
  int rank = 0;
  for (std::size_t i = 0; i < in_box.size(); ++i) {
    if (!in_box[i]) continue;
    const double* p = at(i);
    if (rank == 0) {
      basis[0] = p;
      rank = 1;
    } else if (rank == 1) {
      if (!std::equal(p, p + D, basis[0])) basis[static_cast<std::size_t>(rank++)] = p;
    } else if (rank < D) {  // 3D with two points: is p on their line?
      if (!kernels::collinear3(basis[0], basis[1], p)) basis[static_cast<std::size_t>(rank++)] = p;
    } else {
      const double* s[D + 1];
      for (int k = 0; k < D; ++k) s[k] = basis[static_cast<std::size_t>(k)];
      s[D] = p;
      if (kernels::orientation(D, s) != 0) return false;
    }
  }
  return true;
}

// A simplex to start hull completion from when the cells pass found none:
// every circumcentre lies outside the box (nearly flat input). The cells
// still hold facets of the triangulation: a cell vertex on D - 1 bisectors
// and one box plane lies on the (perturbed) Voronoi edge of its generator and
// those neighbours (3D; in 2D on the Voronoi edge of the generator and one
// neighbour), which therefore exists, so its dual {generator, neighbours} is a
// facet of the perturbed triangulation. A facet of a triangulation of a solid
// set lies in a simplex on at least one side, and gift wrapping finds it
// (HullCompletion::wrap_toward, the same perturbed choice as every other
// wrap). The cells of 32 generators spread over the bin order are rebuilt
// and searched (at this stage each one reaches across the set: searching
// all 4,000 cells of a near-line took 72 s). None may have such a vertex
// where the bisectors are all but parallel (3D points within rounding of a
// line): then nullopt.
template <class CellT>
std::optional<std::array<std::int32_t, CellT::dim + 1>> seed_simplex(const front::Pass<CellT::dim>& pass,
                                                                     const front::HullCompletion<CellT::dim>& hc) {
  constexpr int D = CellT::dim;
  const auto& gens = pass.gens;
  kernels::CellBuilder<CellT> builder(*gens.locator, gens.coords, gens.lo.data(), gens.hi.data(), gens.exact,
                                      gens.tree);
  CellT cell;
  const std::size_t n = gens.order.size();
  const std::size_t tries = std::min<std::size_t>(n, 32);
  for (std::size_t t = 0; t < tries; ++t) {
    const std::int32_t gen = gens.order[t * n / tries];
    const double* p = gens.coords + static_cast<std::size_t>(gen) * D;
    if (!builder.build_any(gen, p, cell).has_cell) continue;
    for (const auto& v : cell.vertices()) {
      std::array<std::int32_t, D> facet;
      facet[0] = gen;
      int boxes = 0;
      for (int k = 0, m = 1; k < D; ++k) {
        const std::int32_t id = cell.planes()[v.p[k]].id;
        if (id < 0) ++boxes;
        else if (m < D) facet[static_cast<std::size_t>(m++)] = id;
      }
      if (boxes != 1) continue;
      std::sort(facet.begin(), facet.end());
      for (const int side : {1, -1}) {
        const std::int32_t apex = hc.wrap_toward(facet, side);
        if (apex < 0) continue;
        std::array<std::int32_t, D + 1> simplex;
        std::copy(facet.begin(), facet.end(), simplex.begin());
        simplex[D] = apex;
        std::sort(simplex.begin(), simplex.end());
        return simplex;
      }
    }
  }
  return std::nullopt;
}

using front::id_hash;

// The points whose cells are skipped (docs/design.md, "Skipped cells").
//
// A point is skipped when its hash ranks in the lowest `fraction` of the
// hashes of the points near it: those within the radius that holds about
// spread_neighbours of them at the density of the 3^D bins around its own.
// Ranking among neighbours spreads the skipped points out, so fewer
// simplices have skipped points only (they are wrapped, at several times a
// cell's cost per simplex) than when a point is skipped by its hash alone.
// Simulated on 100k uniform 3D points: 0.30 of them skipped by hash leave
// 0.81% of the simplices to the wraps; ranking among ~8 neighbours skips
// 0.32 for 0.55%, and 0.38 for 1.1% (hash alone at 0.4: 2.5%). 1M uniform
// points on two threads: 2.78 -> 2.67 s (medians of 5, alternating runs;
// 0.3 by hash against 0.35 ranked, which skips 0.37), though choosing
// costs ~0.1 s (~54 distances per point); clustered inputs, which ask for
// larger fractions, gain nothing.
//
// Where those bins are crowded (over spread_max points: dense clusters,
// where the scan would cost more than it spares) a point is skipped when
// its hash falls below `fraction` of the range. Points with an exact
// duplicate are never skipped (a cell decides which of them owns it):
// coincident points share a bin, so the scan sees them (a crowded bin's
// points are sorted first). The choice depends on the points and their ids
// only, not on the thread count. Located points only.
inline constexpr double spread_neighbours = 8;
inline constexpr std::size_t spread_max = 160;

template <int D>
std::vector<std::uint8_t> choose_skipped(const front::Pass<D>& pass, double fraction, std::size_t n) {
  std::vector<std::uint8_t> skipped(n, 0);
  const auto& loc = *pass.locator;
  const auto threshold = static_cast<std::uint64_t>(std::ldexp(fraction, 64));
  const auto& off = loc.offsets();
  // Per slot, the hash's top 53 bits as a double: ranks compare exactly,
  // and the scan below runs in double lanes.
  std::vector<double> rank_key(loc.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, loc.size(), 1 << 14), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t k = r.begin(); k != r.end(); ++k) rank_key[k] = static_cast<double>(id_hash(loc.id(k)) >> 11);
  });
  double bin_volume = 1;
  for (int d = 0; d < D; ++d) bin_volume *= loc.bin_size(d);
  const double ball = spread_neighbours / (D == 3 ? 4.0 / 3.0 * std::numbers::pi : std::numbers::pi);

  // Bin k by the rank among neighbours; false (nothing decided) when the
  // 3^D bins around it are crowded.
  auto by_rank = [&](std::size_t k) {
    std::array<std::int32_t, D> lo, hi;
    std::size_t rest = k, bins = 1;
    for (int d = 0; d < D; ++d) {
      const auto du = static_cast<std::size_t>(d);
      const auto divs = static_cast<std::size_t>(loc.divisions()[du]);
      const auto c = static_cast<std::int32_t>(rest % divs);
      rest /= divs;
      lo[du] = std::max(c - 1, 0);
      hi[du] = std::min(c + 1, loc.divisions()[du] - 1);
      bins *= static_cast<std::size_t>(hi[du] - lo[du] + 1);
    }
    // Their slots, as one run per row of bins.
    constexpr int rows = D == 3 ? 9 : 3;
    std::uint32_t first[rows], last[rows];
    int nr = 0;
    std::size_t count = 0;
    loc.for_each_row_run(lo, hi, [&](std::uint32_t a, std::uint32_t e) {
      first[nr] = a;
      last[nr] = e;
      count += e - a;
      ++nr;
    });
    if (count > spread_max) return false;
    // The radius of a ball that holds spread_neighbours points at the density around.
    const double density = static_cast<double>(count - 1) / (static_cast<double>(bins) * bin_volume);
    const double r2 = density > 0 ? std::pow(ball / density, 2.0 / D) : 0.0;
    for (std::uint32_t i = off[k]; i < off[k + 1]; ++i) {
      const auto& p = loc.point(i);
      const double own = rank_key[i];
      // Counted over every slot, the point itself included (d2 = 0, not lower).
      std::uint32_t zero = 0, near = 0, lower = 0;
      for (int w = 0; w < nr; ++w)
        for (std::uint32_t j = first[w]; j < last[w]; ++j) {
          const auto& q = loc.point(j);
          double d2 = 0;
          for (int d = 0; d < D; ++d) d2 += (q[static_cast<std::size_t>(d)] - p[static_cast<std::size_t>(d)]) * (q[static_cast<std::size_t>(d)] - p[static_cast<std::size_t>(d)]);
          const bool in = d2 <= r2;
          zero += d2 == 0;  // also for points within ~1e-162: kept, which is always safe
          near += in;
          lower += in & (rank_key[j] < own);
        }
      const bool alone = zero == 1;
      near -= 1;
      const bool pick = near == 0 ? id_hash(loc.id(i)) < threshold
                                  : static_cast<double>(lower) < fraction * static_cast<double>(near);
      skipped[static_cast<std::size_t>(loc.id(i))] = alone && pick;
    }
    return true;
  };

  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, loc.num_bins(), 4096), [&](const tbb::blocked_range<std::size_t>& r) {
    std::vector<std::uint32_t> order;
    for (std::size_t k = r.begin(); k != r.end(); ++k) {
      const std::uint32_t a = off[k], e = off[k + 1];
      if (a == e || by_rank(k)) continue;
      // Crowded: by hash.
      order.resize(e - a);
      std::iota(order.begin(), order.end(), a);
      std::sort(order.begin(), order.end(), [&](std::uint32_t x, std::uint32_t y) { return loc.point(x) < loc.point(y); });
      for (std::size_t i = 0; i < order.size(); ++i) {
        const std::int32_t id = loc.id(order[i]);
        const bool alone = (i == 0 || loc.point(order[i - 1]) != loc.point(order[i])) &&
                           (i + 1 == order.size() || loc.point(order[i + 1]) != loc.point(order[i]));
        skipped[static_cast<std::size_t>(id)] = alone && id_hash(id) < threshold;
      }
    }
  });
  return skipped;
}


/// From this pilot ratio on, points go to insertion rather than to the
/// cells. Both build the same rows, so the choice may follow the thread
/// count. Measured at 1M points (docs/design.md, "Insertion for costly
/// inputs"): insertion takes ~4.5-5 s on one thread whatever the input,
/// and ~2.6-3.0 s on two where its parallel phases work (volumes: uniform,
/// blobs, sheets, hierarchies; stop 33); on surfaces they turn themselves off and
/// it stays serial, but there the cells cost several times more. The cells
/// take 4.8 s on one thread and 2.55 s on two on uniform points (ratio 1),
/// 2.7 s on two on a fractal hierarchy (1.3), 7.8-8.3 s on blobs and
/// sheets (3.4-3.8), more on surface samples (an ellipsoid's 12-16, a
/// terrain's 42-73, a torus's 52-176): about 2.55 s times ratio^0.7. So the
/// threshold is 1.6 on two threads (the hierarchy, 1.3, measures level
/// both ways; lattices, ~1, take twice as long by insertion) and 1.13 on one;
/// beyond two threads it grows as sqrt(threads), a model (the cells scale
/// nearly linearly, the phases defer more as their slabs thin), not a
/// measurement.
///
/// In 2D the insertion is cheap, and since stop 38 it has the parallel
/// phases too: 1M uniform points 0.70 s on one thread and 0.42 s on two
/// (stop 39; 0.80 / 0.47 s in stop 38),
/// 200k 0.073 s on two, about the same on curves, blobs and segments. The
/// cells take 1.13 s on one thread and 0.60 s on two at 1M uniform points,
/// 0.11 s on two at 200k, and on 200k clustered points (ratios 6-7)
/// 0.29-0.34 s on two. Lattices (ratio 0.6-1.2), whose every in-circle
/// test is a tie, take 0.10-0.14 s by the cells and 0.15-0.16 s by
/// insertion at 250k points; they stay with the cells below 1.4 on two
/// threads, as sqrt(threads) beyond.
template <int D>
double insertion_ratio(int threads) {
  return (D == 3 ? 1.6 : 1.4) * std::sqrt(std::max(threads, 1) / 2.0);
}

/// Completion's budget, in candidates its wraps consider per input point,
/// beyond which the automatic method turns to insertion. Measured per point
/// (stop 34, two threads): 1.6 at 1M uniform points, 3.5 at 100k, 5.5 on the
/// benchmark's clustered 100k, 2.4 on a 200k fractal hierarchy, 1.1 on the
/// 50^3 lattice, 29 on a 60^3 lattice jittered by 1e-3 (cells 0.66 s,
/// insertion 0.60 s); 337-522 on rotated lattices of 10^3-20^3 points (20^3:
/// 8.2 s, insertion 0.49 s) and 1041 on a 60^3 lattice jittered by 1e-9
/// (10.7 s, insertion 0.60 s).
inline constexpr std::uint64_t completion_budget = 64;

/// Below this many exact evaluations per pilot cell an input has no ties to
/// speak of (PilotEstimate::exact_per_cell; lattices ~53).
inline constexpr double clean_exact_per_cell = 1.0;

/// The share of the inside generators the labelled pass's pilot may build
/// (as the cells' pilot: few inside points are measured too).
inline constexpr double labelled_pilot_share = 0.5;

// `b` grown about its centre by `grow` on every axis, or nullopt where that
// box, or its extent, would not be finite.
std::optional<Bounds> grown_box(Bounds b, int dim, double grow) {
  for (std::size_t a = 0; a < static_cast<std::size_t>(dim); ++a) {
    const double mid = 0.5 * (b.lo[a] + b.hi[a]), half = 0.5 * (b.hi[a] - b.lo[a]);
    b.lo[a] = mid - grow * half;
    b.hi[a] = mid + grow * half;
    if (!(std::isfinite(b.lo[a]) && std::isfinite(b.hi[a]) && std::isfinite(b.hi[a] - b.lo[a]))) return std::nullopt;
  }
  return b;
}

// The triangulation by insertion of the located points (front::insert_located).
template <int D>
Delaunay by_insertion(const front::Pass<D>& pass, Delaunay out) {
  engine::ThreadArena(pass.engine_options.threads).execute([&] {
    front::LocatedInsertion ins = front::insert_located(pass, pass.engine_options.progress);
    front::report_duplicates(pass, {}, out.duplicates);  // (no labels here: completion)
    out.hull_completed = true;
    if (!ins.rows) return;  // all on one plane (2D: line): no simplex exists
    out.from_insertion = ins.rows->size() / (D + 1);
    out.simplices = std::move(*ins.rows);
  });
  if (out.n_simplices() > 0) front::list_hidden(out);  // (flat input: no simplex, nobody hidden)
  return out;
}

template <class CellT>
Delaunay run(std::span<const double> input, std::span<const std::int32_t> labels, const DelaunayOptions& opt,
             int attempt = 0, bool* labelled_cell_touches_box = nullptr) {
  constexpr int D = CellT::dim;
  const std::size_t n = input.size() / D;
  const bool complete = opt.complete_hull && labels.empty();
  front::Pass<D> pass(input, labels, opt);
  Delaunay out;
  out.dim = D;
  out.n_points = n;
  out.bounds = pass.user_bounds;
  out.ignored_outside_bounds = pass.ignored_outside;
  out.threads_used = pass.engine_options.threads;
  out.power = !pass.radii.empty();

  // The labelled cells pass of delaunay()'s first way, with the automatic
  // method: where a sample of its cells finds them costly, and costlier in
  // all than the whole triangulation (the second way, which the automatic
  // method builds by insertion on such input; about a cell's cost per
  // point), it gives way to that. The centre of 40,000 points on a sphere,
  // alone inside, has every sphere point as a face, clipped one by one: 4 s,
  // and past 65,534 points (until stop 59) the face limit (0.2 s by insertion). A clustered
  // ball inside a cloud ten times its size keeps the pass.
  if (labelled_cell_touches_box != nullptr && opt.method == DelaunayMethod::automatic) {
    const double insert_from = insertion_ratio<D>(pass.engine_options.threads);
    const double ratio = pilot_estimate<CellT>(pass, insert_from, labelled_pilot_share).ratio;
    if (ratio >= insert_from && ratio * static_cast<double>(pass.order.size()) >= static_cast<double>(n)) {
      *labelled_cell_touches_box = true;
      return out;
    }
  }

  // Skipped cells (docs/design.md, "Skipped cells"): only where completion
  // runs, as it closes their cavities. Automatically from 20,000 points, by
  // what the cells cost (pilot_estimate): in 3D 35% to 90% (1M uniform
  // points: 3.0 -> 2.7 s on two threads at 30% by hash); in 2D none on
  // uniform points, whose cells are cheap next to the wraps that would
  // replace them, 30% to 60% on clustered ones.
  const bool pilot = complete && opt.skip_cells < 0 && n >= pilot_min_points && opt.method != DelaunayMethod::insertion;
  const bool may_insert = opt.method == DelaunayMethod::automatic;
  const double insert_from = insertion_ratio<D>(pass.engine_options.threads);
  const PilotEstimate estimate =
      pilot ? pilot_estimate<CellT>(pass, may_insert ? insert_from : std::numeric_limits<double>::infinity()) : PilotEstimate{};
  {
    // Cells far costlier than what they find (surface samples, clustered
    // volumes; in 2D curves, blobs, points on a circle): insertion
    // (docs/design.md, "Insertion for costly inputs").
    // Too few points for a pilot: insertion, which no input makes costly
    // (the cells of points nearly on a sphere each test every point: 5,000
    // such points took 4.1 s, 0.13 s by insertion; 5,000 on a circle 1.0 s,
    // 0.003 s); 10,000 uniform 3D points take 0.029 s against 0.042 s, a
    // 20^3 lattice 0.037 s against 0.028; 5,000 uniform 2D points 0.003 s
    // against 0.004.
    const bool small = may_insert && complete && opt.skip_cells < 0 && n < pilot_min_points;
    // On one or two threads, inputs without exact ties go to insertion too:
    // 1M uniform points 2.47 against 2.55 s on two threads, 4.34 against
    // 4.81 s on one; a 1M fractal hierarchy 2.79 against 2.71 s; a 60^3
    // lattice jittered by 1e-9, whose near-coplanar hull makes completion
    // stall, 0.60 against 2.0 s (cells, then insertion past
    // completion_budget). Exact ties need both many exact evaluations in
    // the pilot's cells and coordinates on a grid (make_grid): a 60^3
    // lattice, or one offset by 1e6, takes 0.55 s by the cells and 1.16 s
    // by insertion, whose every in-sphere test is then a tie; the same
    // lattice rotated, or scaled by 0.1, is off any grid, its near-ties
    // settled by the extended filter: 1.29 s and 2.54 s by insertion,
    // minutes and 4.49 s by the cells. Beyond two threads the cells scale
    // better (a model; this machine has two cores). In 2D likewise (1M
    // uniform points: 0.80 against 1.13 s on one thread, 0.47 against 0.60
    // s on two; a rotated 300^2 lattice 0.042 against 0.075 s).
    const bool ties = estimate.exact_per_cell >= clean_exact_per_cell && pass.exact.grid != nullptr;
    const bool clean = !ties && pass.engine_options.threads <= 2;
    const bool insert = opt.method == DelaunayMethod::insertion || small ||
                        (may_insert && pilot && (estimate.ratio >= insert_from || clean));
    if (insert && complete && attempt == 0) return by_insertion(pass, std::move(out));
  }
  const double skip = !complete ? 0 : opt.skip_cells >= 0 ? opt.skip_cells : pilot ? estimate.fraction : 0;
  std::vector<std::uint8_t> skipped;
  std::vector<std::int32_t> built_order;
  std::vector<std::uint32_t> built_slots;
  if (skip > 0) {
    engine::ThreadArena(pass.engine_options.threads).execute([&] { skipped = choose_skipped<D>(pass, skip, n); });
    for (std::size_t g = 0; g < pass.order.size(); ++g)
      if (!skipped[static_cast<std::size_t>(pass.order[g])]) {
        built_order.push_back(pass.order[g]);
        built_slots.push_back(pass.slots[g]);
      }
    pass.gens.order = built_order;
    pass.gens.slots = built_slots;
  }

  // Where completion turns out far costlier than the cells (near-coplanar
  // hull faces: a rotated or slightly jittered lattice), insertion takes
  // over (HullCompletion::set_budget). It builds the same rows, so only
  // the automatic method may switch.
  const bool fall_back = D == 3 && complete && opt.method == DelaunayMethod::automatic && attempt == 0;
  const bool power = complete && !pass.radii.empty() && attempt == 0;
  const Delaunay before_cells = fall_back || power ? out : Delaunay{};
  // Progress never restarts: where an insertion may take over, the cells
  // report the bar's first 80% and the insertion the rest (it restarted the
  // bar at 0 after the cells had filled it).
  constexpr double cells_share = 0.8;
  if (fall_back && opt.progress)
    pass.engine_options.progress = [&opt](double f) { opt.progress(cells_share * f); };
  front::DelaunayPassResult<D> found;
  front::DelaunayCompositor<CellT> comp(found, n, labels, complete, skipped);
  out.exact_predicate_calls = engine::tessellate<CellT>(pass.gens, comp, pass.engine_options);
  if (skip > 0 && found.found == 0) {
    // Nothing found to complete from (a few or nearly flat points): the
    // paths below start from every cell.
    DelaunayOptions all = opt;
    all.skip_cells = 0;
    return run<CellT>(input, labels, all, attempt);
  }
  const std::size_t found_duplicates = found.duplicates.size();
  out.duplicates = std::move(found.duplicates);
  front::report_duplicates(pass, labels, out.duplicates);
  out.from_cells = found.found;
  if (labelled_cell_touches_box != nullptr) *labelled_cell_touches_box = found.labelled_cell_touches_box;
  out.skipped_cells = skip > 0 ? pass.order.size() - built_order.size() : 0;

  if (complete && out.from_cells == 0 && exactly_flat<D>(pass.points, pass.in_box)) {
    // No simplex exists. Rerunning in larger boxes (below) would find none
    // either, at a cost quadratic in the points (every cell then reaches
    // across the whole flat set: 2,170 points took 61 s).
    out.hull_completed = true;
    std::sort(out.duplicates.begin(), out.duplicates.end());
    return out;
  }
  const bool none_found = complete && out.from_cells == 0 && pass.locator->size() - found_duplicates > D;
  if (none_found && power) {
    // A regular triangulation whose power cells have no vertex in the box
    // is not flat input: one sphere's power is the least all over the box
    // (its weight beyond the others' by far more than the box's extent
    // squared), and every orthocentre lies beyond it, 1e24 box lengths out
    // for a radius of 1e12 beside unit ones; larger boxes would not reach
    // them, and the seeded wrap below reported the points flat. Insertion
    // builds the same rows from no box at all.
    return by_insertion(pass, before_cells);
  }
  // Every circumcentre lies outside the box (a handful of points, or nearly
  // flat input), so completion has no found simplex to start from. The
  // triangulation does not depend on the box: run again in a box 2^20, then
  // 2^50 times larger, and complete the rest from there. Costly (every cell
  // then reaches across the set: 2,000 points flat to an ulp take ~6 s)
  // but reached only on such inputs, and cheaper there than wrapping the
  // whole triangulation from one seed (below: ~36 s on those points,
  // whose slivers' balls are too ill-conditioned to prune the search).
  // Near the end of double's range (points at 1e300) the larger box would
  // not be finite: the seeded wrap below takes it from this one.
  const std::optional<Bounds> grown =
      none_found && attempt < 2 ? grown_box(pass.user_bounds, D, attempt == 0 ? 0x1p20 : 0x1p50) : std::nullopt;
  if (grown) {
    const Bounds& b = *grown;
    DelaunayOptions big = opt;
    big.progress = nullptr;
    big.bounds = b;
    big.ignore_outside_points = true;
    std::vector<double> kept;
    if (!pass.ignored_outside.empty()) {
      // Keep the original domain's selection: points it dropped stay dropped.
      kept.assign(input.begin(), input.end());
      for (std::int32_t id : pass.ignored_outside)
        for (int d = 0; d < D; ++d) kept[static_cast<std::size_t>(id) * D + d] = 2 * b.hi[static_cast<std::size_t>(d)];
    }
    Delaunay retry = run<CellT>(kept.empty() ? input : std::span<const double>(kept), labels, big, attempt + 1);
    retry.bounds = out.bounds;
    retry.ignored_outside_bounds = out.ignored_outside_bounds;
    return retry;
  }

  std::vector<std::array<std::int32_t, D + 1>> added;
  if (complete) {
    out.hull_completed = true;
    // Candidates: the points whose cells reach the box, and the skipped ones.
    if (!skipped.empty())
      for (std::size_t i = 0; i < n; ++i) found.touches_box[i] |= skipped[i];
    std::optional<front::CandidateTree<D>> tree;
    engine::ThreadArena(pass.engine_options.threads).execute([&] { tree.emplace(pass.points, found.touches_box); });
    const front::CandidateTree<D>& candidates = *tree;
    double diam2 = 0;
    for (int d = 0; d < D; ++d) {
      double e = pass.gens.hi[static_cast<std::size_t>(d)] - pass.gens.lo[static_cast<std::size_t>(d)];
      diam2 += e * e;
    }
    front::HullCompletion<D> hc(pass.exact, candidates, std::sqrt(diam2));
    if (fall_back) hc.set_budget(completion_budget * n + (1u << 16));
    if (!none_found) {
      added = hc.run(found.open, pass.engine_options.threads);
    } else {
      // Not flat, yet no circumcentre within 2^50 extents of the input: flat
      // to within ~1e-15 of its extent (points 1e-300 off a plane or a
      // line). Completion starts from one simplex found by gift wrapping a
      // facet the cells hold (seed_simplex) and wraps the whole
      // triangulation from there; every cell reaches the box, so every point
      // is a candidate.
      const auto seed = seed_simplex<CellT>(pass, hc);
      if (!seed)
        // 3D points within rounding of a line: their bisectors are all but
        // parallel, and no cell searched has a vertex on a single box plane.
        // Returning no simplex would be a wrong, empty answer.
        throw InputError(
            "the points are flat to within rounding (3D points all but on a line): no Delaunay simplex or facet "
            "could be found within 2^50 times the input's extent; remove the near-degenerate offsets or joggle");
      added = hc.run_from(*seed, pass.engine_options.threads);
    }
    if constexpr (D == 3)
      if (hc.over_budget()) {
        if (opt.progress)
          pass.engine_options.progress = [&opt](double f) { opt.progress(cells_share + (1 - cells_share) * f); };
        return by_insertion(pass, std::move(before_cells));
      }
  }
  out.from_hull_completion = added.size();

  // Orient the completion's simplices (they have no cell to read it from)
  // by the exact predicate. The cells' foreign rows (skipped cells) join
  // them, and write() lays out the found rows and these extra ones in one
  // pass.
  std::atomic<std::size_t> flat = 0;
  engine::ThreadArena(pass.engine_options.threads).execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, added.size(), 4096), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i) {
        auto& row = added[i];
        const int o = kernels::orientation(pass.exact, row.data());
        if (o < 0) std::swap(row[D - 1], row[D]);
        if (o == 0) flat.fetch_add(1, std::memory_order_relaxed);
      }
    });
  });
  if (flat != 0)
    throw std::logic_error("tessera: " + std::to_string(flat.load()) + " Delaunay simplices are flat (inconsistent topology)");
  if (added.size() < found.foreign.size()) added.swap(found.foreign);  // append the shorter list
  added.insert(added.end(), found.foreign.begin(), found.foreign.end());
  std::vector<std::array<std::int32_t, D + 1>>().swap(found.foreign);
  engine::ThreadArena(pass.engine_options.threads).execute([&] { comp.write(added, out.simplices); });
  std::sort(out.duplicates.begin(), out.duplicates.end());
  if (complete) front::list_hidden(out);
  return out;
}

/// The distinct values of [first, last) ascending, in place; returns their
/// end. A point's bucket of Delaunay edges lists each edge once per simplex
/// around it (~40 entries for ~8 distinct in 3D): sorting them all cost most
/// of vertex_neighbors. Repeats are dropped first, each entry compared with
/// the values kept so far four at a time, branch-free; then the few kept are
/// sorted. Short and long buckets (2D; a point of very high degree) are
/// sorted whole.
std::int32_t* distinct_ascending(std::int32_t* first, std::int32_t* last) {
  constexpr std::size_t cap = 256;
  const std::size_t n = static_cast<std::size_t>(last - first);
  if (n <= 12 || n > cap) {  // 2D buckets (~6 entries) sort faster whole
    std::sort(first, last);
    return std::unique(first, last);
  }
  using Quad = std::int32_t __attribute__((vector_size(16)));
  // Kept values, then padding that no id equals; slot m may also hold an
  // entry found to repeat, which only ever matches that same kept value.
  alignas(16) std::int32_t kept[cap + 4];
  std::fill(kept, kept + n + 4, -1);
  std::size_t m = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const std::int32_t x = first[i];
    const Quad vx = {x, x, x, x};
    Quad seen = {};
    for (std::size_t j = 0; j < m; j += 4) {
      Quad k;
      std::memcpy(&k, kept + j, sizeof k);
      seen |= k == vx;
    }
    kept[m] = x;
    m += (seen[0] | seen[1] | seen[2] | seen[3]) == 0;
  }
  std::sort(kept, kept + m);
  return std::copy(kept, kept + m, first);
}

// The labelled triangulation from the whole one (hull completed): its
// simplices whose vertices are all inside points, rows in their order (so
// still ascending), and the duplicates that are inside points. The same
// simplices as the labelled cells pass finds where their circumcentres lie
// in the box (there, outside generators build no cell and a simplex with an
// outside vertex is dropped), and besides them the thin hull simplices
// beyond the box, which that pass cannot reach.
void keep_inside(Delaunay& dt, std::span<const std::int32_t> labels) {
  const std::size_t w = static_cast<std::size_t>(dt.dim + 1), n = dt.n_simplices();
  std::int32_t* const rows = dt.simplices.data();
  std::size_t kept = 0;
  for (std::size_t r = 0; r < n; ++r) {
    const std::int32_t* row = rows + r * w;
    bool inside = true;
    for (std::size_t k = 0; k < w; ++k) inside &= labels[static_cast<std::size_t>(row[k])] >= 0;
    if (!inside) continue;
    if (kept != r) std::copy(row, row + w, rows + kept * w);
    ++kept;
  }
  dt.simplices.resize(kept * w);
  dt.outside_simplices = n - kept;
  dt.hull_completed = false;  // a region, not the convex hull: locate() must not walk
  std::erase_if(dt.duplicates, [&](const auto& d) { return labels[static_cast<std::size_t>(d.first)] < 0; });
  std::erase_if(dt.hidden, [&](std::int32_t id) { return labels[static_cast<std::size_t>(id)] < 0; });
}

// Whether the inside points come within 5% of the points' extent of the
// points' bounding box on some side (an inside point on the hull does).
bool inside_reaches_out(std::span<const double> points, int dim, std::span<const std::int32_t> labels) {
  const Bounds all = front::bounding_box(points, dim), inside = front::bounding_box(points, dim, labels);
  for (std::size_t a = 0; a < static_cast<std::size_t>(dim); ++a) {
    const double margin = 0.05 * (all.hi[a] - all.lo[a]);
    if (!(inside.lo[a] - all.lo[a] > margin && all.hi[a] - inside.hi[a] > margin)) return true;  // NaN (overflowed extent) too
  }
  return false;
}

/// delaunay_of_images (front/periodic.hpp): the cells pass alone, its
/// compositor given no labels so that images (label < 0, no cell of their
/// own) may be vertices; no hull, no skipped cells.
template <class CellT>
Delaunay images_pass(std::span<const double> points, std::span<const std::int32_t> labels,
                     const VoronoiOptions& opt, std::vector<double>& reach) {
  constexpr int D = CellT::dim;
  const std::size_t n = points.size() / D;
  front::Pass<D> pass(points, labels, opt);
  Delaunay out;
  out.dim = D;
  out.n_points = n;
  out.bounds = pass.user_bounds;
  out.threads_used = pass.engine_options.threads;
  out.power = !pass.radii.empty();
  front::DelaunayPassResult<D> found;
  front::DelaunayCompositor<CellT> comp(found, n, {}, false);
  comp.record_reach(&reach);
  out.exact_predicate_calls = engine::tessellate<CellT>(pass.gens, comp, pass.engine_options);
  out.from_cells = found.found;
  out.duplicates = std::move(found.duplicates);
  front::report_duplicates(pass, labels, out.duplicates);
  std::sort(out.duplicates.begin(), out.duplicates.end());
  const std::vector<std::array<std::int32_t, D + 1>> none;
  engine::ThreadArena(pass.engine_options.threads).execute([&] { comp.write(none, out.simplices); });
  for (double& r : reach) r = pass.unscale(std::sqrt(r));
  return out;
}

}  // namespace

Delaunay delaunay(std::span<const double> input, int dim, std::span<const std::int32_t> labels,
                  const DelaunayOptions& given) {
  if (!given.radii.empty()) {
    // The regular (weighted Delaunay) triangulation, the dual of the power
    // cells (docs/design.md, "Regular triangulations"): the cells pass and
    // hull completion with the power test. Equal radii are the ordinary
    // triangulation, by any method.
    if (dim == 2 || dim == 3) front::check_radii(given.radii, input.size() / static_cast<std::size_t>(dim));
    if (std::adjacent_find(given.radii.begin(), given.radii.end(), std::not_equal_to<>()) == given.radii.end()) {
      DelaunayOptions plain = given;
      plain.radii = {};
      return delaunay(input, dim, labels, plain);
    }
  }
  if (!given.walls.empty())
    throw InputError("delaunay takes no walls: the triangulation's domain is the box (--bounds)");
  if (given.periodic_box()) {
    if (!given.periodic[0] && !given.periodic[1] && !given.periodic[2])
      throw InputError("a tilt (triclinic box) needs periodic axes");
    return front::periodic_delaunay(input, dim, labels, given);
  }
  const front::CheckedInput<DelaunayOptions> in(input, dim, labels, given);
  const std::span<const double> points = in.points;
  const DelaunayOptions& options = in.options;
  if (options.method == DelaunayMethod::insertion && !options.complete_hull)
    throw InputError("the insertion method triangulates the whole convex hull: it needs complete_hull");
  if (!(options.skip_cells < 1))
    throw InputError("skip_cells must be below 1 (a fraction of the points; negative: automatic), got " +
                     std::to_string(options.skip_cells));
  if (!options.radii.empty() && !labels.empty() && options.complete_hull) {
    // With labels the whole regular triangulation, filtered: the labelled
    // pass's shortcut (below) rests on each point lying in its own cell,
    // which a power cell need not hold. Otherwise radii take every path as
    // the ordinary triangulation does: the cells pass with hull completion
    // and skipped cells (their cavities' wraps use the power test), or the
    // insertion (with the power test, hidden points left out).
    Delaunay dt = dim == 3 ? run<kernels::Hull>(points, {}, options) : run<kernels::Tile>(points, {}, options);
    keep_inside(dt, labels);
    return dt;
  }
  if (!labels.empty() && options.complete_hull) {
    // The whole triangulation's inside simplices. An inside simplex whose
    // circumcentre v lies beyond the box has each vertex's cell holding v
    // and the vertex, so the segment between them, which crosses the box:
    // each of those inside cells has a face on the box. Where no inside cell
    // has one, the labelled cells pass (inside cells only, circumcentres in
    // the box) therefore finds them all, and outside cells need not be
    // built (a ball of inside points in a cloud of outside ones). Otherwise
    // the whole triangulation is built, by any method, and filtered. The
    // pass is not tried where inside points come near the points' bounding
    // box (inside_reaches_out): there their cells nearly always reach the
    // domain box, and the pass would be thrown away (speed only; either
    // way gives the same rows).
    if (options.method != DelaunayMethod::insertion && !inside_reaches_out(points, dim, labels)) {
      DelaunayOptions boxed = options;
      boxed.complete_hull = false;  // (run() reads the method: automatic lets its pilot decline the pass)
      bool touches = true;
      Delaunay dt = dim == 3 ? run<kernels::Hull>(points, labels, boxed, 0, &touches)
                             : run<kernels::Tile>(points, labels, boxed, 0, &touches);
      if (!touches) return dt;
    }
    Delaunay dt = dim == 3 ? run<kernels::Hull>(points, {}, options) : run<kernels::Tile>(points, {}, options);
    keep_inside(dt, labels);
    return dt;
  }
  return dim == 3 ? run<kernels::Hull>(points, labels, options) : run<kernels::Tile>(points, labels, options);
}

namespace front {

void list_hidden(Delaunay& dt) {
  if (!dt.power) return;
  std::vector<std::uint8_t> used(dt.n_points, 0);
  for (const std::int32_t id : dt.simplices) used[static_cast<std::size_t>(id)] = 1;
  for (const auto& [dup, owner] : dt.duplicates) used[static_cast<std::size_t>(dup)] = 1;
  for (const std::int32_t id : dt.ignored_outside_bounds) used[static_cast<std::size_t>(id)] = 1;
  for (std::size_t i = 0; i < dt.n_points; ++i)
    if (!used[i]) dt.hidden.push_back(static_cast<std::int32_t>(i));
}

Delaunay delaunay_of_images(std::span<const double> points, int dim, std::span<const std::int32_t> labels,
                            const VoronoiOptions& options, std::vector<double>& reach) {
  return dim == 3 ? images_pass<kernels::Hull>(points, labels, options, reach)
                  : images_pass<kernels::Tile>(points, labels, options, reach);
}

}  // namespace front

std::vector<std::int32_t> simplex_neighbors(const Delaunay& dt) {
  front::refuse_periodic(dt, "simplex_neighbors");
  const std::size_t w = static_cast<std::size_t>(dt.dim + 1);
  std::vector<std::int32_t> nb(dt.n_simplices() * w, -1);
  // Each point pairs the facets it is lowest in (simplex_facets.hpp): every
  // entry of nb is written by one point, so points run at once. Records of
  // one facet pair up in ascending simplex order; a third (a non-conforming
  // triangulation) stays -1.
  engine::ThreadArena(dt.threads_used).execute([&] {
    const front::FacetBuckets buckets(dt);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, dt.n_points, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
      std::vector<front::FacetRecord> recs;
      for (std::size_t a = r.begin(); a != r.end(); ++a) {
        buckets.records(a, recs);
        for (std::size_t i = 0; i + 1 < recs.size(); ++i) {
          if (!recs[i].same_facet(recs[i + 1])) continue;
          nb[static_cast<std::size_t>(recs[i].simplex) * w + static_cast<std::size_t>(recs[i].k)] = recs[i + 1].simplex;
          nb[static_cast<std::size_t>(recs[i + 1].simplex) * w + static_cast<std::size_t>(recs[i + 1].k)] = recs[i].simplex;
          ++i;
        }
      }
    });
  });
  return nb;
}

std::vector<std::int32_t> vertex_to_simplex(const Delaunay& dt) {
  front::check_simplex_ids(dt);
  std::vector<std::int32_t> out(dt.n_points, -1);
  const std::size_t w = static_cast<std::size_t>(dt.dim + 1);
  for (std::size_t s = dt.n_simplices(); s-- > 0;)  // the lowest index is written last
    for (std::size_t k = 0; k < w; ++k) out[static_cast<std::size_t>(dt.simplices[s * w + k])] = static_cast<std::int32_t>(s);
  return out;
}

VertexNeighbors vertex_neighbors(const Delaunay& dt) {
  front::refuse_periodic(dt, "vertex_neighbors");
  front::check_simplex_ids(dt);
  const std::size_t n = dt.n_points, w = static_cast<std::size_t>(dt.dim + 1);
  // A simplex's edges as slot pairs (i < j): 3 in 2D, 6 in 3D.
  std::array<std::array<std::size_t, 2>, 6> edge{};
  std::size_t edges = 0;
  for (std::size_t i = 0; i < w; ++i)
    for (std::size_t j = i + 1; j < w; ++j) edge[edges++] = {i, j};
  const std::int32_t* const rows = dt.simplices.data();
  VertexNeighbors out;
  engine::ThreadArena(dt.threads_used).execute([&] {
    // Every simplex edge {u, v} goes to its lower end as the higher one
    // (bucket_by_point); each point keeps the distinct values of its bucket
    // in place (distinct_ascending): its higher neighbours H, ascending.
    std::vector<std::int64_t> at;
    std::vector<std::int32_t> higher;
    auto end_of = [&](std::size_t s, std::size_t e, bool high) {
      const std::int32_t a = rows[s * w + edge[e][0]], b = rows[s * w + edge[e][1]];
      return (a < b) == high ? b : a;
    };
    front::bucket_by_point(
        dt, edges, [&](std::size_t s, std::size_t e) { return end_of(s, e, false); },
        [&](std::size_t s, std::size_t e) { return end_of(s, e, true); }, at, higher);
    std::vector<std::int64_t> h_count(n);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t v = r.begin(); v != r.end(); ++v) {
        std::int32_t* const first = higher.data() + at[v];
        std::int32_t* end = distinct_ascending(first, higher.data() + at[v + 1]);
        if (first != end && static_cast<std::size_t>(*first) == v)  // a row naming v twice (hand-made)
          end = std::copy(first + 1, end, first);
        h_count[v] = end - first;
      }
    });
    // Point v's list is its lower neighbours L (the points u < v with v in
    // H(u)), then H(v): ascending as it stands. L is H transposed, by the same
    // counting sort over the points u, which lists each bucket in ascending u.
    std::vector<std::int64_t> l_at;
    std::vector<std::int32_t> lower;
    front::bucket_rows(
        n, n, [&](std::size_t u) { return h_count[u]; },
        [&](std::size_t u, std::size_t k) { return higher[static_cast<std::size_t>(at[u]) + k]; },
        [](std::size_t u, std::size_t) { return static_cast<std::int32_t>(u); }, l_at, lower);
    out.offsets.assign(n + 1, 0);
    for (std::size_t v = 0; v < n; ++v) out.offsets[v + 1] = out.offsets[v] + (l_at[v + 1] - l_at[v]) + h_count[v];
    out.ids.resize(static_cast<std::size_t>(out.offsets[n]));
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t v = r.begin(); v != r.end(); ++v) {
        const auto o = std::copy(lower.begin() + l_at[v], lower.begin() + l_at[v + 1], out.ids.begin() + out.offsets[v]);
        std::copy(higher.begin() + at[v], higher.begin() + at[v] + h_count[v], o);
      }
    });
  });
  return out;
}

}  // namespace tessera
