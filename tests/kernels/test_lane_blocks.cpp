// LaneBlocks, the sign pass of a huge cell by blocks of vertex slots, against
// filter::classify: the same signs, the same removed slots and the same
// exact evaluations in the same order, slot for slot, whatever the blocks
// skip; and the same largest r2. Vertices lie on curves and sheets (as a
// huge cell's do, slots grouped in space) and scattered at random, with
// some near each plane (the float filter undecided), far, non-finite, and
// within |q|/2 of the generator.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include "tessera/kernels/filter.hpp"
#include "tessera/kernels/lane_blocks.hpp"

namespace {

using tessera::kernels::LaneBlocks;
using tessera::kernels::filter::Bisector;
using tessera::kernels::filter::FilterLanes;
using tessera::kernels::filter::Sign;

struct V {
  double y[3];
  double e;
  double r2;
};

// A vertex at y with a plausible error bound and radius (filter.hpp).
V vertex(double x, double y, double z, double err) {
  V v{{x, y, z}, 0, 0};
  const double ymax = std::max({std::fabs(x), std::fabs(y), std::fabs(z)});
  v.e = err + 16 * 0x1p-53 * ymax;
  v.r2 = (x * x + y * y + z * z + 4 * err * (std::fabs(x) + std::fabs(y) + std::fabs(z) + err)) * (1 + 1e-12);
  return v;
}

// The exact stage's stand-in: any fixed sign per (plane, slot) will do, as
// both passes must ask the same slots.
int fake_exact(std::uint64_t plane, std::size_t t) {
  std::uint64_t h = (plane * 0x9E3779B97F4A7C15ull) ^ (t * 0xC2B2AE3D27D4EB4Full);
  h ^= h >> 29;
  return (h & 1) ? 1 : -1;
}

// What the passes did over a test's planes: it proves nothing unless blocks
// were skipped and others evaluated, vertices removed and signs asked.
struct Tally {
  std::size_t skipped = 0, evaluated = 0, removed = 0, asked = 0;
};

// One plane through both passes; fails on any difference.
void same_pass(const FilterLanes<3>& lanes, LaneBlocks<3>& blocks, const double* q, std::uint64_t plane,
               Tally& tally) {
  const Bisector<3> b(q);
  std::vector<Sign> expected;
  std::vector<std::size_t> asked_classify, asked_blocks;
  const std::size_t removed = tessera::kernels::filter::classify<3>(
      lanes, b.n, b.d, b.n1, b.d_unscaled, expected, [&](std::size_t t) {
        asked_classify.push_back(t);
        return fake_exact(plane, t);
      });
  // classify leaves its signs untouched when it proves nothing removed.
  if (removed == 0) expected.assign(lanes.padded(), 1);
  // Hull keeps +1 outside a pass; a mark here shows which slots were skipped.
  constexpr Sign unread = 2;
  std::vector<Sign> got(lanes.padded(), unread);
  std::vector<std::uint32_t> holes;
  const std::size_t listed = blocks.classify(lanes, b.n, b.d, b.n1, b.d_unscaled, got, holes, [&](std::size_t t) {
    asked_blocks.push_back(t);
    return fake_exact(plane, t);
  });
  ASSERT_EQ(listed, removed) << "plane " << plane;
  EXPECT_EQ(asked_blocks, asked_classify) << "plane " << plane;
  std::vector<std::uint32_t> holes_expected;
  for (std::size_t t = 0; t < lanes.size(); ++t) {
    if (got[t] == unread) {
      ++tally.skipped;
      got[t] = 1;
    } else {
      ++tally.evaluated;
    }
    ASSERT_EQ(got[t], expected[t]) << "plane " << plane << " slot " << t;
    if (expected[t] < 0) holes_expected.push_back(static_cast<std::uint32_t>(t));
  }
  holes.resize(listed);
  EXPECT_EQ(holes, holes_expected) << "plane " << plane;
  tally.removed += removed;
  tally.asked += asked_classify.size();
}

// Vertices of a huge cell's kind: on a parabola-like curve (the cell of a
// point beside a line of points) or a paraboloid (beside a sheet), in the
// order of their slots, with error bounds from tiny to wide.
std::vector<V> curved_vertices(std::size_t n, bool sheet, std::mt19937_64& g) {
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<V> vs;
  const std::size_t side = static_cast<std::size_t>(std::sqrt(double(n))) + 1;
  for (std::size_t t = 0; t < n; ++t) {
    double x, z;
    if (sheet) {
      x = double(t % side) - 0.5 * side + 0.3 * u(g);
      z = double(t / side) - 0.5 * side + 0.3 * u(g);
    } else {
      x = (double(t / 2) - 0.25 * n) * (t % 4 < 2 ? 1 : -1) + 0.3 * u(g);
      z = t % 2 ? 40.0 : -40.0;
    }
    const double y = -100 + (x * x + (sheet ? z * z : 0)) / 400;
    const double err = u(g) < 0.05 ? 1e-3 * u(g) : 1e-12 * u(g);
    vs.push_back(vertex(x, y, z, err));
  }
  return vs;
}

void load(FilterLanes<3>& lanes, LaneBlocks<3>& blocks, const std::vector<V>& vs) {
  lanes.resize(vs.size());
  for (std::size_t t = 0; t < vs.size(); ++t) lanes.set(t, vs[t]);
  blocks.start(vs.size());
}

TEST(LaneBlocks, SignsAreClassifys) {
  std::mt19937_64 g(11);
  std::uniform_real_distribution<double> u(0, 1);
  for (int shape = 0; shape < 4; ++shape) {
    SCOPED_TRACE(shape == 0 ? "curve" : shape == 1 ? "sheet" : shape == 2 ? "scattered" : "tight clusters");
    std::vector<V> vs;
    if (shape < 2) {
      vs = curved_vertices(5000, shape == 1, g);
    } else if (shape == 3) {
      // Blocks of near copies with wide bounds: the planes below pass just
      // beyond them, within their bounds, so the filter cannot decide any
      // though every plane value is positive (a box test without e would
      // skip them).
      for (int c = 0; c < 40; ++c) {
        const double x = 200 * u(g) - 100, y = 200 * u(g) - 100, z = 200 * u(g) - 100;
        for (int k = 0; k < 64; ++k) vs.push_back(vertex(x + 1e-9 * u(g), y + 1e-9 * u(g), z, 1e-4));
      }
    } else {
      for (int t = 0; t < 3001; ++t)  // not a whole number of lane groups
        vs.push_back(vertex(200 * u(g) - 100, 200 * u(g) - 100, 200 * u(g) - 100, 1e-12));
    }
    // Non-finite and near vertices in a few slots.
    if (shape == 3) vs.push_back(vertex(0.01, 0.01, 0.01, 0));
    vs[77] = vertex(std::numeric_limits<double>::infinity(), 1, 1, 0);
    vs[1234].y[1] = std::numeric_limits<double>::quiet_NaN();
    vs[1234].e = std::numeric_limits<double>::quiet_NaN();
    vs[999] = vertex(0.01, -0.02, 0.015, 1e-15);
    FilterLanes<3> lanes;
    LaneBlocks<3> blocks;
    load(lanes, blocks, vs);
    EXPECT_EQ(blocks.max_r2(lanes), lanes.max_r2());
    std::uint64_t plane = 0;
    Tally tally;
    for (int k = 0; k < 300; ++k) {
      // A plane through (or just off) a vertex: q with q.y = |q|^2 / 2 there,
      // q along the vertex's direction tilted a little (a bisector cutting a
      // corner of the cell), or a random q.
      const V& at = vs[g() % vs.size()];
      double q[3];
      if (shape == 3) {
        // q along the cluster's direction, its bisector 1e-6 beyond it
        // (P ~ 1e-6 |q|, the bound ~1e-4 |q|_1).
        const double r = std::sqrt(at.y[0] * at.y[0] + at.y[1] * at.y[1] + at.y[2] * at.y[2]);
        for (int a = 0; a < 3; ++a) q[a] = at.y[a] * 2 * (r + 1e-6) / r;
      } else if (k % 3 == 2 || !std::isfinite(at.y[0] + at.y[1] + at.y[2])) {
        for (double& c : q) c = 400 * u(g) - 200;
      } else {
        double s = 0;
        for (int a = 0; a < 3; ++a) {
          q[a] = at.y[a] * (1 + 0.05 * (u(g) - 0.5));
          s += q[a] * q[a];
        }
        const double dot = q[0] * at.y[0] + q[1] * at.y[1] + q[2] * at.y[2];
        const double f = 2 * dot / s * (k % 3 == 0 ? 1.0 : 1.0 + 1e-14 * (u(g) - 0.5));  // q.y = |q|^2/2
        for (double& c : q) c *= f;
      }
      same_pass(lanes, blocks, q, ++plane, tally);
    }
    // Slots rewritten (a clip's new vertices in its holes), appended and
    // dropped, each touched as Hull does: the summaries follow.
    for (int round = 0; round < 20; ++round) {
      for (int w = 0; w < 40; ++w) {
        const std::size_t t = g() % vs.size();
        vs[t] = vertex(vs[t].y[0] * 0.9, vs[t].y[1] + 3, vs[t].y[2] * 1.1, 1e-10);
        lanes.set(t, vs[t]);
        blocks.touch(t);
      }
      const std::size_t old = vs.size();
      if (round % 2 == 0) {
        for (int w = 0; w < 70; ++w) vs.push_back(vertex(300 * u(g) - 150, 50, 10, 1e-9));
        lanes.resize(vs.size());
        for (std::size_t t = old; t < vs.size(); ++t) {
          lanes.set(t, vs[t]);
          blocks.touch(t);
        }
      } else {
        vs.resize(old - 90);
        lanes.resize(vs.size());
        blocks.touch_range(vs.size(), old);
      }
      EXPECT_EQ(blocks.max_r2(lanes), lanes.max_r2());
      for (int k = 0; k < 20; ++k) {
        const V& at = vs[g() % vs.size()];
        double q[3];
        for (int a = 0; a < 3; ++a) q[a] = std::isfinite(at.y[a]) ? 1.02 * at.y[a] * 2 : 1.0;
        same_pass(lanes, blocks, q, ++plane, tally);
      }
    }
    EXPECT_GT(tally.skipped, shape < 2 ? tally.evaluated : 0);  // a huge cell's are grouped in space
    if (shape == 3) EXPECT_GT(tally.asked, 64u * 300u);
    EXPECT_GT(tally.evaluated, 0u);
    EXPECT_GT(tally.removed, 0u);
    EXPECT_GT(tally.asked, 0u);
    std::printf("[ blocks ] skipped %zu evaluated %zu removed %zu asked %zu\n", tally.skipped, tally.evaluated,
                tally.removed, tally.asked);
  }
}

}  // namespace
