// Builds one generator's cell: the meshless method's per-point loop.
//
// Start from the domain box; visit the locator's bins in shells of growing
// Chebyshev radius; in each shell sort the candidates by distance and clip by
// each bisector in turn. A candidate j can only clip while |p_j - p_i| <= 2R
// (R: the distance to the farthest cell vertex, so the flower of petals — the
// balls centred at the vertices through p_i — lies within 2R): bins and whole
// shells beyond the security radius are skipped, and the loop ends when the
// next shell's distance lower bound passes it. A candidate inside the radius
// but in no petal leaves every vertex in place and costs only the sign pass.
//
// One builder per thread: its buffers grow to the largest cell seen and are
// reused, so steady state allocates nothing.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <cmath>
#include <limits>
#include <span>
#include <utility>
#include <vector>

#include "tessera/kernels/exact_predicates.hpp"
#include "tessera/kernels/hull.hpp"  // ClipResult
#include "tessera/kernels/kd_tree.hpp"
#include "tessera/kernels/locator.hpp"
#include "tessera/kernels/support_bound.hpp"

namespace tessera::kernels {

/// A bin holding more points than this sends its cells to the k-d tree (the
/// pass builds one when some bin does): scanning the bin would cost each of
/// them that much. The grid aims at two points per bin.
inline constexpr std::uint32_t overfull_bin = 1024;

/// Outcome of building one cell.
struct BuildStatus {
  bool has_cell = true;          ///< false: an exact duplicate of `duplicate_of`
  std::int32_t duplicate_of = -1;
  /// The search's work in deterministic units: points scanned in the bins,
  /// plus the k-d tree's own effort (a unit per node or leaf point it
  /// measures, two per entry it queues: KdTree::nearest_first; a unit per
  /// node of KdTree::nearest), plus four per candidate tested against the
  /// cell (a sign pass costs about four scanned points), plus off_grid_weight
  /// per exact evaluation no small integer grid served and exact_solve_weight
  /// per vertex solved exactly. Used to estimate
  /// what cells cost on an input (delaunay's skipped-cell fraction); the
  /// same for any thread count. Scanned points are counted as the pruned
  /// shell walk scans them only by a builder with a work cap (the pilot's,
  /// whose rule was calibrated in those units); without one, shell 2 is
  /// scanned whole and counted so.
  std::uint64_t work = 0;
  /// The search passed the builder's work cap (set_work_cap) and was
  /// abandoned: no cell (has_cell is false, duplicate_of -1).
  bool capped = false;
  /// The cell was assembled from its Delaunay star, with no clip
  /// (build_from_star).
  bool assembled = false;
};

template <class CellT>
class CellBuilder {
 public:
  static constexpr int D = CellT::dim;
  using Index = typename CellT::Index;  // the kernel's local plane index

  /// `tree`, when given, serves the cells of overfull bins (see KdTree) and
  /// long cells (certify_by_petals).
  CellBuilder(const BinLocator<D>& locator, const double* coords, const double* lo, const double* hi,
              const ExactContext* exact, const SharedKdTree<D>* tree = nullptr)
      : loc_(locator), coords_(coords), lo_(lo), hi_(hi), exact_(exact), tree_(tree) {}

  /// Build the cell of generator i, whose coordinates p holds (the same
  /// doubles as the input's: the locator's copy), into `cell`.
  BuildStatus build(std::int32_t i, const double* p, CellT& cell) {
    work_ = 0;
    BuildStatus status = walk_shells(i, p, cell);
    status.work = cell_work(cell);
    cell.solve_deferred();
    return status;
  }

  /// Abandon a cell once its work, each exact predicate evaluation counted
  /// exact_weight times, passes `cap` (BuildStatus::capped). For a pilot
  /// measuring what cells cost: on points nearly on one sphere every cell
  /// reaches its centre and tests every point there, most of them exactly.
  /// A capped builder also walks shell 2 pruned, as every shell was before
  /// gather_dense, so that its work keeps the units the pilot's rule
  /// (front/pilot.hpp) was calibrated in: the same cells, ~1.4 times the
  /// scanned points on uniform 3D input otherwise.
  void set_work_cap(std::uint64_t cap) { work_cap_ = cap; }
  static constexpr std::uint64_t exact_weight = 32;
  /// BuildStatus::work's units per exact evaluation no small grid served
  /// (PreparedSigns::off_grid_calls: ~120 ns each, a work unit ~15 ns).
  static constexpr std::uint64_t off_grid_weight = 8;
  /// BuildStatus::work's units per vertex solved exactly (rationals).
  static constexpr std::uint64_t exact_solve_weight = 64;

  /// How many cells this builder finished by certify_by_petals (the rest
  /// of its long cells fell back to the shell walk): for tests and tuning.
  std::uint64_t petal_certified() const { return petal_certified_; }

  /// The cell of generator i by the path its place asks for: build(), or
  /// build_nearest_first() in an overfull bin or beyond the grid (searches_tree).
  BuildStatus build_any(std::int32_t i, const double* p, CellT& cell) {
    // A capped builder (the pilot's) counts off-grid evaluations, which the
    // stage gates move: each of its cells starts with them open, so that its
    // work depends on the cell alone (until stop 71 a mixed-tie input's
    // pilot ratio varied from run to run on two threads, 2.984-3.002).
    if (capped_builder()) cell.reset_stage_gates();
    return searches_tree(p) ? build_nearest_first(i, p, cell) : build(i, p, cell);
  }

  /// Whether the cell of a generator at p is searched in the pass's eager
  /// k-d tree (build_nearest_first) rather than the grid: it lies in an
  /// overfull bin, or beyond the grid's box (an outlier, BinLocator::
  /// beyond_core, whose cell reaches far and whose edge bin's bounds say
  /// little about its distances).
  bool searches_tree(const double* p) const {
    if (tree_ == nullptr || !tree_->eager()) return false;
    if (loc_.outside_core() != 0 && loc_.beyond_core(p)) return true;
    const std::size_t own = loc_.bin_index(loc_.bin_coords(p));
    return loc_.offsets()[own + 1] - loc_.offsets()[own] > overfull_bin;
  }

