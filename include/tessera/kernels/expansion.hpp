// Exact sums and products of doubles as floating-point expansions, for the
// exact stage of the orientation predicate (delaunay_predicates.cpp).
//
// An expansion is a number written as an unevaluated sum of doubles whose
// bits do not overlap, stored from the smallest magnitude to the largest;
// its sign is the sign of its largest component. Sums and products stay
// exact because the rounding error of one double addition or product is
// itself a double, recovered by a few more operations (Knuth's two-sum,
// Dekker's product); Shewchuk, "Adaptive Precision Floating-Point Arithmetic
// and Fast Robust Geometric Predicates", Discrete Comput. Geom. 18 (1997),
// proves that merging two expansions by magnitude and sweeping them with
// two-sum (his Theorem 13), and scaling one by a double (Theorem 19), give
// expansions again. What is written here follows those theorems; the code is
// ours.
//
// Exact only while nothing overflows or underflows: exact_range() says
// whether the inputs of a predicate of degree up to five are safe; GMP
// rationals stay behind for the rest. Where hull completion met a rotated
// lattice's near-coplanar faces, the rational orientation (a gcd per
// operation) dominated: 20^3 points took 4.1 s by the cells pass, 1.8 s with
// this stage. The in-sphere test keeps its GMP integers: an expansion stage
// for it (about 90 sums and products per test, on these arrays or on
// vectors) took twice as long as GMP on a rotated lattice and on points
// nearly on a sphere; a hand-unrolled one is what to try next.
#pragma once

#include <algorithm>
#include <cmath>
#include <utility>

