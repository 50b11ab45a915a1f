// The smoothing's pair test (front/net_crossings.hpp) against an oracle in
// GMP rationals, on inputs made to be degenerate: corners on a coarse
// lattice (coplanar triangles, corners on edges, chords from edge to edge),
// the same configurations far from the origin and nearly flat triangles a
// few ulps wide, where the float filters see mostly rounding.
#include <gtest/gtest.h>
#include <gmpxx.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "front/net_crossings.hpp"

namespace {

using Q = mpq_class;
using QP = std::array<Q, 3>;

QP sub(const QP& a, const QP& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
QP cross(const QP& u, const QP& w) {
  return {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
}
Q dot(const QP& u, const QP& w) { return u[0] * w[0] + u[1] * w[1] + u[2] * w[2]; }
QP along(const QP& p, const QP& q, const Q& h) {  // p + h (q - p)
  return {p[0] + h * (q[0] - p[0]), p[1] + h * (q[1] - p[1]), p[2] + h * (q[2] - p[2])};
}

/// For a point y in the plane of triangle t (normal n), its side of edge k
/// (t_k, t_k+1): positive inside.
Q edge_side(const std::array<QP, 3>& t, const QP& n, int k, const QP& y) {
  return dot(n, cross(sub(t[(k + 1) % 3], t[k]), sub(y, t[k])));
}

/// The ends of segment pq met with the closed triangle t (not flat), added to
/// `points`.
void segment_meets(const QP& p, const QP& q, const std::array<QP, 3>& t, std::vector<QP>& points) {
  const QP n = cross(sub(t[1], t[0]), sub(t[2], t[0]));
  const Q sp = dot(n, sub(p, t[0])), sq = dot(n, sub(q, t[0]));
  if (sp == 0 && sq == 0) {  // in the plane: clip h in [0, 1] by the edges
    Q lo = 0, hi = 1;
    for (int k = 0; k < 3; ++k) {
      const Q gp = edge_side(t, n, k, p), gq = edge_side(t, n, k, q);
      if (gp == gq) {
        if (gp < 0) return;
      } else if (gq > gp) {
        lo = std::max(lo, Q(gp / (gp - gq)));
      } else {
        hi = std::min(hi, Q(gp / (gp - gq)));
      }
    }
    if (lo > hi) return;
    points.push_back(along(p, q, lo));
    points.push_back(along(p, q, hi));
    return;
  }
  if ((sp > 0 && sq > 0) || (sp < 0 && sq < 0)) return;
  const QP x = along(p, q, sp / (sp - sq));
  for (int k = 0; k < 3; ++k)
    if (edge_side(t, n, k, x) < 0) return;
  points.push_back(x);
}

/// Whether triangles a and b share a point interior to one of them (one of
/// zero area has none). Their intersection I is convex; its corners lie on
/// an edge of one met with the other, so the mean c of those meetings' ends
/// is in I's relative interior. If I is not within the boundary of a, it is
/// within no edge of a, and its relative interior lies in a's interior: so
/// they cross iff c is strictly inside a or strictly inside b.
bool oracle_crosses(const std::array<QP, 3>& a, const std::array<QP, 3>& b) {
  const QP na = cross(sub(a[1], a[0]), sub(a[2], a[0])), nb = cross(sub(b[1], b[0]), sub(b[2], b[0]));
  const QP zero{0, 0, 0};
  const bool flat_a = na == zero, flat_b = nb == zero;
  std::vector<QP> points;
  for (int k = 0; k < 3; ++k) {
    if (!flat_a) segment_meets(b[k], b[(k + 1) % 3], a, points);
    if (!flat_b) segment_meets(a[k], a[(k + 1) % 3], b, points);
  }
  if (points.empty()) return false;
  QP c{0, 0, 0};
  for (const QP& p : points)
    for (int d = 0; d < 3; ++d) c[d] += p[d];
  for (int d = 0; d < 3; ++d) c[d] /= static_cast<long>(points.size());
  auto strictly_inside = [&](const std::array<QP, 3>& t, const QP& n) {
    for (int k = 0; k < 3; ++k)
      if (edge_side(t, n, k, c) <= 0) return false;
    return true;
  };
  return (!flat_a && strictly_inside(a, na)) || (!flat_b && strictly_inside(b, nb));
}

/// Compares the pair test (both orders, filtered and exact alone) with the
/// oracle on pairs of triangles over a pool of vertices: triangles take 3 of
/// its ids, so pairs share 0 to 3 of them; distinct ids may share a
/// position. Returns how many pairs cross.
template <class Position>
int compare_with_oracle(std::uint64_t seed, int pairs, int pool, Position&& position) {
  std::mt19937_64 rng(seed);
  std::vector<std::array<double, 3>> xyz(static_cast<std::size_t>(pool));
  std::uniform_int_distribution<int> pick(0, pool - 1);
  int crossing = 0;
  for (int r = 0; r < pairs; ++r) {
    if (r % 50 == 0)
      for (auto& p : xyz) p = position(rng);
    std::array<std::int32_t, 6> ids;
    auto same_triangle = [&] {
      for (int k = 0; k < 3; ++k)
        if (ids[k] != ids[3] && ids[k] != ids[4] && ids[k] != ids[5]) return false;
      return true;
    };
    do {
      for (int t = 0; t < 2; ++t)
        do {
          for (int k = 0; k < 3; ++k) ids[3 * t + k] = pick(rng);
        } while (ids[3 * t] == ids[3 * t + 1] || ids[3 * t + 1] == ids[3 * t + 2] || ids[3 * t] == ids[3 * t + 2]);
    } while (same_triangle());  // (one triangle: the pair test does not pair it with itself)
    const double* a[3];
    const double* b[3];
    std::array<QP, 3> qa, qb;
    for (int k = 0; k < 3; ++k) {
      a[k] = xyz[static_cast<std::size_t>(ids[k])].data();
      b[k] = xyz[static_cast<std::size_t>(ids[3 + k])].data();
      for (int d = 0; d < 3; ++d) qa[k][d] = a[k][d], qb[k][d] = b[k][d];
    }
    const bool want = oracle_crosses(qa, qb);
    crossing += want;
    auto show = [&] {
      std::string s;
      for (int k = 0; k < 6; ++k) {
        const double* p = k < 3 ? a[k] : b[k - 3];
        char buf[128];
        std::snprintf(buf, sizeof buf, "%s#%d(%.17g, %.17g, %.17g)", k == 3 ? " | " : " ", ids[k], p[0], p[1], p[2]);
        s += buf;
      }
      return s;
    };
    EXPECT_EQ(tessera::front::triangle_pair_crosses(a, &ids[0], b, &ids[3]), want) << show();
    EXPECT_EQ(tessera::front::triangle_pair_crosses(b, &ids[3], a, &ids[0]), want) << show();
    EXPECT_EQ(tessera::front::triangle_pair_crosses_exactly(a, b), want) << show();
    if (::testing::Test::HasFailure()) return crossing;
  }
  return crossing;
}

// Corners on the lattice {0..3}^3: every degenerate meeting of two
// triangles occurs (in one plane, corners on edges, chords from edge to
// edge, triangles of zero area).
TEST(NetCrossings, PairTestMatchesRationalOracleOnALattice) {
  std::uniform_int_distribution<int> k(0, 3);
  const int crossing = compare_with_oracle(1, 20000, 8, [&](std::mt19937_64& rng) {
    return std::array<double, 3>{double(k(rng)), double(k(rng)), double(k(rng))};
  });
  EXPECT_GT(crossing, 2000);
}

// The same configurations far from the origin, each axis scaled by its own
// power of two (an exact affine map: the same answers), and the corners of
// two lattice planes (many coplanar pairs).
TEST(NetCrossings, PairTestMatchesRationalOracleFarFromTheOrigin) {
  std::uniform_int_distribution<int> k(0, 3);
  const double scale[3] = {std::ldexp(1.0, -30), std::ldexp(1.0, -28), std::ldexp(1.0, -33)};
  const int crossing = compare_with_oracle(2, 20000, 8, [&](std::mt19937_64& rng) {
    return std::array<double, 3>{1e6 + k(rng) * scale[0], 1e6 + k(rng) * scale[1], -1e6 + k(rng) * scale[2]};
  });
  EXPECT_GT(crossing, 2000);
  std::uniform_int_distribution<int> plane(0, 1);
  const int in_planes = compare_with_oracle(3, 20000, 8, [&](std::mt19937_64& rng) {
    const int x = k(rng), y = k(rng);
    return std::array<double, 3>{1e6 + x * scale[0], 1e6 + y * scale[1], 1e6 + (plane(rng) ? x + y : 0) * scale[2]};
  });
  EXPECT_GT(in_planes, 2000);
}

// Corners of wildly different magnitudes: lattice points scaled by 2^e,
// e from -600 to 600 per vertex (a net of points no frame fits mixes
// triangles 1e277 long with ones of 0.07), in space and in one plane. The
// float filters' products overflow or underflow there; they must scale
// their vectors (net_crossings.cpp, normalize) or leave the pair to the
// exact signs, and never decide wrongly.
TEST(NetCrossings, PairTestMatchesRationalOracleAcrossMagnitudes) {
  std::uniform_int_distribution<int> k(-3, 3), e(0, 6);
  std::uniform_real_distribution<double> fraction(0, 1);
  // (2^-530: products of two differences are subnormal, rounded to a few
  // bits, and a far point's 2^530 lifts them above any unscaled bound.)
  const int exponents[7] = {-600, -530, -300, 0, 300, 530, 600};
  for (const int kind : {0, 1, 2}) {  // lattice points, in one plane, off the lattice
    const int crossing = compare_with_oracle(6 + static_cast<std::uint64_t>(kind), 4000, 8, [&](std::mt19937_64& rng) {
      const int x = exponents[e(rng)];
      auto c = [&] { return std::ldexp(k(rng) + (kind == 2 ? fraction(rng) : 0.0), x); };
      return std::array<double, 3>{c(), c(), kind == 1 ? 0.0 : c()};
    });
    EXPECT_GT(crossing, kind == 1 ? 1600 : 300) << kind;
  }
}

// Where rounding decides: lattice positions 1e6 + k h, with h a few ulps of
// 1e6, each nudged by up to 2 ulps at random, and triangles nearly flat
// (corners near one line through the pool). The float filters must let
// every uncertain pair through to the exact signs.
TEST(NetCrossings, PairTestMatchesRationalOracleWhereRoundingDecides) {
  const double ulp = std::nextafter(1e6, 2e6) - 1e6;
  std::uniform_int_distribution<int> k(0, 3), nudge(-2, 2);
  const int crossing = compare_with_oracle(4, 20000, 8, [&](std::mt19937_64& rng) {
    std::array<double, 3> p;
    for (double& c : p) c = 1e6 + (8 * k(rng) + nudge(rng)) * ulp;
    return p;
  });
  EXPECT_GT(crossing, 1000);
  std::uniform_real_distribution<double> along(-1, 1);
  const int slivers = compare_with_oracle(5, 20000, 8, [&](std::mt19937_64& rng) {
    const double h = along(rng);
    std::array<double, 3> p{1e6 + h, 1e6 + 0.7 * h, 1e6 - 0.3 * h};
    for (double& c : p) c += nudge(rng) * ulp;
    return p;
  });
  EXPECT_GT(slivers, 100);
}

}  // namespace
