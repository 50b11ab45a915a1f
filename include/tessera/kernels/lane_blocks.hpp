// The sign pass of a huge cell by blocks of vertex slots.
//
// A clip's sign pass (filter::classify) reads every vertex, and so does the
// security radius's maximum after it: a cell of F faces built clip by clip
// costs O(F) per clip, O(F^2) in all. Such cells occur where the search is
// the only method, or the pilot did not see them: 3D points on one plane
// (no tetrahedron, so no Delaunay star) with a point beside them that sees
// all of them, as points on a line and one off it (80,000 points: a cell of
// 80,000 faces, 24 s).
//
// LaneBlocks keeps, over a FilterLanes mirror, a summary of every block of
// `block` consecutive slots (the box of its y, its largest e and r2) and of
// every group of `group` blocks. A clip's sign pass then skips each group or
// block whose box lies, in the float filter's own terms, surely on the kept
// side of the plane, and runs classify's two passes over the rest, lane
// group by lane group, term for term. A skipped slot is one classify marks
// kept by its float filter alone (below), so the signs, the removed slots,
// and the exact evaluations (the same slots, in the same ascending order)
// are classify's: the cell, and every later decision that depends on it,
// are the same bit for bit. The slots of a huge cell stay roughly grouped
// in space: a clip refills the slots it removed with the vertices it makes
// there, and appends the rest.
//
// Boxes are loose where the planes nearly touch a smooth stretch of the
// cell (a paraboloid's tangent planes: the cell of a point above a sheet):
// a block's box reaches |n| times its width towards the plane, while the
// vertices' plane values grow only with the square of their distance from
// the touching point. So on such cells a pass still reads a few thousand
// slots: beside the line of 160,000 points ~2,200 of 320,000 per clip (all
// but ~70 by the first, store-free pass), above a sheet of 200 x 200 ~8,500
// of 65,000. Boxes in each block's own frame would fit such stretches
// closely; not done.
//
// Summaries are refreshed lazily: a write to a slot marks its block (touch),
// and refresh() recomputes the marked blocks and their groups from the
// lanes before a pass or a maximum reads them.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "tessera/kernels/filter.hpp"

namespace tessera::kernels {

template <int D>
class LaneBlocks {
 public:
  static constexpr std::size_t block = 32;  // slots per block
  static constexpr std::size_t group = 32;  // blocks per group

  /// Summaries for the first n slots of `f`, every block to be measured.
  void start(std::size_t n) {
    blocks_.clear();
    groups_.clear();
    dirty_.clear();
    marked_.clear();
    group_marked_.clear();
    touch_range(0, n);
  }

  /// Slot t was written, or left the list.
  void touch(std::size_t t) {
    const std::size_t b = t / block;
    if (b >= marked_.size()) grow(b + 1);
    if (marked_[b] == 0) {
      marked_[b] = 1;
      dirty_.push_back(static_cast<std::uint32_t>(b));
    }
  }
  void touch_range(std::size_t a, std::size_t e) {
    for (std::size_t t = a / block * block; t < e; t += block) touch(t);
  }

  /// The largest r2 of the first f.size() slots, at least 0: the value of
  /// FilterLanes::max_r2 (the maximum of doubles is exact in any order).
  double max_r2(const filter::FilterLanes<D>& f) {
    refresh(f);
    double m = 0.0;
    const std::size_t ng = groups(f.size());
    for (std::size_t g = 0; g < ng; ++g) m = std::max(m, groups_[g].r2);
    return m;
  }