  /// build() by the k-d tree: candidates nearest first, until the next one
  /// lies beyond the security radius. The same clips as the shell walk's,
  /// from the same differences; exact ties come in id order, so the
  /// duplicate rule holds as there. A separate function, chosen by the
  /// engine: with both paths in build() the compiler laid out the hot loops
  /// worse (2D on 2 threads ~5% slower).
  [[gnu::noinline]] BuildStatus build_nearest_first(std::int32_t i, const double* p, CellT& cell) {
    work_ = 0;
    BuildStatus status = search_nearest_first(i, p, cell);
    status.work = cell_work(cell);
    cell.solve_deferred();
    return status;
  }

  /// The cell of generator i clipped by the points of locator slots `slots`
  /// alone, nearest first, with no search: for a caller that knows every
  /// point that clips (the Delaunay neighbours, from incremental insertion,
  /// whose perturbed in-sphere test is this clip predicate:
  /// front/delaunay_stars.hpp). The points are distinct, exclude i and
  /// its coincident points, and come in an order that does not depend on the
  /// thread count (the clip order follows it among near-ties, and with it
  /// the last bits of the cell's geometry).
  BuildStatus build_from(std::int32_t i, const double* p, std::span<const std::uint32_t> slots, CellT& cell) {
    cell.reset(i, p, lo_, hi_, exact_);
    BuildStatus status;
    const std::size_t n = slots.size();
    if (cand_.size() < n) {
      cand_.resize(2 * n);
      keys_.resize(cand_.size());
    }
    for (std::size_t k = 0; k < n; ++k) {
      Candidate& cd = cand_[k];
      const auto& pj = loc_.point(slots[k]);
      double r2 = 0;
      for (int d = 0; d < D; ++d) {
        cd.q[d] = pj[d] - p[d];
        r2 += cd.q[d] * cd.q[d];
      }
      cd.r2 = r2;
      cd.id = loc_.id(slots[k]);
      keys_[k] = sort_key(r2, static_cast<std::uint32_t>(k));
    }
    std::uint64_t* const keys = keys_.data();
    sort_keys(keys, keys + n);
    status.work = 4 * n;
    for (std::size_t k = 0; k < n; ++k) {
      const Candidate& cd = cand_[static_cast<std::uint32_t>(keys[k])];
      if (cell.clip(cd.id, cd.q) == ClipResult::emptied) [[unlikely]] {
        status.has_cell = false;  // only coincident points empty a cell, and they are not listed
        break;
      }
    }
    cell.solve_deferred();
    return status;
  }

