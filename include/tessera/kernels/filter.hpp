// The float filter in front of the exact predicate.
//
// A cell keeps its vertices relative to its generator (y = v - p_i), each with
// `err`, a bound on the infinity-norm distance between the computed y and the
// exact vertex of its defining planes. A plane is stored as n.y <= d (for a
// bisector with p_j: n = p_j - p_i, d = |n|^2 / 2, both rounded once). The
// clip quantity P~ = d - n.y then differs from the exact one by at most
//     |n|_1 * (err + 16u |y|_inf) + 16u |d|
// (first-order forward error of the rounded n, d and dot product, with a
// factor of two to spare). When |P~| exceeds it the float sign is certain;
// otherwise the exact predicate decides. Vertices are solved by Cramer's rule
// from three (two) planes; their `err` is u * cond * scale * 64 (Higham,
// "Accuracy and Stability of Numerical Algorithms", §1 and §9 for the bound
// shape); beyond a condition number of 1e6 the vertex is instead solved
// exactly and rounded, so every vertex position is accurate.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

namespace tessera::kernels::filter {

inline constexpr double u = std::numeric_limits<double>::epsilon() * 0.5;  // unit roundoff
inline constexpr double plane_eps = 16 * u;
inline constexpr double vertex_eps = 64 * u;
/// Absolute slack for underflow in sums of a few products (a plane value, a
/// squared length): each rounding below DBL_MIN errs by at most 2^-1075 in
/// absolute terms, far below this. The front end shifts inputs by a power of
/// two so nonzero coordinates lie within [2^-147, 2^200) where it can
/// (front/pass.cpp, choose_scaling), and this never matters on sane data.
/// Vertex solves, which divide, need more: underflow_slack.
inline constexpr double abs_eps = 0x1p-900;
/// The same slack in a vertex's radius bound r2 (a sum of three squares
/// errs by at most 3 x 2^-1075 below DBL_MIN), kept far below abs_eps: in a
/// frame where the bulk of the points lies near 2^-465 (beside an outlier
/// at 1e200, front/pass.cpp) their r2 are ~2^-940, and abs_eps made every
/// security radius span the whole bulk.
inline constexpr double radius_abs_eps = 0x1p-1000;
/// The absolute term of a determinant filter (orientation, in-sphere, a
/// side test) whose products may round below DBL_MIN. Each such product
/// errs by eta <= 2^-1075 in absolute terms (sums of subnormals are exact),
/// and later products multiply that error: `growth` bounds the sum of those
/// multipliers, so that underflow moves the determinant by at most
/// eta * growth (each filter derives its own). Returns 8 eta growth, and at
/// least 2^-1000: a normal double (subnormal arithmetic costs a microcode
/// assist). Needed where no frame fits (ExactContext::may_underflow):
/// 1e-155 beside 1e131, whose 2x2 minors underflow and are then multiplied
/// by the large row; the insertion's walk went wrong on such input with
/// abs_eps in its place. The floor lies below abs_eps (2^-900), which in
/// such a frame (the bulk near 2^-465 beside an outlier at 2^200) exceeded
/// every determinant of the bulk and sent each to the slower stages. NaN
/// growth gives NaN, which leaves the filter undecided.
inline double underflow_bound(double growth) { return (!(growth <= 0x1p72) ? growth : 0x1p72) * 0x1p-1072; }
/// The absolute error that underflow adds to a vertex solved by Cramer's
/// rule (3D, or 2D with its smaller sums), beyond the relative bound. Each
/// product that rounds below DBL_MIN errs by eta <= 2^-1075 (sums of
/// subnormals are exact). A numerator sum_r d_r c_r errs by at most
/// 3 eta + 6 eta max|d| + 4 eta s (s bounds the cofactors' entries) from its
/// own products, the rounded d and cofactors included; the determinant by
/// 3 eta + 2 eta max|n|_1, which moves y by |y| |inv| times that; the final
/// product by eta. 2^-1070 = 32 eta covers every factor. The result is kept
/// a normal double: below 2^-969 it is rounded up to that, still far below
/// abs_eps, so no arithmetic touches a subnormal (each such operation costs
/// a microcode assist on x86: computed directly, the term slowed every cell
/// of such input by 60%). Only asked for when ExactContext::may_underflow.
inline double underflow_slack(double inv, double amax, double bmax, double s, double ymax) {
  const double t = std::fabs(inv) * (1 + bmax + s + ymax * (1 + amax));
  return t > 0x1p100 ? t * 0x1p-1069 : 0x1p-969;  // >= 2^-1070 (1 + t) either way (NaN: the constant)
}
/// Beyond this condition number the float solve's position is too inaccurate
/// for geometry (volumes, merged coordinates): the vertex is solved exactly.
inline constexpr double exact_vertex_condition = 1e6;

/// A vertex whose condition number lies in [exact_vertex_condition,
/// deferred_vertex_condition), made by a clip or far out in an assembly,
/// keeps its float position and bound while the cell is built; only if it
/// survives every clip (the box's, for an assembled cell) is it solved
/// exactly (Hull/Tile::solve_deferred). Its bound stays first order: the computed
/// determinant errs relatively by about cond * 4u < 1e-6 here, which the
/// bound's factor of two covers. Most such vertices are cut away again (a
/// thin band of points on a cylinder: ~100 per cell, where the cell keeps
/// a few), and each exact solve costs about a microsecond in GMP.
inline constexpr double deferred_vertex_condition = 1e9;

/// Exact evaluations a cell may ask of its deferred vertices before its next
/// clip solves them (Hull/Tile::clip): kept with their wide bounds through a
/// long search (a far point's cell tries every point of the bulk), they sent
/// every candidate to the exact stages (stop 70).
inline constexpr std::uint32_t deferred_ask_limit = 64;

/// How solve() treats a vertex too ill-conditioned for its float bound
/// (Hull/Tile::ill_conditioned, assembly::ill_conditioned_fate): exact_now
/// solves it at once; deferrable (a clip) defers it below
/// deferred_vertex_condition, else solves it; float_only (the assembly's
/// first pass) solves one near the box at once, defers one far out below
/// that condition, and refuses the rest (a NaN bound: the assembly solves
/// those it can pay for with exact_now, or sends the cell to the clips). A
/// vertex on a hull point's far plane is never solved exactly: below that
/// condition it keeps its float bound, beyond it is refused
/// (assembly::ill_conditioned_fate).
enum class SolveMode : std::uint8_t { float_only, exact_now, deferrable };

/// floor(log2(x)) for a finite x > 0, clamped to [-1022, 1022] (subnormals
/// give -1022), read from the bits.
inline std::int32_t binary_exponent(double x) {
  const auto biased = static_cast<std::int32_t>((std::bit_cast<std::uint64_t>(x) >> 52) & 0x7FF);
  return std::clamp(biased - 1023, -1022, 1022);
}

/// 2^e for e in [-1022, 1023], built from the bits (no libm call).
inline double pow2(std::int32_t e) { return std::bit_cast<double>(static_cast<std::uint64_t>(e + 1023) << 52); }

/// Bisectors of points very far from, or very near to, the generator (|q|
/// beyond about 2^200 or below about 2^-300) are stored scaled: n = q 2^-s,
/// d = |n|^2 2^s / 2 and n1 = |n|_1, with s = floor(log2 |q|_1), the same
/// plane n.y = d with |n|_1 in [1, 2). Such planes occur only in input that no
/// single power-of-two frame fits (front/pass.cpp: a bulk of points and a far
/// outlier, 1e-200 beside 1). Unscaled, d = |q|^2 / 2 overflows (from |q| ~
/// 1.3e154) or its products with the cofactors do in the vertex solve, and
/// every sign against it went to the exact stage; at the small end those
/// products underflow, the vertices came out as zeros, and every cell was
/// measured in rationals (4,000 points beside one at 1e200: 9.6 s, now
/// 0.25 s; docs/design.md, "Bisectors beyond the frame"). Scaling
/// by a power of two is exact, and Cramer's rule gives the same vertex on
/// rows scaled by powers of two, so the filter's relative bounds hold as for
/// any plane. classify() takes the unscaled d for its radius test.
inline constexpr double huge_bisector_d = 0x1p400, tiny_bisector_d = 0x1p-600;
/// The bisector with q = p_j - p_i as a clip tests and stores it: n.y <= d,
/// n = q and d = |q|^2 / 2 (both rounded once), n1 = |n|_1, or the scaled
/// form above where d lies outside [tiny_bisector_d, huge_bisector_d] (scale
/// != 0). Used in place: n may point into the object itself.
template <int D>
struct Bisector {
  const double* n;
  double d, n1;
  double d_unscaled;      // |q|^2 / 2 as computed: classify's radius test
  std::int32_t scale = 0;
  double scaled[D];