  /// filter::classify's signs for the plane n.y <= d (|n|_1 = n1, d_unscaled
  /// as classify's), over the first f.size() slots: each slot a skipped
  /// block holds is left alone (the caller keeps `sign` at +1 outside a
  /// pass), every other one gets its sign (the padding too, +1), `exact(t)`
  /// deciding those the filter cannot, in ascending slot order as classify
  /// asks them. The removed slots are written to `removed`, ascending;
  /// returns how many.
  template <class Exact>
  std::size_t classify(const filter::FilterLanes<D>& f, const double* n, double d, double n1, double d_unscaled,
                       std::vector<filter::Sign>& sign, std::vector<std::uint32_t>& removed, Exact&& exact) {
    static_assert(block % filter::FilterLanes<D>::lanes == 0, "blocks of whole lane groups");
    using filter::detail::Lane;
    using filter::detail::LaneMask;
    refresh(f);
    const std::size_t nv = f.size(), np = f.padded();
    if (removed.size() < nv) removed.resize(nv);
    if (sign.size() < np) sign.resize(np);
    // classify's own bounds, from the same expressions.
    const double q2lo = 2.0 * d_unscaled * (1.0 - 1e-12) - filter::abs_eps;
    const double de = filter::plane_eps * std::fabs(d) + filter::abs_eps;
    const double* const E = f.e();
    const double* const R = f.r2();
    std::size_t nr = 0;
    const std::size_t ng = groups(nv);
    for (std::size_t g = 0; g < ng; ++g) {
      if (kept(groups_[g], n, d, n1, de)) continue;
      const std::size_t b_end = std::min((g + 1) * group, blocks(nv));
      for (std::size_t b = g * group; b < b_end; ++b) {
        if (kept(blocks_[b], n, d, n1, de)) continue;
        // classify's passes over the block's lane groups (padding included,
        // which they keep), term for term: the first proves that none may
        // be cut, by the float filter alone (the signs stay +1); else the
        // second gives every sign, then the exact ones, ascending.
        const std::size_t t0 = b * block, t1 = std::min(t0 + block, np);
        auto plane_value = [&](std::size_t t) {
          Lane dot = n[0] * filter::detail::load(f.y(0) + t);
          for (int k = 1; k < D; ++k) dot += n[k] * filter::detail::load(f.y(k) + t);
          return d - dot;
        };
        LaneMask hit{};
        for (std::size_t t = t0; t < t1; t += 2) hit |= ~(plane_value(t) > n1 * filter::detail::load(E + t) + de);
        if (!(hit[0] | hit[1])) continue;
        std::int64_t uncertain = 0;
        for (std::size_t t = t0; t < t1; t += 2) {
          const Lane P = plane_value(t);
          const Lane e = n1 * filter::detail::load(E + t) + de;
          const LaneMask near = 4.0 * filter::detail::load(R + t) < q2lo;  // never cut
          const LaneMask s = near ? LaneMask{1, 1} : (P < -e) - (P > e);
          for (int k = 0; k < 2; ++k) {
            sign[t + static_cast<std::size_t>(k)] = static_cast<filter::Sign>(s[k]);
            uncertain += s[k] == 0;
          }
        }
        for (std::size_t t = t0; uncertain && t < t1; ++t) {
          if (sign[t] != 0) continue;
          sign[t] = static_cast<filter::Sign>(exact(t));
          --uncertain;
        }
        for (std::size_t t = t0; t < t1; ++t) {
          removed[nr] = static_cast<std::uint32_t>(t);
          nr += sign[t] < 0;
        }
      }
    }
    return nr;
  }

 private:
  struct Summary {
    double lo[D], hi[D];  // the box of the slots' y
    double e;             // their largest e
    double r2;            // their largest r2 (-inf: no slot)
  };

  static std::size_t blocks(std::size_t nv) { return (nv + block - 1) / block; }
  static std::size_t groups(std::size_t nv) { return (blocks(nv) + group - 1) / group; }

