// What the 2D tile and the 3D hull share in assembling a cell known whole
// in advance (its Delaunay star: CellBuilder::build_from_star) rather than
// clipping it from the box: its bisector planes, the far plane that closes
// a hull point's unbounded cell, and the signs of its vertices against the
// domain box's planes (the box cuts what lies outside).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <utility>
#include <vector>

#include "tessera/kernels/exact_predicates.hpp"
#include "tessera/kernels/filter.hpp"
#include "tessera/kernels/power.hpp"

namespace tessera::kernels::assembly {

/// Planes [first, first + m) of `planes` (resized to hold them): the
/// bisectors with the points q (relative to the generator, D each) of
/// generator ids `ids`, written as a clip writes its plane (the same d and
/// n1, so the same vertices).
template <int D, class Plane>
void bisector_planes(std::vector<Plane>& planes, std::size_t first, const std::int32_t* ids, const double* q,
                     std::size_t m) {
  planes.resize(first + m);
  for (std::size_t k = 0; k < m; ++k) {
    Plane& pl = planes[first + k];  // written in place (a copied struct stalls store forwarding)
    const double* n = q + D * k;
    double d = 0, n1 = 0;
    for (int a = 0; a < D; ++a) {
      pl.n[a] = n[a];
      d += n[a] * n[a];
      n1 += std::fabs(n[a]);
    }
    pl.d = 0.5 * d;
    pl.n1 = n1;
    pl.id = ids[k];
    pl.scale = 0;  // assemble() refuses extreme input (may_underflow), the only kind with huge bisectors
  }
}

/// bisector_planes for a power cell of generator `gen` (power.hpp): each
/// plane written as a power cell's clip writes it (filter::Bisector, then
/// weigh: d moved by (r_gen^2 - r_j^2) / 2), so an assembled power cell has
/// the vertices its clips would give. The star comes from the regular
/// triangulation, whose simplices are the power cells' vertices as the
/// Delaunay triangulation's are the Voronoi cells'. False where a plane
/// needed scaling (filter::Bisector::rescale: never outside the extreme
/// input assemble() refuses), leaving the cell to the clips.
template <int D, class Plane>
bool power_planes(std::vector<Plane>& planes, std::size_t first, const std::int32_t* ids, const double* q,
                  std::size_t m, const ExactContext& ctx, std::int32_t gen) {
  planes.resize(first + m);
  for (std::size_t k = 0; k < m; ++k) {
    filter::Bisector<D> b(q + D * k);
    weigh(b, ctx, gen, ids[k]);
    if (b.scale != 0) return false;
    Plane& pl = planes[first + k];
    for (int a = 0; a < D; ++a) pl.n[a] = b.n[a];
    pl.d = b.d;
    pl.n1 = b.n1;
    pl.id = ids[k];
    pl.scale = 0;
  }
  return true;
}

/// The planes of a star for Hull/Tile::assemble: bisector_planes, or with
/// `weights` (the ExactContext of a power cell's radii) power_planes. False
/// where power_planes declines.
template <int D, class Plane>
bool star_planes(std::vector<Plane>& planes, std::size_t first, const std::int32_t* ids, const double* q,
                 std::size_t m, const ExactContext* weights, std::int32_t gen) {
  if (weights != nullptr) return power_planes<D>(planes, first, ids, q, m, *weights, gen);
  bisector_planes<D>(planes, first, ids, q, m);
  return true;
}

/// The id of the far plane that closes a hull point's cell (far_plane): no
/// generator's and no box plane's. It never reaches a finished cell: the box
/// cuts away every vertex on it, and the kernels then drop it.
inline constexpr std::int32_t far_plane_id = std::numeric_limits<std::int32_t>::min();

/// The least angle far_direction leaves between the far plane and any ray,
/// as n.dir >= far_margin |n| for unit directions.
inline constexpr double far_margin = 1e-3;

/// Each ray's own margin: six times the bound on its direction's tilt. A
/// 3D ray is the cross product of its hull facet's two differences q_a and
/// q_b; its rounding and the q's own (each component errs by at most ~4u
/// |q_a| |q_b|, and the exact q's cross product and the float one's differ
/// by about as much) tilt it by under facet_tilt / t, t its facet's
/// thinness |q_a x q_b| / (|q_a| |q_b|). A 2D ray is q turned by a right
/// angle (exact) and normalised: ~2u. far_direction asks every ray for
/// the larger of far_margin and its own margin; where no direction gives
/// that (a hull point whose rays span nearly a half space: one 1,000 radii
/// above a ring of points, whose rays lie within 1e-3 of the horizon; in 2D
/// one far above a row), it asks again with that floor (below) in place of
/// far_margin. So every ray the far plane is chosen to cross, it crosses.
/// A ray met nearly edge on puts its far vertex far out, ill-conditioned
/// (far_vertex_condition).
/// (A 3D ray's error along a given direction can be much smaller than its
/// tilt bound: far_direction's ray_axis_errors.) The floor under every
/// margin in that second round covers only the dot product's rounding and
/// the ray's normalisation (and a 2D ray's own error): 16u times the sum of
/// |n_a dir_a|. Stop 60 set a fixed floor, far_margin_least, at 1e-12,
/// which left a point 1e12 above a row (its rays 1e-12 from the horizon) to
/// the clips; stop 61 1e-14, which left apexes 1e14 above circles and
/// points 1e15 off rows; stop 62 the computed floor.
inline constexpr double facet_tilt = 1.6e-15;
// No facet is too thin to close (stop 62; from stop 59 to 61 those below
// `thin_facet`, last 1e-14, were refused). A thin facet's ray is uncertain
// sideways by ~facet_tilt / thinness, past a right angle below ~1e-15, but
// far_direction never relies on more than it knows: a ray's isotropic
// margin is then above 1, which no direction meets, and its bound along
// the normal (ray_axis_errors) bounds the cross product's own component
// errors, divided by the computed length on both sides of the test, so
// it holds at any thinness. Only a zero cross product (the facet's two
// neighbours in line with the point, in floats) has no direction. The
// test had left a point 1e12 below a plane of 2,000 points (facets
// ~7e-15 thin) and an apex 1e12 radii above 2,000 circle points (~1e-18)
// to the clips: 9 s and 4 s, quadratic; 0.07-0.09 s now.

/// A vertex on the far plane is never output: only the box's cut reads it,
/// and it lies outside the box by half the box's extent along the far
/// plane's normal. It keeps its float position and first-order bound up to
/// this condition number cond = |A^-1| |A| (Hull/Tile::solve), and beyond
/// is solved exactly (exact_vertex_on_plane: the far plane's normal and
/// offset are doubles, so exact rationals), as other vertices are; until
/// stop 60 it was refused beyond 1e9, and the star went to the clips. The
/// bound, 64u |A^-1| (|A| |y| + |b|), is over six times the first-order
/// error of the rounded planes (~u |A^-1| (|A| |y| + 5 |b|)) and of
/// Cramer's rule (~u |A^-1| (6 |A| |y| + 5 |b|)). Beyond first order, the
/// computed determinant errs relatively by delta ~ 5u cond (5.6e-3 here),
/// which multiplies those errors by 1 / (1 - delta), and |y| may exceed the
/// computed |y| by the bound itself, 64u cond (7%) of it: the margin covers
/// both. (filter::deferred_vertex_condition stops at 1e9 for another reason:
/// a vertex that stays in a cell needs a bound narrow enough for the sign
/// passes.)
inline constexpr double far_vertex_condition = 1e13;

/// v scaled by a power of two (exactly: the same direction, the same signs
/// of its dot products) so that its largest component lies in [1, 2); left
/// alone if zero or not finite. far_direction's n may be tiny: the rays'
/// sum, or a step (n / |n| plus the worst ray), where unit rays cancel (a
/// point 1e52 off unit points, whose rays come in opposite pairs: 2^-175
/// long). Its floor, 2^-1000 of |n|, then underflowed to zero, a ray at
/// right angles to n passed, and the far vertex's planes were dependent: an
/// internal error, exit 1. So its tests read n scaled, and it returns n
/// scaled.
template <int D>
void scale_to_unit(double* v) {
  double m = 0;
  for (int a = 0; a < D; ++a) m = std::max(m, std::fabs(v[a]));
  if (!(m > 0 && m <= std::numeric_limits<double>::max())) return;
  const int e = filter::binary_exponent(m);
  for (int a = 0; a < D; ++a) v[a] = std::ldexp(v[a], -e);
}

/// The plane that closes the cell of a point on the convex hull, whose
/// Voronoi cell is unbounded: its star's simplices give the bounded
/// vertices, and each hull facet at the point one unbounded edge, a ray in
/// the facet's outward normal direction. A plane P = {y : n.y = c} that every
/// such ray crosses, with the domain box and every bounded vertex strictly
/// inside, turns the cell into the polytope cell ∩ {n.y <= c}, whose
/// vertices are the bounded ones and one per ray (where it crosses P), all
/// known from the star; the box then cuts P away whole, as it lies outside.
///
/// `dirs`: the k rays' unit directions (D each, from the rounded
/// differences q), and `ray_margins` their own margins (the floor;
/// null: far_margin alone). `ray_axis_errors` (optional, D per ray): bounds
/// e on the error of each of a ray's components, so that a ray's error along
/// a unit n is at most sum_a |n_a| e_a; where that is below its own margin
/// it serves instead. (A 3D ray is the cross product of two nearly parallel
/// q over a thin facet: its direction is uncertain by the margin, but only
/// sideways; along the far plane's normal it may be known far better. An
/// apex 1e5 radii above a circle: rays tilted 1e-5 up, margins up to 1e-3,
/// their errors along the axis ~1e-20 / the circle points' gap.)
///
/// n is their sum, or where that leaves a ray short, a direction found by
/// stepping towards the worst ray, or the same from the caller's hint
/// (below); every ray must make an angle with n
/// short of a right angle by its margin (n.dir >= margin |n|, beyond its
/// rounding), else false (a hull vertex whose normal cone is a half space
/// to within the rounding: the cell is clipped instead). c lies beyond the box's corners and the vertices [0,
/// nv) (each widened by its error bound) by half the box's extent along n,
/// so every vertex on P is certainly outside the box (box_signs).
/// `box`: the kernel's first 2D planes (box_planes), n = -+e_axis, d = the
/// offset from the generator.
template <int D>
bool far_direction(const double* dirs, std::size_t k, double* n, const double* hint = nullptr,
                   const double* ray_margins = nullptr, const double* ray_axis_errors = nullptr) {
  bool relaxed = false;  // the second round: the rounding floor in place of far_margin
  // The ray m falls shortest of its margin on (k: none; k + 1: NaN, or m = 0).
  auto worst_ray = [&](const double* m_in) {
    // On n scaled to unit range (scale_to_unit): the same dots' signs, and
    // a floor that does not underflow.
    double m[D];
    for (int a = 0; a < D; ++a) m[a] = m_in[a];
    scale_to_unit<D>(m);
    double len2 = 0, mabs[D];
    for (int a = 0; a < D; ++a) {
      len2 += m[a] * m[a];
      mabs[a] = std::fabs(m[a]);
    }
    const double len = std::sqrt(len2);
    if (!(len > 0)) return k + 1;
    std::size_t worst = k;
    double least = 0;  // the worst's dot less its margin, times |m|
    for (std::size_t r = 0; r < k; ++r) {
      double dot = 0;
      for (int a = 0; a < D; ++a) dot += m[a] * dirs[D * r + static_cast<std::size_t>(a)];
      double margin_len = far_margin * len;  // the ray's margin, times |m|
      if (ray_margins != nullptr) {
        double own = ray_margins[r] * len, terms = 0;
        for (int a = 0; a < D; ++a) terms += mabs[a] * std::fabs(dirs[D * r + static_cast<std::size_t>(a)]);
        if (ray_axis_errors != nullptr) {  // the bound along m itself, where smaller
          double along = 0;
          for (int a = 0; a < D; ++a) along += mabs[a] * ray_axis_errors[D * r + static_cast<std::size_t>(a)];
          own = std::min(own, along);
        }
        // The floor (far_margin_least's place, stop 62): the dot's rounding
        // and the ray's normalisation, each under 4u of the sum of
        // |m_a dir_a|, and in 2D the ray's own error (q's rounding and the
        // normalisation, each component within 3u of itself); and products
        // lost to underflow. It must stay positive: where own and the terms
        // are all zero (q_a and q_b with a common zero component, and m
        // orthogonal to the ray in floats: a rotated lattice's hull edge), a
        // zero dot would pass, and the far vertex's planes are dependent.
        const double least_len = 16 * filter::u * terms + 0x1p-1000 * len;
        margin_len = std::max(relaxed ? least_len : far_margin * len, own);
      }
      const double short_by = dot - margin_len;
      if (!(short_by >= least)) {
        if (!(short_by == short_by)) return k + 1;
        least = short_by;
        worst = r;
      }
    }
    return worst;
  };
  // From n: while some ray falls short, step towards the worst (halfway,
  // as unit vectors), up to 64 times. Where the rays crowd one side of a
  // wide cone (a hull point at the end of a thin band: thousands of rays
  // across the band, a few along it), their sum leans towards the crowd and
  // the rest fall short of it; these are a perceptron's steps, which find a
  // direction for any cone that admits one by the margin.
  auto steps_from = [&]() {
    for (int step = 0;; ++step) {
      const std::size_t worst = worst_ray(n);
      if (worst == k) {  // every ray crosses n's planes at far_margin of a right angle or more
        scale_to_unit<D>(n);
        return true;
      }
      if (worst > k || step == 64) return false;
      double len2 = 0;
      for (int a = 0; a < D; ++a) len2 += n[a] * n[a];
      const double len = std::sqrt(len2);
      for (int a = 0; a < D; ++a) n[a] = n[a] / len + dirs[D * worst + static_cast<std::size_t>(a)];
    }
  };
  // From the rays' sum, then from the caller's hint. A point far above a
  // ring of points (an apex 50 radii over a circle) has rays all round the
  // horizon, tilted up by 1/50: their sum is mostly the noise of their
  // spacing, and steps of a degree or so do not reach the axis. The point
  // less its hull neighbours' mean does. (The sum first: where its steps
  // succeed, the direction they find stays; from the hint, the end of a
  // thin parabolic band closed fewer stars.)
  auto from_sum_or_hint = [&]() {
    for (int a = 0; a < D; ++a) n[a] = 0;
    for (std::size_t r = 0; r < k; ++r)
      for (int a = 0; a < D; ++a) n[a] += dirs[D * r + static_cast<std::size_t>(a)];
    if constexpr (D == 2) {
      // A 2D hull point has two rays, and their sum is their bisector. Where
      // they are nearly opposite the sum cancels: a point 1e12 below the end
      // of a row has rays (-1, 0) and (1, -3e-9), whose x parts sum to 0 in
      // floats, and the perceptron's steps cannot find a direction within
      // 1.5e-9 of the right angle to both (its cell was clipped by all its
      // neighbours, quadratically). For unit rays the bisector is at right
      // angles to their difference, which does not cancel there.
      if (k == 2 && dirs[0] * dirs[2] + dirs[1] * dirs[3] < 0) {
        n[0] = dirs[3] - dirs[1];
        n[1] = dirs[0] - dirs[2];
        if (n[0] * dirs[0] + n[1] * dirs[1] < 0) n[0] = -n[0], n[1] = -n[1];
      }
    }
    if (steps_from()) return true;
    if (hint == nullptr) return false;
    for (int a = 0; a < D; ++a) n[a] = hint[a];
    return steps_from();
  };
  if (from_sum_or_hint()) return true;
  // Then with the rounding floor in far_margin's place.
  if (ray_margins == nullptr) return false;
  relaxed = true;
  return from_sum_or_hint();
}

/// far_plane's second half: the plane of normal n (from far_direction)
/// beyond the box and the vertices, as far_plane describes.
template <int D, class Plane, class Vertex>
bool far_offset(const double* n, const Plane* box, const Vertex* verts, std::size_t nv, Plane& out) {
  double n1 = 0;
  for (int a = 0; a < D; ++a) n1 += std::fabs(n[a]);
  double cmax = 0, extent = 0;  // over the box's corners: sum over axes of the larger end
  for (int a = 0; a < D; ++a) {
    const double lo = -box[2 * a].d, hi = box[2 * a + 1].d;
    cmax += std::max(n[a] * lo, n[a] * hi);
    extent += std::fabs(n[a]) * (hi - lo);
  }
  for (std::size_t t = 0; t < nv; ++t) {
    double dot = 0;
    for (int a = 0; a < D; ++a) dot += n[a] * verts[t].y[a];
    cmax = std::max(cmax, dot + n1 * verts[t].e);
  }
  const double c = cmax + 0.5 * extent;
  if (!(c < std::numeric_limits<double>::max() && extent > 0)) return false;
  for (int a = 0; a < D; ++a) out.n[a] = n[a];
  out.d = c;
  out.n1 = n1;
  out.id = far_plane_id;
  out.scale = 0;
  return true;
}

/// The direction (far_direction: where the rays allow none, false before
/// any vertex is read), then the offset (far_offset).
template <int D, class Plane, class Vertex>
bool far_plane(const double* dirs, std::size_t k, const Plane* box, const Vertex* verts, std::size_t nv, Plane& out,
               const double* ray_margins = nullptr) {
  double n[D];
  return far_direction<D>(dirs, k, n, nullptr, ray_margins) && far_offset<D>(n, box, verts, nv, out);
}

/// Whether v was solved exactly and rounded (exact_vertex: each coordinate
/// within 2 ulp; Hull/Tile::solve_now and settle_ill_conditioned set its
/// bound to 4u |y|_inf + plane_eps |y|_inf). A float solve's bound is at
/// least vertex_eps |y|_inf (64u), so the two never meet. (The box's corners,
/// each coordinate rounded once, pass too, rightly.) Such a vertex's error
/// along one axis is its own coordinate's rounding, which can be far below
/// its bound: a far vertex of an apex 1e14 radii above a circle lies 1e28 out
/// along y with x = -1.1e12, 2.2e12 inside the box's plane x = x1, where the
/// bound is 2.2e13, and the star went to the clips (box_signs).
template <class Vertex>
bool exactly_solved(const Vertex& v) {
  double ymax = 0;
  for (const double c : v.y) ymax = std::max(ymax, std::fabs(c));
  return v.e <= (4 * filter::u + filter::plane_eps) * ymax;  // false on NaN
}

/// The vertices of [0, nv) that box plane k (offset h, as box_signs)
/// cannot place by their float bounds, and whose exact solve would narrow
/// the bound (not one solved exactly already): each passed to solve(t).
/// Returns whether there were any. A first-order bound is wide (1e-9 at a
/// condition of 1e5, more for a deferred vertex) and may straddle a plane
/// the exact vertex does not touch; solved, such a vertex lets box_signs
/// decide. Vertices on the far plane too (exact_vertex_on_plane; until
/// stop 61 they were left, and the cell clipped): one far out along a ray
/// met nearly edge on (an apex 1e5 radii above a circle: 1e10 out, its
/// bound 3e8) may be outside the box, yet not certainly on one side of a
/// side plane.
template <int D, class Vertex, class Solve>
bool solve_near_box_plane(const Vertex* verts, std::size_t nv, int k, double h, Solve&& solve) {
  const int axis = k / 2;
  const double s = (k & 1) ? 1.0 : -1.0;
  const double de = filter::plane_eps * std::fabs(h) + filter::abs_eps;
  bool solved = false;
  for (std::size_t t = 0; t < nv; ++t) {
    const Vertex& v = verts[t];
    const double P = h - s * v.y[axis], e = v.e + de;
    if (P > e || P < -e) continue;
    if (!(v.e == v.e) || exactly_solved(v)) continue;  // NaN, or exact already
    solve(t);
    solved = true;
  }
  return solved;
}

/// After the box cut of a hull point's cell: false if a vertex still lies
/// on the far plane (the last of `planes`; the box removes every vertex on
/// it, as it lies outside the box and each decision was certain, so this is
/// a check), else the plane is dropped and true.
template <int D, class Plane, class Vertices>
bool drop_far_plane(std::vector<Plane>& planes, const Vertices& verts) {
  const auto far = static_cast<std::remove_cvref_t<decltype(verts.front().p[0])>>(planes.size() - 1);
  for (const auto& v : verts)
    for (int k = 0; k < D; ++k)
      if (v.p[k] == far) return false;
  planes.pop_back();
  return true;
}

/// Whether an assembled vertex too ill-conditioned for the float solve is
/// worth its exact solve: its float estimate y lies in the domain box grown
/// by a quarter of its size per axis (`box`: the kernel's first 2D planes).
/// Farther out the box most likely cuts it away, and an exact solve there is
/// wasted (a terrain's flat simplices, whose circumcentres lie far above and
/// below it: its run took 13% longer when every one was solved); such a
/// vertex gets a NaN bound and its cell is clipped, which never makes it.
/// Points on a circle need the ones inside (their cells' shared corner at
/// the centre: clipping those cells cost them 7%). Either way the cell is
/// exact. y is widened by `err`, its first-order bound (0 where that is not
/// finite): a vertex whose planes are so nearly dependent that the float
/// solve says nothing of where it lies (cond u near 1 or more) may well lie
/// inside (stop 62). An apex 1e10 radii above 2,000 points on a circle, all
/// on one sphere: its star's vertices lie on the axis, inside the box, but
/// their float estimates lay anywhere, most far out; refused, they were
/// more than its exact solves paid for, and the star was clipped (3.9 s,
/// 2M exact evaluations).
template <int D, class Plane>
bool worth_exact_solve(const double* y, double err, const Plane* box) {
  bool in = true;
  for (int a = 0; a < D; ++a) {
    const double lo = box[2 * a].d, hi = box[2 * a + 1].d, grow = 0.25 * (lo + hi);
    in &= y[a] + err >= -lo - grow && y[a] - err <= hi + grow;  // false on NaN
  }
  return in;
}

/// How many of an assembled cell's vertices that worth_exact_solve turned
/// down (far out, where the box most likely cuts them) are solved exactly
/// after all rather than the cell clipped by its m neighbours (nt
/// vertices): as many as that clipping would cost. Clipping costs about m
/// sign passes over the cell's vertices, ~1 ns per vertex, plus ~100 ns per
/// clip (points on a helix: ~0.8 ms for a cell of 760 neighbours and 1,500
/// vertices); an exact solve, in rationals where no grid holds the input,
/// ~15 µs (a terrain's 10,000 cells with one such vertex each, ~20
/// neighbours, took 7 µs more each solved than clipped). So a small star
/// is clipped, as before stop 56, and a star of hundreds of neighbours
/// (points on a helix, whose Delaunay triangulation is quadratic: 2,000 of
/// them have ~380 neighbours each, and three vertices in a thousand spoiled
/// four cells in five) solves its few far vertices rather than clip
/// quadratically. Four more are paid for at any size (stop 61): that
/// clipping cost holds for well-conditioned stars, but a star with a
/// vertex too ill-conditioned for floats is near a degenerate one, and its
/// clips' tests near that vertex go to the exact stages. The cylinder
/// band's stars (~50 neighbours, ~100 vertices, paid none) made ~500 exact
/// evaluations each when clipped: 100k band points 7.6-7.9 -> 6.3-6.6 s on
/// one thread with all but 15 stars assembled, a 1-degree latitude-longitude
/// grid on the sphere 0.67-0.82 -> 0.59 s; a terrain, a torus, an ellipsoid,
/// a helix and the clustered benchmark level.
inline std::size_t exact_solves_paid(std::size_t m, std::size_t nt) { return m * (nt + 100) / 16000 + 4; }

/// What becomes of a vertex too ill-conditioned for its float bound
/// (Hull/Tile::ill_conditioned; its D local planes `p`, its float estimate
/// y, its condition `cond`, its first-order bound `err`, which may be
/// infinite or NaN):
///   refuse: a NaN bound. On a hull point's far plane beyond the deferred
///     bound (the box test then gives the cell up); or, in the assembly
///     (float_only), one far out beyond it: the assembly solves as many of
///     those as it can pay for (exact_solves_paid), else the cell is
///     clipped;
///   keep: on a hull point's far plane, which is no bisector and has no
///     exact form, below filter::deferred_vertex_condition: it keeps its
///     float position and first-order bound for good. The far plane lies
///     half the box's extent beyond it, so the box cuts every such vertex
///     with certainty (drop_far_plane checks), and none is ever output.
///     Until stop 59 these were refused: the ends of hull facets thin as
///     seen from the point (two neighbours nearly in line with it: the end
///     of a thin band, the apex of a cone over a circle) sent stars of
///     tens of thousands of neighbours to the clips, quadratic (80,000
///     circle points and the two apexes: 61 s);
///   defer: it keeps its float position and bound (filter::
///     deferred_vertex_condition) until the cell is built. A clip's, and in
///     the assembly one far out (not worth_exact_solve): the box cuts it
///     with certainty, never solved (a thin cylindrical band's stars all have
///     such vertices, and were clipped for them);
///   solve: exactly, now. exact_now, a clip's beyond the deferred bound,
///     and in the assembly one near the box, which most likely survives its
///     cut: deferred, its wide bound near a box plane would give the cell up
///     (the end of a 2D parabola, whose star holds most points and has
///     thousands of such vertices, was then clipped by all of them: 400k
///     points 0.85 → 16 s).
enum class IllConditioned { solve, defer, refuse, keep };
template <int D, class Plane, class Index>
IllConditioned ill_conditioned_fate(filter::SolveMode mode, double cond, double err, const double* y,
                                    const Plane* planes, const Index* p) {
  const bool bounded = std::isfinite(err);
  for (int k = 0; k < D; ++k)
    if (planes[p[k]].id == far_plane_id)
      return cond < far_vertex_condition && bounded ? IllConditioned::keep : IllConditioned::solve;
  const bool deferrable = cond < filter::deferred_vertex_condition && bounded;
  if (mode == filter::SolveMode::exact_now) return IllConditioned::solve;
  if (mode == filter::SolveMode::deferrable) return deferrable ? IllConditioned::defer : IllConditioned::solve;
  if (worth_exact_solve<D>(y, bounded ? err : 0.0, planes)) return IllConditioned::solve;
  return deferrable ? IllConditioned::defer : IllConditioned::refuse;
}

/// A kernel's ill-conditioned vertex v (Hull/Tile::ill_conditioned) given
/// its fate: its first-order bound `err` and |y|_inf `ymax` as they stand,
/// `defer()` recording the deferral the kernel's own way (a flag in the
/// hull's vertex, a key set in the tile), `solve()` solving v exactly and
/// returning its new |y|_inf. Returns v's err and ymax: NaN for err where
/// refused.
template <int D, class Plane, class Vertex, class Defer, class Solve>
std::pair<double, double> settle_ill_conditioned(filter::SolveMode mode, double cond, double err, double ymax,
                                                 const Vertex& v, const Plane* planes, Defer&& defer, Solve&& solve) {
  switch (ill_conditioned_fate<D>(mode, cond, err, v.y, planes, v.p)) {
    case IllConditioned::refuse:
      return {std::numeric_limits<double>::quiet_NaN(), ymax};
    case IllConditioned::defer:
      defer();
      return {err, ymax};
    case IllConditioned::keep:  // on the far plane: the box cuts it
      return {err, ymax};
    case IllConditioned::solve:
      break;
  }
  const double exact_ymax = solve();
  return {4 * filter::u * exact_ymax, exact_ymax};
}

/// No vertex can be placed against a box plane in floating point (box_signs).
inline constexpr std::size_t undecided = std::numeric_limits<std::size_t>::max();

/// The signs of vertices [0, nv) against the domain box's plane k (axis k / 2,
/// the upper side when k is odd: n.y <= h, n = +-e_axis, h the plane's
/// offset from the generator) by the clip's float test, +1 keep and -1
/// remove, into `sign` (grown to nv + 1 if shorter; untouched when every
/// vertex is kept, and then 0 returned); returns how many are removed, or
/// `undecided`. A vertex within its error bound of the plane is passed to
/// `decide(t)` (+1, -1, or 0: undecided; exact_box_side), and one whose
/// bound is NaN (Hull/Tile::solve refused it the exact solve:
/// ill_conditioned_fate) is undecided: the exact clips must build that cell.
template <class Vertex, class Decide>
std::size_t box_signs(const Vertex* verts, std::size_t nv, int k, double h, std::vector<filter::Sign>& sign,
                      Decide&& decide) {
  const int axis = k / 2;
  const double s = (k & 1) ? 1.0 : -1.0;
  const double de = filter::plane_eps * std::fabs(h) + filter::abs_eps;
  // Nearly every plane keeps every vertex: prove that first, with no stores
  // (as the sign pass's first pass does), and write signs only otherwise.
  std::size_t first = 0;
  while (first < nv && h - s * verts[first].y[axis] > verts[first].e + de) ++first;
  if (first == nv) return 0;
  if (sign.size() < nv + 1) sign.resize(nv + 1);
  std::fill(sign.begin(), sign.begin() + static_cast<std::ptrdiff_t>(first), filter::Sign{1});
  std::size_t removed = 0;
  for (std::size_t t = first; t < nv; ++t) {
    const double P = h - s * verts[t].y[axis], e = verts[t].e + de;
    int side = P > e ? 1 : P < -e ? -1 : 0;
    if (side == 0) {
      if (!(P == P && e == e)) return undecided;  // NaN: refused its exact solve
      if (exactly_solved(verts[t])) {
        // Each coordinate is rounded on its own (within 2 ulp): its own
        // error bounds this plane's test, not the largest coordinate's.
        const double ea = 8 * filter::u * std::fabs(verts[t].y[axis]) + de;
        side = P > ea ? 1 : P < -ea ? -1 : 0;
      }
      if (side == 0) side = decide(t);
      if (side == 0) return undecided;
    }
    sign[t] = side > 0 ? filter::Sign{1} : filter::Sign{-1};
    removed += side < 0;
  }
  return removed;
}

/// box_signs by the float test alone: undecided at any vertex within its
/// bound of the plane.
template <class Vertex>
std::size_t box_signs(const Vertex* verts, std::size_t nv, int k, double h, std::vector<filter::Sign>& sign) {
  return box_signs(verts, nv, k, h, sign, [](std::size_t) { return 0; });
}

/// The vertex on the planes p[0, D) of generator gen's cell, solved exactly
/// into y (exact_vertex; exact_vertex_on_plane for one on the far plane).
template <int D, class Plane, class Index>
void exact_solve(const ExactContext& exact, std::int32_t gen, const Plane* planes, const Index* p, double* y) {
  std::int32_t ids[D];
  int far = -1;
  for (int c = 0; c < D; ++c) {
    ids[c] = planes[p[c]].id;
    if (ids[c] == far_plane_id) far = c;
  }
  if (far < 0) {
    exact_vertex(exact, gen, ids, y);
  } else {
    const Plane& f = planes[p[far]];
    exact_vertex_on_plane(exact, gen, ids, far, f.n, f.d, y);
  }
}

/// Box plane k's side of a vertex on the planes p[0, D) (exact_box_sign):
/// +1 keep, -1 remove, 0 undecided (a vertex on the far plane, whose row
/// exact_box_sign does not take, or no exact context). For the vertices the float test
/// and solve_near_box_plane leave within rounding of a box plane: exact
/// ties between a bisector and the box (an apex over points on a circle,
/// one of them on a box plane's diagonal: the apex's bisector with it holds
/// a box edge), which sent the cell to the clips, quadratic in a star of
/// thousands.
template <int D, class Plane, class Index>
int exact_box_side(const ExactContext* exact, std::int32_t gen, const Plane* planes, const Index* p, int k) {
  if (exact == nullptr) return 0;
  std::int32_t ids[D];
  for (int c = 0; c < D; ++c) {
    ids[c] = planes[p[c]].id;
    if (ids[c] == far_plane_id) return 0;
  }
  return exact_box_sign(*exact, gen, ids, planes[k].id);
}

/// Box plane k's signs for an assembled cell's box cut (box_signs), as
/// both kernels' clip_to_box take them: by the float bounds; where a vertex
/// lies within its bound of the plane, again after `solve_near()` has
/// solved such vertices exactly (the kernel's step around
/// solve_near_box_plane), with the exact, perturbed side (exact_box_side)
/// for any still within rounding. Returns box_signs' count or undecided.
template <int D, class Vertex, class Plane, class SolveNear>
std::size_t box_cut_signs(const Vertex* verts, std::size_t nv, int k, const Plane* planes,
                          std::vector<filter::Sign>& sign, const ExactContext* exact, std::int32_t gen,
                          SolveNear&& solve_near) {
  const std::size_t removed = box_signs(verts, nv, k, planes[k].d, sign);
  if (removed != undecided) return removed;
  solve_near();
  return box_signs(verts, nv, k, planes[k].d, sign,
                   [&](std::size_t t) { return exact_box_side<D>(exact, gen, planes, verts[t].p, k); });
}

}  // namespace tessera::kernels::assembly
