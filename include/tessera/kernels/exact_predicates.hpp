// The one combinatorial question every clip asks, decided exactly.
//
// Cell of generator i, a vertex v of it (the meeting point of `dim` planes:
// bisectors of i with other generators, or domain-box planes), a candidate j.
// The clip removes v iff v is closer to p_j than to p_i:
//
//     P = pow_j(v) - pow_i(v),   pow_k(x) = |x - p_k|^2 - w_k
//
// where w_k are infinitesimal symbolic weights (w_k >> w_l when k < l) that
// break every exact tie (Edelsbrunner & Mücke, "Simulation of Simplicity",
// 1990; in the spirit of Devillers & Teillaud 2011 for weighted Delaunay).
// Because P does not depend on which of v's generators asks (at v all their
// power distances are equal), every cell sharing v gets the same answer: the
// merged mesh is conformal and every vertex has exactly dim+1 generators.
//
// Formulation: v solves A v = b (dim rows: a bisector row 2(p_k-p_i).x =
// |p_k|^2-|p_i|^2 - w_k + w_i, or a box row x_axis = c). With the query row
// (a_j, b_j) appended, det[[A,b],[a_j,b_j]] = det(A) * P (Schur complement), so
// sign(P) = sign(det M) * sign(det A). det M is linear in the weights; its
// coefficients are the last-column cofactors, so the perturbed sign costs
// nothing beyond the determinant. All of it is evaluated on the input doubles
// scaled to integers (every double is an integer times a power of two): in
// 64/128-bit integers on a grid of at most 22 bits, in fixed-width integers
// (WidePredicate) on one of at most 60, else in GMP. A tie whose points all
// sit at corners of one axis-aligned box is decided first, from the
// coordinates' pattern alone (BoxTiePredicate, box_ties.hpp).
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "tessera/kernels/wide_int.hpp"

