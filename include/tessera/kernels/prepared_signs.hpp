// The exact stages of a cell's sign pass, prepared once per vertex.
//
// When the float filter cannot decide whether candidate j removes vertex v,
// the sign is exact_clip_sign's. A vertex is asked against many candidates
// (on lattices nearly every vertex ties with several), so what depends only
// on the vertex is prepared once, in the first stage that can serve it:
//   0. BoxTiePredicate: a tie at the corners of an axis-aligned box (any
//      lattice or tensor-product grid, whatever its spacing), decided from
//      the coordinates' pattern alone; a candidate off the vertex's box goes
//      on to the stages below, which are prepared only then;
//   1. VertexPredicate: the vertex's points on a small integer grid (lattices,
//      voxel centres, integer and dyadic grids);
//   2. ExtendedPredicate: x87 extended precision with a certified bound, for
//      near-ties at the level of double rounding (points normalized onto a
//      sphere); it answers 0 when unsure, as on every exact tie;
//   3. WidePredicate: fixed-width integers on a grid of up to 60 bits, for
//      exact ties off a small grid (a lattice of spacing 0.1) and what the
//      extended stage leaves; prepared on the vertex's first such call;
//   4. exact_clip_sign itself (GMP), for points spanning more bits.
// Every stage returns the same sign; the order, and the gates that skip a
// stage that keeps failing (StageGate), are speed only.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "tessera/kernels/box_ties.hpp"
#include "tessera/kernels/exact_predicates.hpp"

namespace tessera::kernels {

/// Whether a stage that keeps failing on an input is still worth trying.
/// After 64 failures in a row only one try in 64 is let through, until one
/// succeeds. Speed only: every stage decides the same exact sign. Used for
/// VertexPredicate off a global grid, whose search for a small grid common
/// to the vertex's points fails on every vertex of, say, a rotated lattice (6%
/// of its cells' time went to failed tries), and for ExtendedPredicate, which
/// cannot decide exact ties (a 0.1-spaced lattice: its prepare took a quarter
/// of the cells' time, for nothing).
class StageGate {
 public:
  bool open() { return misses_ < 64 || (++skipped_ & 63) == 0; }
  /// After a try: whether the stage served.
  void record(bool served) { misses_ = served ? 0 : misses_ + 1; }

 private:
  std::uint64_t misses_ = 0, skipped_ = 0;
};

/// `Index`: the kernel's local plane index (Hull::Index, Tile::Index).
template <int D, class Index>
class PreparedSigns {
 public:
  /// A new cell: every slot's preparation is stale.
  void start_cell() {
    ++cell_;
    calls_ = 0;
    off_grid_ = 0;
  }

  /// exact_clip_sign(ctx, gen, ids, j) for the vertex in slot t, whose local
  /// plane indices are p[0..D) and their ids ids[0..D). A slot's preparation
  /// stays valid while it holds the same local planes in the same cell (a
  /// cell's local plane indices only grow, and a removed vertex never returns).
  int sign(const ExactContext& ctx, std::int32_t gen, std::size_t t, const Index* p, const std::int32_t* ids,
           std::int32_t j) {
    ++calls_;
    if (ctx.radii != nullptr) [[unlikely]] {  // the prepared stages know no radii (ExactContext::radii)
      ++off_grid_;
      return exact_clip_sign_by_arithmetic(ctx, gen, ids, j);
    }
    if (slots_.size() <= t) slots_.resize(t + 1);
    Slot& s = slots_[t];
    bool same = s.cell == cell_;
    for (int k = 0; k < D; ++k) same &= s.p[k] == p[k];
    if (!same) {
      s.cell = cell_;
      for (int k = 0; k < D; ++k) s.p[k] = p[k];
      s.box_tried = box_gate_.open();
      s.box = s.box_tried && s.box_pred.prepare(ctx, gen, ids);
      if (s.box_tried) box_gate_.record(s.box);
      s.staged = false;
    }
    if (s.box) {
      int r;
      if (s.box_pred.sign(ctx, j, r)) return r;
    }
    if (!s.staged) {
      s.staged = true;
      // On a global grid (ExactContext::grid) VertexPredicate always serves.
      const bool global = ctx.grid != nullptr;
      const bool tried = global || grid_gate_.open();
      s.grid = tried && s.pred.prepare(ctx, gen, ids);
      if (tried && !global) grid_gate_.record(s.grid);
      s.extended = !s.grid && extended_gate_.open() && s.ext.prepare(ctx, gen, ids);
      s.wide = Wide::untried;
    }
    if (s.grid) return s.pred.sign(ctx, j);
    ++off_grid_;
    if (s.extended) {
      const int r = s.ext.sign(ctx, j);
      extended_gate_.record(r != 0);
      if (r != 0) return r;
    }
    if (s.wide == Wide::untried) s.wide = s.wide_pred.prepare(ctx, gen, ids) ? Wide::usable : Wide::unusable;
    if (s.wide == Wide::usable) return s.wide_pred.sign(ctx, j);
    // The box stage, where it was tried, refused this candidate: asking it
    // again inside exact_clip_sign would only repeat the refusal.
    return s.box_tried ? exact_clip_sign_by_arithmetic(ctx, gen, ids, j) : exact_clip_sign(ctx, gen, ids, j);
  }

  /// Every stage gate open again, as for the first cell. The gates carry
  /// from cell to cell, and which cells a thread met first then moves which
  /// evaluations count as off the grid; the pilot, whose counts choose the
  /// method, starts each cell afresh so that they depend on the cell alone,
  /// not on the threads' schedule (CellBuilder::build_any with a work cap).
  void reset_gates() {
    box_gate_ = {};
    grid_gate_ = {};
    extended_gate_ = {};
  }

  /// Exact evaluations since start_cell.
  std::uint64_t calls() const { return calls_; }
  /// Those of them no small integer grid served (stages 2-4): on lattices
  /// nearly none, where every call is a few integer products; off any grid
  /// (a cylindrical grid's cos and sin, a rotated lattice) ~100-150 ns each.
  std::uint64_t off_grid_calls() const { return off_grid_; }

 private:
  enum class Wide : std::uint8_t { untried, usable, unusable };
  struct Slot {
    std::uint64_t cell = 0;
    Index p[D] = {};
    bool box_tried = false; // box_pred's prepare ran (its gate was open)
    bool box = false;       // box_pred prepared (a candidate may still be off its box)
    bool staged = false;    // the stages below box_pred prepared
    bool grid = false;      // pred serves the vertex
    bool extended = false;  // ext prepared
    Wide wide = Wide::untried;
    BoxTiePredicate<D> box_pred;
    VertexPredicate pred;
    ExtendedPredicate ext;
    WidePredicate wide_pred;
  };
  std::vector<Slot> slots_;
  std::uint64_t cell_ = 0;  // cells started (the slots' epoch)
  std::uint64_t calls_ = 0, off_grid_ = 0;
  StageGate box_gate_;       // whether a slot tries BoxTiePredicate
  StageGate grid_gate_;      // whether a slot tries VertexPredicate (off a global grid)
  StageGate extended_gate_;  // whether a slot prepares ExtendedPredicate
};

}  // namespace tessera::kernels
