// The 2D cell builder: a convex polygon clipped by half-planes.
//
// The tile is a counter-clockwise cycle of vertices; edge k runs from vertex k
// to vertex k+1 and lies on plane `next` of vertex k (= plane `prev` of
// vertex k+1). A vertex is the meeting point of its two planes, so its
// topological coordinate is {generator, prev plane id, next plane id}. Clip
// decisions use the float filter and the exact predicate exactly as the 3D
// hull does (see hull.hpp, filter.hpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <tuple>
#include <utility>
#include <vector>

#include "tessera/kernels/assembly.hpp"
#include "tessera/kernels/deferred_solves.hpp"
#include "tessera/kernels/exact_predicates.hpp"
#include "tessera/kernels/walls.hpp"  // walls::Ball
#include "tessera/kernels/filter.hpp"
#include "tessera/kernels/hull.hpp"  // ClipResult
#include "tessera/kernels/power.hpp"
#include "tessera/kernels/prepared_signs.hpp"

namespace tessera::kernels {

class Tile {
 public:
  static constexpr int dim = 2;
  /// A local plane's index (vertices hold two): 32 bits cost the tile
  /// nothing (its vertex is 40 bytes either way, in padding), so a polygon
  /// may have any number of edges (the hull's are 32-bit since stop 59). Before stop
  /// 57 they were 16-bit too: the centre of 65,535 points on a circle, or
  /// the end of 400k points on a parabola (whose triangulation fans from
  /// it), failed with a length error, and past 65,520 neighbours a star
  /// could not be assembled and was clipped, quadratic in them.
  using Index = std::uint32_t;
  /// The domain box's planes are always the tile's first local planes.
  static constexpr Index box_planes = 4;
  /// The most bisectors assemble() takes: any star (its neighbours are
  /// input points, fewer than 2^31).
  static constexpr std::size_t max_assembled_planes = 0xFFFFFFF0;
  struct Plane {
    double n[2];
    double d;
    double n1;
    std::int32_t id;
    std::int32_t scale;  // a bisector: n = q 2^-scale; 0 unless |q| is huge or tiny (filter::Bisector)
  };
  struct Vertex {
    double y[2];
    double e;            // err + plane_eps * |y|_inf (see hull.hpp)
    double r2;           // upper bound on the exact |y|^2
    Index p[2];  // [0] = plane of the edge arriving, [1] = of the edge leaving
  };
  static_assert(sizeof(Vertex) == 40, "32-bit plane indices fill what was padding");

  void reset(std::int32_t gen, const double* p, const double* lo, const double* hi,
             const ExactContext* exact) {
    start(gen, p, lo, hi, exact);
    // Corners counter-clockwise from (lo, lo); local planes x0=0, x1=1, y0=2, y1=3.
    const Index in[4] = {0, 2, 1, 3}, out[4] = {2, 1, 3, 0};
    const int cx[4] = {0, 1, 1, 0}, cy[4] = {0, 0, 1, 1};
    verts_.resize(4);
    for (int c = 0; c < 4; ++c) {
      Vertex& v = verts_[static_cast<std::size_t>(c)];
      v.y[0] = cx[c] ? planes_[1].d : -planes_[0].d;
      v.y[1] = cy[c] ? planes_[3].d : -planes_[2].d;
      double ymax = std::max(std::fabs(v.y[0]), std::fabs(v.y[1]));
      double err = filter::u * ymax;
      v.e = err + filter::plane_eps * ymax;
      set_radius(v, err);
      v.p[0] = in[c];
      v.p[1] = out[c];
    }
    lanes_.assign(verts_);
    update_radius();
  }