  explicit Bisector(const double* q) : n(q) {
    d = 0, n1 = 0;
    for (int a = 0; a < D; ++a) {
      d += q[a] * q[a];
      n1 += std::fabs(q[a]);
    }
    d *= 0.5;
    d_unscaled = d;
    if (!(d <= huge_bisector_d && d >= tiny_bisector_d)) [[unlikely]]  // a far outlier's, in extreme input
      rescale(q);
  }
  Bisector(const Bisector&) = delete;
  Bisector& operator=(const Bisector&) = delete;

 private:
  // Leaves q unscaled where it is 0 (a duplicate) or |q| itself overflowed:
  // the exact stage decides those.
  [[gnu::noinline, gnu::cold]] void rescale(const double* q) {
    if (!(n1 > 0 && n1 <= std::numeric_limits<double>::max())) return;
    scale = binary_exponent(n1);
    const double down = pow2(-scale);
    double nn = 0, l1 = 0;
    for (int a = 0; a < D; ++a) {
      scaled[a] = q[a] * down;
      nn += scaled[a] * scaled[a];
      l1 += std::fabs(scaled[a]);
    }
    n = scaled;
    d = 0.5 * nn * pow2(scale);
    n1 = l1;
  }
};

/// memmove of `count` elements from base[src] to base[dst] (the ranges may
/// overlap) as a plain loop: the moves are a few elements long, where a
/// library call costs more than the copy. The empty asm statement keeps GCC
/// from turning the loop back into that call (it emits no instruction).
template <class T>
void shift(T* base, std::size_t dst, std::size_t src, std::size_t count) {
  if (dst < src) {
    for (std::size_t k = 0; k < count; ++k) {
      base[dst + k] = base[src + k];
      __asm__ volatile("");
    }
  } else {
    for (std::size_t k = count; k-- > 0;) {
      base[dst + k] = base[src + k];
      __asm__ volatile("");
    }
  }
}

/// The vertices' filter data (y, e, r2 of each vertex, as in `classify`) kept
/// as structure-of-arrays beside the cell's own vertex list, so the sign pass
/// reads contiguous doubles and runs in SIMD lanes. Slots from size() up to
/// the next multiple of `lanes` always hold padding (y = 0, e = 0, r2 = -1),
/// which `classify` never marks for removal (its plane value is d, its radius
/// fails the radius test), so the pass needs no tail.
template <int D>
class FilterLanes {
 public:
  static constexpr std::size_t lanes = 4;

