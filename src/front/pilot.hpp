// The pilot: what a sample of cells costs to search per Delaunay simplex it
// finds, relative to uniform input. tessera::delaunay sizes its skipped
// cells by it and turns to insertion where cells are costly; tessera::voronoi
// turns to cells from Delaunay neighbours (delaunay_stars.hpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <type_traits>
#include <vector>

#include "id_hash.hpp"
#include "pass.hpp"
#include "tessera/engine/tessellate.hpp"

namespace tessera::front {

// The pilot's compositor: what the cells it is given cost to search
// (BuildStatus::work, plus tie_weight units per exact evaluation a small
// grid or the box-corner pattern served) and how many of their vertices
// are Delaunay simplices (no box plane). The cells themselves are not kept.
template <class CellT>
struct PilotCompositor {
  struct Batch {
    std::uint64_t cells = 0, work = 0, vertices = 0, found = 0, capped = 0;
  };
  Batch total;
  std::uint64_t tie_weight = 0;
  void add(Batch& b, std::int32_t, const kernels::BuildStatus& st, CellT& cell) {
    ++b.cells;
    // (a capped cell's counts up to the cap: a lower bound)
    b.work += st.work + tie_weight * (cell.exact_calls() - cell.off_grid_exact_calls());
    b.capped += st.capped;
    if (!st.has_cell) return;
    b.vertices += cell.vertices().size();
    for (const auto& v : cell.vertices()) {
      bool found = true;
      for (int k = 0; k < CellT::dim; ++k) found &= v.p[k] >= CellT::box_planes;
      b.found += found;
    }
  }
  void finish(std::span<Batch> batches) {
    for (const Batch& b : batches) {
      total.cells += b.cells;
      total.work += b.work;
      total.vertices += b.vertices;
      total.found += b.found;
      total.capped += b.capped;
    }
  }
};

/// The pilot's cells kept for the cells pass (tessera::voronoi). A cell the
/// pilot built whole (not capped) is the one the search would build again:
/// a cell's search depends on its generator alone, and the capped builder's
/// pruned shell 2 keeps exactly the candidates of the whole one, in order
/// (CellBuilder::gather_dense). Where the search is chosen, the pass takes
/// these batches as they are (engine::tessellate's `earlier`) and leaves their
/// generators out: on small inputs the pilot builds up to half the cells
/// (pilot_share), which the pass built a second time until stop 71 (1,000
/// uniform 3D points: 5.7 ms by the automatic method, 2.1 ms by the search).
/// Where the insertion is chosen they are dropped (the stars' cells may
/// differ in the last bits). `Keep`: the pass's compositor, whose Batch
/// lists its generators in `gen`.
template <class Keep>
struct PilotKeep {
  using Compositor = Keep;
  Keep& comp;
  std::vector<typename Keep::Batch> batches;  // kept cells only; none capped
  std::uint64_t exact_calls = 0;              // the kept cells' exact evaluations
};

/// Counts for the pilot (PilotCompositor) and hands each whole cell to the
/// kept compositor too.
template <class CellT, class Keep>
struct KeepingPilotCompositor {
  struct Batch {
    typename PilotCompositor<CellT>::Batch counts;
    typename Keep::Batch kept;
    std::uint64_t exact = 0;
  };
  PilotCompositor<CellT>& pilot;
  PilotKeep<Keep>& keep;
  void add(Batch& b, std::int32_t gen, const kernels::BuildStatus& st, CellT& cell) {
    pilot.add(b.counts, gen, st, cell);
    if (st.capped) return;  // abandoned: the pass builds it
    keep.comp.add(b.kept, gen, st, cell);
    b.exact += cell.exact_calls();
  }
  void finish(std::span<Batch> batches) {
    std::vector<typename PilotCompositor<CellT>::Batch> counts;
    counts.reserve(batches.size());
    for (Batch& b : batches) {
      counts.push_back(b.counts);
      keep.exact_calls += b.exact;
      if (!b.kept.gen.empty()) keep.batches.push_back(std::move(b.kept));
    }
    pilot.finish(counts);
  }
};

// The automatic fraction of skipped cells (3D; 2D below). Skipping a cell saves its
// build; what its simplices then cost depends on the others' cells (the
// simplices of skipped points only are wrapped, each at several times what
// a cell spends per simplex). So the fraction should grow with what a cell
// costs per simplex it finds, which differs by two orders between inputs.
// Measured optima (docs/design.md, "Skipped cells"; the fraction as
// choose_skipped takes it): 1M uniform points and lattices 0.35-0.4;
// clustered volumes (the benchmark's clustered 100k, blobs and sheets of
// 200k: cells 3-4 times a uniform one's search) 0.5-0.6; surface samples
// (needle cells: the ellipsoid's 8-12 times, the torus's 40-160 times; a
// terrain's 4-7 times, but nine in ten of its cells' vertices lie on the
// box, as its simplices' balls reach far outside) 0.9 or more. The rule
// tau = 0.3 sqrt(cost per found simplex, relative to uniform input),
// clamped to [0.35, 0.9], fits all of them. The cost is measured, not
// guessed from the bins (a surface and a set of blobs both leave ~80% of
// the bins empty): a pilot builds the cells of points spread by their hash
// (any spatially random sample would do) and counts their search work
// (BuildStatus::work) and found vertices, both deterministic, so the
// choice is the same for every thread count and run. It goes in bands of
// pilot_band cells until pilot_bands are done or the estimate is far past
// the clamp (costly cells need no more precision). The pilot's cells are
// built again in the pass: at 1M uniform points that is ~0.2% of the run.
//
// In 2D a cell is cheap next to the wraps that would replace it: uniform
// points want none skipped (1M points: 0.63 s, 0.65 s at 0.2, 0.67 s at
// 0.35), but clustered ones (200k points in blobs, along curves, along
// segments: ratios 5.8-7.1) gain 15-25% at 0.45-0.6 (curves 0.50 -> 0.37
// s). So in 2D nothing is skipped below a ratio of 2, and above it the
// fraction is 0.2 sqrt(ratio) in [0.3, 0.6].
inline constexpr std::size_t pilot_min_points = 20000;
inline constexpr std::size_t pilot_band = 256;
inline constexpr std::size_t pilot_bands = 4;
/// Each band is built in parts of ~pilot_band / pilot_parts cells, spread by
/// the hash as the bands are, and may stop after any (pilot_estimate).
inline constexpr std::uint32_t pilot_parts = 8;
/// A pilot cell is abandoned past this many times a uniform cell's work
/// (CellBuilder::set_work_cap; the ratio past which insertion is chosen is
/// 1.6 on two threads). Points nearly on one sphere have cells that all
/// reach its centre, where every point is nearly cospherical with them:
/// each cell tests every point, most exactly (200k points: 2.3M exact
/// evaluations per cell; the pilot's first band alone ran for minutes).
inline constexpr double pilot_work_cap = 64;

struct SkipRule {
  /// BuildStatus::work of a uniform cell, on average, with the default two
  /// points per bin (3D: 307 at 100k and at 1M points, 169 on the 50^3
  /// lattice; 2D: 81-83 at 200k and 1M).
  double uniform_work;
  /// Vertices of a uniform cell, on average (3D 26-27, 2D 6).
  double uniform_vertices;
  double off_below;  ///< no skipping below this ratio
  double slope, lowest, highest;
};
inline constexpr SkipRule skip_rule_3d{307.0, 27.0, 0.0, 0.3, 0.35, 0.9};
inline constexpr SkipRule skip_rule_2d{82.0, 6.0, 2.0, 0.2, 0.3, 0.6};

/// Whether the pilot's cells so far measure what the search costs: none was
/// abandoned at the work cap (the ratio is then a lower bound), and they
/// average at most twice a uniform cell's vertices. Larger cells cost more
/// than the work count (candidates) sees, as every clip classifies every
/// vertex: 60 points inside a sphere of 20,000 outside ones, cells of 107
/// vertices, measured a ratio of 6.9 (~25 us a cell) and were searched at
/// 2.8 ms a cell.
inline bool pilot_measured(std::uint64_t cells, std::uint64_t capped, std::uint64_t vertices, const SkipRule& rule) {
  return capped == 0 && static_cast<double>(vertices) <= 2 * rule.uniform_vertices * static_cast<double>(cells);
}

/// The pilot's measure: ratio, the cells' search work per simplex they find
/// relative to uniform input (infinite when they find none; 1 when too few
/// points to measure), and the skipped fraction it asks for.
struct PilotEstimate {
  double ratio = 1;
  double fraction = 0;
  /// Exact predicate evaluations per pilot cell: ~53 on lattices (rotated
  /// or not), where ties are everywhere; below 0.2 on uniform, clustered
  /// and jittered input. Infinite when not measured.
  double exact_per_cell = std::numeric_limits<double>::infinity();
  /// The cells the pilot built.
  std::uint64_t cells = 0;
  /// Whether the ratio measures the search's cost (pilot_measured); false
  /// when not measured at all.
  bool measured = false;
};

/// `enough`: a ratio at which the caller's choice is made (insertion), so
/// the pilot stops at the first band that reaches it. A band of a thin
/// sheet's 1M points costs ~0.16 s, and all four took 0.63 s where the
/// insertion then took 2.9. `max_share`: the fraction of the generators the
/// pilot may build, in bands of pilot_band or fewer cells (at least 16)
/// where that many would exceed it (tessera::voronoi, whose small inputs
/// need the measure too: 500 points nearly on a sphere take 0.11 s by the
/// search, 0.014 s from their Delaunay neighbours). 0: bands of pilot_band
/// in the top hash range that skipped cells leave alone (1 - the highest
/// skipped fraction). `tie_weight`: work units per exact evaluation that a
/// small grid or the box-corner pattern served (PilotCompositor), which
/// BuildStatus::work leaves out: tessera::voronoi weighs them against its
/// insertion (cells.cpp, tie_weight), tessera::delaunay does not, as its own
/// insertion pays for the same ties in its in-sphere tests.
/// `enough_unmeasured` (default: `enough`): the ratio at which the choice
/// is made while the cells so far are not pilot_measured (tessera::voronoi
/// weighs its threshold by the points per generator only where they are).
/// `keep`: where given, the whole cells built are kept for the pass (PilotKeep).
template <class CellT, class Kept = std::nullptr_t>
PilotEstimate pilot_estimate(const Pass<CellT::dim>& pass, double enough, double max_share = 0,
                             std::uint64_t tie_weight = 0, double enough_unmeasured = -1, Kept* keep = nullptr) {
  constexpr int D = CellT::dim;
  constexpr SkipRule rule = D == 3 ? skip_rule_3d : skip_rule_2d;
  if (enough_unmeasured < 0) enough_unmeasured = enough;
  auto measured = [&](const auto& t) { return pilot_measured(t.cells, t.capped, t.vertices, rule); };
  auto enough_now = [&](const auto& t) { return measured(t) ? enough : enough_unmeasured; };
  constexpr double slope = rule.slope, lowest = rule.lowest, highest = rule.highest;
  constexpr double unmeasured = D == 3 ? lowest : 0.0;  // too few points for a pilot
  if (pass.order.empty()) return {1.0, unmeasured};
  // Band k: the points whose hash lies in the k-th cells / n of the range,
  // counted down from the top (n: the generators).
  const double share = max_share > 0 ? max_share : 1 - highest;
  const double cells = max_share > 0 ? std::clamp(share * static_cast<double>(pass.order.size()) / pilot_bands, 16.0,
                                                  static_cast<double>(pilot_band))
                                      : static_cast<double>(pilot_band);
  double band = cells / static_cast<double>(pass.order.size());
  std::size_t bands = std::min<std::size_t>(pilot_bands, static_cast<std::size_t>(share / band));
  if (bands == 0 && max_share > 0) {
    // Fewer generators than two bands of 16 (a small input, or a few inside
    // points among outside ones): one band of them all, each capped. One of
    // them may be costly alone: the centre of 40,000 outside points on a
    // sphere, the only inside point, was searched for 2.4 s (0.3 s from its
    // Delaunay star), and past 65,534 points it failed (until stop 59).
    band = 1.0;
    bands = 1;
  }
  if (bands == 0) return {1.0, unmeasured};
  // Every band's generators in one scan (bin order kept), with their band.
  const auto from = static_cast<std::uint64_t>(std::ldexp(1.0 - static_cast<double>(bands) * band, 64));
  struct Pick {
    std::int32_t gen;
    std::uint32_t slot, band, part;
  };
  std::vector<Pick> picks;
  std::vector<std::size_t> band_cells(bands, 0);
  for (std::size_t g = 0; g < pass.order.size(); ++g)
    if (const std::uint64_t h = id_hash(pass.order[g]); h >= from) {
      const double at = (1.0 - std::ldexp(static_cast<double>(h), -64)) / band;  // band index and fraction
      const auto k = std::min(static_cast<std::uint32_t>(bands - 1), static_cast<std::uint32_t>(at));
      const auto part = std::min(pilot_parts - 1, static_cast<std::uint32_t>((at - k) * pilot_parts));
      picks.push_back({pass.order[g], pass.slots[g], k, part});
      ++band_cells[k];
    }
  PilotCompositor<CellT> comp;
  comp.tie_weight = tie_weight;
  double ratio = 1;
  std::uint64_t exact = 0;
  auto estimate = [&](double r, double fraction) {
    return PilotEstimate{r, fraction,
                         static_cast<double>(exact) / static_cast<double>(std::max<std::uint64_t>(comp.total.cells, 1)),
                         comp.total.cells, comp.total.cells > 0 && measured(comp.total)};
  };
  engine::ThreadArena arena(pass.engine_options.threads);  // one for all the parts
  std::size_t cells_to_band_end = 0;
  for (std::size_t k = 0; k < bands; ++k) {
    cells_to_band_end += band_cells[k];
    // The band in parts, so that it may stop at one whose work already
    // settles the band's outcome (below).
    bool settled = false;
    for (std::uint32_t part = 0; part < pilot_parts && !settled; ++part) {
      std::vector<std::int32_t> order;
      std::vector<std::uint32_t> slots;
      for (const Pick& pk : picks)
        if (pk.band == k && pk.part == part) {
          order.push_back(pk.gen);
          slots.push_back(pk.slot);
        }
      if (order.empty()) continue;
      engine::Generators<CellT::dim> gens = pass.gens;
      gens.order = order;
      gens.slots = slots;
      engine::EngineOptions eo = pass.engine_options;
      eo.progress = nullptr;
      eo.batch_size = 4;  // a part of 32 cells in 8 batches, shared among the threads
      eo.arena = &arena;
      eo.work_cap = static_cast<std::uint64_t>(pilot_work_cap * rule.uniform_work);
      if constexpr (std::is_same_v<Kept, std::nullptr_t>) {
        exact += engine::tessellate<CellT>(gens, comp, eo);
      } else {
        KeepingPilotCompositor<CellT, typename Kept::Compositor> keeping{comp, *keep};
        exact += engine::tessellate<CellT>(gens, keeping, eo);
      }
      // The band's ratio (below) is at least its work per cell over a
      // uniform cell's, as at most every vertex is found, and work only
      // grows: once the work so far reaches `enough` times a uniform cell's
      // for every cell up to the band's end, the band would end at or past
      // `enough`, and the caller's choice is made. The same choice, sooner:
      // 3,000 points of a plane and one 1e12 off it (every sample cell a
      // column, capped after ~600 exact evaluations) spent 0.17 s on the
      // band's 256 cells, and the insertion then 0.035 s.
      settled = static_cast<double>(comp.total.work) >=
                enough_now(comp.total) * rule.uniform_work * static_cast<double>(cells_to_band_end);
    }
    const auto& t = comp.total;
    if (t.vertices == 0 && t.capped == 0) continue;  // no cell yet (duplicates only)
    // None found: all comes from completion, or every cell was abandoned.
    if (t.found == 0) return estimate(std::numeric_limits<double>::infinity(), highest);
    const double work = static_cast<double>(t.work) / static_cast<double>(t.cells) / rule.uniform_work;
    ratio = work / (static_cast<double>(t.found) / static_cast<double>(t.vertices));
    if (slope * std::sqrt(ratio) > 2 * highest || ratio >= enough_now(t)) break;
  }
  if (ratio < rule.off_below) return estimate(ratio, 0.0);
  return estimate(ratio, std::clamp(slope * std::sqrt(ratio), lowest, highest));
}

}  // namespace tessera::front