  ClipResult clip(std::int32_t j, const double* q) {
    if (deferred_asks_ >= filter::deferred_ask_limit) [[unlikely]] {
      deferred_asks_ = 0;
      solve_deferred();
    }
    filter::Bisector<2> b(q);
    if (weighted_) [[unlikely]] weigh(b, *exact_, gen_, j);  // a power diagram's plane (power.hpp)
    const std::size_t nv = verts_.size();
    auto exact = [&](std::size_t t) { return exact_sign(t, j); };
    // Where no frame fits, n.y may overflow (filter::classify).
    const std::size_t removed = may_underflow_ ? filter::classify_unbounded<2>(lanes_, b, sign_, exact)
                                               : filter::classify<2>(lanes_, b.n, b.d, b.n1, b.d_unscaled, sign_, exact);
    if (removed == 0) return ClipResult::unchanged;
    if (removed == nv) {
      verts_.clear();
      lanes_.clear();
      security2_ = 0;
      return ClipResult::emptied;
    }
    const Index pn = static_cast<Index>(planes_.size());
    Plane& pl = planes_.emplace_back();  // written in place (see reset)
    pl.n[0] = b.n[0]; pl.n[1] = b.n[1];
    pl.d = b.d;
    pl.n1 = b.n1;
    pl.id = j;
    pl.scale = b.scale;
    cut(pn, nv, removed);
    return ClipResult::clipped;
  }

  /// As Hull::clip_wall: cut the finished tile by wall k (walls.hpp).
  ClipResult clip_wall(int k, const walls::Ball<2>& b);  // (kernels/clip_walls.cpp)
  walls::Ball<2> vertex_ball() const { return walls::vertex_ball<2>(verts_.data(), verts_.size()); }


 private:
  // Replace the run of vertices sign_ marks removed (-1; `removed` of the
  // nv, not all) by two on local plane pn: a clip's work after its sign pass.
  void cut(Index pn, std::size_t nv, std::size_t removed) {
    // The removed vertices form one cyclic run (the polygon is convex). It is
    // replaced in place by a (leaving: the edge plane of the last kept vertex,
    // then the new plane) and b (entering: the new plane, then the edge plane
    // of the first kept vertex), keeping the cycle's start where vertex 0
    // survives:
    //   vertex 0 kept:    [0 .. L] a b [E+1 .. nv-1]   (removed run L+1 .. E)
    //   vertex 0 removed: b [k0 .. k1] a               (kept run k0 .. k1)
    const std::size_t kept = nv - removed;
    // The new vertices are built in their slots (see reset on why not copied in).
    auto make = [&](std::size_t ta, Index a0, std::size_t tb, Index b1) {
      Vertex& va = verts_[ta];
      Vertex& vb = verts_[tb];
      va.p[0] = a0;
      va.p[1] = pn;
      vb.p[0] = pn;
      vb.p[1] = b1;
      solve_pair(va, vb, filter::SolveMode::deferrable);
      lanes_.set(ta, va);
      lanes_.set(tb, vb);
    };
    if (removed == 1) grow(kept + 2);  // one vertex out, two in
    if (sign_[0] > 0) {
      std::size_t r0 = 1;
      while (sign_[r0] > 0) ++r0;
      const std::size_t e1 = r0 + removed;  // first slot after the run (nv: none)
      const Index a0 = verts_[r0 - 1].p[1], b1 = verts_[e1 % nv].p[0];
      const std::size_t tail = nv - e1;
      if (removed != 2) {
        filter::shift(verts_.data(), r0 + 2, e1, tail);
        lanes_.move(r0 + 2, e1, tail);
      }
      make(r0, a0, r0 + 1, b1);
    } else {
      std::size_t k0 = 1;
      while (sign_[k0] < 0) ++k0;
      const Index b1 = verts_[k0].p[0], a0 = verts_[k0 + kept - 1].p[1];
      if (k0 != 1) {
        filter::shift(verts_.data(), 1, k0, kept);
        lanes_.move(1, k0, kept);
      }
      make(kept + 1, a0, 0, b1);
    }
    verts_.resize(kept + 2);
    lanes_.resize(kept + 2);
    update_radius();
  }

