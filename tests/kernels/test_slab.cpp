// Slab bounds (slab.hpp) against exact rational arithmetic: whenever a slab
// rules a query out, every one of its points must be out, at every scale the
// input can take (subnormal offsets included); and the bounds must rule out
// the queries they exist for (not vacuous).
#include <gtest/gtest.h>
#include <gmpxx.h>

#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "tessera/kernels/slab.hpp"

namespace {

using Slab3 = tessera::kernels::Slab<3>;
using Point = std::array<double, 3>;

// n points of a gently curved patch z = k (x^2 - y^2) of half-width w,
// rotated by a random rotation, scaled by 2^scale and moved to `at`. With
// `subnormal`, a few coordinates get offsets of a few 2^-1074 instead.
std::vector<Point> patch(std::mt19937_64& rng, int n, int scale, const Point& at, bool subnormal) {
  std::uniform_real_distribution<double> u(-1, 1);
  // A random rotation from a normalised quaternion.
  double q[4], len = 0;
  for (double& c : q) {
    c = u(rng);
    len += c * c;
  }
  for (double& c : q) c /= std::sqrt(len);
  const double a = q[0], b = q[1], c = q[2], d = q[3];
  const double rot[3][3] = {{a * a + b * b - c * c - d * d, 2 * (b * c - a * d), 2 * (b * d + a * c)},
                            {2 * (b * c + a * d), a * a - b * b + c * c - d * d, 2 * (c * d - a * b)},
                            {2 * (b * d - a * c), 2 * (c * d + a * b), a * a - b * b - c * c + d * d}};
  const double k = 0.05 * u(rng);
  std::vector<Point> out;
  for (int i = 0; i < n; ++i) {
    const double x = u(rng), y = u(rng), z = k * (x * x - y * y);
    Point p;
    for (int r = 0; r < 3; ++r) p[r] = at[r] + std::ldexp(rot[r][0] * x + rot[r][1] * y + rot[r][2] * z, scale);
    if (subnormal && rng() % 3 == 0) p[rng() % 3] = static_cast<double>(1 + rng() % 4) * 0x1p-1074;
    out.push_back(p);
  }
  return out;
}

Slab3 fit(const std::vector<Point>& pts) {
  return Slab3::fit(pts.size(), [&](std::size_t k) { return pts[k].data(); });
}

// Whether every point p has n.(p - o) < -margin, exactly.
bool all_below(const std::vector<Point>& pts, const double* n, const Point& o, double margin) {
  for (const Point& p : pts) {
    mpq_class v = margin;
    for (int d = 0; d < 3; ++d) v += mpq_class(n[d]) * (mpq_class(p[d]) - mpq_class(o[d]));
    if (sgn(v) >= 0) return false;
  }
  return true;
}

// Whether every point lies farther than r from x, exactly.
bool all_outside(const std::vector<Point>& pts, const Point& x, double r) {
  const mpq_class r2 = mpq_class(r) * mpq_class(r);
  for (const Point& p : pts) {
    mpq_class v = 0;
    for (int d = 0; d < 3; ++d) v += (mpq_class(p[d]) - mpq_class(x[d])) * (mpq_class(p[d]) - mpq_class(x[d]));
    if (cmp(v, r2) <= 0) return false;
  }
  return true;
}

// The patch point farthest along direction v.
Point extreme(const std::vector<Point>& pts, const double* v) {
  Point best = pts[0];
  double top = -INFINITY;
  for (const Point& p : pts) {
    const double t = v[0] * p[0] + v[1] * p[1] + v[2] * p[2];
    if (t > top) {
      top = t;
      best = p;
    }
  }
  return best;
}

TEST(Slab, BelowHoldsForEveryPointExactly) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  int ruled_out = 0, queries = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const int scale = std::array<int, 5>{0, -30, 20, -1000, -1060}[trial % 5];
    const bool subnormal = trial % 7 == 0;
    // Far from the origin at unit scale; at the tiny scales within a few
    // patch widths of it, where the offsets still register.
    const double reach = scale == 0 ? 100 : std::ldexp(8.0, scale);
    const Point at = {u(rng) * reach, u(rng) * reach, u(rng) * reach};
    const auto pts = patch(rng, 32, scale, at, subnormal);
    const Slab3 s = fit(pts);
    for (int k = 0; k < 40; ++k) {
      // Normals at every magnitude, the smallest so small that their squares
      // underflow; origins around the patch, and planes through its points.
      double n[3];
      const int ns = std::array<int, 4>{0, -600, 300, -1040}[k % 4];
      for (double& c : n) c = std::ldexp(u(rng), ns);
      Point o = pts[rng() % pts.size()];
      if (k % 2)
        for (int d = 0; d < 3; ++d) o[d] += std::ldexp(u(rng), scale + 1);
      const double margin = k % 3 == 0 ? 0.0 : std::fabs(std::ldexp(u(rng), ns + scale - 8));
      const Slab3::Plane plane(n, o.data(), margin);
      ++queries;
      if (!s.below(plane)) continue;
      ++ruled_out;
      ASSERT_TRUE(all_below(pts, n, o, margin)) << "trial " << trial << " query " << k;
    }
    // The tight case: a plane nearly parallel to the patch, just below its
    // highest point along the normal, which the bound's thickness term must
    // keep out.
    if (!(s.thick < Slab3::flat * s.rho)) continue;
    for (int k = 0; k < 8; ++k) {
      double n[3];
      for (int d = 0; d < 3; ++d) n[d] = s.nrm[d] * (k % 2 ? 1 : -1) + 1e-3 * u(rng);
      Point o = extreme(pts, n);
      for (int d = 0; d < 3; ++d) o[d] -= std::ldexp(1e-4, scale) * n[d];
      ASSERT_FALSE(s.below(Slab3::Plane(n, o.data(), 0.0)) && !all_below(pts, n, o, 0.0)) << "trial " << trial;
    }
  }
  // Planes through a point of a flat patch, with a random normal, put about
  // a sixth of the patch strictly below by far; the bound must see most.
  EXPECT_GT(ruled_out, queries / 20) << ruled_out << " of " << queries;
}