  std::size_t size() const { return n_; }
  /// size() rounded up to whole lanes: the extent `classify` reads.
  std::size_t padded() const { return (n_ + lanes - 1) / lanes * lanes; }

  void clear() { resize(0); }
  template <class Vertex>
  void set(std::size_t t, const Vertex& v) { put(t, v); }
  /// Replace the contents by the vertices of `vs`.
  template <class Vertices>
  void assign(const Vertices& vs) {
    grow(vs.size());
    n_ = vs.size();
    for (std::size_t t = 0; t < n_; ++t) put(t, vs[t]);
    pad();
  }
  /// Move slots [src, src + count) to [dst, dst + count) (the ranges may
  /// overlap), as the vertex list's own memmove does.
  void move(std::size_t dst, std::size_t src, std::size_t count) {
    grow(std::max(dst, src) + count);
    for (int k = 0; k < D; ++k) shift(y_[k].data(), dst, src, count);
    shift(e_.data(), dst, src, count);
    shift(r2_.data(), dst, src, count);
  }
  /// Keep (or make room for) the first n slots; new slots are unset until set().
  void resize(std::size_t n) {
    grow(n);
    n_ = n;
    pad();
  }

  /// The largest r2 (0 when empty; padding is -1). One accumulator per lane:
  /// the max of doubles is exact in any order, and a single serial chain of
  /// maxima dominated the tail of every clip.
  double max_r2() const {
    double m[lanes] = {0.0, 0.0, 0.0, 0.0};
    const double* r = r2_.data();
    for (std::size_t t = 0; t < padded(); t += lanes)
      for (std::size_t a = 0; a < lanes; ++a) m[a] = std::max(m[a], r[t + a]);
    return std::max(std::max(m[0], m[1]), std::max(m[2], m[3]));
  }

