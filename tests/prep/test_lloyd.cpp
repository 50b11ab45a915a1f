// tessera::lloyd: one step against the brute-force oracle's centroids (walls,
// power cells, periodic and triclinic boxes by explicit images), fixed
// points, the CVT energy's decrease (computed here from each cell's mesh),
// the fixed domain, points without cells, the box of periodic results,
// thread independence, the tolerance, progress and bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <random>
#include <span>
#include <vector>

#include "cells/oracle.hpp"
#include "tessera/cells.hpp"
#include "tessera/prep/lloyd.hpp"

namespace {

using tessera::Bounds;
using tessera::LloydOptions;
using tessera::LloydResult;

std::vector<double> random_points(std::size_t n, int dim, unsigned seed, double lo = 0.0, double hi = 1.0) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(lo, hi);
  std::vector<double> c(n * static_cast<std::size_t>(dim));
  for (double& v : c) v = u(rng);
  return c;
}

Bounds unit_box() { return Bounds{{0, 0, 0}, {1, 1, 1}}; }

bool bit_equal(std::span<const double> a, std::span<const double> b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

LloydResult run(const std::vector<double>& p, int dim, LloydOptions o, std::span<const std::int32_t> labels = {}) {
  return tessera::lloyd(p, dim, labels, o);
}

LloydOptions steps(int iterations, std::optional<Bounds> bounds = unit_box()) {
  LloydOptions o;
  o.iterations = iterations;
  o.voronoi.bounds = bounds;
  return o;
}

// ---------------------------------------------------------------- energy

double dot(const double* a, const double* b, int dim) {
  double s = 0;
  for (int k = 0; k < dim; ++k) s += a[k] * b[k];
  return s;
}

/// The CVT energy sum_i of the integral over cell i of |x - p_i|^2 (minus
/// r_i^2 for power cells: the power energy), exactly from each cell's mesh:
/// the cell as simplices from its generator over its (oriented) faces, each
/// simplex's second moment in closed form, vol / ((d+1)(d+2)) (sum |a_k|^2 +
/// |sum a_k|^2) for vertices a_k relative to the generator (which is one of
/// them). Signed volumes: right where the generator lies outside its power
/// cell too.
double cvt_energy(const std::vector<double>& pts, int dim, const Bounds& domain, const std::vector<double>& radii = {}) {
  tessera::VoronoiOptions o;
  o.bounds = domain;
  o.radii = radii;
  const tessera::Cells c = tessera::voronoi(pts, dim, {}, o);
  const auto du = static_cast<std::size_t>(dim);
  double energy = 0;
  for (std::size_t ci = 0; ci < c.n_cells(); ++ci) {
    const auto g = static_cast<std::size_t>(c.generator[ci]);
    const double* p = pts.data() + g * du;
    const double r2 = radii.empty() ? 0.0 : radii[g] * radii[g];
    for (std::int64_t f = c.cell_face_offsets[ci]; f < c.cell_face_offsets[ci + 1]; ++f) {
      const auto* fv = c.face_vertices.data() + c.face_vertex_offsets[f];
      const std::int64_t m = c.face_vertex_offsets[f + 1] - c.face_vertex_offsets[f];
      auto rel = [&](std::int32_t v, double* a) {
        for (std::size_t k = 0; k < du; ++k) a[k] = c.vertices[static_cast<std::size_t>(v) * du + k] - p[k];
      };
      if (dim == 2) {
        double a[2], b[2];
        rel(fv[0], a);
        rel(fv[1], b);
        const double area = 0.5 * (a[0] * b[1] - a[1] * b[0]);
        const double s[2] = {a[0] + b[0], a[1] + b[1]};
        energy += area / 12 * (dot(a, a, 2) + dot(b, b, 2) + dot(s, s, 2)) - r2 * area;
        continue;
      }
      double a0[3];
      rel(fv[0], a0);
      for (std::int64_t k = 1; k + 1 < m; ++k) {
        double a1[3], a2[3];
        rel(fv[k], a1);
        rel(fv[k + 1], a2);
        const double cr[3] = {a1[1] * a2[2] - a1[2] * a2[1], a1[2] * a2[0] - a1[0] * a2[2],
                              a1[0] * a2[1] - a1[1] * a2[0]};
        const double vol = dot(a0, cr, 3) / 6;
        const double s[3] = {a0[0] + a1[0] + a2[0], a0[1] + a1[1] + a2[1], a0[2] + a1[2] + a2[2]};
        energy += vol / 20 * (dot(a0, a0, 3) + dot(a1, a1, 3) + dot(a2, a2, 3) + dot(s, s, 3)) - r2 * vol;
      }
    }
  }
  return energy;
}

// ------------------------------------------------------------------ tests

// One iteration moves each point to the centroid of its cell as the
// brute-force oracle clips it (the box cut by every bisector), given bounds
// and the default domain (the oracle's box: the domain the result reports).
TEST(PrepLloyd, OneStepMatchesTheOracle) {
  for (const int dim : {2, 3}) {
    const std::size_t n = dim == 2 ? 80 : 40;
    const auto p = random_points(n, dim, 1 + dim);
    for (const bool given : {true, false}) {
      const LloydResult r = run(p, dim, steps(1, given ? std::optional<Bounds>(unit_box()) : std::nullopt));
      ASSERT_EQ(r.iterations, 1);
      ASSERT_TRUE(r.domain.has_value());
      if (given) {
        EXPECT_EQ(r.domain->lo, unit_box().lo);
        EXPECT_EQ(r.domain->hi, unit_box().hi);
      }
      EXPECT_EQ(r.moved.front(), n);
      double largest = 0;
      for (std::size_t i = 0; i < n; ++i) {
        const oracle::Cell c = oracle::cell(p, dim, i, r.domain->lo, r.domain->hi);
        double d = 0;
        for (int a = 0; a < dim; ++a) {
          EXPECT_NEAR(r.points[i * dim + a], c.centroid[a], 1e-12) << dim << " " << given << " " << i;
          d += (c.centroid[a] - p[i * dim + a]) * (c.centroid[a] - p[i * dim + a]);
        }
        largest = std::max(largest, std::sqrt(d));
      }
      EXPECT_NEAR(r.largest_displacement.front(), largest, 1e-12);
      EXPECT_LE(r.rms_displacement.front(), r.largest_displacement.front());
      EXPECT_GT(r.rms_displacement.front(), 0);
    }
  }
}

// The weighted step: each point to its power cell's centroid (the oracle
// clips by radical planes); a point whose power cell is empty stays.
TEST(PrepLloyd, PowerStepMatchesTheOracle) {
  for (const int dim : {2, 3}) {
    const std::size_t n = dim == 2 ? 80 : 40;
    const auto p = random_points(n, dim, 11 + dim);
    std::vector<double> radii = random_points(n, 1, 21 + dim, 0.0, dim == 2 ? 0.12 : 0.25);
    radii[3] = 0;  // (small among large radii: some cells are empty)
    LloydOptions o = steps(1);
    o.voronoi.radii = radii;
    const LloydResult r = run(p, dim, o);
    std::size_t with_cells = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const oracle::Cell c = oracle::cell(p, dim, i, r.domain->lo, r.domain->hi, radii);
      const bool stays = c.volume <= 0;
      with_cells += !stays;
      for (int a = 0; a < dim; ++a) {
        if (stays)
          EXPECT_EQ(r.points[i * dim + a], p[i * dim + a]) << dim << " " << i;
        else
          EXPECT_NEAR(r.points[i * dim + a], c.centroid[a], 1e-12) << dim << " " << i;
      }
    }
    EXPECT_EQ(r.moved.front(), with_cells);
  }
}