 public:
  /// Hull::assemble for the polygon: edges on the bisectors with the m
  /// points q (q[2k..2k+2)), and nt vertices, counter-clockwise, given as
  /// `corners` pairs (the plane of the edge arriving, then of the edge
  /// leaving), solved two at a time as a clip solves them. False, leaving
  /// the tile to be reset and clipped, in the same cases.
  ///
  /// `open`: the generator lies on the convex hull, and the corners are a
  /// chain, not a cycle (its fan of triangles, counter-clockwise), from
  /// hull edge (p, first corner's arriving plane) to hull edge (p, last
  /// corner's leaving plane). Each of those two edges adds a vertex where
  /// its ray crosses a far line (assembly::far_plane), which closes the
  /// cycle, and the box cuts them away.
  bool assemble(std::int32_t gen, const double* p, const double* lo, const double* hi, const ExactContext* exact,
                const std::int32_t* ids, const double* q, std::size_t m, const Index* corners,
                std::size_t nt, bool open = false) {
    start(gen, p, lo, hi, exact);
    // A power cell's star comes from the regular triangulation, its planes weighed.
    if (may_underflow_ || m > max_assembled_planes ||
        !assembly::star_planes<2>(planes_, box_planes, ids, q, m, weighted_ ? exact_ : nullptr, gen))
      return false;
    verts_.resize(open ? nt + 2 : nt);
    for (std::size_t t = 0; t < nt; ++t) {
      verts_[t].p[0] = box_planes + corners[2 * t];
      verts_[t].p[1] = box_planes + corners[2 * t + 1];
    }
    for (std::size_t t = 0; t + 1 < nt; t += 2) solve_pair(verts_[t], verts_[t + 1], filter::SolveMode::float_only);
    if (nt % 2 != 0) solve(verts_[nt - 1], filter::SolveMode::float_only);
    // Vertices too ill-conditioned for the float solve that lie far out
    // (assembly::ill_conditioned_fate) are solved exactly after all, as long as that
    // costs less than clipping the cell (Hull::assemble's rule): the end
    // of points on a parabola, whose star holds nearly every point, has
    // thousands of them, and clipping it was quadratic (100k points: 1.0 s).
    const std::size_t may_refuse = assembly::exact_solves_paid(m, nt);
    std::size_t refused = 0;
    for (std::size_t t = 0; t < nt; ++t)
      if (!(verts_[t].e <= std::numeric_limits<double>::max())) {
        if (++refused > may_refuse) return false;
        solve(verts_[t], filter::SolveMode::exact_now);
      }
    if (open) {
      // Hull edges (p, s) at the chain's start and (p, e) at its end: the
      // fan lies counter-clockwise from s to e, the outside beyond them, so
      // their outward normals are q_s turned clockwise and q_e
      // counter-clockwise (exact turns), the rays' directions.
      const Index s = corners[0], e = corners[2 * nt - 1];
      const double* qs = q + 2 * s;
      const double* qe = q + 2 * e;
      const double ls = std::hypot(qs[0], qs[1]), le = std::hypot(qe[0], qe[1]);
      const double dirs[4] = {qs[1] / ls, -qs[0] / ls, -qe[1] / le, qe[0] / le};
      const Index far = static_cast<Index>(planes_.size());
      Plane& pf = planes_.emplace_back();
      const double margins[2] = {0, 0};  // tilts ~3u: far_margin, then far_direction's floor
      if (!assembly::far_plane<2>(dirs, 2, planes_.data(), verts_.data(), nt, pf, margins)) return false;
      Vertex& ve = verts_[nt];  // leaving along e's ray, arriving on the far line
      Vertex& vs = verts_[nt + 1];
      ve.p[0] = box_planes + e;
      ve.p[1] = far;
      vs.p[0] = far;
      vs.p[1] = box_planes + s;
      solve_pair(ve, vs, filter::SolveMode::float_only);  // never exact: on the far line
    }
    lanes_.assign(verts_);
    update_radius();
    // false too where a vertex needed the exact solve (its bound is NaN)
    return clip_to_box() && (!open || assembly::drop_far_plane<2>(planes_, verts_));
  }

  double security_radius2() const { return security2_; }
  /// An upper bound on every vertex's distance from the generator (half the
  /// security radius); a cut by a wall never raises it.
  double vertex_reach() const { return 0.5 * std::sqrt(security2_); }
  /// power_slack (power.hpp) of a power cell, in every vertex's r2; 0 without radii.
  double power_slack() const { return slack_; }
  std::int32_t generator() const { return gen_; }
  /// The generator's coordinates: vertices are relative to them.
  const double* site() const { return site_; }
  std::size_t num_vertices() const { return verts_.size(); }
  const std::vector<Vertex>& vertices() const { return verts_; }
  const std::vector<Plane>& planes() const { return planes_; }
  std::uint64_t exact_calls() const { return signs_.calls(); }
  std::uint64_t off_grid_exact_calls() const { return signs_.off_grid_calls(); }
  /// The exact stages' gates open again (PreparedSigns::reset_gates).
  void reset_stage_gates() { signs_.reset_gates(); }
  /// Vertices of this cell solved exactly (too ill-conditioned for the float solve).
  std::uint64_t exact_solves() const { return exact_solves_; }