namespace tessera::kernels {

/// Domain-box plane ids as they appear in topological coordinates.
/// Axis a (0..2): lower plane -1-2a, upper plane -2-2a (x0=-1, x1=-2, y0=-3, ...).
constexpr std::int32_t box_plane_id(int axis, bool upper) { return -1 - 2 * axis - (upper ? 1 : 0); }
constexpr int box_plane_axis(std::int32_t id) { return (-1 - id) / 2; }
constexpr bool box_plane_upper(std::int32_t id) { return ((-1 - id) & 1) != 0; }

/// Walls: half-spaces n.x <= d (absolute coordinates) that cut the domain
/// box down to a convex polytope (VoronoiOptions::walls). Wall k's plane id
/// is -7 - k in both dimensions, below every box plane's; the far plane of
/// an assembled cell (assembly::far_plane_id, INT32_MIN) is none.
struct Wall {
  double n[3];  ///< normal, |n|_inf in [1, 2) (front/walls.cpp scales it so, exactly)
  double d;     ///< offset
  double norm;  ///< an upper bound on |n|_2 (walls::misses)
};
/// At most this many walls (their ids stay far above INT32_MIN).
constexpr int max_walls = 1 << 26;
constexpr std::int32_t wall_plane_id(int k) { return -7 - k; }
constexpr bool is_wall_plane(std::int32_t id) { return id <= -7 && id > -7 - max_walls; }
constexpr int wall_index(std::int32_t id) { return -7 - id; }

/// Exponent of the lowest set bit of x != 0: x is an odd integer times 2^that.
int lowest_bit_exponent(double x);

/// A finite double by its bits: x = mant * 2^e2 exactly, |mant| < 2^53
/// (subnormals included). No libm calls: the integer-grid paths run this on
/// every coordinate they see.
struct DoubleParts {
  std::int64_t mant;
  int e2;
};
inline DoubleParts double_parts(double x) {
  const auto bits = std::bit_cast<std::uint64_t>(x);
  const int biased = static_cast<int>((bits >> 52) & 0x7ff);
  std::uint64_t m = bits & ((std::uint64_t{1} << 52) - 1);
  int e2 = -1074;
  if (biased != 0) {
    m |= std::uint64_t{1} << 52;
    e2 = biased - 1075;
  }
  const auto sm = static_cast<std::int64_t>(m);
  return {(bits >> 63) ? -sm : sm, e2};
}

/// x / 2^shift into `out` when that is an integer below 2^bits in magnitude
/// (x lies on the grid of step 2^shift, within its bound); false otherwise.
/// Read from the bits, not computed in floating point: x * 2^-shift can
/// round (a subnormal x halved rounds to a neighbour, or to zero), and a
/// rounded value would pass for a grid point.
inline bool grid_integer(double x, int shift, int bits, std::int64_t& out) {
  const DoubleParts pt = double_parts(x);
  if (pt.mant == 0) {
    out = 0;
    return true;
  }
  const auto m = static_cast<std::uint64_t>(pt.mant < 0 ? -pt.mant : pt.mant);
  const int low = pt.e2 + std::countr_zero(m), high = pt.e2 + 64 - std::countl_zero(m);
  if (low < shift || high - shift > bits) return false;  // off the grid, or |x| / 2^shift >= 2^bits
  const int k = pt.e2 - shift;
  out = k >= 0 ? pt.mant * (std::int64_t{1} << k) : pt.mant >> -k;  // exact: the bits shifted out are zero
  return true;
}

/// The common grid of a set of doubles (lattices, voxel centres, integer and
/// dyadic grids): see() each value; then every one is an integer times
/// 2^shift, below 2^top in magnitude, so fits(bits) says whether those
/// integers all have at most `bits` bits, and scaled(x) gives x / 2^shift.
/// The integer exact paths use it.
struct GridScale {
  int shift = INT32_MAX, top = INT32_MIN;
  /// See x; returns its parts, which the integer paths go on to use.
  DoubleParts see(double x) {
    const DoubleParts pt = double_parts(x);
    if (pt.mant != 0) {
      const auto m = static_cast<std::uint64_t>(pt.mant < 0 ? -pt.mant : pt.mant);
      shift = std::min(shift, pt.e2 + std::countr_zero(m));
      top = std::max(top, pt.e2 + 64 - std::countl_zero(m));
    }
    return pt;
  }
  bool all_zero() const { return top == INT32_MIN; }
  bool fits(int bits) const { return all_zero() || top - shift <= bits; }
  /// The grid's exponent (0 when every value seen was zero).
  int scale() const { return all_zero() ? 0 : shift; }
  /// x / 2^scale() when it is an integer below 2^bits in magnitude (x on the
  /// grid): grid_integer.
  bool scaled(double x, int bits, std::int64_t& out) const;
};

inline bool GridScale::scaled(double x, int bits, std::int64_t& out) const {
  return grid_integer(x, scale(), bits, out);
}

namespace walls {
class Index;  // (wall_index.hpp)
}

/// Everything the exact predicate needs to know about the input.
struct ExactContext {
  const double* points = nullptr;   ///< n * dim input coordinates
  int dim = 3;
  std::array<double, 3> lo{}, hi{}; ///< domain box
  /// Optional (see make_grid): the same coordinates and box as integers on
  /// one grid of step 2^grid_shift, each below 2^22 in magnitude. Null when
  /// the input has no such grid; the exact paths then read `points`.
  const std::int32_t* grid = nullptr;
  int grid_shift = 0;
  std::array<std::int32_t, 3> grid_lo{}, grid_hi{};
  /// The coordinates span so wide a range that float products in the
  /// kernels may round into the subnormal range (front/pass.cpp,
  /// choose_scaling): their vertex bounds then add filter::underflow_slack.
  bool may_underflow = false;
  /// A power (radical) diagram: the radius of each point's sphere (n
  /// entries, >= 0, in the computation's frame), or null for the ordinary
  /// diagram. Point k's power at x is |x - p_k|^2 - radii[k]^2, so every
  /// bisector row's right-hand side gains r_i^2 - r_k^2 (exact: the radii
  /// join the coordinates' grid, and their squares are the coordinates'
  /// degree). With radii every exact question goes to the GMP rows
  /// (build_rows): the prepared integer stages, the box-tie stage and the
  /// integer vertex solves assume |q|^2 alone. `max_radius` is the largest.
  const double* radii = nullptr;
  double max_radius = 0;
  /// The walls (num_walls of them), in the computation's frame, or null.
  /// Cells are clipped by them after their neighbours (Hull/Tile::
  /// clip_wall), so the only exact questions about them are a vertex's side
  /// of a wall (exact_wall_sign), a vertex on walls solved exactly, and the
  /// exact measure of a cell with wall faces: all through the GMP rows.
  const Wall* walls = nullptr;
  int num_walls = 0;
  /// Where the walls are many, which of them matter near a point (or null:
  /// all of them everywhere).
  const walls::Index* wall_index = nullptr;
};

/// The offset d of the power bisector of points i and j relative to p_i:
/// the plane q.y = d, q = p_j - p_i, d = (|q|^2 + r_i^2 - r_j^2) / 2 with
/// the exact q and radii (ctx.radii), rounded toward zero (within one ulp)
/// and then to the double range. For the clips whose float d cancels
/// (the plane passes near p_i: kernels/power.hpp).
double exact_power_offset(const ExactContext& ctx, std::int32_t i, std::int32_t j);

/// Put n points (n * dim doubles) and the box [lo, hi] on their common grid
/// when it has at most 22 bits (lattices, voxel centres, integer and dyadic
/// grids), so prepared exact predicates read integers instead of decomposing
/// doubles on every call. Fills `grid` (n * dim) and returns true with
/// `ctx.grid` pointing at it; false (ctx unchanged) otherwise.
bool make_grid(ExactContext& ctx, std::size_t n, std::vector<std::int32_t>& grid);

/// Exact sign of P (see above) for the vertex of cell `i` defined by
/// `planes[0..dim)` (generator ids >= 0, box-plane ids < 0), against candidate
/// `j`. Returns +1 when the vertex stays (strictly closer to p_i in the
/// perturbed sense), -1 when the clip removes it. Never returns 0.
/// Precondition: the planes define a vertex (their normals are independent),
/// and j is not i nor one of the planes.
int exact_clip_sign(const ExactContext& ctx, std::int32_t i, const std::int32_t* planes, std::int32_t j);

/// exact_clip_sign without its first stage (the tie at a box's corners,
/// box_ties.hpp): the same sign by arithmetic on the coordinates. For
/// callers that asked that stage already (its answer would be a refusal
/// again), and for the tests of the arithmetic stages.
int exact_clip_sign_by_arithmetic(const ExactContext& ctx, std::int32_t i, const std::int32_t* planes, std::int32_t j);

/// The side of domain-box plane `box` (a box-plane id) on which the vertex
/// of cell i where planes[0..dim) meet lies, in the perturbed sense of
/// exact_clip_sign: +1 inside the box's half-space, -1 outside, 0 where the
/// weights leave it on the plane (or the planes define no vertex, or
/// include `box`). The assembly's box cut asks it of a vertex within
/// rounding of the plane (Hull/Tile::clip_to_box): the same perturbed
/// diagram the clips build, so an assembled cell is the clipped one.
/// With the box row (e_axis, c) as M's last row, det M = det A (c - v_axis)
/// (Schur complement), and the box row carries no weight.
int exact_box_sign(const ExactContext& ctx, std::int32_t i, const std::int32_t* planes, std::int32_t box);
/// The offset of wall w relative to point p (dim coordinates), d - n.p,
/// computed exactly and rounded to a double (within two ulps): a clipping
/// plane's offset must be as accurate as a rounded difference's (the
/// filters' plane_eps), which the float d - n.p is not where it cancels (a
/// point near a wall far from the origin: the vertices of a slab between
/// two walls 1e-9 apart were placed 1e-16 off, and measured 1e-8 off).
double exact_wall_offset(const Wall& w, const double* p, int dim);
/// The exact sign of d - n.p: +1 p lies strictly inside wall w, 0 on it, -1
/// outside (the front end's test of the points, where floats cannot tell).
int exact_wall_point_side(const Wall& w, const double* p, int dim);
/// The side of wall `wall` (an index into ctx.walls) on which the vertex of
/// cell i where planes[0..dim) meet (generators, box planes or walls) lies:
/// +1 inside or exactly on the wall's plane, -1 outside. A tie counts as
/// inside: it is the symbolic perturbation that moves every wall outwards
/// by an infinitesimal far larger than the points' weights, later walls
/// by more than earlier ones (each wall's decisions are taken with the
/// walls before it already cut), so every cell that holds a vertex takes
/// the same decision, and the cut polytopes stay conformal. With the wall
/// row (n, d) as M's last row, det M = det A (d - n.v) (Schur complement).
int exact_wall_sign(const ExactContext& ctx, std::int32_t i, const std::int32_t* planes, int wall);

/// The exact sign of n . ((p_a - p_i) x (p_b - p_i)) in 3D (n any finite
/// doubles): whether a plane of normal n crosses, going outwards, the ray of
/// cell i's unbounded edge dual to its hull facet (i, a, b), whose direction
/// is that cross product (the facet's outward normal, for a and b in the
/// order Hull::link_boundary takes them from its link's boundary edge). The
/// assembly asks it where the float rays are too uncertain to place a far
/// plane.
int exact_ray_side(const ExactContext& ctx, std::int32_t i, std::int32_t a, std::int32_t b, const double* n);

/// The symbolic perturbation's tie-break (exact_clip_sign): when det M0 is
/// exactly zero, the weights w_k (decreasing with id) decide, through the
/// first term in ascending id whose coefficient is non-zero. The terms are
/// the generator i (row -1) and the vertex's bisector rows; the query j's
/// coefficient, -sign(det A), is never zero and is passed apart.
class PerturbationTerms {
 public:
  /// The terms of generator i and the rows' generators gen[0, dim) (box ids < 0 carry no weight).
  void set(std::int32_t i, const std::int32_t* gen, int dim) {
    // Each term packed as (id << 8 | row + 1), ascending with the id; absent
    // ones (box planes, the missing row in 2D) as the largest key, so a
    // sorting network of four orders them without a branch: on lattices
    // every vertex sets its terms, and a branching sort mispredicted.
    constexpr std::int64_t absent = INT64_MAX;
    std::int64_t k[4] = {pack(i, -1), absent, absent, absent};
    for (int r = 0; r < dim; ++r) k[r + 1] = gen[r] >= 0 ? pack(gen[r], r) : absent;
    auto order = [&](int x, int y) {
      const std::int64_t lo = std::min(k[x], k[y]), hi = std::max(k[x], k[y]);
      k[x] = lo;
      k[y] = hi;
    };
    order(0, 1), order(2, 3), order(0, 2), order(1, 3), order(1, 2);
    for (int t = 0; t < 4; ++t) keys_[t] = k[t];
  }
  /// sign(det M) on a tie: coef(row) gives each term's coefficient sign
  /// (row -1: w_i's), j_coef the query's.
  template <class Coef>
  int decide(std::int32_t j, int j_coef, Coef&& coef) const {
    // Terms below j in id: keys below j's smallest packed key (absent ones
    // are above every id).
    const std::int64_t below = pack(j, -1);
    for (int t = 0; t < 4 && keys_[t] < below; ++t)
      if (const int c = coef(static_cast<int>(keys_[t] & 0xff) - 1); c != 0) return c;
    return j_coef;
  }