/// A periodic box's step by the oracle: each point's cell among its explicit
/// images (shifts -2..2 of the lattice vectors, in a box wide enough not to
/// clip), its centroid wrapped into the box; compared by the shortest
/// lattice-reduced difference (a point near a face may wrap to either side
/// of it, by rounding).
TEST(PrepLloyd, PeriodicStepMatchesTheOracleOfImages) {
  struct Case {
    int dim;
    std::array<double, 3> lo, hi, tilt;
    std::array<bool, 3> periodic;
  };
  const Case cases[] = {
      {2, {0, 0, 0}, {2, 1, 0}, {0, 0, 0}, {true, true, false}},
      {3, {0, 0, 0}, {1, 1, 1}, {0, 0, 0}, {true, true, true}},
      {3, {-1, 0, 2}, {0, 1.5, 3}, {0.3, -0.2, 0.4}, {true, true, true}},
      {2, {0, 0, 0}, {1, 1, 0}, {0.4, 0, 0}, {true, true, false}},
  };
  for (const Case& k : cases) {
    const int dim = k.dim;
    const auto du = static_cast<std::size_t>(dim);
    const std::size_t n = dim == 2 ? 60 : 40;
    Bounds box{k.lo, k.hi};
    const auto lattice = tessera::periodic_lattice(box, k.tilt);
    // Points inside the parallelepiped (fractional coordinates in [0, 1)).
    const auto f = random_points(n, dim, 31 + dim);
    std::vector<double> p(n * du);
    for (std::size_t i = 0; i < n; ++i) {
      const std::array<double, 3> s{f[i * du], f[i * du + 1], dim == 3 ? f[i * du + 2] : 0.0};
      double x[3];
      const double lo[3] = {k.lo[0], k.lo[1], k.lo[2]};
      tessera::periodic_image(lattice, dim, lo, s, x);
      for (std::size_t a = 0; a < du; ++a) p[i * du + a] = x[a];
    }
    LloydOptions o;
    o.iterations = 1;
    o.voronoi.bounds = box;
    o.voronoi.periodic = k.periodic;
    o.voronoi.tilt = k.tilt;
    const LloydResult r = run(p, dim, o);
    ASSERT_EQ(r.moved.front(), n);
    // The images, point i at shift 0 at index `home * n + i`.
    std::vector<double> images;
    std::size_t home = 0, shifts = 0;
    const int reach = 2;
    std::array<double, 3> big_lo{0, 0, 0}, big_hi{0, 0, 0};
    for (std::size_t a = 0; a < du; ++a) {
      const double l = k.hi[a] - k.lo[a] + std::fabs(k.tilt[0]) + std::fabs(k.tilt[1]) + std::fabs(k.tilt[2]);
      big_lo[a] = k.lo[a] - 3 * l;
      big_hi[a] = k.hi[a] + 3 * l;
    }
    for (int s0 = -reach; s0 <= reach; ++s0)
      for (int s1 = -reach; s1 <= reach; ++s1)
        for (int s2 = (dim == 3 ? -reach : 0); s2 <= (dim == 3 ? reach : 0); ++s2) {
          if (s0 == 0 && s1 == 0 && s2 == 0) home = shifts;
          ++shifts;
          const std::array<int, 3> s{s0, s1, s2};
          for (std::size_t i = 0; i < n; ++i) {
            double x[3];
            tessera::periodic_image(lattice, dim, p.data() + i * du, s, x);
            images.insert(images.end(), x, x + du);
          }
        }
    for (std::size_t i = 0; i < n; ++i) {
      const oracle::Cell c = oracle::cell(images, dim, home * n + i, big_lo, big_hi);
      // The difference, reduced by whole lattice vectors (lower triangular).
      double d[3] = {0, 0, 0};
      for (std::size_t a = 0; a < du; ++a) d[a] = r.points[i * du + a] - c.centroid[a];
      for (std::size_t a = du; a-- > 0;) {
        const double t = std::nearbyint(d[a] / lattice[a][a]);
        for (std::size_t b = 0; b <= a; ++b) d[b] -= t * lattice[a][b];
      }
      EXPECT_LT(std::hypot(d[0], d[1], d[2]), 1e-12) << dim << " " << i;
      // In the box: fractional coordinates in [0, 1), up to rounding.
      double fr[3] = {0, 0, 0}, x[3];
      for (std::size_t a = 0; a < du; ++a) x[a] = r.points[i * du + a] - k.lo[a];
      for (std::size_t a = du; a-- > 0;) {
        fr[a] = x[a] / lattice[a][a];
        for (std::size_t b = 0; b < a; ++b) x[b] -= fr[a] * lattice[a][b];
      }
      for (std::size_t a = 0; a < du; ++a) {
        EXPECT_GE(fr[a], -1e-12) << i;
        EXPECT_LT(fr[a], 1 + 1e-12) << i;
      }
    }
  }
}

