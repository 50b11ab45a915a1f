// The power bisector's offset d (kernels/power.hpp) against GMP rationals.
//
// What this proves: weigh() gives d = (|p_j - p_i|^2 + r_i^2 - r_j^2) / 2
// within 8u|d| of its exact value, the accuracy the float filter's 16u|d|
// assumes with a factor of two to spare, in each of its tiers: far
// candidates (the float d), cancelling ones (the compensated sum), planes
// through p_i to within a few ulps and exact ties (exact_power_offset, which
// must give 0 exactly where d is 0). And power_slack bounds r_max^2 - r_i^2
// from above.
#include <gtest/gtest.h>
#include <gmpxx.h>

#include <cmath>
#include <random>
#include <vector>

#include "tessera/kernels/power.hpp"

namespace {

using tessera::kernels::ExactContext;
namespace filter = tessera::kernels::filter;

mpq_class exact_d(const double* pi, const double* pj, double ri, double rj, int dim) {
  mpq_class s = 0;
  for (int a = 0; a < dim; ++a) {
    const mpq_class q = mpq_class(pj[a]) - mpq_class(pi[a]);
    s += q * q;
  }
  s += mpq_class(ri) * mpq_class(ri) - mpq_class(rj) * mpq_class(rj);
  return s / 2;
}

// weigh()'s d for points i = 0, j = 1 of `pts` with radii `r`, and whether it
// is within 8u|d_exact| (an exact zero must come out as zero).
template <int D>
void expect_accurate(const std::vector<double>& pts, const std::vector<double>& r, int& tried) {
  ExactContext ctx;
  ctx.points = pts.data();
  ctx.dim = D;
  ctx.radii = r.data();
  double q[D];
  for (int a = 0; a < D; ++a) q[a] = pts[D + a] - pts[a];
  filter::Bisector<D> b(q);
  ASSERT_EQ(b.scale, 0);
  tessera::kernels::weigh(b, ctx, 0, 1);
  const mpq_class want = exact_d(pts.data(), pts.data() + D, r[0], r[1], D);
  const mpq_class err = abs(mpq_class(b.d) - want);
  EXPECT_TRUE(err <= mpq_class(8 * filter::u) * abs(want))
      << "d " << b.d << " exact " << want.get_d() << " error " << err.get_d();
  ++tried;
}

template <int D>
void random_planes(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1), pos(0, 1);
  int tried = 0;
  for (int t = 0; t < 20000; ++t) {
    std::vector<double> pts(2 * D);
    for (double& x : pts) x = u(rng);
    double qq = 0;
    for (int a = 0; a < D; ++a) qq += (pts[D + a] - pts[a]) * (pts[D + a] - pts[a]);
    std::vector<double> r(2);
    switch (t % 4) {
      case 0:  // ordinary radii: far and near candidates
        r = {pos(rng), pos(rng)};
        break;
      case 1:  // r_j^2 close to |q|^2 + r_i^2: the plane passes near p_i (d cancels)
        r[0] = pos(rng);
        r[1] = std::sqrt(qq + r[0] * r[0]) * (1 + 1e-9 * u(rng));
        break;
      case 2:  // within a few ulps of through p_i
        r[0] = pos(rng);
        r[1] = std::nextafter(std::sqrt(qq + r[0] * r[0]), 2.0 * (t % 8 < 4));
        break;
      default:  // beyond p_i: d < 0
        r[0] = pos(rng);
        r[1] = std::sqrt(qq + r[0] * r[0]) + pos(rng);
    }
    expect_accurate<D>(pts, r, tried);
    if (::testing::Test::HasFailure()) return;
  }
  EXPECT_EQ(tried, 20000);
}

TEST(PowerOffset, Within8uOfExact2D) { random_planes<2>(71); }
TEST(PowerOffset, Within8uOfExact3D) { random_planes<3>(72); }

// Planes exactly through p_i: 3-4-5 in the plane, r_j^2 = |q|^2 + r_i^2 on
// dyadic values, so d is exactly 0 and must come out as 0.
TEST(PowerOffset, ExactZero) {
  int tried = 0;
  expect_accurate<2>({0.25, 0.5, 0.25 + 0.375, 0.5 + 0.5}, {0.0, 0.625}, tried);  // |q| = 0.625
  expect_accurate<3>({1, 1, 1, 1 + 0.75, 1, 1 + 1}, {0.0, 1.25}, tried);
  expect_accurate<3>({0, 0, 0, 3, 0, 0}, {4, 5}, tried);  // 9 + 16 - 25
  EXPECT_EQ(tried, 3);
  ExactContext ctx;
  const std::vector<double> pts = {0, 0, 0, 3, 0, 0}, r = {4, 5};
  ctx.points = pts.data();
  ctx.dim = 3;
  ctx.radii = r.data();
  EXPECT_EQ(tessera::kernels::exact_power_offset(ctx, 0, 1), 0.0);
  EXPECT_EQ(tessera::kernels::exact_power_offset(ctx, 1, 0), 9.0);  // (9 + 25 - 16) / 2
}

TEST(PowerOffset, SlackBoundsTheWeightSpread) {
  std::mt19937_64 rng(73);
  std::uniform_real_distribution<double> pos(0, 10);
  for (int t = 0; t < 10000; ++t) {
    const double a = pos(rng), b = pos(rng);
    const double rmax = std::max(a, b), ri = std::min(a, b);
    const mpq_class want = mpq_class(rmax) * rmax - mpq_class(ri) * ri;
    EXPECT_TRUE(mpq_class(tessera::kernels::power_slack(rmax, ri)) >= want);
  }
  EXPECT_EQ(tessera::kernels::power_slack(2.5, 2.5), 0.0);
}

}  // namespace