 private:
  static std::int64_t pack(std::int32_t id, int row) { return (std::int64_t{id} << 8) | (row + 1); }
  std::int64_t keys_[4] = {INT64_MAX, INT64_MAX, INT64_MAX, INT64_MAX};  // ascending
};

/// exact_clip_sign for one vertex asked against many candidates. What
/// depends only on the vertex (its rows, det A and A's cofactors) is computed
/// once, in 64/128-bit integers, when its points lie on a common grid of at
/// most 22 bits: lattices, voxel centres and integer grids, where nearly
/// every vertex ties with several candidates and the exact predicate
/// dominated the run. Each candidate then costs a few dot products. A
/// candidate off the vertex's grid goes through exact_clip_sign.
class VertexPredicate {
 public:
  /// Prepare for the vertex of cell i where planes[0..dim) meet; false (and
  /// unusable) when the vertex's points are off the integer path.
  bool prepare(const ExactContext& ctx, std::int32_t i, const std::int32_t* planes);
  /// Equal to exact_clip_sign(ctx, i, planes, j).
  int sign(const ExactContext& ctx, std::int32_t j) const;

 private:
  void set_cofactors(const std::int64_t (*a)[3]);  // cof_ and det_a_ from A's rows
  template <int D>
  bool prepare_narrow(const ExactContext& ctx);  // the narrow form, or false
  template <int D>
  int sign_narrow(const ExactContext& ctx, std::int32_t j) const;
  // The narrow form: on a global grid (ExactContext::grid) with every
  // bisector row's q_r = p_r - p_i below 2^10 grid steps per coordinate, the
  // rows are taken relative to p_i and every quantity fits in 64 bits (bounds
  // at kNarrowLimit in exact_predicates.cpp). Lattices and voxel centres,
  // where nearly every vertex ties, take it.
  bool narrow_ = false;
  std::int64_t nb_[3] = {0, 0, 0}, ndet_a_ = 0;  // b relative to p_i, det A (cofactors in cof_)
  int dim_ = 3, shift_ = 0;
  std::int32_t i_ = -1, gen_[3] = {0, 0, 0};
  std::int64_t ci_[3] = {0, 0, 0};   // p_i on the grid
  std::int64_t cof_[3][3] = {};      // row r: A's cofactors along row r
  __int128 ci2_ = 0, det_a_ = 0, b_[3] = {0, 0, 0};
  int det_a_sign_ = 0;
  PerturbationTerms terms_;
};

/// The stage between the float filter and exact_clip_sign for a 3D vertex of
/// three bisectors, asked against many candidates: the same sign, computed
/// in x87 extended precision (64-bit mantissa) with a certified error bound,
/// or 0 when the bound cannot separate it from zero.
///
/// With q_k = p_k - p_i and s_k = |q_k|^2, the predicate's determinant reads
/// (the b column shifted by p_i times the a columns, which leaves it unchanged;
/// factors of 2 dropped) D4 = W . q_j + D3 s_j, where
///     D3 = det[q_0; q_1; q_2],  W = -s_0 (q_1 x q_2) + s_1 (q_0 x q_2) - s_2 (q_0 x q_1)
/// depend only on the vertex, and sign(P) = sign(D4) sign(D3). Expanded, D4 is
/// a sum of degree-5 monomials in the coordinates of the q's; each passes
/// through at most 24 roundings of unit 2^-64 (the q's, then the products and
/// sums), so |computed - exact| <= gamma_24 * (the same expression on absolute
/// values) (Higham, "Accuracy and Stability of Numerical Algorithms", §3.1).
/// A sign is returned only when |D4| exceeds twice that bound, and likewise
/// for D3. Where the float filter fails only because the input is nearly
/// degenerate at the level of double rounding (points normalized onto one
/// sphere: their differences from exact cospherity are ~1e-16 relative), this
/// extra 11 bits decide nearly every call for a few dozen cycles instead of
/// the ~1.5 µs of the GMP path.
class ExtendedPredicate {
 public:
  /// Prepare for the vertex of cell i where the bisectors with planes[0..dim)
  /// meet; false (unusable) with a box plane, or when D3's sign is not
  /// certain. 2D likewise: D2 = q_0 x q_1, W = (s_1 q_0y - s_0 q_1y,
  /// s_0 q_1x - s_1 q_0x), D = W . q_j + D2 s_j.
  bool prepare(const ExactContext& ctx, std::int32_t i, const std::int32_t* planes);
  /// exact_clip_sign(ctx, i, planes, j) when certain, else 0.
  int sign(const ExactContext& ctx, std::int32_t j) const;