  /// As Hull::solve_deferred: the surviving vertices whose exact solve was
  /// deferred are solved now (by CellBuilder for every cell it returns, and
  /// by clip() once filter::deferred_ask_limit exact questions were asked).
  void solve_deferred() {
    if (deferred_.empty()) return;
    deferred_.seal();
    for (std::size_t t = 0; t < verts_.size(); ++t)
      if (deferred_.contains(pair_key(verts_[t]))) solve_now(t);
    deferred_.clear();
    update_radius();
  }
  /// The input's exact context (null in bare kernel tests).
  const ExactContext* exact_context() const { return exact_; }

 private:
  // The assembled tile cut by the domain box's planes, each decided by the
  // float filter alone, after solving exactly the vertices a plane cannot
  // place (as Hull::clip_to_box).
  bool clip_to_box() {
    for (Index k = 0; k < box_planes; ++k) {
      const std::size_t nv = verts_.size();
      const std::size_t removed = assembly::box_cut_signs<2>(verts_.data(), nv, static_cast<int>(k), planes_.data(),
                                                             sign_, exact_, gen_, [&] { solve_near(k); });
      if (removed == assembly::undecided || removed == nv) return false;
      if (removed != 0) cut(k, nv, removed);
    }
    return true;
  }

  // Vertex t solved exactly now (solve_deferred's step, and solve_near's). A
  // deferred one keeps its key: solve_deferred solves it again, to the same
  // doubles (the set has no removal; this is rare).
  void solve_now(std::size_t t) {
    Vertex& v = verts_[t];
    const double ymax = solve_exactly(v);
    const double err = 4 * filter::u * ymax;
    v.e = err + filter::plane_eps * ymax;
    set_radius(v, err);
    lanes_.set(t, v);
  }

  // As Hull::solve_near.
  void solve_near(Index k) {
    const bool solved = assembly::solve_near_box_plane<2>(verts_.data(), verts_.size(), static_cast<int>(k),
                                                          planes_[k].d, [this](std::size_t t) { solve_now(t); });
    if (solved) update_radius();
  }

  // The cell's generator and the domain box's planes (always its first
  // local planes), with no vertices yet.
  void start(std::int32_t gen, const double* p, const double* lo, const double* hi, const ExactContext* exact) {
    gen_ = gen;
    for (int a = 0; a < 2; ++a) site_[a] = p[a];
    exact_ = exact;
    may_underflow_ = exact != nullptr && exact->may_underflow;
    weighted_ = exact != nullptr && exact->radii != nullptr;
    slack_ = weighted_ ? kernels::power_slack(exact->max_radius, exact->radii[gen]) : 0.0;
    signs_.start_cell();
    exact_solves_ = 0;
    deferred_.clear();
    deferred_asks_ = 0;
    // Planes and corners are written in place: a local struct copied in
    // would be read back wider than it was written (a store-forwarding stall).
    planes_.resize(box_planes);
    for (int k = 0; k < static_cast<int>(box_planes); ++k) {
      const int axis = k / 2;
      const bool upper = k & 1;
      Plane& pl = planes_[static_cast<std::size_t>(k)];
      pl.n[axis] = upper ? 1.0 : -1.0;
      pl.n[1 - axis] = 0.0;
      pl.d = upper ? hi[axis] - p[axis] : p[axis] - lo[axis];
      pl.n1 = 1.0;
      pl.id = box_plane_id(axis, upper);
      pl.scale = 0;
    }
  }

  // The exact sign of vertex slot t against j (prepared_signs.hpp).
  int exact_sign(std::size_t t, std::int32_t j) {
    const Vertex& v = verts_[t];
    deferred_asks_ += !deferred_.empty();
    const std::int32_t ids[2] = {planes_[v.p[0]].id, planes_[v.p[1]].id};
    return signs_.sign(*exact_, gen_, t, v.p, ids, j);
  }

  // verts_ and its sign-pass mirror (lanes_) change together.
  void grow(std::size_t n) {
    if (verts_.size() < n) {
      verts_.resize(n);
      lanes_.resize(n);
    }
  }

