// The Delaunay side's float filters where products underflow: points of
// wildly different magnitudes (no power-of-two frame fits them,
// ExactContext::may_underflow). A certain sign from a filter must be the
// exact sign; CGAL's predicates (interval filters, exact fallback) are the
// oracle. Stop 52 found the insertion's walk stopping in a simplex not in
// conflict on such input: the minors of three tiny points underflowed, the
// large row multiplied the error past the filter's absolute term, and the
// orientation filter answered a wrong sign.
#include <gtest/gtest.h>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <utility>

#include "front/insertion_filters.hpp"
#include "tessera/kernels/delaunay_predicates.hpp"

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;

// A point of magnitude 2^e in a random direction, e drawn per point from
// either the tiny or the huge range, so that orientations mix three tiny
// points with one huge (the case found) and everything in between.
struct MixedPoints {
  std::mt19937_64 rng;
  std::normal_distribution<double> g;
  std::uniform_int_distribution<int> tiny{-560, -440}, huge{250, 480}, coin{0, 3};
  explicit MixedPoints(std::uint64_t seed) : rng(seed) {}
  void next(double* p, int dim) {
    const int e = coin(rng) == 0 ? huge(rng) : tiny(rng);
    for (int a = 0; a < dim; ++a) p[a] = std::ldexp(g(rng), e);
  }
};

// Stop 73's configuration at random: of the D + 2 points, those on a tiny
// line near 2^-445 (y, and z in 3D, shared: the rows' minors underflow in
// double), one off it and far along the last axis (2^-260 to 2^-150), and
// one far along y (2^100 to 2^220: a squared length past 2^200), in random
// roles. Before the fix the 3D test failed at its 73rd trial.
struct FarRows {
  std::mt19937_64 rng;
  std::uniform_int_distribution<int> near_far{-260, -150}, far_far{100, 220}, role{0, 4};
  std::uniform_real_distribution<double> x{-1, 1};
  explicit FarRows(std::uint64_t seed) : rng(seed) {}
  void fill(double (*p)[3], int dim) {
    const int n = dim + 2;
    int a = role(rng) % n, b = role(rng) % n;
    if (b == a) b = (a + 1) % n;
    for (int i = 0; i < n; ++i) {
      p[i][0] = std::ldexp(x(rng), -445);
      for (int c = 1; c < dim; ++c) p[i][c] = std::ldexp(1.0078125, -445);
    }
    if (dim == 3) p[a][1] = std::ldexp(x(rng), -445);
    p[a][dim - 1] = std::ldexp(x(rng), near_far(rng));
    p[b][1] = std::ldexp(x(rng), far_far(rng));
  }
};

int cgal_orientation(const double (*p)[3], int dim) {
  if (dim == 2) return CGAL::orientation(K::Point_2(p[0][0], p[0][1]), K::Point_2(p[1][0], p[1][1]), K::Point_2(p[2][0], p[2][1]));
  return CGAL::orientation(K::Point_3(p[0][0], p[0][1], p[0][2]), K::Point_3(p[1][0], p[1][1], p[1][2]),
                           K::Point_3(p[2][0], p[2][1], p[2][2]), K::Point_3(p[3][0], p[3][1], p[3][2]));
}

// +1 when p[dim + 1] is strictly inside the circle / sphere through the others.
int cgal_inside(const double (*p)[3], int dim) {
  CGAL::Bounded_side s;
  if (dim == 2)
    s = CGAL::side_of_bounded_circle(K::Point_2(p[0][0], p[0][1]), K::Point_2(p[1][0], p[1][1]),
                                     K::Point_2(p[2][0], p[2][1]), K::Point_2(p[3][0], p[3][1]));
  else
    s = CGAL::side_of_bounded_sphere(K::Point_3(p[0][0], p[0][1], p[0][2]), K::Point_3(p[1][0], p[1][1], p[1][2]),
                                     K::Point_3(p[2][0], p[2][1], p[2][2]), K::Point_3(p[3][0], p[3][1], p[3][2]),
                                     K::Point_3(p[4][0], p[4][1], p[4][2]));
  return s == CGAL::ON_BOUNDED_SIDE ? 1 : (s == CGAL::ON_UNBOUNDED_SIDE ? -1 : 0);
}

int insertion_orientation(const double (*p)[3], int dim, bool underflow) {
  namespace f = tessera::front::insertion;
  return dim == 2 ? f::orientation_filter(p[0], p[1], p[2], underflow) : f::orientation_filter(p[0], p[1], p[2], p[3], underflow);
}

int insertion_inside(const double (*p)[3], int dim, bool underflow) {
  namespace f = tessera::front::insertion;
  return dim == 2 ? f::in_circle_filter(p[0], p[1], p[2], p[3], underflow)
                  : f::in_sphere_filter(p[0], p[1], p[2], p[3], p[4], underflow);
}

// Counts, over many mixed configurations, the filters' certain answers that
// differ from CGAL's (and how many were certain at all).
struct Tally {
  long certain = 0, wrong = 0;
  void see(int filter, int exact) {
    if (filter == 0) return;
    ++certain;
    wrong += filter != exact;
  }
};

struct Tallies {
  Tally orient, inside;
};

Tallies run_filters(int dim, bool underflow, int trials, std::uint64_t seed) {
  MixedPoints gen(seed);
  FarRows far(seed + 100);
  Tallies t;
  for (int k = 0; k < trials; ++k) {
    double p[5][3] = {};
    if (k % 4 == 3) far.fill(p, dim);
    else
      for (int i = 0; i <= dim + 1; ++i) gen.next(p[i], dim);
    const int o = cgal_orientation(p, dim);
    t.orient.see(insertion_orientation(p, dim, underflow), o);
    if (o == 0) continue;
    if (o < 0) std::swap(p[0], p[1]);  // the in-sphere filters take a positively oriented simplex
    t.inside.see(insertion_inside(p, dim, underflow), cgal_inside(p, dim));
  }
  return t;
}

