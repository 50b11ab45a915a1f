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
// this stage. The in-sphere test keeps its GMP integers: with these
// operations on std::vector its exact stage took twice as long (its
// expansions are short after compress(), so the cost is per operation; a
// fixed-size version is the way to try next).
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

namespace tessera::kernels::expansion {

/// Components from the smallest magnitude up, none zero; empty is zero.
using Expansion = std::vector<double>;

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

inline int sign(const Expansion& e) { return e.empty() ? 0 : (e.back() > 0 ? 1 : -1); }

/// a - b as an expansion (one or two components).
inline void difference(double a, double b, Expansion& out) {
  double s, e;
  two_sum(a, -b, s, e);
  out.clear();
  if (e != 0) out.push_back(e);
  if (s != 0) out.push_back(s);
}

inline void negate(Expansion& e) {
  for (double& x : e) x = -x;
}

/// e with as few components as its value needs (about its bits / 53), by
/// renormalising (Shewchuk's Compress): a sweep from the largest component
/// down gathers each run that sums without error into one double, then a
/// sweep up restores the order by magnitude. The products of near-degenerate
/// predicates otherwise grow to hundreds of components, most of them
/// carrying a few bits each, and the sums and products over them cost more
/// than GMP's integers.
inline void compress(Expansion& e) {
  if (e.size() < 3) return;
  const std::size_t m = e.size();
  // Down: e[m-1] first; a nonzero error closes the run, whose sum is kept
  // at the top of the free part of e.
  std::size_t bottom = m - 1;
  double q = e[m - 1];
  for (std::size_t i = m - 1; i-- > 0;) {
    double s, err;
    fast_two_sum(q, e[i], s, err);
    if (err != 0) {
      e[bottom--] = s;
      q = err;
    } else {
      q = s;
    }
  }
  e[bottom] = q;
  // Up: from the smallest kept value, each sum's error is final.
  std::size_t top = 0;
  for (std::size_t i = bottom + 1; i < m; ++i) {
    double s, err;
    fast_two_sum(e[i], q, s, err);
    if (err != 0) e[top++] = err;
    q = s;
  }
  if (q != 0 || top == 0) e[top++] = q;
  e.resize(top);
  if (top == 1 && e[0] == 0) e.clear();
}

/// h = e + f. h must be another vector than e and f.
inline void sum(const Expansion& e, const Expansion& f, Expansion& h) {
  h.clear();
  if (e.empty() || f.empty()) {
    h = e.empty() ? f : e;
    return;
  }
  // The components of both by increasing magnitude, swept from the
  // smallest with two-sum: each step's error is final (no later, larger
  // component overlaps it), the running sum carries on.
  std::size_t i = 0, j = 0;
  auto next = [&] {
    if (j == f.size() || (i < e.size() && std::fabs(e[i]) < std::fabs(f[j]))) return e[i++];
    return f[j++];
  };
  double q = next();
  while (i < e.size() || j < f.size()) {
    double s, err;
    two_sum(q, next(), s, err);
    if (err != 0) h.push_back(err);
    q = s;
  }
  if (q != 0 || h.empty()) h.push_back(q);
  if (h.size() == 1 && h[0] == 0) h.clear();
  if (h.size() > 4) compress(h);
}

/// h = e * b. h must be another vector than e.
inline void scale(const Expansion& e, double b, Expansion& h) {
  h.clear();
  if (e.empty() || b == 0) return;
  double q, err;
  two_product(e[0], b, q, err);
  if (err != 0) h.push_back(err);
  for (std::size_t i = 1; i < e.size(); ++i) {
    double p, p_err, s, s_err;
    two_product(e[i], b, p, p_err);
    two_sum(q, p_err, s, s_err);
    if (s_err != 0) h.push_back(s_err);
    fast_two_sum(p, s, q, s_err);
    if (s_err != 0) h.push_back(s_err);
  }
  if (q != 0) h.push_back(q);
}

/// Scratch vectors for products; reused, so a thread's evaluations stop
/// allocating once they have seen their largest sizes.
struct Workspace {
  Expansion term, acc, next;
};

/// h = e * f (h another vector than e and f).
inline void product(const Expansion& e, const Expansion& f, Expansion& h, Workspace& ws) {
  const Expansion& small = e.size() <= f.size() ? e : f;
  const Expansion& large = e.size() <= f.size() ? f : e;
  ws.acc.clear();
  for (const double x : small) {
    scale(large, x, ws.term);
    sum(ws.acc, ws.term, ws.next);
    ws.acc.swap(ws.next);
  }
  h.swap(ws.acc);
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