  // A vertex's solve by Cramer's rule and its error bound, written once for
  // one vertex (T = double) and for two in the lanes of SSE2 registers
  // (T = filter::detail::Lane): the same operations in the same order, so
  // the same doubles either way.
  using Lane = filter::detail::Lane;
  static double magnitude(double x) { return std::fabs(x); }
  static Lane magnitude(Lane x) {  // fabs per lane: the sign bit cleared
    using M = filter::detail::LaneMask;
    return reinterpret_cast<Lane>(reinterpret_cast<M>(x) & M{INT64_MAX, INT64_MAX});
  }
  template <class T>
  static T larger(T a, T b) { return a < b ? b : a; }  // std::max (per lane)
  template <class T>
  struct Cramer {
    T y0, y1, inv, ymax, inv_norm, amax, bmax, cond;
    // Planes A (n = (an0, an1), d = ad, |n|_1 = an) and B.
    Cramer(T an0, T an1, T ad, T an, T bn0, T bn1, T bd, T bn) {
      const T det = an0 * bn1 - an1 * bn0;
      inv = 1.0 / det;
      y0 = (bn1 * ad - an1 * bd) * inv;
      y1 = (an0 * bd - bn0 * ad) * inv;
      ymax = larger(magnitude(y0), magnitude(y1));
      inv_norm = (an + bn) * magnitude(inv);  // sum of |adj| entries / |det|
      amax = larger(an, bn);
      bmax = larger(magnitude(ad), magnitude(bd));
      cond = inv_norm * amax;
    }
    T err() const { return filter::vertex_eps * inv_norm * (amax * ymax + bmax); }
  };
  // The bound on |y|^2 before set_radius's clamp to infinity.
  // With radii it bounds |y|^2 + slack_ (power.hpp); slack_ 0 adds nothing.
  template <class T>
  T radius2(T y0, T y1, T err) const {
    const T a = y0 * y0 + y1 * y1;
    const T l1 = magnitude(y0) + magnitude(y1);
    return (a + 4.0 * err * (l1 + err) + slack_) * (1.0 + 1e-12) + filter::radius_abs_eps;
  }

  // solve() for the two new vertices of a clip at once, one division for
  // both. The rare cases (ill-conditioned, possible underflow) take the
  // scalar path.
  [[gnu::always_inline]] void solve_pair(Vertex& va, Vertex& vb, filter::SolveMode mode) const {  // as Hull::solve
    const Plane& A0 = planes_[va.p[0]];
    const Plane& B0 = planes_[va.p[1]];
    const Plane& A1 = planes_[vb.p[0]];
    const Plane& B1 = planes_[vb.p[1]];
    const Cramer<Lane> c(Lane{A0.n[0], A1.n[0]}, Lane{A0.n[1], A1.n[1]}, Lane{A0.d, A1.d}, Lane{A0.n1, A1.n1},
                         Lane{B0.n[0], B1.n[0]}, Lane{B0.n[1], B1.n[1]}, Lane{B0.d, B1.d}, Lane{B0.n1, B1.n1});
    const bool ok = !may_underflow_ && c.cond[0] < filter::exact_vertex_condition &&
                    c.cond[1] < filter::exact_vertex_condition && std::isfinite(c.ymax[0]) && std::isfinite(c.ymax[1]);
    if (!ok) [[unlikely]] {
      solve(va, mode);
      solve(vb, mode);
      return;
    }
    const Lane err = c.err();
    const Lane e = err + filter::plane_eps * c.ymax;
    const Lane r2 = radius2(c.y0, c.y1, err);
    Vertex* const v[2] = {&va, &vb};
    for (int k = 0; k < 2; ++k) {
      v[k]->y[0] = c.y0[k];
      v[k]->y[1] = c.y1[k];
      v[k]->e = e[k];
      v[k]->r2 = clamp_radius(r2[k]);
    }
  }