TEST(FiltersUnderflow, InsertionFiltersAgreeWithCgal) {
  for (int dim : {2, 3}) {
    SCOPED_TRACE(testing::Message() << "dim " << dim);
    const Tallies t = run_filters(dim, true, 200000, 52 + static_cast<std::uint64_t>(dim));
    EXPECT_EQ(t.orient.wrong, 0);
    EXPECT_EQ(t.inside.wrong, 0);
    // The filters still decide many (2D: most; 3D: 80,562 orientations and
    // 4,590 in-sphere tests of 200,000, as the tiny points' degree-5 terms
    // underflow to zero, and the long double stage takes those).
    EXPECT_GT(t.orient.certain, 40000);
    EXPECT_GT(t.inside.certain, 2000);
  }
  // Without the underflow term (abs_eps alone, what a frame that fits
  // uses) the 3D orientation filter does answer wrong signs here: the test
  // sees the defect it guards against.
  EXPECT_GT(run_filters(3, false, 200000, 55).orient.wrong, 0);
}

// The kernels' orientation (double filter, then long double, then GMP)
// equals CGAL's on the same mixed points, and its filter alone never errs.
TEST(FiltersUnderflow, KernelOrientationEqualsCgal) {
  for (int dim : {2, 3}) {
    MixedPoints gen(60 + static_cast<std::uint64_t>(dim));
    for (int k = 0; k < 100000; ++k) {
      double p[4][3] = {};
      for (int i = 0; i <= dim; ++i) gen.next(p[i], dim);
      const double* pts[4] = {p[0], p[1], p[2], p[3]};
      const int want = cgal_orientation(p, dim);
      ASSERT_EQ(tessera::kernels::orientation(dim, pts), want) << "dim " << dim << " trial " << k;
      double r[3][3] = {};
      const double* rows[3] = {r[0], r[1], r[2]};
      for (int i = 0; i < dim; ++i)
        for (int a = 0; a < dim; ++a) r[i][a] = p[i + 1][a] - p[0][a];
      const int f = tessera::kernels::orientation_filter(dim, rows);
      ASSERT_TRUE(f == 0 || f == want) << "dim " << dim << " trial " << k;
    }
  }
}

// The kernels' in-sphere test (double filter, long double, exact) equals
// CGAL's wherever CGAL's is strict.
TEST(FiltersUnderflow, KernelInSphereEqualsCgal) {
  for (int dim : {2, 3}) {
    MixedPoints gen(70 + static_cast<std::uint64_t>(dim));
    FarRows far(80 + static_cast<std::uint64_t>(dim));
    for (int k = 0; k < 100000; ++k) {
      double p[5][3] = {};
      if (k % 2) far.fill(p, dim);
      else
        for (int i = 0; i <= dim + 1; ++i) gen.next(p[i], dim);
      if (cgal_orientation(p, dim) == 0) continue;  // in_sphere's precondition
      const int want = cgal_inside(p, dim);
      if (want == 0) continue;  // a tie: the perturbation decides, CGAL does not
      tessera::kernels::ExactContext ctx;
      ctx.points = &p[0][0];
      ctx.dim = 3;  // rows of 3 doubles; a 2D test reads x, y of each
      double q[5][2];
      if (dim == 2) {
        for (int i = 0; i < 4; ++i) q[i][0] = p[i][0], q[i][1] = p[i][1];
        ctx.points = &q[0][0];
        ctx.dim = 2;
      }
      ctx.may_underflow = true;
      const std::int32_t planes[3] = {1, 2, 3};
      ASSERT_EQ(tessera::kernels::in_sphere(ctx, 0, planes, dim + 1), want > 0) << "dim " << dim << " trial " << k;
    }
  }
}

// Stop 73's case, from a 187-point input (tests/data/
// insertion_flat_simplex_far_points_3d.npy) in the frame its pass chose:
// three points on one line near 2^-445, one row of about 2^200 and one far
// along z. The long double stage summed its permanents in double, where the
// minor of the three collinear rows underflowed to zero beside the long row's
// squared length of 2^400: the bound was 1e49 times too small, and the test
// called the fifth point inside a sphere it lies outside of. The insertion
// then built a flat tetrahedron and stopped ("vertex planes are dependent").
TEST(FiltersUnderflow, InSphereWhoseMinorUnderflowsBesideALongRow) {
  const double s = std::ldexp(1.0, -446);
  const double raw[5][3] = {{0.0, -0.0078125, 2.4660072906329225e+72},
                            {0.7683581027956148, 1.0078125, 1.0078125},
                            {0.5, 1.0078125, 1.0078125},
                            {0.5, 8.885839264641884e+193, 0.5},
                            {0.25, 1.0078125, 1.0078125}};
  double p[5][3];
  for (int i = 0; i < 5; ++i)
    for (int a = 0; a < 3; ++a) p[i][a] = raw[i][a] * s;
  ASSERT_GT(cgal_orientation(p, 3), 0);
  ASSERT_EQ(cgal_inside(p, 3), -1);
  tessera::kernels::ExactContext ctx;
  ctx.points = &p[0][0];
  ctx.may_underflow = true;
  const std::int32_t planes[3] = {1, 2, 3};
  EXPECT_FALSE(tessera::kernels::in_sphere(ctx, 0, planes, 4));
  EXPECT_FALSE(tessera::kernels::in_sphere_past_filter(ctx, 0, planes, 4));
}

}  // namespace