// Cell centres of a k^D lattice are the centroids of their (cubic) cells:
// nothing moves, with walls and in a periodic box.
TEST(PrepLloyd, LatticeOfCellCentresIsAFixedPoint) {
  for (const int dim : {2, 3}) {
    const int k = dim == 2 ? 8 : 5;
    std::vector<double> p;
    for (int i = 0; i < k; ++i)
      for (int j = 0; j < k; ++j)
        for (int l = 0; l < (dim == 3 ? k : 1); ++l) {
          p.push_back((i + 0.5) / k);
          p.push_back((j + 0.5) / k);
          if (dim == 3) p.push_back((l + 0.5) / k);
        }
    for (const bool periodic : {false, true}) {
      LloydOptions o = steps(3);
      if (periodic) o.voronoi.periodic = {true, true, dim == 3};
      const LloydResult r = run(p, dim, o);
      ASSERT_EQ(r.iterations, 3);
      for (std::size_t q = 0; q < p.size(); ++q) EXPECT_NEAR(r.points[q], p[q], 1e-15) << dim << " " << q;
      for (const double d : r.largest_displacement) EXPECT_LE(d, 1e-15);
    }
  }
}

// Lloyd's step lowers the CVT energy within one domain (Du, Faber and
// Gunzburger 1999, §2): the centroid minimises each cell's integral, and the
// Voronoi cells minimise it for the moved points. A wrong centroid or a
// step in another domain breaks it. Also the power energy with radii.
TEST(PrepLloyd, EnergyDecreasesAtEveryStep) {
  for (const int dim : {2, 3}) {
    for (const bool power : {false, true}) {
      for (const bool given : {true, false}) {
        const std::size_t n = dim == 2 ? 300 : 120;
        std::vector<double> p = random_points(n, dim, 41 + dim + 2 * power);
        // Clustered: the first steps move far.
        for (std::size_t q = 0; q < p.size(); ++q) p[q] = 0.2 + 0.6 * p[q] * p[q];
        std::vector<double> radii;
        if (power) radii = random_points(n, 1, 51 + dim, 0.0, 0.05);
        LloydOptions o = steps(1, given ? std::optional<Bounds>(unit_box()) : std::nullopt);
        o.voronoi.radii = radii;
        const Bounds domain = *run(p, dim, o).domain;
        o.voronoi.bounds = domain;  // each single step in that domain, as the iterations take it
        double before = cvt_energy(p, dim, domain, radii);
        std::vector<double> q = p;
        for (int step = 1; step <= 8; ++step) {
          q = run(q, dim, o).points;
          const double after = cvt_energy(q, dim, domain, radii);
          EXPECT_LE(after, before + 1e-12 * std::fabs(before)) << dim << " " << power << " " << given << " " << step;
          before = after;
          // The same as `step` iterations at once (the domain kept).
          LloydOptions all = o;
          all.iterations = step;
          all.voronoi.bounds = given ? std::optional<Bounds>(unit_box()) : std::nullopt;
          EXPECT_TRUE(bit_equal(run(p, dim, all).points, q)) << dim << " " << power << " " << given << " " << step;
        }
        EXPECT_LT(before, 0.9 * cvt_energy(p, dim, domain, radii));  // it did relax
      }
    }
  }
}