 private:
  bool prepare2(const ExactContext& ctx, std::int32_t i, const std::int32_t* planes);
  using L = long double;
  int dim_ = 3;
  L pi_[3] = {0, 0, 0};
  L w_[3] = {0, 0, 0}, w_abs_[3] = {0, 0, 0};  // W, and W on absolute values
  L d3_ = 0, d3_abs_ = 0;                     // D3 (2D: D2), and on absolute values
  bool d3_positive_ = false;
};

/// The stage after ExtendedPredicate, for what it cannot decide: exact ties
/// and near-ties off any small grid (a lattice of spacing 0.1, whose cube
/// corners are exactly cospherical while every coordinate has a full
/// mantissa). exact_clip_sign's sign, computed in fixed-width integers
/// (WideInt) when the vertex's points, the candidate's and the box
/// coordinates involved lie on a common grid of at most `bits` bits: any
/// input whose nearby coordinates share a binade or a few. Prepared once per
/// vertex, as VertexPredicate; each candidate then costs a few dozen
/// multiplications instead of GMP's ~1 µs.
///
/// The rows are taken relative to p_i (translating the vertex leaves det M
/// and its last-column cofactors unchanged): a bisector row is (2 q_k,
/// |q_k|^2) with q_k = p_k - p_i, a box row (e_axis, c - p_i). On the grid
/// |q| < 2^61, so |a| < 2^62, |b| < 2^124, A's cofactors < 2^125 (int128),
/// det A and a_j . C_r < 3 * 2^187 (3 limbs), and det M0, four products of a
/// b and one of those, < 2^315 (5 limbs).
class WidePredicate {
 public:
  /// The bound on the grid integers' magnitude, in bits.
  static constexpr int bits = 60;
  /// Prepare for the vertex of cell i where planes[0..dim) meet; `also`, when
  /// >= 0, is a candidate whose coordinates must fit the grid as well. False
  /// (unusable) when the points do not fit, or the planes are dependent.
  bool prepare(const ExactContext& ctx, std::int32_t i, const std::int32_t* planes, std::int32_t also = -1);
  /// Equal to exact_clip_sign(ctx, i, planes, j); a candidate off the
  /// vertex's grid goes through exact_clip_sign.
  int sign(const ExactContext& ctx, std::int32_t j) const;
  /// The same sign into `out`, or false when p_j is off the vertex's grid.
  bool sign_on_grid(const ExactContext& ctx, std::int32_t j, int& out) const;

