// HullCompletion's gift wrap, one facet at a time, against the triangulation
// itself: wrapping any facet of a Delaunay simplex away from its apex gives
// the apex of the simplex on the other side (or -1 on the hull), and the
// seeds a wrap is given change its work, never its answer.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <random>
#include <vector>

#include "front/hull_completion.hpp"
#include "random_points.hpp"
#include "tessera/delaunay.hpp"

namespace {

using Facet = std::array<std::int32_t, 3>;

// Every facet of the triangulation with the apexes of the (one or two)
// simplices holding it.
std::map<Facet, std::vector<std::int32_t>> facet_apexes(const tessera::Delaunay& dt) {
  std::map<Facet, std::vector<std::int32_t>> out;
  for (std::size_t s = 0; s < dt.n_simplices(); ++s) {
    const std::int32_t* row = dt.simplices.data() + 4 * s;
    for (int k = 0; k < 4; ++k) {
      Facet f;
      for (int m = 0, j = 0; m < 4; ++m)
        if (m != k) f[static_cast<std::size_t>(j++)] = row[m];
      std::sort(f.begin(), f.end());
      out[f].push_back(row[k]);
    }
  }
  return out;
}

void check_wraps(const std::vector<double>& p, std::uint64_t seed) {
  const auto n = static_cast<std::int32_t>(p.size() / 3);
  tessera::DelaunayOptions o;
  o.dim = 3;
  const tessera::Delaunay dt = tessera::delaunay(p, 3, {}, o);
  ASSERT_GT(dt.n_simplices(), 0u);

  // The points' box: the exact context's domain and the diameter the
  // completion's float margins scale with (delaunay.cpp passes the same).
  tessera::kernels::ExactContext ctx;
  ctx.points = p.data();
  ctx.dim = 3;
  double diam2 = 0;
  for (std::size_t d = 0; d < 3; ++d) {
    ctx.lo[d] = ctx.hi[d] = p[d];
    for (std::size_t at = d; at < p.size(); at += 3) {
      ctx.lo[d] = std::min(ctx.lo[d], p[at]);
      ctx.hi[d] = std::max(ctx.hi[d], p[at]);
    }
    diam2 += (ctx.hi[d] - ctx.lo[d]) * (ctx.hi[d] - ctx.lo[d]);
  }
  const std::vector<std::uint8_t> use(static_cast<std::size_t>(n), 1);
  const tessera::front::CandidateTree<3> tree(p, use);
  const tessera::front::HullCompletion<3> hc(ctx, tree, std::sqrt(diam2));

  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<std::int32_t> any(-1, n - 1);
  std::size_t hull = 0, inner = 0;
  for (const auto& [f, apexes] : facet_apexes(dt)) {
    ASSERT_LE(apexes.size(), 2u);
    for (std::size_t a = 0; a < apexes.size(); ++a) {
      const std::int32_t want = apexes.size() == 2 ? apexes[1 - a] : -1;
      (want < 0 ? hull : inner) += 1;
      EXPECT_EQ(hc.wrap(f, apexes[a]), want);
      // Seeds: the answer, the facet's own points and apex, -1, and points
      // anywhere (most of them on the wrong side or worse than the answer).
      std::array<std::int32_t, 8> seeds{any(rng), f[0], apexes[a], -1, any(rng), want, any(rng), f[2]};
      std::shuffle(seeds.begin(), seeds.end(), rng);
      EXPECT_EQ(hc.wrap(f, apexes[a], seeds), want);
      std::array<std::int32_t, 3> wrong{any(rng), any(rng), any(rng)};
      EXPECT_EQ(hc.wrap(f, apexes[a], wrong), want);
    }
  }
  EXPECT_GT(hull, 0u);
  EXPECT_GT(inner, 0u);
}

}  // namespace

TEST(HullCompletion, WrapFindsTheSimplexAcrossWithAnySeeds) {
  check_wraps(uniform_points(150, 3, 11), 1);
  // A shallow cap over a few points below: thin hull simplices with huge
  // circumballs, the wraps hull completion exists for.
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> cap;
  for (int i = 0; i < 120; ++i) {
    const double x = u(rng), y = u(rng);
    cap.insert(cap.end(), {x, y, 1e-4 * (x * x + y * y)});
  }
  for (int i = 0; i < 20; ++i) cap.insert(cap.end(), {u(rng), u(rng), -0.1 * u(rng)});
  check_wraps(cap, 2);
}