// The default domain is the first iteration's, given to every later one:
// the result is that of the same iterations with that domain as bounds, and
// stays in it. (Steps each with its own default domain differ: with a wide
// padding the outer points move out into it, and the next box grows.)
TEST(PrepLloyd, DefaultDomainIsTheFirstIterationsAndStaysFixed) {
  for (const int dim : {2, 3}) {
    const auto p = random_points(dim == 2 ? 500 : 200, dim, 61 + dim);
    tessera::VoronoiOptions vo;
    vo.padding = 0.5;
    const Bounds first = tessera::voronoi(p, dim, {}, vo).bounds;
    LloydOptions o = steps(4, std::nullopt);
    o.voronoi.padding = 0.5;
    const LloydResult r = run(p, dim, o);
    EXPECT_EQ(r.domain->lo, first.lo);
    EXPECT_EQ(r.domain->hi, first.hi);
    EXPECT_TRUE(bit_equal(r.points, run(p, dim, steps(4, first)).points));
    for (std::size_t i = 0; i < r.points.size(); ++i) {
      const auto a = i % static_cast<std::size_t>(dim);
      EXPECT_GE(r.points[i], first.lo[a]);
      EXPECT_LE(r.points[i], first.hi[a]);
    }
    std::vector<double> q = p;
    Bounds last = first;
    o.iterations = 1;
    for (int s = 0; s < 4; ++s) {
      const LloydResult one = run(q, dim, o);
      q = one.points;
      last = *one.domain;
    }
    EXPECT_FALSE(bit_equal(q, r.points));
    EXPECT_LT(last.lo[0], first.lo[0]);
    EXPECT_GT(last.hi[0], first.hi[0]);
  }
}