 private:
  int dim_ = 3, shift_ = 0;
  std::int32_t i_ = -1, gen_[3] = {0, 0, 0};
  std::int64_t ci_[3] = {0, 0, 0};  // p_i on the grid
  __int128 cof_[3][3] = {};         // row r: A's cofactors along row r
  __int128 b_[3] = {0, 0, 0};
  WideInt<3> det_a_{};
  int det_a_sign_ = 0;
  PerturbationTerms terms_;
};

/// The vertex of cell `i` where `planes[0..dim)` meet, relative to p_i,
/// computed exactly and rounded once per coordinate (within 2 ulp). Used when
/// the float solve is too ill-conditioned to give a trustworthy position (a
/// near-duplicate pair's two bisectors seen from a third cell, say).
void exact_vertex(const ExactContext& ctx, std::int32_t i, const std::int32_t* planes, double* y);

/// exact_vertex where row `row` of the planes is no bisector or box plane
/// but the plane n.y = d (y relative to p_i; n and d any finite doubles,
/// each an exact rational): the far plane that closes a hull point's
/// assembled cell (assembly::far_plane), whose vertices can be too
/// ill-conditioned for a float bound (assembly::far_vertex_condition).
void exact_vertex_on_plane(const ExactContext& ctx, std::int32_t i, const std::int32_t* planes, int row,
                           const double* n, double d, double* y);

/// One term of a cell's measure: det(foot of `plane`, y_a, y_b) in 3D (the
/// cone over a triangle of a face, measure() in front/cell_geometry.hpp), or
/// det(y_a, y_b) in 2D (the shoelace; `plane` unused).
struct MeasureTerm {
  std::int32_t plane;
  std::uint32_t a, b;
};

/// The exact volume (area in 2D) of cell `i`, rounded once (to nearest,
/// ties to even; an infinity from 2^1024 on), and its centroid relative to
/// p_i (dim doubles into `centroid`), likewise. The vertices are given by their planes (dim ids
/// each, `vertex_planes`) and solved exactly; the terms are summed exactly
/// (divided by 6, or 2 in 2D). For cells whose float measure cancels to no
/// correct digits (slivers thinner than the rounding of their vertices:
/// near-duplicate points). Computed in fixed point with certified error
/// bounds (~0.1 ms for a cell of 20 vertices), in rationals where those
/// leave a double undetermined.
double exact_cell_measure(const ExactContext& ctx, std::int32_t i, std::span<const std::int32_t> vertex_planes,
                          std::span<const MeasureTerm> terms, double* centroid);

/// The same doubles as exact_cell_measure, always by GMP rationals: its
/// fallback, and the reference its fixed-point tier is tested against.
/// Slow (~2 ms for a cell of 20 vertices: gcds on growing denominators).
double rational_cell_measure(const ExactContext& ctx, std::int32_t i, std::span<const std::int32_t> vertex_planes,
                             std::span<const MeasureTerm> terms, double* centroid);

/// exact_cell_measure's first tier: the vertices truncated to fixed point
/// `bits` bits below the largest coordinate, the sums in integers, and the
/// doubles certified by error bounds. True with `volume` and `centroid` set
/// (then the doubles rational_cell_measure gives); false where the bounds
/// leave them undetermined (cancellation deeper than the bits kept, an
/// exactly zero centroid coordinate, a result within the bounds' width of a
/// midpoint between two doubles),
/// with `*wanted` (if given) the bits likely to certify them (twice `bits`
/// where a sum or moment came out zero, which gives no measure).
bool fixed_point_cell_measure(const ExactContext& ctx, std::int32_t i, std::span<const std::int32_t> vertex_planes,
                              std::span<const MeasureTerm> terms, long bits, double& volume, double* centroid,
                              long* wanted = nullptr);

}  // namespace tessera::kernels