  /// The cell of generator i, at locator slot s, from its Delaunay star:
  /// the simplices `star` (indices of rows of D + 1 locator slots each in
  /// `rows`, positively oriented: 2D counter-clockwise, 3D det > 0) that
  /// have s as a vertex, in an order independent of the thread count. Its
  /// Voronoi vertices are those simplices' circumcentres and its faces the
  /// bisectors with their other vertices, so the cell is assembled from
  /// them (Hull/Tile::assemble), then cut by the domain box where vertices
  /// lie outside it, with no clip by a neighbour and no sign pass. A point
  /// on the hull (an open star) has an unbounded cell: its hull facets' rays
  /// are closed by a far plane beyond the box, which the box cuts away. The
  /// rest — cells with a vertex within rounding of the box or too
  /// ill-conditioned for the float solve, hull points whose far plane
  /// cannot be placed — are clipped by the star's vertices (build_from), in
  /// the order they first appear.
  /// The cell is the one build_from gives either way (the same exact
  /// predicate decided the triangulation), up to the last bits of its
  /// geometry.
  ///
  /// Power cells (ExactContext::radii) come from the regular triangulation's
  /// stars, assembled the same way from their weighed planes
  /// (assembly::power_planes); a point in no simplex is hidden, and its
  /// power cell is empty.
  BuildStatus build_from_star(std::int32_t i, const double* p, std::uint32_t s, const std::uint32_t* rows,
                              std::span<const std::uint32_t> star, CellT& cell) {
    constexpr int W = D + 1;
    const std::size_t nt = star.size();
    if (nt == 0 && exact_ != nullptr && exact_->radii != nullptr) {
      cell.reset(i, p, lo_, hi_, exact_);
      BuildStatus hidden;
      hidden.has_cell = false;  // (duplicate_of -1: empty)
      return hidden;
    }
    nn_ = 0;
    if (slot_mark_.size() < loc_.size()) slot_mark_.assign(loc_.size(), 0);
    if (++mark_epoch_ == std::uint64_t{1} << 32) {  // wrapped: stale marks could read as this cell's
      std::fill(slot_mark_.begin(), slot_mark_.end(), 0);
      mark_epoch_ = 1;
    }  // from 1: no mark matches before its first cell
    if (corners_.size() < D * nt) corners_.resize(D * nt);
    Index* const corners = corners_.data();
    // Each simplex's other vertices as local indices into nbr_ (their order
    // of first appearance), in the kernel's orientation: 2D (next, after
    // next) counter-clockwise; 3D an even permutation of the row that
    // starts with s.
    bool fits = true;
    for (std::size_t t = 0; t < nt; ++t) {
      const std::uint32_t* row = rows + W * static_cast<std::size_t>(star[t]);
      int c = 0;
      while (c < D && row[c] != s) ++c;
      // Local indices in row order (the order build_from's list has always
      // had), then placed in the kernel's.
      std::size_t at[W];
      for (int r = 0; r < W; ++r)
        if (r != c) at[r] = local_index(row[r]);
      at[c] = 0;
      static constexpr int order2[3][2] = {{1, 2}, {2, 0}, {0, 1}};
      static constexpr int order3[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
      const int* order;
      if constexpr (D == 2) order = order2[c];
      else order = order3[c];
      for (int k = 0; k < D; ++k) {
        const std::size_t a = at[order[k]];
        fits &= a < CellT::max_assembled_planes;
        corners[D * t + static_cast<std::size_t>(k)] = static_cast<Index>(a);
      }
    }
    const std::size_t m = nn_;
    // Closed star: in 2D a cycle through every neighbour (m == nt), in 3D a
    // triangulated sphere (nt == 2m - 4). A point on the hull has an open
    // star: in 2D a chain (m == nt + 1), in 3D a disk, whose boundary of at
    // least three edges makes nt <= 2m - 5 (the kernel checks the disk).
    bool ok = fits && nt >= 1 && m <= CellT::max_assembled_planes;
    bool open = false;
    if constexpr (D == 2) {
      open = m == nt + 1;
      ok &= (m == nt && nt >= 3) || open;
      if (ok) {
        // Chain the pairs (arriving, leaving) into the counter-clockwise
        // cycle, or the chain from the one neighbour that leaves no simplex.
        if (succ_.size() < m) succ_.resize(m);
        std::fill(succ_.begin(), succ_.begin() + static_cast<std::ptrdiff_t>(m), std::uint32_t{0xFFFFFFFF});
        for (std::size_t t = 0; t < nt; ++t) succ_[corners[2 * t]] = static_cast<std::uint32_t>(t);
        std::uint32_t t = 0;
        if (open) {
          // The chain's first simplex: its arriving neighbour is no
          // simplex's leaving one.
          if (leaving_.size() < m) leaving_.resize(m);
          std::fill(leaving_.begin(), leaving_.begin() + static_cast<std::ptrdiff_t>(m), std::uint8_t{0});
          for (std::size_t k = 0; k < nt; ++k) leaving_[corners[2 * k + 1]] = 1;
          std::size_t k = 0;
          while (k < nt && leaving_[corners[2 * k]] != 0) ++k;
          t = static_cast<std::uint32_t>(k);
          ok = k < nt;
        }
        if (cycle_.size() < 2 * m) cycle_.resize(2 * m);
        for (std::size_t k = 0; k < nt && ok; ++k) {
          cycle_[2 * k] = corners[2 * t];
          cycle_[2 * k + 1] = corners[2 * t + 1];
          t = succ_[corners[2 * t + 1]];
          // A cycle returns to its start after nt steps; a chain ends there.
          ok &= open ? (t == 0xFFFFFFFF) == (k + 1 == nt) : t < nt && (t == 0) == (k + 1 == nt);
        }
      }
    } else {
      open = nt + 5 <= 2 * m;
      ok &= (nt + 4 == 2 * m && nt >= 4) || open;
    }
    if (ok) {
      if (ids_.size() < m) {
        ids_.resize(2 * m);
        qs_.resize(2 * m * D);
      }
      for (std::size_t k = 0; k < m; ++k) {
        const auto& pj = loc_.point(nbr_[k]);
        for (int d = 0; d < D; ++d) qs_[D * k + static_cast<std::size_t>(d)] = pj[d] - p[d];
        ids_[k] = loc_.id(nbr_[k]);
      }
      const Index* vc = D == 2 ? cycle_.data() : corners;
      if (cell.assemble(i, p, lo_, hi_, exact_, ids_.data(), qs_.data(), m, vc, nt, open)) {
        cell.solve_deferred();  // the box's cuts may have deferred some
        BuildStatus status;
        status.work = 4 * m;
        status.assembled = true;
        return status;
      }
    }
    return build_from(i, p, std::span<const std::uint32_t>(nbr_.data(), m), cell);
  }

 private:
  /// nbr_'s index of slot v, appended if new: marks by slot, stamped with
  /// the cell's epoch (a scan of nbr_ cost stars of a hundred simplices, on
  /// surface samples, more than their clips had). A star's vertices are its
  /// generator's spatial neighbours, so their marks lie near in slot order.
  std::size_t local_index(std::uint32_t v) {
    std::uint64_t& mark = slot_mark_[v];
    if ((mark >> 32) == mark_epoch_) return static_cast<std::size_t>(mark & 0xFFFFFFFF);
    const std::size_t k = nn_;
    if (nbr_.size() <= k) nbr_.resize(2 * k + 16);
    nbr_[k] = v;
    ++nn_;
    mark = (mark_epoch_ << 32) | std::min<std::size_t>(k, 0xFFFFFFFF);
    return k;
  }

  std::vector<std::uint32_t> nbr_;  // build_from_star: the star's vertices (slots), first appearance
  std::vector<std::uint64_t> slot_mark_;  // per slot: (epoch << 32) | its index in nbr_
  std::uint64_t mark_epoch_ = 0;
  std::size_t nn_ = 0;              // how many nbr_ holds
  std::vector<Index> corners_;  // D per simplex: indices into nbr_
  std::vector<Index> cycle_;  // 2D: corners in counter-clockwise order
  std::vector<std::uint32_t> succ_;   // 2D: per neighbour, the simplex whose first corner it is
  std::vector<std::uint8_t> leaving_;  // 2D open star: per neighbour, some simplex's second corner
  std::vector<std::int32_t> ids_;
  std::vector<double> qs_;

  /// build(): the shell walk.
  BuildStatus walk_shells(std::int32_t i, const double* p, CellT& cell) {
    cell.reset(i, p, lo_, hi_, exact_);
    const auto b = loc_.bin_coords(p);
    const int last = loc_.max_shell(b);
    BuildStatus status;
    const std::array<std::int32_t, D>* range = nullptr;  // the flower's bins, once measured
    const bool pilot = capped_builder();
    for (int s = 0; s <= last; ++s) {
      if (over_cap(cell)) [[unlikely]]
        return capped(status);
      double sec2 = cell.security_radius2();
      if (s > 1) {
        double lb = loc_.shell_lower_bound(p, b, s);
        if (lb * lb > sec2) break;
        if (s == 2 && sec2 > long_cell2_ && tree_ != nullptr && tree_->long_cells()) {
          // A long cell: try once to finish it by its petals (certify_by_petals).
          // Further tries, after shells that left the cell unchanged, cost
          // the closed surfaces' cells more than they saved (stop 24's joint
          // walk: an ellipsoid's 50k points 6.2 s against 5.4 s).
          const Certified c = certify_by_petals(i, p, cell, lb * lb);
          if (c == Certified::final) {
            ++petal_certified_;
            return status;
          }
          if (c == Certified::no_cell) {
            status.has_cell = false;
            return status;
          }
          sec2 = cell.security_radius2();
        }
        if (sec2 > flower_min2_) {
          // The security sphere is far wider than a bin: bound the flower
          // by a box instead (flower_bins), and stop once the shell lies
          // wholly outside it.
          range = flower_bins(cell, p);
          int reach = 0;
          for (int d = 0; d < D; ++d) reach = std::max({reach, b[d] - range[0][d], range[1][d] - b[d]});
          if (reach < s) break;
        }
      }
      // Candidates of slots [a, e) within the security radius, appended to
      // cand_/keys_ (storage only grows; nc counts what is in use). Each run
      // is a few bins' worth of contiguous slots: this loop is the search.
      std::size_t nc = 0;
      auto gather = [&](std::uint32_t a, std::uint32_t e) {
        work_ += e - a;
        if (cand_.size() < nc + (e - a)) [[unlikely]] {
          cand_.resize(2 * (nc + (e - a)));
          keys_.resize(cand_.size());
        }
        Candidate* cd = cand_.data() + nc;
        std::uint64_t* key = keys_.data() + nc;
        std::uint32_t m = static_cast<std::uint32_t>(nc);
        for (std::uint32_t k = a; k < e; ++k) {
          const std::int32_t j = loc_.id(k);
          const auto& pj = loc_.point(k);
          double r2 = 0;
          for (int d = 0; d < D; ++d) {
            cd->q[d] = pj[d] - p[d];
            r2 += cd->q[d] * cd->q[d];
          }
          if (r2 > sec2 || j == i) continue;
          cd->r2 = r2;
          cd->id = j;
          *key++ = sort_key(r2, m);
          ++cd;
          ++m;
        }
        nc = m;
      };
      // The generator's own bin and the shell around it are gathered and
      // sorted together (own bin first, so coincident points keep id order).
      // The bins next to the generator's are always near: prune only beyond.
      auto walk = [&](auto&& visit_run) {
        if (s > 1) loc_.for_each_shell_run_near(p, b, s, sec2, gaps_, visit_run, range);
        else loc_.for_each_shell_run(b, s, visit_run);
        if (s == 0 && last >= 1) {
          s = 1;
          loc_.for_each_shell_run(b, s, visit_run);
        }
      };
      std::size_t nr = 0, scanned = 0;
      auto record = [&](std::uint32_t a, std::uint32_t e) {
        if (runs_.size() == nr) [[unlikely]] runs_.resize(2 * nr + 16);
        runs_[nr++] = {a, e};
        scanned += e - a;
      };
      if (s == 2 && range == nullptr && !capped_builder()) {
        // Shell 2 (nearly every cell reaches it: 99% in 3D, 68% in 2D on
        // uniform points) is scanned whole, branch-free (gather_dense):
        // pruning its bins by distance (for_each_shell_run_near) scanned
        // fewer points (3D: 71 of ~190) but its per-shell gap tables, runs
        // and the gather's unpredictable branch cost more (3D and 2D ~4.5%).
        // A crowded shell (clustered points) is still pruned, and so is
        // every shell 2 of the pilot's capped builder (set_work_cap).
        loc_.for_each_shell_run(b, s, record);
        if (scanned <= dense_max) {
          nc = gather_dense(p, nr, scanned, sec2);
        } else {
          nr = 0;
          walk(record);
          for (std::size_t r = 0; r < nr; ++r) gather(runs_[r].first, runs_[r].second);
        }
      } else if constexpr (D == 3) {
        // The walk only records the runs, and one loop gathers them: a 3D
        // shell has many short runs, and a call into the gather per run cost
        // more than their few points (2.5%). In 2D, with a few longer runs,
        // the detour cost 3%.
        walk(record);
        for (std::size_t r = 0; r < nr; ++r) gather(runs_[r].first, runs_[r].second);
      } else {
        walk(gather);
      }
      // Clip in key order, the nearest first: a shell of ordinary size
      // (at most 2 sort_head candidates) is sorted whole. A larger one (a
      // dense region, or a cell whose security radius holds a cluster) has
      // its head sorted: the candidates at or below a sampled threshold, some
      // sort_head of them. Those make the cell nearly final; the rest are
      // taken in gather order, each first checked against the security
      // radius and the support bound, as nearly all of them leave the cell
      // unchanged: ordering them cost more than their sign passes.
      enum class Next { go, stop, no_cell, capped };
      auto visit = [&](std::uint64_t key) {
        const Candidate& cd = cand_[static_cast<std::uint32_t>(key)];
        if (cd.r2 > sec2) {
          // Keys order r2 rounded to float and truncated (sort_keys), so a
          // later candidate may still be slightly nearer; stop only once every
          // later one is surely beyond: a later key's r2 is at least this
          // key's truncated r2 times (1 - 2^-24), the float rounding.
          return truncated_r2(key) * (1.0 - 1e-7) > sec2 ? Next::stop : Next::go;  // never on 0 (no bound)
        }
        if (cd.r2 == 0 && exactly_equal(p, cd.id)) {
          // Exact duplicates: the lowest id owns the cell. Coincident points
          // share a bin, which the stable bin sort keeps in id order, and ties
          // in the sort key keep gather order, so the first lower id met here
          // is the lowest of the group.
          if (cd.id < i) {
            status.has_cell = false;
            status.duplicate_of = cd.id;
            return Next::no_cell;
          }
          return Next::go;  // a higher-id duplicate of ours never clips
        }
        work_ += 4;
        const ClipResult r = cell.clip(cd.id, cd.q);
        sec2 = cell.security_radius2();  // unchanged unless it clipped: a load, not a branch
        if (r == ClipResult::emptied) [[unlikely]] {
          // Only possible for coincident points, which are handled above.
          status.has_cell = false;
          return Next::no_cell;
        }
        // A capped builder (the pilot's) is stopped within a shell too: one
        // shell can hold thousands of candidates (points on a circle, whose
        // cells all reach its axis, every test there an exact tie; the
        // pilot's 1,024 cells took 0.8 s of a run that then took 0.04 s).
        if (pilot && over_cap(cell)) [[unlikely]]
          return Next::capped;
        return Next::go;
      };
      if (s >= screen_from && nc > screen_min) nc = screen(cell, nc, sec2);
      Next next = Next::go;
      std::uint64_t* const keys = keys_.data();
      std::uint64_t* const end = keys + nc;
      std::uint64_t* const head_end = nc > 2 * sort_head ? split_head(keys, end) : end;
      sort_keys(keys, head_end);
      for (std::uint64_t* it = keys; next == Next::go && it != head_end; ++it) next = visit(*it);
      if (next == Next::go && head_end != end) {
        support_.measure(cell.vertices(), cell.power_slack());
        for (std::uint64_t* it = head_end; next != Next::no_cell && next != Next::capped && it != end; ++it) {
          const Candidate& cd = cand_[static_cast<std::uint32_t>(*it)];
          if (cd.r2 > sec2 || support_.excludes(cd.q)) continue;
          const double before = sec2;
          next = visit(*it);
          if (sec2 != before) support_.measure(cell.vertices(), cell.power_slack());  // it clipped
        }
      }
      if (next == Next::no_cell) return status;
      if (next == Next::capped) return capped(status);
    }
    return status;
  }

  /// Shell 2's candidates, from the first nr runs_ (`scanned` slots, the
  /// whole shell): every point's r2, the slot advancing only for those
  /// within sec2 (branch-free), then their candidates and keys. The same
  /// candidates, in the same order, as the pruned walk and gather.
  std::size_t gather_dense(const double* p, std::size_t nr, std::size_t scanned, double sec2) {
    work_ += scanned;
    if (dense_slot_.size() < scanned) {
      dense_slot_.resize(scanned);
      dense_r2_.resize(scanned);
    }
    std::uint32_t* const slot = dense_slot_.data();
    double* const rr = dense_r2_.data();
    double c[D];
    for (int d = 0; d < D; ++d) c[d] = p[d];
    std::size_t n = 0;
    for (std::size_t r = 0; r < nr; ++r) {
      const std::uint32_t e = runs_[r].second;
      for (std::uint32_t k = runs_[r].first; k < e; ++k) {
        const auto& pj = loc_.point(k);
        const double q0 = pj[0] - c[0];
        double r2 = q0 * q0;
        for (int d = 1; d < D; ++d) {
          const double qd = pj[d] - c[d];
          r2 += qd * qd;
        }
        slot[n] = k;
        rr[n] = r2;
        n += r2 <= sec2;
      }
    }
    if (cand_.size() < n) [[unlikely]] {
      cand_.resize(2 * n);
      keys_.resize(cand_.size());
    }
    for (std::size_t t = 0; t < n; ++t) {
      Candidate& cd = cand_[t];
      const auto& pj = loc_.point(slot[t]);
      for (int d = 0; d < D; ++d) cd.q[d] = pj[d] - c[d];
      cd.r2 = rr[t];
      cd.id = loc_.id(slot[t]);
      keys_[t] = sort_key(rr[t], static_cast<std::uint32_t>(t));
    }
    return n;
  }

  /// build_nearest_first(): the k-d tree's search.
  BuildStatus search_nearest_first(std::int32_t i, const double* p, CellT& cell) {
    cell.reset(i, p, lo_, hi_, exact_);
    BuildStatus status;
    double sec2 = cell.security_radius2();
    // Once the cell is nearly final (a few dozen candidates in), whole tree
    // nodes that meet none of its petals are skipped: behind a cell that
    // reaches across empty space lies a cluster none of them reaches.
    std::size_t visited = 0;
    bool stale = true;
    auto prune = [&](const double* lo, const double* hi) {
      if (visited < 32) return false;
      if (stale) {
        petals_.measure(cell.vertices());
        stale = false;
      }
      return petals_.excludes_box(lo, hi, p);
    };
    tree_->get().nearest_first(p, i, heap_, [&] { return sec2; }, [&](std::int32_t j, double r2) {
      ++visited;
      work_ += 4;
      if ((visited & 63) == 0 && over_cap(cell)) [[unlikely]] {
        capped(status);
        return false;
      }
      if (r2 == 0 && exactly_equal(p, j)) {
        if (j < i) {  // the first duplicate met is the lowest id
          status.has_cell = false;
          status.duplicate_of = j;
          return false;
        }
        return true;
      }
      double q[D];
      for (int d = 0; d < D; ++d) q[d] = coords_[static_cast<std::size_t>(j) * D + d] - p[d];
      const ClipResult r = cell.clip(j, q);
      if (r == ClipResult::clipped) {
        sec2 = cell.security_radius2();
        stale = true;
      } else if (r == ClipResult::emptied) {
        status.has_cell = false;
        return false;
      }
      return true;
    }, prune, work_);
    return status;
  }

  enum class Certified { final, unsure, no_cell };

  /// Try to finish a long cell by certifying its vertices (corner
  /// validation: Sainlot, Nivoliers & Attali, "Restricting Voronoi diagrams
  /// to meshes using corner validation", 2017). A candidate cuts vertex v
  /// only if it lies in v's petal, the ball centred at v through the
  /// generator; the shell walk rules that out for every point of the whole
  /// security sphere, 2R around the generator. That sphere is wasteful for a
  /// long cell: a point sampled on a surface has a needle-shaped cell
  /// reaching from the surface to the far side of the object or to the
  /// domain box, and its security sphere holds a large part of the input
  /// although its petals, tangent to the surface, hold nothing.
  ///
  /// Here the vertices are taken one at a time, the widest petal first: the
  /// k-d tree's nearest point to v not yet tried (KdTree::nearest, bounded
  /// by v's widened petal) either clips the cell, removing v — the nearest
  /// point cuts deepest, so a needle's far tip shrinks in a few steps, much
  /// as a walk towards the true vertex — or there is none, and v is
  /// certified: no point can remove it, and later clips only add vertices.
  /// When no vertex is left uncertified the cell is final. Vertices whose
  /// petals lie within `near2` of the generator (the shells already
  /// clipped) are certified from the start.
  ///
  /// An empty petal costs a search of every tree node that meets its
  /// sphere, and a petal inside a closed surface nearly touches it over a
  /// wide area (a tube's touches it along a whole circle), so some inputs'
  /// cells cost more this way than by the shell walk. After a few searches
  /// the cost of the rest is predicted (vertices left times nodes per
  /// search so far); above the number of points the shell walk would
  /// gather (those in the bins of the flower's box: a node searched costs
  /// about as much as a point gathered and screened there), or when one
  /// search alone would spend what is left of that, it gives up, unsure,
  /// and the shell walk goes on from the cell as it is. The clip
  /// decisions are the exact ones either way, so the cell is the same.
  [[gnu::noinline]] Certified certify_by_petals(std::int32_t i, const double* p, CellT& cell, double near2) {
    const KdTree<D>& tree = tree_->get();
    if (tried_.size() < tree.id_bound()) tried_.assign(tree.id_bound(), 0);
    if (++epoch_ == 0) {  // wrapped: stale marks could read as this cell's
      std::fill(tried_.begin(), tried_.end(), 0);
      epoch_ = 1;
    }
    auto mark = [&](std::int32_t j) {
      if (j >= 0 && static_cast<std::size_t>(j) < tried_.size()) tried_[static_cast<std::size_t>(j)] = epoch_;
    };
    // Searches skip the points already tried: the planes' own generators
    // lie on their vertices' petal spheres, and a point that clipped the
    // cell lies strictly inside no petal of it then or later (the cell stays
    // on the generator's side of its bisector). A higher-id duplicate of the
    // generator never clips (a lower one shares its bin and ended the build
    // before).
    for (const auto& pl : cell.planes()) mark(pl.id);
    auto skip = [&](std::int32_t j) {
      return tried_[static_cast<std::size_t>(j)] == epoch_ || exactly_equal(p, j);
    };
    certified_.assign(cell.vertices().size(), uncertified);
    for (std::size_t t = 0; t < cell.vertices().size(); ++t) {
      const auto& v = cell.vertices()[t];
      if (4 * v.r2 * (1 + 1e-12) < near2) certified_[t] = vertex_key(v);
    }
    std::size_t nodes = 0, searches = 0, afford = 0;
    for (;;) {
      const auto& verts = cell.vertices();
      if (certified_.size() < verts.size()) certified_.resize(verts.size(), uncertified);
      std::size_t widest = verts.size(), open = 0;
      for (std::size_t t = 0; t < verts.size(); ++t) {
        if (certified_[t] == vertex_key(verts[t])) continue;
        ++open;
        if (widest == verts.size() || verts[t].r2 > verts[widest].r2) widest = t;
      }
      if (open == 0) return Certified::final;
      if (searches >= 4) {
        const std::size_t predicted = nodes + open * (nodes / searches);
        if (predicted > afford) {
          // Measured again only when needed: the flower shrinks with the cell.
          const auto* range = flower_bins(cell, p);
          afford = loc_.count_in(range[0], range[1]);
          if (predicted > afford) return Certified::unsure;
        }
      }
      // v's petal in absolute coordinates: c = p + y, and the tree's
      // distances from it round by far less than the absolute margin.
      const auto& v = verts[widest];
      double c[D], mag = 0;
      for (int d = 0; d < D; ++d) {
        c[d] = p[d] + v.y[d];
        mag = std::max({mag, std::fabs(p[d]), std::fabs(c[d])});
      }
      const double reach = petal_radius(v) + 1e-12 * mag;
      // Once the shell walk's cost is known, one search may not spend more
      // than what is left of it (a single search as costly as the rest was
      // predicted to be is itself the sign to give up).
      const std::size_t allowed = searches >= 4 ? afford - nodes : ~std::size_t{0};
      std::size_t budget = allowed;
      const std::int32_t j = tree.nearest(c, i, reach * reach * (1.0 + 1e-9), skip, budget);
      nodes += allowed - budget;
      work_ += allowed - budget;
      ++searches;
      if (j == -2) return Certified::unsure;
      if (j == -1) {
        certified_[widest] = vertex_key(v);
        continue;
      }
      mark(j);
      work_ += 4;
      double q[D];
      for (int d = 0; d < D; ++d) q[d] = coords_[static_cast<std::size_t>(j) * D + d] - p[d];
      if (cell.clip(j, q) == ClipResult::emptied) return Certified::no_cell;
    }
  }

  /// A vertex's local planes (identify it within one cell: a new vertex
  /// always holds the newest plane). Whole indices: packed 16 bits apiece
  /// (until stop 59), the keys of a cell past 65,535 planes (2D since stop
  /// 57, 3D since 59) could collide, and a vertex pass for certified.
  using VertexKey = std::array<Index, D>;
  static constexpr VertexKey uncertified = [] {
    VertexKey k{};
    k.fill(std::numeric_limits<Index>::max());  // no vertex's: its planes differ
    return k;
  }();
  static VertexKey vertex_key(const typename CellT::Vertex& v) {
    VertexKey k;
    for (int d = 0; d < D; ++d) k[static_cast<std::size_t>(d)] = v.p[d];
    return k;
  }

  /// The bins that can hold a point of the cell's flower (the union of its
  /// petals, the balls centred at its vertices through the generator): a
  /// candidate x (relative to the generator) cuts vertex v only if
  /// |x - v| <= |v|, so x[d] lies within |v| of v[d]. With the exact vertex
  /// within e of the stored y (per axis) and no farther than sqrt(r2) from
  /// the generator, the box y[d] -+ (sqrt(r2) + e), widened far past the
  /// rounding of these sums, holds every candidate that can clip. The
  /// flower only shrinks as the cell does (it is the union of the balls of
  /// all the cell's points, by convexity), so a box measured earlier stays
  /// valid. A cell reaching the domain box has its far vertices outside
  /// the points' extent: its flower reaches little beyond its generator
  /// inwards, where its security sphere reaches twice its size.
  const std::array<std::int32_t, D>* flower_bins(const CellT& cell, const double* p) {
    double lo[D], hi[D];
    for (int d = 0; d < D; ++d) {
      lo[d] = std::numeric_limits<double>::infinity();
      hi[d] = -std::numeric_limits<double>::infinity();
    }
    bool finite = true;
    for (const auto& v : cell.vertices()) {
      const double r = (std::sqrt(v.r2) + v.e) * (1.0 + 1e-9);
      for (int d = 0; d < D; ++d) {
        lo[d] = std::min(lo[d], v.y[d] - r);
        hi[d] = std::max(hi[d], v.y[d] + r);
        finite &= std::fabs(v.y[d]) + r < std::numeric_limits<double>::infinity();  // false on NaN
      }
    }
    if (!finite)
      for (int d = 0; d < D; ++d) {
        lo[d] = -std::numeric_limits<double>::infinity();
        hi[d] = std::numeric_limits<double>::infinity();
      }
    for (int d = 0; d < D; ++d) {
      lo[d] = p[d] + lo[d] - 1e-9 * (std::fabs(p[d]) + std::fabs(lo[d]));
      hi[d] = p[d] + hi[d] + 1e-9 * (std::fabs(p[d]) + std::fabs(hi[d]));
    }
    loc_.bin_range(lo, hi, flower_range_[0], flower_range_[1]);
    return flower_range_;
  }

  /// The shell from which a gather of more than screen_min candidates is
  /// screened by the support bound before it is sorted (see screen). A
  /// uniform cell is final after its second gather (shells 0-1, then 2),
  /// which rarely holds that many: 24 cost 1.2% on uniform input, 96 no
  /// better than 48.
  static constexpr int screen_from = 2;
  static constexpr std::size_t screen_min = 48;

  /// Drop the candidates of this gather that surely leave the cell unchanged:
  /// beyond the security radius, or excluded by the support bound measured
  /// now. Returns how many remain (their keys first, in gather order). A cell
  /// that is still being gathered this far out reaches the domain box or
  /// empty space: its security radius holds hundreds of candidates, nearly
  /// all behind its generator, and each would cost a sign pass over a cell
  /// of many vertices. The clips that follow are exactly those without the
  /// screen, in the same order: a dropped candidate could not have clipped.
  std::size_t screen(const CellT& cell, std::size_t nc, double sec2) {
    support_.measure(cell.vertices(), cell.power_slack());
    std::uint64_t* const keys = keys_.data();
    std::size_t kept = 0;
    for (std::size_t k = 0; k < nc; ++k) {
      const Candidate& cd = cand_[static_cast<std::uint32_t>(keys[k])];
      keys[kept] = keys[k];
      kept += cd.r2 <= sec2 && !support_.excludes(cd.q);
    }
    return kept;
  }

  /// The size of the sorted head of an oversized shell (above: a shell of at
  /// most twice as many is sorted whole). A uniform cell uses about 47.
  static constexpr std::size_t sort_head = 64;

  /// Candidate keys in visiting order, nearest first. Up to 2 * sort_head
  /// keys are ranked, each one's place being the number of keys below it:
  /// n^2 comparisons, but branch-free, which at these sizes (a uniform
  /// cell's first gather holds ~54 keys in 3D, ~20 in 2D) beat straight
  /// insertion, whose mispredicted exits dominated. The ranking compares
  /// compact 32-bit keys, four per SSE instruction: the float key's top 24
  /// bits (8 of mantissa), then the key's position, below 2^8, which breaks
  /// ties in gather order and makes the keys distinct. Candidates within
  /// 2^-15 of each other in r2 so keep gather order rather than distance
  /// order: any order gives the same cell, and this one is as deterministic.
  /// Longer runs (a rare oversized head) by std::sort on the whole keys.
  /// Either way a later key's truncated r2 (truncated_r2) is no smaller.
  static void sort_keys(std::uint64_t* first, std::uint64_t* last) {
    using Quad = std::int32_t __attribute__((vector_size(16)));
    const std::size_t n = static_cast<std::size_t>(last - first);
    if (n > 2 * sort_head) {
      std::sort(first, last);
      return;
    }
    static_assert(2 * sort_head <= 0x100, "positions fit the compact key's low 8 bits");
    // The compact keys are below 2^31 (r2 >= 0 has a clear float sign bit),
    // so they compare alike as signed; the padding is above them all.
    alignas(16) std::int32_t k[2 * sort_head + 8];
    std::uint64_t whole[2 * sort_head];
    std::memcpy(whole, first, n * sizeof *whole);
    for (std::size_t t = 0; t < n; ++t)
      k[t] = static_cast<std::int32_t>(truncated_bits(whole[t]) | static_cast<std::uint32_t>(t));
    for (std::size_t t = n; t < n + 8; ++t) k[t] = std::numeric_limits<std::int32_t>::max();
    const std::size_t m = (n + 3) & ~std::size_t{3};  // whole quads
    for (std::size_t i = 0; i < n; i += 4) {
      Quad below[4] = {};
      for (std::size_t j = 0; j < m; j += 4) {
        Quad kj;
        std::memcpy(&kj, k + j, sizeof kj);
        for (std::size_t a = 0; a < 4; ++a) below[a] += kj < Quad{k[i + a], k[i + a], k[i + a], k[i + a]};  // -1 per key below
      }
      for (std::size_t a = 0; a < 4 && i + a < n; ++a)
        first[-(below[a][0] + below[a][1] + below[a][2] + below[a][3])] = whole[i + a];
    }
  }

  /// A candidate's sort key: r2 in key units (key_scale_) rounded to float
  /// (non-negative floats order as their bits), then its position in the
  /// gather, which is deterministic.
  std::uint64_t sort_key(double r2, std::uint32_t position) const {
    return (static_cast<std::uint64_t>(std::bit_cast<std::uint32_t>(static_cast<float>(r2 * key_scale_))) << 32) |
           position;
  }

  /// A key's float r2 bits without their low 8 (the compact key's order).
  static std::uint32_t truncated_bits(std::uint64_t key) {
    return static_cast<std::uint32_t>(key >> 32) & ~std::uint32_t{0xFF};
  }
  /// A lower bound on the r2 of this key's candidate and of every later one,
  /// or 0 where the key gives none: a float key that overflowed (infinite:
  /// its candidates then only follow every finite key, in gather order) or
  /// lies below the normal floats, where rounding is not relative.
  double truncated_r2(std::uint64_t key) const {
    const float f = std::bit_cast<float>(truncated_bits(key));
    if (!(f >= std::numeric_limits<float>::min() && f <= std::numeric_limits<float>::max())) return 0;
    return static_cast<double>(f) * key_unscale_;
  }

  /// Reorder [first, last) (more than 2 * sort_head keys) so that the keys
  /// at or below a threshold come first, and return the end of that head.
  /// The threshold is the sample key whose expected rank is about
  /// sort_head; the split is branch-free (a partition around an unknown
  /// pivot mispredicts half its branches, and nth_element needs several).
  /// The head is only a prefix of the sorted order, of no fixed size.
  std::uint64_t* split_head(std::uint64_t* first, std::uint64_t* last) {
    constexpr std::size_t samples = 64;
    const std::size_t n = static_cast<std::size_t>(last - first);
    std::uint64_t sample[samples];
    for (std::size_t k = 0; k < samples; ++k) sample[k] = first[k * n / samples];
    sort_keys(sample, sample + samples);
    const std::uint64_t tau = sample[samples * sort_head / n];  // n > 2 sort_head: index < samples / 2
    spill_.assign(first, last);
    std::size_t head = 0, rest = n;
    for (const std::uint64_t key : spill_) {
      // Written at both ends; the end that does not advance is overwritten later.
      first[head] = key;
      first[rest - 1] = key;
      const bool in = key <= tau;
      head += in;
      rest -= !in;
    }
    return first + head;
  }

  struct Candidate {
    double r2;
    std::int32_t id;
    double q[D];
  };

  bool exactly_equal(const double* p, std::int32_t j) const {
    const double* pj = coords_ + static_cast<std::size_t>(j) * D;
    for (int d = 0; d < D; ++d)
      if (p[d] != pj[d]) return false;
    return true;
  }

  const BinLocator<D>& loc_;
  const double* coords_;
  const double* lo_;
  const double* hi_;
  const ExactContext* exact_;
  const SharedKdTree<D>* tree_;
  std::vector<typename KdTree<D>::Entry> heap_;  // the tree searches' scratch
  std::vector<std::uint32_t> tried_;  // certify_by_petals: per point, the epoch it was last marked in
  std::uint32_t epoch_ = 0;
  std::uint64_t petal_certified_ = 0;
  std::uint64_t work_ = 0;  // the current cell's BuildStatus::work
  std::uint64_t work_cap_ = std::numeric_limits<std::uint64_t>::max();  // set_work_cap

  // BuildStatus::work of the cell just built: the search's count and its exact work.
  std::uint64_t cell_work(const CellT& cell) const {
    return work_ + off_grid_weight * cell.off_grid_exact_calls() + exact_solve_weight * cell.exact_solves();
  }
  bool capped_builder() const { return work_cap_ != std::numeric_limits<std::uint64_t>::max(); }
  bool over_cap(const CellT& cell) const { return work_ + exact_weight * cell.exact_calls() > work_cap_; }
  static BuildStatus& capped(BuildStatus& status) {
    status.capped = true;
    status.has_cell = false;
    return status;
  }
  std::vector<VertexKey> certified_;  // per vertex slot: the key it was certified with
  PetalCover<D> petals_;  // build_nearest_first's
  std::vector<Candidate> cand_;
  std::vector<std::uint64_t> keys_;
  std::vector<double> gaps_;  // for_each_shell_run_near's scratch
  std::vector<std::pair<std::uint32_t, std::uint32_t>> runs_;  // a shell's slot runs
  std::vector<std::uint64_t> spill_;  // split_head's scratch
  std::vector<std::uint32_t> dense_slot_;  // gather_dense's scratch
  std::vector<double> dense_r2_;
  /// The most points shell 2 may hold to be scanned whole (a uniform 3D
  /// shell 2 holds ~196 at the default two points per bin).
  static constexpr std::size_t dense_max = 512;
  SupportBound<D> support_;
  std::array<std::int32_t, D> flower_range_[2];  // flower_bins' result
  /// Above this squared security radius (nine squared smallest bin sizes)
  /// a cell bounds its flower before walking a shell (flower_bins): a
  /// uniform cell's is about one bin size and never pays for it.
  double flower_min2_ = 9 * loc_.min_bin_size() * loc_.min_bin_size();
  /// Above this squared security radius after the first gather (six
  /// smallest bin sizes), a cell is long: it tries certify_by_petals.
  double long_cell2_ = 36 * loc_.min_bin_size() * loc_.min_bin_size();
  /// Sort keys hold r2 * key_scale_, a power of two that brings a squared
  /// bin size near 1, so that a cell's candidates stay within float's
  /// normal range whatever the input's units. Unscaled, r2 above 2^128
  /// (coordinates past about 1e19) overflowed to the same infinite key, and
  /// the stop rule then dropped nearer candidates: wrong cells.
  double key_scale_ = std::ldexp(1.0, -2 * std::ilogb(loc_.min_bin_size()));
  double key_unscale_ = 1.0 / key_scale_;
};

}  // namespace tessera::kernels
