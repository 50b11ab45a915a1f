// The walls' exact questions (kernels/walls.hpp) against an oracle in GMP
// rationals: a wall's offset relative to a point (exact_wall_offset, within
// two ulps; exact_wall_point_side, its sign), and a vertex's side of a wall (exact_wall_sign: ties inside),
// for vertices of bisectors, box planes and other walls, on small integer
// coordinates where ties are common.
#include <gmpxx.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "tessera/kernels/exact_predicates.hpp"

namespace {

using namespace tessera::kernels;
using Q = mpq_class;

TEST(WallPredicates, OffsetIsWithinTwoUlpsAndSideIsExact) {
  std::mt19937_64 rng(88);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 20000; ++trial) {
    const int dim = 2 + trial % 2;
    Wall w{};
    double p[3];
    const double scale = std::ldexp(1.0, static_cast<int>(rng() % 600) - 300);
    for (int a = 0; a < dim; ++a) {
      w.n[a] = u(rng) * (trial % 7 == 0 ? 1e-12 : 1.0);
      p[a] = u(rng) * scale;
    }
    w.n[trial % dim] = 1.5;  // |n|_inf in [1, 2)
    // Most walls pass within a few ulps of the point: the offset cancels.
    double dot = 0;
    for (int a = 0; a < dim; ++a) dot += w.n[a] * p[a];
    w.d = trial % 3 == 0 ? u(rng) * scale : dot * (1 + u(rng) * 1e-12 * (trial % 5));
    Q exact = Q(w.d);
    for (int a = 0; a < dim; ++a) exact -= Q(w.n[a]) * Q(p[a]);
    EXPECT_EQ(exact_wall_point_side(w, p, dim), sgn(exact)) << "trial " << trial;
    const double got = exact_wall_offset(w, p, dim);
    const Q err = abs(Q(got) - exact);
    EXPECT_LE(err, abs(exact) * Q(std::ldexp(1.0, -51)))
        << "trial " << trial << ": " << got << " vs " << exact.get_d();
  }
}

// The vertex where planes meet, exactly: rows a.x = b (bisector of points i
// and k: 2 (p_k - p_i).x = |p_k|^2 - |p_i|^2; box plane: x_axis = bound;
// wall: n.x = d), by Cramer's rule.
std::vector<Q> vertex(const ExactContext& ctx, std::int32_t i, const std::int32_t* planes) {
  const int D = ctx.dim;
  Q a[3][3], b[3];
  for (int r = 0; r < D; ++r) {
    const std::int32_t id = planes[r];
    if (id >= 0) {
      b[r] = 0;
      for (int c = 0; c < D; ++c) {
        const Q pk(ctx.points[id * D + c]), pi(ctx.points[i * D + c]);
        a[r][c] = 2 * (pk - pi);
        b[r] += pk * pk - pi * pi;
      }
    } else if (is_wall_plane(id)) {
      const Wall& w = ctx.walls[wall_index(id)];
      for (int c = 0; c < D; ++c) a[r][c] = Q(w.n[c]);
      b[r] = Q(w.d);
    } else {
      const int axis = box_plane_axis(id);
      for (int c = 0; c < D; ++c) a[r][c] = c == axis ? 1 : 0;
      b[r] = Q(box_plane_upper(id) ? ctx.hi[axis] : ctx.lo[axis]);
    }
  }
  auto det = [&](Q m[3][3]) {
    if (D == 2) return Q(m[0][0] * m[1][1] - m[0][1] * m[1][0]);
    return Q(m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
             m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]));
  };
  const Q da = det(a);
  if (da == 0) return {};
  std::vector<Q> v(D);
  for (int c = 0; c < D; ++c) {
    Q m[3][3];
    for (int r = 0; r < D; ++r)
      for (int cc = 0; cc < D; ++cc) m[r][cc] = cc == c ? b[r] : a[r][cc];
    v[c] = det(m) / da;
  }
  return v;
}

TEST(WallPredicates, SideOfAVertexIsTheExactOneWithTiesInside) {
  std::mt19937_64 rng(89);
  std::size_t ties = 0, checked = 0;
  for (int trial = 0; trial < 6000; ++trial) {
    const int D = 2 + trial % 2;
    // Small integers (and halves): bisectors, box planes and walls tie often.
    auto small = [&] { return static_cast<double>(static_cast<int>(rng() % 9) - 4) * 0.5; };
    std::vector<double> pts(6 * D);
    for (double& x : pts) x = small();
    std::vector<Wall> walls(3);
    for (Wall& w : walls) {
      for (int a = 0; a < 3; ++a) w.n[a] = a < D ? small() : 0.0;
      if (w.n[0] == 0 && w.n[1] == 0) w.n[0] = 1;
      w.d = small();
    }
    ExactContext ctx;
    ctx.points = pts.data();
    ctx.dim = D;
    ctx.lo = {-3, -3, -3};
    ctx.hi = {3, 3, 3};
    ctx.walls = walls.data();
    ctx.num_walls = 3;
    // A vertex of cell 0: D planes among bisectors with points 1..5, box planes, walls 0 and 1.
    std::int32_t planes[3];
    for (int r = 0; r < D; ++r) {
      const int kind = static_cast<int>(rng() % 3);
      planes[r] = kind == 0 ? static_cast<std::int32_t>(1 + rng() % 5)
                  : kind == 1 ? box_plane_id(static_cast<int>(rng() % D), rng() % 2 == 1)
                              : wall_plane_id(static_cast<int>(rng() % 2));
    }
    const auto v = vertex(ctx, 0, planes);
    if (v.empty()) continue;  // dependent planes: no vertex
    const Wall& w = walls[2];
    Q side = Q(w.d);
    for (int c = 0; c < D; ++c) side -= Q(w.n[c]) * v[c];
    const int want = side >= 0 ? 1 : -1;
    ties += side == 0;
    ++checked;
    EXPECT_EQ(exact_wall_sign(ctx, 0, planes, 2), want) << "trial " << trial;
  }
  EXPECT_GT(checked, 3000u);
  EXPECT_GT(ties, 30u);  // (64 with this seed)
}

}  // namespace