  const double* y(int k) const { return y_[k].data(); }
  const double* e() const { return e_.data(); }
  const double* r2() const { return r2_.data(); }

 private:
  template <class Vertex>
  void put(std::size_t t, const Vertex& v) {
    for (int k = 0; k < D; ++k) y_[k][t] = v.y[k];
    e_[t] = v.e;
    r2_[t] = v.r2;
  }
  void grow(std::size_t n) {
    const std::size_t need = (n + lanes - 1) / lanes * lanes + lanes;
    if (r2_.size() < need) [[unlikely]] reserve_slots(need);
  }
  void reserve_slots(std::size_t need) {
    const std::size_t cap = std::max(need, 2 * r2_.size());
    for (int k = 0; k < D; ++k) y_[k].resize(cap, 0.0);
    e_.resize(cap, 0.0);
    r2_.resize(cap, -1.0);
  }
  void pad() {
    for (std::size_t t = n_; t < padded(); ++t) {
      for (int k = 0; k < D; ++k) y_[k][t] = 0;
      e_[t] = 0;
      r2_[t] = -1;
    }
  }

  std::size_t n_ = 0;
  std::vector<double> y_[D], e_, r2_;
};

/// A vertex's side of a clipping plane: +1 keep, -1 remove, 0 undecided.
/// Deliberately not a char type: a store through a char type may alias any
/// object, so after each one the compiler reloaded every vector's data
/// pointer in the clip loops.
using Sign = std::int16_t;

namespace detail {
// Two lanes of doubles in GCC's vector extension: one SSE2 register, the
// default x86-64-v2 target's width. Comparisons yield 0 / -1 per lane.
using Lane = double __attribute__((vector_size(16)));
// The comparisons' own type: vectors of long in GCC, of long long in Clang,
// whose vector conditionals need both arms of one type.
using LaneMask = decltype(Lane{} < Lane{});
inline Lane load(const double* p) {
  Lane v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
}  // namespace detail

/// The sign pass every clip starts with, shared by the 2D tile and the 3D hull.
///
/// Vertices carry y[D] (relative to the generator), e = err + plane_eps*|y|_inf
/// and r2 (an upper bound on the exact |y|^2), read from `f`. The plane is
/// n.y <= d with |n|_1 = n1, d = |q|^2/2. Fills `sign` (padded() entries) with
/// +1 (keep) / -1 (remove), asking `exact(vertex index)` only where the filter
/// cannot decide, and returns the number removed. A vertex no farther than
/// |q|/2 from the generator cannot be cut: q.y <= |q||y| <= |q|^2/2 (equality
/// would need y = q/2 exactly, which the strict margin excludes). Candidates
/// usually fail to clip; a first pass only proves that, a lane group at a
/// time, and then `sign` is left untouched. It uses the float filter alone:
/// a near vertex fails the filter only where it (nearly) touches the plane,
/// rare enough that leaving the radius test to the second pass measured
/// cheaper. Both passes take a lane group (four
/// vertices) at a time, branch-free within it; the arithmetic is the same, term
/// for term, as a scalar loop's (no contraction), so the signs do not depend on
/// the vector width.
///
/// Overflow: in a frame that fits (front/pass.cpp) coordinates stay below
/// 2^200 and no product overflows. Where none fits (may_underflow) a cell
/// reaching the box has vertices near 2^970, and n.y overflows: a sum with
/// one term at +inf is +inf whatever the others, so P came out -inf (a
/// certain "remove") for a vertex the plane keeps, or +inf (proved kept in
/// the first pass) for one it cuts. Found by the hostile fuzz (points spread
/// log-uniformly over 1e-300..1e300: a neighbour lost, wrong topology, and a
/// crash in the exact measure of the malformed cell). With `Unbounded`, a
/// lane whose P is not finite (an overflow in it, as inf never returns to a
/// finite value) is undecided in both passes.
template <int D, bool Unbounded = false, class Exact>
std::size_t classify(const FilterLanes<D>& f, const double* n, double d, double n1, double d_unscaled,
                     std::vector<Sign>& sign, Exact&& exact) {
  static_assert(FilterLanes<D>::lanes == 4, "two detail::Lanes per lane group");
  using detail::Lane;
  using detail::LaneMask;
  const std::size_t nv = f.size(), np = f.padded();
  // <= the exact |p_j - p_i|^2 (from the plane's d before Bisector's scaling:
  // infinite only where the exact value exceeds every double, and so any
  // finite 4 r2)
  const double q2lo = 2.0 * d_unscaled * (1.0 - 1e-12) - abs_eps;
  const double de = plane_eps * std::fabs(d) + abs_eps;
  const double* E = f.e();
  const double* R = f.r2();
  // P~ = d - n.y (summed in axis order, like a scalar loop) and its bound.
  auto plane_value = [&](std::size_t t) {
    Lane dot = n[0] * detail::load(f.y(0) + t);
    for (int k = 1; k < D; ++k) dot += n[k] * detail::load(f.y(k) + t);
    return d - dot;
  };
  std::size_t first = 0;  // the first lane group holding a vertex that may be cut
  for (; first < np; first += 4) {
    LaneMask hit{};
    if constexpr (Unbounded) {
      for (std::size_t h = first; h < first + 4; h += 2) {
        const Lane P = plane_value(h);
        hit |= ~((P > n1 * detail::load(E + h) + de) & (P - P == 0));
      }
    } else {
      for (std::size_t h = first; h < first + 4; h += 2) hit |= ~(plane_value(h) > n1 * detail::load(E + h) + de);
    }
    if (hit[0] | hit[1]) break;
  }
  if (first >= np) return 0;
  // Grown only (entries past np are never read): a resize on every clip
  // became an out-of-line call once classify had two instantiations, and cost
  // uniform 3D cells 3%.
  if (sign.size() < np) [[unlikely]]
    sign.resize(np);
  std::fill(sign.begin(), sign.begin() + static_cast<std::ptrdiff_t>(first), Sign{1});
  std::int64_t removed = 0, uncertain = 0;
  for (std::size_t t = first; t < np; t += 2) {
    const Lane P = plane_value(t);
    const Lane e = n1 * detail::load(E + t) + de;
    const LaneMask near = 4.0 * detail::load(R + t) < q2lo;  // never cut
    const LaneMask s0 = near ? LaneMask{1, 1} : (P < -e) - (P > e);
    const LaneMask s = Unbounded ? ((near | (P - P == 0)) ? s0 : LaneMask{0, 0}) : s0;
    for (int k = 0; k < 2; ++k) {
      sign[t + static_cast<std::size_t>(k)] = static_cast<Sign>(s[k]);
      removed += s[k] < 0;
      uncertain += s[k] == 0;
    }
  }
  for (std::size_t t = first; uncertain && t < nv; ++t) {
    if (sign[t] != 0) continue;
    sign[t] = static_cast<Sign>(exact(t));
    removed += (sign[t] < 0);
    --uncertain;
  }
  return static_cast<std::size_t>(removed);
}

/// classify<D, true> for bisector b, out of line and cold: the cells of input
/// no frame fits (may_underflow) take it, and the ordinary clip's code keeps
/// its one hot instantiation.
template <int D, class Exact>
[[gnu::noinline, gnu::cold]] std::size_t classify_unbounded(const FilterLanes<D>& f, const Bisector<D>& b,
                                                            std::vector<Sign>& sign, Exact&& exact) {
  return classify<D, true>(f, b.n, b.d, b.n1, b.d_unscaled, sign, exact);
}

}  // namespace tessera::kernels::filter