TEST(Slab, ExcludesHoldsForEveryPointExactly) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  int ruled_out = 0, queries = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const int scale = std::array<int, 4>{0, -30, 20, -500}[trial % 4];
    const double reach = scale == 0 ? 10 : std::ldexp(8.0, scale);
    const Point at = {u(rng) * reach, u(rng) * reach, u(rng) * reach};
    const auto pts = patch(rng, 32, scale, at, false);
    const Slab3 s = fit(pts);
    for (int k = 0; k < 40; ++k) {
      // Balls around a point off the patch, of radius up to the distance of
      // its nearest point (within 1%): most are empty, many nearly touch.
      Point x = pts[rng() % pts.size()];
      for (int d = 0; d < 3; ++d) x[d] += std::ldexp(2 * u(rng), scale);
      double nearest = INFINITY;
      for (const Point& p : pts) {
        double r2 = 0;
        for (int d = 0; d < 3; ++d) r2 += (p[d] - x[d]) * (p[d] - x[d]);
        nearest = std::min(nearest, std::sqrt(r2));
      }
      const double r = nearest * (1 + 0.5 * u(rng));
      ++queries;
      if (!s.excludes(x.data(), r)) continue;
      ++ruled_out;
      ASSERT_TRUE(all_outside(pts, x, r)) << "trial " << trial << " query " << k;
    }
    // The tight case: a large ball above the patch along its normal whose
    // surface dips just below the highest point there.
    if (!(s.thick < Slab3::flat * s.rho)) continue;
    for (int k = 0; k < 8; ++k) {
      double v[3];
      for (int d = 0; d < 3; ++d) v[d] = s.nrm[d] * (k % 2 ? 1 : -1);
      const Point top = extreme(pts, v);
      const double r = std::ldexp(1.0 + 10 * (u(rng) + 1), scale);
      Point x;
      for (int d = 0; d < 3; ++d) x[d] = top[d] + (r - std::ldexp(1e-4, scale)) * v[d];
      ASSERT_FALSE(s.excludes(x.data(), r) && !all_outside(pts, x, r)) << "trial " << trial;
    }
  }
  EXPECT_GT(ruled_out, queries / 20) << ruled_out << " of " << queries;
}

}  // namespace