namespace tessera::kernels::expansion {

/// Components from the smallest magnitude up, none zero (n == 0 is zero),
/// in a fixed array (no allocation: the predicates' expansions stay short
/// once compressed). A result that would outgrow the array is marked invalid
/// (n == -1), and so is everything computed from it: the caller then falls
/// back to GMP. With compress() after every sum that never happens for
/// inputs in exact_range() (their values span under 1500 bits, so at most
/// about 30 nonadjacent components each, 60 in a sum before compressing).
struct Expansion {
  static constexpr int capacity = 160;
  int n = 0;
  double c[capacity];  // only c[0..n) is ever read
  bool valid() const { return n >= 0; }
  void clear() { n = 0; }
};

/// s + e == a + b exactly, s the rounded sum.
inline void two_sum(double a, double b, double& s, double& e) {
  s = a + b;
  const double b_part = s - a;
  const double a_part = s - b_part;
  e = (a - a_part) + (b - b_part);
}

/// The same when |a| >= |b| (or a == 0).
inline void fast_two_sum(double a, double b, double& s, double& e) {
  s = a + b;
  e = b - (s - a);
}

/// hi + lo == a, each with at most 26 significant bits (Veltkamp's split;
/// |a| well below the overflow threshold).
inline void split(double a, double& hi, double& lo) {
  const double t = 134217729.0 * a;  // 2^27 + 1
  hi = t - (t - a);
  lo = a - hi;
}

/// p + e == a * b exactly, p the rounded product (Dekker's product: the
/// portable build has no fused multiply-add).
inline void two_product(double a, double b, double& p, double& e) {
  p = a * b;
  double ah, al, bh, bl;
  split(a, ah, al);
  split(b, bh, bl);
  e = ((ah * bh - p) + ah * bl + al * bh) + al * bl;
}

/// Of a valid expansion.
inline int sign(const Expansion& e) { return e.n == 0 ? 0 : (e.c[e.n - 1] > 0 ? 1 : -1); }

/// a - b as an expansion (one or two components).
inline void difference(double a, double b, Expansion& out) {
  double s, e;
  two_sum(a, -b, s, e);
  out.n = 0;
  if (e != 0) out.c[out.n++] = e;
  if (s != 0) out.c[out.n++] = s;
}

inline void negate(Expansion& e) {
  for (int i = 0; i < e.n; ++i) e.c[i] = -e.c[i];
}

/// e with as few components as its value needs (about its bits / 53), by
/// renormalising (Shewchuk's Compress): a sweep from the largest component
/// down gathers each run that sums without error into one double, then a
/// sweep up restores the order by magnitude. The products of near-degenerate
/// predicates otherwise grow to hundreds of components, most of them
/// carrying a few bits each, and the sums and products over them cost more
/// than GMP's integers.
inline void compress(Expansion& e) {
  if (e.n < 3) return;
  double* const c = e.c;
  const int m = e.n;
  // Down: c[m-1] first; a nonzero error closes the run, whose sum is kept
  // at the top of the free part of c.
  int bottom = m - 1;
  double q = c[m - 1];
  for (int i = m - 2; i >= 0; --i) {
    double s, err;
    fast_two_sum(q, c[i], s, err);
    if (err != 0) {
      c[bottom--] = s;
      q = err;
    } else {
      q = s;
    }
  }
  c[bottom] = q;
  // Up: from the smallest kept value, each sum's error is final.
  int top = 0;
  for (int i = bottom + 1; i < m; ++i) {
    double s, err;
    fast_two_sum(c[i], q, s, err);
    if (err != 0) c[top++] = err;
    q = s;
  }
  if (q != 0) c[top++] = q;
  e.n = top;
}

/// to = from.
inline void assign(const Expansion& from, Expansion& to) {
  if (&from == &to) return;
  to.n = from.n;
  if (from.n > 0) std::copy(from.c, from.c + from.n, to.c);
}

/// h = e + f, compressed. h must be another object than e and f.
inline void sum(const Expansion& e, const Expansion& f, Expansion& h) {
  if (!e.valid() || !f.valid() || e.n + f.n > Expansion::capacity) {
    h.n = -1;
    return;
  }
  h.n = 0;
  if (e.n == 0 || f.n == 0) {
    assign(e.n == 0 ? f : e, h);
    return;
  }
  // The components of both by increasing magnitude, swept from the
  // smallest with two-sum: each step's error is final (no later, larger
  // component overlaps it), the running sum carries on.
  int i = 0, j = 0;
  auto next = [&] {
    if (j == f.n || (i < e.n && std::fabs(e.c[i]) < std::fabs(f.c[j]))) return e.c[i++];
    return f.c[j++];
  };
  double q = next();
  while (i < e.n || j < f.n) {
    double s, err;
    two_sum(q, next(), s, err);
    if (err != 0) h.c[h.n++] = err;
    q = s;
  }
  if (q != 0) h.c[h.n++] = q;
  if (h.n > 4) compress(h);
}

/// h = e * b. h must be another object than e.
inline void scale(const Expansion& e, double b, Expansion& h) {
  if (!e.valid() || 2 * e.n > Expansion::capacity) {
    h.n = -1;
    return;
  }
  h.n = 0;
  if (e.n == 0 || b == 0) return;
  double q, err;
  two_product(e.c[0], b, q, err);
  if (err != 0) h.c[h.n++] = err;
  for (int i = 1; i < e.n; ++i) {
    double p, p_err, s, s_err;
    two_product(e.c[i], b, p, p_err);
    two_sum(q, p_err, s, s_err);
    if (s_err != 0) h.c[h.n++] = s_err;
    fast_two_sum(p, s, q, s_err);
    if (s_err != 0) h.c[h.n++] = s_err;
  }
  if (q != 0) h.c[h.n++] = q;
}

/// Scratch for products.
struct Workspace {
  Expansion term, acc, next;
};

/// h = e * f (h another object than e and f).
inline void product(const Expansion& e, const Expansion& f, Expansion& h, Workspace& ws) {
  if (!e.valid() || !f.valid()) {
    h.n = -1;
    return;
  }
  const Expansion& small = e.n <= f.n ? e : f;
  const Expansion& large = e.n <= f.n ? f : e;
  Expansion* acc = &ws.acc;
  Expansion* next = &ws.next;
  acc->n = 0;
  for (int i = 0; i < small.n; ++i) {
    scale(large, small.c[i], ws.term);
    sum(*acc, ws.term, *next);
    std::swap(acc, next);
  }
  assign(*acc, h);
}

/// Whether every value is zero or of magnitude in [2^-120, 2^120]. Then the
/// differences of two such values, and products of up to five of those
/// differences with their sums, neither overflow nor underflow: every
/// intermediate is a multiple of the smallest lsb to the fifth power, at
/// least 2^-860, and below 2^620.
inline bool exact_range(const double* x, int n) {
  for (int k = 0; k < n; ++k) {
    const double a = std::fabs(x[k]);
    if (a != 0 && !(a >= 0x1p-120 && a <= 0x1p120)) return false;  // NaN fails too
  }
  return true;
}

}  // namespace tessera::kernels::expansion