  // Whether every slot s summarises is one classify keeps by its float
  // filter alone: P = d - n.y > n1 e + de, each side as classify rounds it.
  // Over the box, n.y <= h = sum_k max(n_k lo_k, n_k hi_k); the rounding of
  // h and of classify's own dot product are each within 4u of sum_k
  // max|n_k y_k| <= a, which the margin 2^-40 a exceeds many times, so
  // classify's dot <= g. Rounding is monotone: its P >= fl(d - g) and its
  // bound <= fl(n1 e_max + de). False on NaN (an unbounded or empty box).
  static bool kept(const Summary& s, const double* n, double d, double n1, double de) {
    double h = 0, a = 0;
    for (int k = 0; k < D; ++k) {
      const double l = n[k] * s.lo[k], u = n[k] * s.hi[k];
      h += std::max(l, u);
      a += std::max(std::fabs(l), std::fabs(u));
    }
    const double g = h + (0x1p-40 * a + filter::abs_eps);
    return d - g > n1 * s.e + de;
  }

  // Room for nb blocks; new summaries are empty.
  void grow(std::size_t nb) {
    marked_.resize(std::max(nb, 2 * marked_.size()), 0);
    Summary empty;
    clear(empty);
    blocks_.resize(marked_.size(), empty);
    groups_.resize((marked_.size() + group - 1) / group, empty);
    group_marked_.resize(groups_.size(), 0);
  }

  // No slot: a box no test passes (its h is infinite or NaN), r2 -inf.
  static void clear(Summary& s) {
    for (int k = 0; k < D; ++k) {
      s.lo[k] = std::numeric_limits<double>::infinity();
      s.hi[k] = -std::numeric_limits<double>::infinity();
    }
    s.e = 0;
    s.r2 = -std::numeric_limits<double>::infinity();
  }
  // A NaN in y or e stays in the box (then never skipped).
  static void join(Summary& s, const Summary& b) {
    for (int k = 0; k < D; ++k) {
      s.lo[k] = b.lo[k] < s.lo[k] || std::isnan(b.lo[k]) ? b.lo[k] : s.lo[k];
      s.hi[k] = b.hi[k] > s.hi[k] || std::isnan(b.hi[k]) ? b.hi[k] : s.hi[k];
    }
    s.e = b.e > s.e || std::isnan(b.e) ? b.e : s.e;
    s.r2 = std::max(s.r2, b.r2);
  }

  // The marked blocks measured again from the lanes, and their groups from
  // their blocks. A slot with a coordinate that is not finite has an e that
  // is not finite either (e >= plane_eps |y|_inf), which no box passes.
  void refresh(const filter::FilterLanes<D>& f) {
    const std::size_t nv = f.size();
    if (blocks(nv) > marked_.size()) touch_range(marked_.size() * block, nv);  // (every write touches: never)
    if (dirty_.empty()) return;
    const double* const E = f.e();
    const double* const R = f.r2();
    for (const std::uint32_t b : dirty_) {
      marked_[b] = 0;
      Summary& s = blocks_[b];
      clear(s);
      const std::size_t t_end = std::min((b + 1) * block, nv);
      for (std::size_t t = b * block; t < t_end; ++t) {
        Summary v;
        for (int k = 0; k < D; ++k) v.lo[k] = v.hi[k] = f.y(k)[t];
        v.e = E[t];
        v.r2 = R[t];
        join(s, v);
      }
      group_marked_[b / group] = 1;
    }
    for (const std::uint32_t b : dirty_) {
      const std::size_t g = b / group;
      if (group_marked_[g] == 0) continue;  // measured already
      group_marked_[g] = 0;
      Summary& s = groups_[g];
      clear(s);
      const std::size_t b_end = std::min((g + 1) * group, blocks_.size());
      for (std::size_t c = g * group; c < b_end; ++c) join(s, blocks_[c]);
    }
    dirty_.clear();
  }

  std::vector<Summary> blocks_, groups_;
  std::vector<std::uint8_t> marked_;  // per block: 1 while in dirty_
  std::vector<std::uint8_t> group_marked_;  // per group: refresh's, 1 while to be measured
  std::vector<std::uint32_t> dirty_;  // the marked blocks
};

}  // namespace tessera::kernels