// Points that own no cell keep their bits: outside points, the copy of a
// duplicate (its owner moves, and the next iteration separates them),
// points set aside by ignore_outside (outside the bounds, or not finite).
// Labels stay with their points (the order never changes).
TEST(PrepLloyd, PointsWithoutCellsStayBitForBit) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const int dim : {2, 3}) {
    const auto du = static_cast<std::size_t>(dim);
    const std::size_t n = 200;
    auto p = random_points(n, dim, 71 + dim);
    std::vector<std::int32_t> labels(n, 1);
    for (std::size_t i = 0; i < n; i += 10) labels[i] = -1;  // fixed samples
    for (std::size_t a = 0; a < du; ++a) p[7 * du + a] = p[5 * du + a];  // 7 duplicates 5, which owns the cell
    p[11 * du] = 1.5;                                                     // outside the bounds
    p[13 * du + 1] = nan;                                                 // not finite
    LloydOptions o = steps(1);
    o.voronoi.ignore_outside_points = true;
    const LloydResult one = run(p, dim, o, labels);
    const LloydResult two = run(p, dim, [&] { auto t = o; t.iterations = 2; return t; }(), labels);
    auto row = [&](const std::vector<double>& v, std::size_t i) { return std::span<const double>(v).subspan(i * du, du); };
    std::size_t stays = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const bool no_cell = labels[i] < 0 || i == 7 || i == 11 || i == 13;
      stays += no_cell;
      if (no_cell) {
        EXPECT_TRUE(bit_equal(row(one.points, i), row(p, i))) << dim << " " << i;
      } else {
        EXPECT_FALSE(bit_equal(row(one.points, i), row(p, i))) << dim << " " << i;
      }
      if (labels[i] < 0 || i == 11 || i == 13) EXPECT_TRUE(bit_equal(row(two.points, i), row(p, i))) << i;
    }
    EXPECT_EQ(one.moved.front(), n - stays);
    // The duplicate's copy moved in the second iteration, apart from its owner.
    EXPECT_FALSE(bit_equal(row(two.points, 7), row(p, 7)));
    EXPECT_FALSE(bit_equal(row(two.points, 7), row(two.points, 5)));
    EXPECT_EQ(two.moved.back(), n - stays + 1);
  }
}

// Periodic results lie in the box, however far out the points were given
// (the cells wrap them; the moved points are wrapped back), walls kept on
// the axes that have them.
TEST(PrepLloyd, PeriodicResultsLieInTheBox) {
  const int dim = 3;
  const std::size_t n = 500;
  auto p = random_points(n, dim, 81);
  for (std::size_t i = 0; i < n; i += 3) {
    p[i * 3] += (i % 2 ? 3.0 : -2.0);  // x: periods away
    p[i * 3 + 1] -= 1.0;               // y: one period below
  }
  LloydOptions o = steps(3);
  o.voronoi.periodic = {true, true, false};  // z has walls
  const LloydResult r = run(p, dim, o);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t a = 0; a < 3; ++a) {
      EXPECT_GE(r.points[i * 3 + a], 0.0) << i << " " << a;
      if (a < 2)
        EXPECT_LT(r.points[i * 3 + a], 1.0) << i << " " << a;
      else
        EXPECT_LE(r.points[i * 3 + a], 1.0) << i;
    }
}

// Byte-identical for 1 and 2 threads: ordinary, periodic (triclinic) and
// power cells.
TEST(PrepLloyd, SameResultForAnyThreadCount) {
  const std::size_t n = 3000;
  for (const int variant : {0, 1, 2}) {
    const auto p = random_points(n, 3, 91 + variant);
    const auto radii = random_points(n, 1, 95, 0.0, 0.03);
    LloydOptions o = steps(3);
    if (variant == 1) {
      o.voronoi.periodic = {true, true, true};
      o.voronoi.tilt = {0.2, 0.1, -0.3};
    }
    if (variant == 2) o.voronoi.radii = radii;
    o.voronoi.threads = 1;
    const LloydResult a = run(p, 3, o);
    o.voronoi.threads = 2;
    const LloydResult b = run(p, 3, o);
    EXPECT_TRUE(bit_equal(a.points, b.points)) << variant;
    EXPECT_TRUE(bit_equal(a.largest_displacement, b.largest_displacement)) << variant;
    EXPECT_TRUE(bit_equal(a.rms_displacement, b.rms_displacement)) << variant;
    EXPECT_EQ(a.moved, b.moved);
  }
}