  // As Hull::solve, by `mode`.
  void solve(Vertex& v, filter::SolveMode mode) const {
    const Plane& A = planes_[v.p[0]];
    const Plane& B = planes_[v.p[1]];
    const Cramer<double> c(A.n[0], A.n[1], A.d, A.n1, B.n[0], B.n[1], B.d, B.n1);
    v.y[0] = c.y0;
    v.y[1] = c.y1;
    double ymax = c.ymax;
    // Extreme input only (front/pass.cpp): products that may have underflowed.
    const double slack = may_underflow_ ? filter::underflow_slack(c.inv, c.amax, c.bmax, A.n1 + B.n1, ymax) : 0.0;
    double err;
    if (c.cond < filter::exact_vertex_condition && std::isfinite(ymax))
      err = c.err() + slack;
    else
      std::tie(err, ymax) = ill_conditioned(v, c.inv, ymax, slack, mode);
    v.e = err + filter::plane_eps * ymax;
    set_radius(v, err);
  }

  // As Hull::ill_conditioned: the bound on the rows scaled to |n|_1 in
  // [1, 2) (the same y, a bound blind to the rows' magnitudes), else the
  // exact solve, now or (below deferred_vertex_condition, unless `mode` is
  // exact_now) deferred. Returns err and ymax.
  [[gnu::noinline, gnu::cold]] std::pair<double, double> ill_conditioned(Vertex& v, double inv, double ymax, double slack, filter::SolveMode mode) const {
    const Plane& A = planes_[v.p[0]];
    const Plane& B = planes_[v.p[1]];
    const std::int32_t ea = filter::binary_exponent(A.n1), eb = filter::binary_exponent(B.n1);
    const double sa = filter::pow2(-ea), sb = filter::pow2(-eb);
    const double na = A.n1 * sa, nb = B.n1 * sb;
    const double inv_norm = (na + nb) * (std::fabs(inv) * filter::pow2(ea) * filter::pow2(eb));
    const double amax = std::max(na, nb);
    const double bmax = std::max(std::fabs(A.d) * sa, std::fabs(B.d) * sb);
    const double cond = inv_norm * amax;
    const double err = filter::vertex_eps * inv_norm * (amax * ymax + bmax) + slack;
    if (cond < filter::exact_vertex_condition && std::isfinite(ymax))  // false on NaN
      return {err, ymax};
    return assembly::settle_ill_conditioned<2>(
        mode, cond, err, ymax, v, planes_.data(), [&] { deferred_.add(pair_key(v)); },
        [&] { return solve_exactly(v); });
  }

  // v's position solved exactly and rounded (exact_vertex); returns |y|_inf.
  double solve_exactly(Vertex& v) const {
    assembly::exact_solve<2>(*exact_, gen_, planes_.data(), v.p, v.y);
    ++exact_solves_;
    return std::max(std::fabs(v.y[0]), std::fabs(v.y[1]));
  }

  // A vertex's two lines, in order (one vertex per ordered pair in a tile).
  static std::uint64_t pair_key(const Vertex& v) { return (std::uint64_t{v.p[0]} << 32) | v.p[1]; }

  static double clamp_radius(double r2) {
    return r2 < std::numeric_limits<double>::infinity() ? r2 : std::numeric_limits<double>::infinity();  // NaN too
  }
  void set_radius(Vertex& v, double err) const { v.r2 = clamp_radius(radius2(v.y[0], v.y[1], err)); }

  void update_radius() {
    security2_ = 4.0 * lanes_.max_r2() * (1 + 1e-12);
  }

  std::int32_t gen_ = -1;
  double site_[2] = {};  // the generator's coordinates
  const ExactContext* exact_ = nullptr;
  bool may_underflow_ = false;  // exact_->may_underflow: solve() adds filter::underflow_slack
  bool weighted_ = false;       // exact_->radii: a power cell (power.hpp)
  double slack_ = 0;            // power_slack of this cell (0 without radii), in every r2
  mutable std::uint64_t exact_solves_ = 0;  // exact_solves(); counted by the const solve
  mutable DeferredSolves deferred_;  // pair_keys of vertices whose exact solve waits (solve_deferred)
  // Exact evaluations asked while some vertex is deferred (a tile cannot
  // tell which without a lookup), since the cell started or they were last
  // solved (filter::deferred_ask_limit).
  std::uint32_t deferred_asks_ = 0;
  std::vector<Plane> planes_;
  std::vector<Vertex> verts_;
  filter::FilterLanes<2> lanes_;  // verts_' filter data, for the sign pass
  std::vector<filter::Sign> sign_;
  double security2_ = 0;
  PreparedSigns<2, Index> signs_;  // the exact stages, prepared per vertex slot
};

}  // namespace tessera::kernels