// The tolerance stops after the first iteration whose largest displacement
// is within it (times the mean spacing), and the iterations done are those
// of a run asked for exactly that many.
TEST(PrepLloyd, ToleranceStopsEarly) {
  for (const int dim : {2, 3}) {
    const std::size_t n = dim == 2 ? 400 : 200;
    const auto p = random_points(n, dim, 101 + dim);
    LloydOptions o = steps(2000);
    o.tolerance = 1e-2;
    const LloydResult r = run(p, dim, o);
    ASSERT_GT(r.iterations, 1);
    ASSERT_LT(r.iterations, 2000);
    EXPECT_EQ(r.largest_displacement.size(), static_cast<std::size_t>(r.iterations));
    EXPECT_NEAR(r.spacing, std::pow(1.0 / n, 1.0 / dim), 1e-15);
    EXPECT_LE(r.largest_displacement.back(), o.tolerance * r.spacing);
    EXPECT_GT(r.largest_displacement[r.largest_displacement.size() - 2], o.tolerance * r.spacing);
    const LloydResult same = run(p, dim, steps(r.iterations));
    EXPECT_TRUE(bit_equal(same.points, r.points));
    EXPECT_TRUE(bit_equal(same.largest_displacement, r.largest_displacement));
  }
}

TEST(PrepLloyd, ZeroIterationsReturnTheInput) {
  const auto p = random_points(50, 3, 111);
  const LloydResult r = run(p, 3, steps(0));
  EXPECT_TRUE(bit_equal(r.points, p));
  EXPECT_EQ(r.iterations, 0);
  EXPECT_TRUE(r.largest_displacement.empty() && r.rms_displacement.empty() && r.moved.empty());
  EXPECT_FALSE(r.domain.has_value());
  EXPECT_EQ(r.spacing, 0);
}

// The callback sees the fraction of all iterations, rising to 1; one that
// throws Cancelled stops the run, inside an iteration's cells or between
// iterations.
TEST(PrepLloyd, ProgressCoversEveryIterationAndCancels) {
  const auto p = random_points(60000, 3, 121);
  LloydOptions o = steps(3);
  std::vector<double> seen;
  o.voronoi.progress = [&](double f) { seen.push_back(f); };
  const LloydResult r = run(p, 3, o);
  ASSERT_GE(seen.size(), 6u);
  EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
  EXPECT_GE(seen.front(), 0.0);
  EXPECT_EQ(seen.back(), 1.0);
  EXPECT_TRUE(std::any_of(seen.begin(), seen.end(), [](double f) { return f > 0.34 && f < 0.66; }));
  o.voronoi.progress = nullptr;
  EXPECT_TRUE(bit_equal(run(p, 3, o).points, r.points));
  for (const double at : {0.5, 2.0 / 3}) {
    int after = 0;
    o.voronoi.progress = [&](double f) {
      if (f >= at) {
        ++after;
        throw tessera::Cancelled();
      }
    };
    EXPECT_THROW(run(p, 3, o), tessera::Cancelled);
    EXPECT_EQ(after, 1);
  }
}

TEST(PrepLloyd, BadInput) {
  const auto p = random_points(30, 3, 131);
  auto refused = [&](LloydOptions o, std::span<const double> pts, int dim = 3, std::vector<std::int32_t> labels = {}) {
    EXPECT_THROW(tessera::lloyd(pts, dim, labels, o), tessera::InputError);
  };
  refused(steps(-1), p);
  for (const double t : {-1.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    LloydOptions o = steps(2);
    o.tolerance = t;
    refused(o, p);
  }
  LloydOptions only = steps(2);
  const std::vector<std::int32_t> ids = {1};
  only.voronoi.only = ids;
  refused(only, p);
  refused(steps(2), p, 4);
  refused(steps(0), std::vector<double>(7, 0.5));  // shapes are checked with 0 iterations too
  refused(steps(0), {});
  refused(steps(0), p, 3, std::vector<std::int32_t>(29, 0));
  LloydOptions radii = steps(0);
  const std::vector<double> r(29, 0.1);
  radii.voronoi.radii = r;
  refused(radii, p);
  auto outside = p;
  outside[5] = 2.0;
  refused(steps(2), outside);  // voronoi()'s own refusals come through
  LloydOptions periodic;
  periodic.voronoi.periodic = {true, true, true};
  refused(periodic, p);  // no bounds
}

}  // namespace
