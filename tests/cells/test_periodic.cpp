// Periodic boxes (VoronoiOptions::periodic).
//
// What this proves:
// * every cell equals the brute-force oracle's cell of the point among its
//   explicit images (volume to 1e-12, and the same faces: neighbour and
//   shift), fully and partly periodic, 2D and 3D, down to boxes of one to
//   three points, whose cells need images several periods out;
// * across the box's faces the cells agree as inside it, ties included: on
//   lattices every neighbour entry (i, j, s) has its twin (j, i, -s), the
//   volumes tile the box, and 1 and 2 threads give identical bytes;
// * points outside the box along a periodic axis are wrapped in;
// * what is refused: no bounds, a z axis in 2D;
// * face sets list each face once with the image it meets, on its bisector,
//   and each region's faces close up modulo the lattice;
// * the same for triclinic boxes (tilts), against the oracle among images
//   by the sheared lattice vectors, and two bases of one lattice agree.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <tuple>
#include <vector>

#include "helpers.hpp"
#include "oracle.hpp"
#include "tessera/delaunay.hpp"
#include "tessera/faces.hpp"
#include "tessera/flower.hpp"
#include "tessera/graph.hpp"
#include "tessera/io/points.hpp"

namespace {

using namespace cells_test;
using Shift = std::array<int, 3>;
using Entry = std::pair<std::int32_t, Shift>;

/// Points on a grid of 2^-30 in the box (snapping leaves them as they are,
/// so the test's explicit images are the library's).
std::vector<double> grid_aligned(std::size_t n, int dim, std::uint64_t seed, const tessera::Bounds& b) {
  auto p = random_points(n, dim, seed, b);
  for (double& x : p) x = std::ldexp(std::floor(std::ldexp(x, 30)), -30);
  return p;
}

using Tilt = std::array<double, 3>;  // xy, xz, yz

tessera::VoronoiOptions periodic_options(int dim, const tessera::Bounds& box, std::array<bool, 3> periodic,
                                         int threads = 1, const Tilt& tilt = {0, 0, 0}) {
  auto o = options(dim, box, threads);
  o.periodic = periodic;
  o.tilt = tilt;
  return o;
}

tessera::Cells run_periodic(const std::vector<double>& pts, int dim, const tessera::Bounds& box,
                            std::array<bool, 3> periodic, int threads = 1,
                            const std::vector<std::int32_t>& labels = {}, const Tilt& tilt = {0, 0, 0}) {
  return tessera::voronoi(pts, dim, labels, periodic_options(dim, box, periodic, threads, tilt));
}

/// The box's lattice vectors (VoronoiOptions::tilt): v[i] along axis i.
std::array<std::array<double, 3>, 3> lattice(const tessera::Bounds& box, const Tilt& t) {
  return {{{box.hi[0] - box.lo[0], 0, 0}, {t[0], box.hi[1] - box.lo[1], 0}, {t[1], t[2], box.hi[2] - box.lo[2]}}};
}

/// Points inside a triclinic box (fractional coordinates in [2^-20, 1 -
/// 2^-20), so that rounding to 2^-30 leaves them inside and wrapping as they are).
std::vector<double> in_parallelepiped(std::size_t n, int dim, std::uint64_t seed, const tessera::Bounds& box,
                                      const Tilt& tilt) {
  const auto du = static_cast<std::size_t>(dim);
  const auto f = random_points(n, dim, seed, make_bounds({0x1p-20, 0x1p-20, 0x1p-20}, {1 - 0x1p-20, 1 - 0x1p-20, 1 - 0x1p-20}));
  const auto v = lattice(box, tilt);
  std::vector<double> p(n * du);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t a = 0; a < du; ++a) {
      double x = box.lo[a];
      for (std::size_t b = a; b < du; ++b) x += f[i * du + b] * v[b][a];
      p[i * du + a] = std::ldexp(std::floor(std::ldexp(x, 30)), -30);
    }
  return p;
}

/// Each cell's (neighbour, shift) entries.
std::vector<std::vector<Entry>> entries(const tessera::Cells& c) {
  std::vector<std::vector<Entry>> out(c.n_cells());
  const auto du = static_cast<std::size_t>(c.dim);
  EXPECT_EQ(c.neighbor_shifts.size(), c.neighbors.size() * du);
  for (std::size_t k = 0; k < c.n_cells(); ++k)
    for (auto e = c.neighbor_offsets[k]; e < c.neighbor_offsets[k + 1]; ++e) {
      const auto eu = static_cast<std::size_t>(e);
      Shift s{0, 0, 0};
      for (std::size_t a = 0; a < du; ++a) s[a] = c.neighbor_shifts[eu * du + a];
      out[k].push_back({c.neighbors[eu], s});
    }
  return out;
}

/// Entries (i, j, s) without as many twins (j, i, -s).
std::size_t asymmetric_entries(const tessera::Cells& c) {
  std::map<std::tuple<std::int32_t, std::int32_t, Shift>, int> count;
  const auto e = entries(c);
  for (std::size_t cell = 0; cell < e.size(); ++cell)
    for (const auto& [j, s] : e[cell]) ++count[{c.generator[cell], j, s}];
  std::size_t asymmetric = 0;
  for (const auto& [key, m] : count) {
    const auto& [i, j, s] = key;
    const auto it = count.find({j, i, Shift{-s[0], -s[1], -s[2]}});
    asymmetric += it == count.end() || it->second != m;
  }
  return asymmetric;
}

/// Each point's cell among its explicit images (shifts within `reach`
/// periods on periodic axes), by the oracle, with its faces as entries.
/// `ties`: a box of a few points, whose images form lattices: a cell that
/// meets four images of one point on a rectangle has a tie there, which the
/// symbolic perturbation settles with faces of no area that the oracle's
/// plain doubles settle otherwise (with faces of rounding-noise area, or
/// none). Then the oracle's faces of some area must be among the cell's.
void compare_with_oracle(const std::vector<double>& pts, int dim, const tessera::Bounds& box,
                         std::array<bool, 3> periodic, int reach, const std::string& what, bool ties = false,
                         const Tilt& tilt = {0, 0, 0}) {
  SCOPED_TRACE(what);
  const auto du = static_cast<std::size_t>(dim);
  const std::size_t n = pts.size() / du;
  const tessera::Cells c = run_periodic(pts, dim, box, periodic, 1, {}, tilt);
  const auto v = lattice(box, tilt);
  ASSERT_EQ(c.n_cells(), n);
  std::vector<double> all;
  std::vector<Entry> label;
  std::vector<std::size_t> original(n);
  int k[3] = {0, 0, 0};
  for (std::size_t a = 0; a < du; ++a) k[a] = periodic[a] ? reach : 0;
  for (std::size_t i = 0; i < n; ++i)
    for (int s0 = -k[0]; s0 <= k[0]; ++s0)
      for (int s1 = -k[1]; s1 <= k[1]; ++s1)
        for (int s2 = -k[2]; s2 <= k[2]; ++s2) {
          const Shift s{s0, s1, s2};
          if (s == Shift{0, 0, 0}) original[i] = label.size();
          for (std::size_t a = 0; a < du; ++a) {
            double x = pts[i * du + a];
            for (std::size_t b = a; b < du; ++b) x += s[b] * v[b][a];
            all.push_back(x);
          }
          label.push_back({static_cast<std::int32_t>(i), s});
        }
  std::array<double, 3> lo = box.lo, hi = box.hi;
  for (std::size_t a = 0; a < du; ++a)
    if (periodic[a]) {
      double span = 0;
      for (std::size_t b = a; b < du; ++b) span += std::fabs(v[b][a]);
      lo[a] -= (reach + 1) * span;
      hi[a] += (reach + 1) * span;
    }
  const auto got = entries(c);
  double total = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const oracle::Cell o = oracle::cell(all, dim, original[i], lo, hi);
    const auto cell = static_cast<std::size_t>(c.cell_of[i]);
    total += c.volume[cell];
    EXPECT_NEAR(c.volume[cell], o.volume, 1e-12 * o.volume) << "point " << i;
    std::vector<Entry> want;
    for (const auto& [lab, area] : o.face) {
      if (lab < 0) {  // a wall: only along axes that are not periodic
        ASSERT_FALSE(periodic[static_cast<std::size_t>((-lab - 1) / 2)])
            << "point " << i << ": the oracle's cell reaches its box (widen `reach`)";
        continue;
      }
      if (ties && area <= 1e-9 * std::pow(o.volume, (dim - 1.0) / dim)) continue;
      want.push_back(label[static_cast<std::size_t>(lab)]);
    }
    std::sort(want.begin(), want.end());
    if (ties)
      EXPECT_TRUE(std::includes(got[cell].begin(), got[cell].end(), want.begin(), want.end())) << "point " << i;
    else
      EXPECT_EQ(got[cell], want) << "point " << i;
  }
  EXPECT_NEAR(total, box_volume(c.bounds, dim), 1e-12 * box_volume(c.bounds, dim));
}

TEST(Periodic, EqualsTheOracleAmongExplicitImages) {
  const auto box3 = make_bounds({-1, 0, 2}, {1, 1.5, 3});
  compare_with_oracle(grid_aligned(150, 3, 1, box3), 3, box3, {true, true, true}, 1, "3D xyz");
  compare_with_oracle(grid_aligned(150, 3, 2, box3), 3, box3, {true, false, false}, 1, "3D x");
  compare_with_oracle(grid_aligned(150, 3, 3, box3), 3, box3, {false, true, true}, 1, "3D yz");
  const auto box2 = make_bounds({0.5, -2, 0}, {1.5, 0, 0});
  compare_with_oracle(grid_aligned(300, 2, 4, box2), 2, box2, {true, true, false}, 1, "2D xy");
  compare_with_oracle(grid_aligned(300, 2, 5, box2), 2, box2, {false, true, false}, 1, "2D y");
}

TEST(Periodic, BoxesOfAFewPointsReachSeveralPeriods) {
  // One point's cell is the box about it; two or three meet their own
  // images and each other's: the layer is widened to what they ask.
  const auto box3 = make_bounds({0, 0, 0}, {1, 2, 1});
  const auto box2 = make_bounds({0, 0, 0}, {3, 1, 0});
  for (std::size_t n : {1, 2, 3, 5}) {
    compare_with_oracle(grid_aligned(n, 3, 10 + n, box3), 3, box3, {true, true, true}, 2,
                        "3D, " + std::to_string(n) + " points", true);
    compare_with_oracle(grid_aligned(n, 2, 20 + n, box2), 2, box2, {true, true, false}, 3,
                        "2D, " + std::to_string(n) + " points", true);
  }
  // One point: its cell is the box about it, bounded by its own images (a
  // lattice: its corners are ties, each settled with faces of no area).
  const tessera::Cells one = run_periodic({0.25, 0.5, 0.75}, 3, box3, {true, true, true});
  EXPECT_EQ(one.volume[0], 2.0);
  for (std::int32_t j : one.neighbors) EXPECT_EQ(j, 0);
  const tessera::ValidationReport r = tessera::validate(one, {}, std::vector<double>{0.25, 0.5, 0.75});
  EXPECT_TRUE(r.ok) << (r.messages.empty() ? "" : r.messages[0]);
}

TEST(Periodic, SparseFacesWidenTheImagesLayer) {
  // A dense middle and a few points near the faces: the layer sized by the
  // mean spacing is too thin for those few cells, and is widened once.
  const auto box = make_bounds({0, 0, 0}, {1, 1, 1});
  auto pts = grid_aligned(400, 3, 50, make_bounds({0.4, 0.4, 0.4}, {0.6, 0.6, 0.6}));
  const auto sparse = grid_aligned(4, 3, 51, box);
  pts.insert(pts.end(), sparse.begin(), sparse.end());
  const double spacing = std::cbrt(1.0 / 404);
  const tessera::Cells c = run_periodic(pts, 3, box, {true, true, true});
  EXPECT_GT(c.image_reach[0], 4 * spacing * 1.01);  // widened past the initial 4 spacings
  compare_with_oracle(pts, 3, box, {true, true, true}, 1, "sparse faces");
}

TEST(Periodic, LatticeTiesAgreeAcrossTheBox) {
  // Every vertex of a lattice is a tie among 2^D points; the perturbation
  // must settle it alike seen from either side of the box's faces.
  for (int dim : {2, 3}) {
    SCOPED_TRACE(dim);
    const int k = dim == 3 ? 6 : 12;
    const double h = 0.1;  // inexact: the box is rounded, the points with it
    auto pts = grid_points(k, dim, h, 0.05);
    const auto box = make_bounds({0, 0, 0}, {k * h, k * h, dim == 3 ? k * h : 0});
    const std::array<bool, 3> all{true, true, dim == 3};
    const tessera::Cells c = run_periodic(pts, dim, box, all);
    const tessera::Cells c2 = run_periodic(pts, dim, box, all, 2);
    expect_same_cells(c, c2, "1 vs 2 threads");
    EXPECT_EQ(c.neighbor_shifts, c2.neighbor_shifts);
    ASSERT_EQ(c.n_cells(), pts.size() / static_cast<std::size_t>(dim));
    EXPECT_EQ(asymmetric_entries(c), 0u);
    const double cell_volume = std::pow(h, dim);
    for (double v : c.volume) EXPECT_NEAR(v, cell_volume, 1e-12 * cell_volume);
    const tessera::ValidationReport r = tessera::validate(c, {}, pts);
    EXPECT_TRUE(r.ok) << (r.messages.empty() ? "" : r.messages[0]);
    EXPECT_EQ(r.asymmetric_spokes, 0u);
  }
}

TEST(Periodic, ImagesAreExactSoTiesAgree) {
  // Four points on a circle about the box's face x = 0, in the frame of A
  // (x = a): the image of B (x = 1 - a) lies at exactly -a. In B's frame
  // A's image, 1 + a, is not a double: without the rounding of the
  // coordinates to the box's grid, B saw A a rounding inside the circle,
  // while A's side settled the exact tie by the perturbation, and in 36 of
  // these 48 orders the two sides disagreed (one-sided neighbours).
  const double a = 0x1p-7 + 0x1p-53;
  const std::array<std::array<double, 2>, 4> square{{{a, 0.5}, {1 - a, 0.5}, {0, 0.5 + a}, {0, 0.5 - a}}};
  const auto box = make_bounds({0, 0, 0}, {1, 1, 0});
  std::array<int, 4> order{0, 1, 2, 3};
  do {
    for (bool more : {false, true}) {
      std::vector<double> pts;
      pts.reserve(16);  // (also keeps GCC 12 from a false -Wstringop-overflow on the inserts)
      for (int k : order) pts.insert(pts.end(), square[static_cast<std::size_t>(k)].begin(), square[static_cast<std::size_t>(k)].end());
      if (more) pts.insert(pts.end(), {0.5, 0.1, 0.5, 0.9, 0.3, 0.3, 0.7, 0.7});
      const tessera::Cells c = run_periodic(pts, 2, box, {true, true, false});
      EXPECT_EQ(asymmetric_entries(c), 0u);
    }
  } while (std::next_permutation(order.begin(), order.end()));
}

TEST(Periodic, FewPointLatticesMeetSeveralImagesOfOnePoint) {
  // Lattices of 1 to 3 points per period: a cell's ties involve several
  // images of one point, which the perturbation orders by their shifts in
  // the same way from either side of the box.
  for (int dim : {2, 3})
    for (int k : {1, 2, 3}) {
      SCOPED_TRACE(::testing::Message() << dim << "D, " << k << " per period");
      const auto pts = grid_points(k, dim, 0.25, 0.125);
      const auto box = make_bounds({0, 0, 0}, {k * 0.25, k * 0.25, dim == 3 ? k * 0.25 : 0});
      const tessera::Cells c = run_periodic(pts, dim, box, {true, true, dim == 3});
      EXPECT_EQ(asymmetric_entries(c), 0u);
      for (double v : c.volume) EXPECT_NEAR(v, std::pow(0.25, dim), 1e-15);
    }
}

TEST(Periodic, RandomPointsThreadsAndValidation) {
  const auto box = make_bounds({0, 0, 0}, {1, 1, 1});
  const auto pts = random_points(20000, 3, 7, box);  // full mantissas: rounded to the box's grid
  const tessera::Cells a = run_periodic(pts, 3, box, {true, true, true}, 1);
  const tessera::Cells b = run_periodic(pts, 3, box, {true, true, true}, 2);
  expect_same_cells(a, b, "1 vs 2 threads");
  EXPECT_EQ(a.neighbor_shifts, b.neighbor_shifts);
  EXPECT_GT(a.periodic_images, 0u);
  const tessera::ValidationReport r = tessera::validate(a, {}, pts);
  EXPECT_TRUE(r.ok) << (r.messages.empty() ? "" : r.messages[0]);
  EXPECT_LT(r.volume_rel_error, 1e-12);
  // The coordinates are rounded to the unit box's grid, 2^-51 (to nearest,
  // ties to even): points already on it give the same bytes, and some of
  // these random ones (multiples of 2^-53) were moved.
  auto on_grid = pts;
  std::size_t moved = 0;
  for (double& x : on_grid) {
    const double g = std::nearbyint(std::ldexp(x, 51)) * 0x1p-51;
    moved += g != x;
    x = g;
  }
  EXPECT_GT(moved, 0u);
  const tessera::Cells g = run_periodic(on_grid, 3, box, {true, true, true}, 2);
  expect_same_cells(a, g, "input rounded to the grid by hand");
  EXPECT_EQ(a.neighbor_shifts, g.neighbor_shifts);
}

TEST(Periodic, PointsOutsideArePeriodicallyWrapped) {
  const auto box = make_bounds({-1, 0, 2}, {1, 1.5, 3});
  const auto pts = grid_aligned(200, 3, 30, box);
  auto moved = pts;
  for (std::size_t i = 0; i < 200; ++i) {
    moved[3 * i] += static_cast<double>(static_cast<int>(i % 5) - 2) * 2.0;  // x: -2..+2 periods
    if (i % 7 == 0) moved[3 * i + 2] += 1.0;                              // z: one period up
  }
  moved[3 * 3] = 1.0;  // on the upper face: wraps to the lower one
  moved[3 * 5] += 1048576.0;  // 2^19 periods out: reduced by fmod, exactly here
  auto at_lower = pts;
  at_lower[3 * 3] = -1.0;
  const tessera::Cells a = run_periodic(moved, 3, box, {true, false, true});
  const tessera::Cells b = run_periodic(at_lower, 3, box, {true, false, true});
  expect_same_cells(a, b, "wrapped");
  EXPECT_EQ(a.neighbor_shifts, b.neighbor_shifts);
}

TEST(Periodic, PointsFarOutAreWrappedIn) {
  // 1e300 box lengths out: reduced by fmod (its position within the period
  // is whatever the double 1e300 holds), then a cell like any other.
  const auto box = make_bounds({0, 0, 0}, {1, 1, 1});
  auto pts = random_points(200, 3, 43, box);
  pts[0] = 1e300;
  pts[4] = -3e299;
  const tessera::Cells c = run_periodic(pts, 3, box, {true, true, true});
  EXPECT_EQ(c.n_cells(), 200u);
  double total = 0;
  for (double v : c.volume) total += v;
  EXPECT_NEAR(total, 1.0, 1e-12);
  EXPECT_EQ(asymmetric_entries(c), 0u);
}

TEST(Periodic, Refused) {
  const auto box = make_bounds({0, 0, 0}, {1, 1, 1});
  const auto pts = random_points(50, 3, 40, box);
  auto o = periodic_options(3, box, {true, true, true});
  o.bounds.reset();
  EXPECT_THROW(tessera::voronoi(pts, 3, {}, o), tessera::InputError);  // no box
  const auto pts2 = random_points(50, 2, 41, box);
  EXPECT_THROW(tessera::voronoi(pts2, 2, {}, periodic_options(2, box, {false, false, true})), tessera::InputError);
  // A box whose images leave double's range is refused. (Until stop 79 a
  // box 1e307 long at -1e308 was too: its squared length overflowed, so the
  // layer took 127 lengths; its images within two lengths are computed now.)
  const auto huge = make_bounds({-1.7e308, 0, 0}, {-0.2e308, 1, 1});
  EXPECT_THROW(run_periodic({-1e308, 0.5, 0.5, -0.5e308, 0.5, 0.5}, 3, huge, {true, false, false}),
               tessera::InputError);
  const auto long_box = make_bounds({-1e308, 0, 0}, {-0.9e308, 1, 1});
  EXPECT_EQ(run_periodic({-0.95e308, 0.5, 0.5, -0.92e308, 0.5, 0.5}, 3, long_box, {true, false, false}).n_cells(), 2u);
  // Outside a wall (a non-periodic axis): refused, or dropped where asked.
  auto out = pts;
  out[1] = 1.5;
  EXPECT_THROW(run_periodic(out, 3, box, {true, false, true}), tessera::InputError);
  auto drop = periodic_options(3, box, {true, false, true});
  drop.ignore_outside_points = true;
  const tessera::Cells d = tessera::voronoi(out, 3, {}, drop);
  EXPECT_EQ(d.ignored_outside_bounds, std::vector<std::int32_t>{0});
  EXPECT_EQ(d.n_cells(), 49u);
  // A period far shorter than the walls: with many points the cells are
  // short and served; one point's cell is a strip 300 periods long, whose
  // images would lie past int8 shifts.
  const auto strip = make_bounds({0, 0, 0}, {1, 300, 0});
  compare_with_oracle(grid_aligned(1000, 2, 42, strip), 2, strip, {true, false, false}, 1, "a short period");
  EXPECT_THROW(run_periodic({0.5, 150}, 2, strip, {true, false, false}), tessera::InputError);
  // (The Delaunay triangulation of a box with walls: test_periodic_delaunay.cpp.)
}

/// Every cell's neighbour entries as (point, neighbour, shift), sorted.
std::vector<std::tuple<std::int32_t, std::int32_t, Shift>> all_entries(const tessera::Cells& c) {
  std::vector<std::tuple<std::int32_t, std::int32_t, Shift>> out;
  const auto per_cell = entries(c);
  for (std::size_t cell = 0; cell < c.n_cells(); ++cell)
    for (const auto& [j, s] : per_cell[cell]) out.emplace_back(c.generator[cell], j, s);
  std::sort(out.begin(), out.end());
  return out;
}

/// A face set's faces as (side 0, side 1, shift), with their twins (side 1,
/// side 0, -shift) for faces between cells: each neighbour entry once.
std::vector<std::tuple<std::int32_t, std::int32_t, Shift>> face_entries(const tessera::FaceSet& fs) {
  std::vector<std::tuple<std::int32_t, std::int32_t, Shift>> out;
  const auto du = static_cast<std::size_t>(fs.dim);
  for (std::size_t f = 0; f < fs.n_faces(); ++f) {
    if (fs.sides[2 * f + 1] < 0) continue;  // a wall
    Shift s{0, 0, 0};
    for (std::size_t a = 0; a < du; ++a) s[a] = fs.side_shifts[f * du + a];
    out.emplace_back(fs.sides[2 * f], fs.sides[2 * f + 1], s);
    out.emplace_back(fs.sides[2 * f + 1], fs.sides[2 * f], Shift{-s[0], -s[1], -s[2]});
  }
  std::sort(out.begin(), out.end());
  return out;
}

/// Copies of one periodic vertex (FaceSet::vertex_key_shifts): per vertex,
/// its key with the shifts taken relative to the first point's, numbered by
/// first appearance, and that point's shift (the copy's translation).
struct Copies {
  std::vector<int> group;
  std::vector<Shift> at;
};
Copies vertex_copies_of(const tessera::FaceSet& fs) {
  const auto du = static_cast<std::size_t>(fs.dim), kn = du + 1;
  std::map<std::vector<int>, int> index;
  Copies out;
  for (std::size_t v = 0; v < fs.n_vertices(); ++v) {
    std::size_t first = 0;
    while (fs.vertex_keys[v * kn + first] < 0) ++first;
    Shift t{0, 0, 0};
    for (std::size_t a = 0; a < du; ++a) t[a] = fs.vertex_key_shifts[(v * kn + first) * du + a];
    std::vector<int> key;
    for (std::size_t e = 0; e < kn; ++e) {
      key.push_back(fs.vertex_keys[v * kn + e]);
      for (std::size_t a = 0; a < du; ++a)
        key.push_back(fs.vertex_key_shifts[(v * kn + e) * du + a] - (fs.vertex_keys[v * kn + e] < 0 ? 0 : t[a]));
    }
    out.group.push_back(index.emplace(key, static_cast<int>(index.size())).first->second);
    out.at.push_back(t);
  }
  return out;
}

/// Directed edges (3D) or segment ends (2D) of a region's faces, its faces
/// on side 1 reversed, over copies of vertices: a surface closed in the
/// periodic box has each directed edge matched by its reverse (the same two
/// vertices, the same relative translation). Returns the unmatched.
std::size_t open_edges_modulo_lattice(const tessera::FaceSet& fs, std::int32_t region) {
  const Copies cp = vertex_copies_of(fs);
  std::map<std::tuple<int, int, Shift>, int> balance;  // (from, to, to's translation - from's)
  auto rel = [&](std::int32_t u, std::int32_t w) {
    const Shift& a = cp.at[static_cast<std::size_t>(u)];
    const Shift& b = cp.at[static_cast<std::size_t>(w)];
    return Shift{b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  };
  for (std::size_t f = 0; f < fs.n_faces(); ++f) {
    const bool side0 = fs.boundary_labels[2 * f] == region, side1 = fs.boundary_labels[2 * f + 1] == region;
    if (side0 == side1) continue;
    std::vector<std::int32_t> loop(fs.face_vertices.begin() + fs.face_offsets[f],
                                   fs.face_vertices.begin() + fs.face_offsets[f + 1]);
    if (side1) std::reverse(loop.begin(), loop.end());
    const std::size_t n = loop.size(), edges = fs.dim == 2 ? 1 : n;
    for (std::size_t k = 0; k < edges; ++k) {
      const std::int32_t u = loop[k], w = loop[(k + 1) % n];
      const int gu = cp.group[static_cast<std::size_t>(u)], gw = cp.group[static_cast<std::size_t>(w)];
      const Shift d = rel(u, w);
      if (fs.dim == 2) {  // a segment's ends: it leaves gu and arrives at gw
        ++balance[{gu, -1, Shift{0, 0, 0}}];
        --balance[{gw, -1, Shift{0, 0, 0}}];
        continue;
      }
      ++balance[{gu, gw, d}];
      --balance[{gw, gu, Shift{-d[0], -d[1], -d[2]}}];
    }
  }
  std::size_t open = 0;
  for (const auto& [edge, m] : balance) open += m != 0;
  return open;
}

TEST(Periodic, FaceSetsListEachFaceOnceWithItsImage) {
  // Face sets of periodic cells (orthogonal, triclinic, 2D, and x-z
  // periodic with y walls): the complex lists every face once, and with its
  // twin each neighbour entry; each face lies on the bisector of side 0's
  // point and side 1's image, its normal towards the image; each region's
  // surface-net faces close up modulo the lattice; 1 and 2 threads agree.
  struct Case {
    int dim;
    std::array<bool, 3> periodic;
    Tilt tilt;
  };
  for (const Case& k : {Case{3, {true, true, true}, {0, 0, 0}}, Case{3, {true, true, true}, {0.25, -0.125, 0.375}},
                        Case{3, {true, false, true}, {0, 0, 0}}, Case{2, {true, true, false}, {0.375, 0, 0}}}) {
    SCOPED_TRACE(k.dim * 100 + k.periodic[1] * 10 + (k.tilt[0] != 0));
    const auto box = make_bounds({0, 0, 0}, {1, 1, 1});
    const auto du = static_cast<std::size_t>(k.dim);
    const auto pts = in_parallelepiped(300, k.dim, 46, box, k.tilt);
    std::vector<std::int32_t> labels(300);
    for (std::size_t i = 0; i < 300; ++i) labels[i] = pts[i * du] + pts[i * du + 1] < 1.0 ? 3 : 7;
    auto o = periodic_options(k.dim, box, k.periodic, 1, k.tilt);
    o.build_mesh = true;
    const tessera::Cells c = tessera::voronoi(pts, k.dim, labels, o);
    o.threads = 2;
    const tessera::Cells c2 = tessera::voronoi(pts, k.dim, labels, o);

    tessera::FaceSetOptions fo;
    fo.kind = tessera::FaceSetKind::complex;
    const tessera::FaceSet fs = tessera::extract_faces(c, labels, fo);
    const tessera::FaceSet fs2 = tessera::extract_faces(c2, labels, fo);
    EXPECT_EQ(fs.face_vertices, fs2.face_vertices);
    EXPECT_EQ(fs.side_shifts, fs2.side_shifts);
    EXPECT_EQ(fs.vertices, fs2.vertices);
    ASSERT_TRUE(fs.is_periodic());
    ASSERT_EQ(fs.side_shifts.size(), fs.n_faces() * du);
    ASSERT_EQ(fs.vertex_key_shifts.size(), fs.vertex_keys.size() * du);
    const auto want = all_entries(c);
    EXPECT_EQ(face_entries(fs), want);

    // Geometry: on the bisector with the image, facing it.
    const std::vector<double>& p = c.periodic_points;
    std::size_t off_bisector = 0, facing_back = 0;
    for (std::size_t f = 0; f < fs.n_faces(); ++f) {
      const std::int32_t j = fs.sides[2 * f + 1];
      if (j < 0) continue;
      const auto i = static_cast<std::size_t>(fs.sides[2 * f]);
      double img[3] = {0, 0, 0};
      tessera::periodic_image(fs.lattice, k.dim, &p[static_cast<std::size_t>(j) * du], &fs.side_shifts[f * du], img);
      V3 pi{0, 0, 0}, pj{0, 0, 0};
      for (std::size_t a = 0; a < du; ++a) pi[a] = p[i * du + a], pj[a] = img[a];
      const double h = norm(sub(pj, pi));
      std::vector<V3> corner;
      for (auto q = fs.face_offsets[f]; q < fs.face_offsets[f + 1]; ++q) {
        V3 x{0, 0, 0};
        for (std::size_t a = 0; a < du; ++a) x[a] = fs.vertices[static_cast<std::size_t>(fs.face_vertices[q]) * du + a];
        off_bisector += std::fabs(norm(sub(x, pi)) - norm(sub(x, pj))) > 1e-9 * h;
        corner.push_back(x);
      }
      V3 normal{0, 0, 0};
      if (k.dim == 2) {
        normal = {corner[1][1] - corner[0][1], corner[0][0] - corner[1][0], 0};  // (dy, -dx)
      } else {
        for (std::size_t t = 1; t + 1 < corner.size(); ++t) {
          const V3 n = cross(sub(corner[t], corner[0]), sub(corner[t + 1], corner[0]));
          for (int a = 0; a < 3; ++a) normal[a] += n[a];
        }
      }
      if (norm(normal) > 1e-9) facing_back += dot(normal, sub(pj, pi)) <= 0;
    }
    EXPECT_EQ(off_bisector, 0u);
    EXPECT_EQ(facing_back, 0u);

    // Each region's surface-net faces close up across the box's faces.
    fo.kind = tessera::FaceSetKind::surface_net;
    fo.capping = true;
    const tessera::FaceSet net = tessera::extract_faces(c, labels, fo);
    EXPECT_GT(net.n_faces(), 0u);
    EXPECT_EQ(open_edges_modulo_lattice(net, 3), 0u);
    EXPECT_EQ(open_edges_modulo_lattice(net, 7), 0u);

    // The library's copies (tessera::vertex_copies) are this test's: the same
    // groups, each copy the same translation from its group's first.
    const Copies mine = vertex_copies_of(net);
    const tessera::VertexCopies lib = tessera::vertex_copies(net);
    ASSERT_EQ(lib.group.size(), net.n_vertices());
    ASSERT_EQ(lib.shift.size(), net.n_vertices() * du);
    EXPECT_LT(lib.n_groups(), net.n_vertices());
    for (std::size_t v = 0; v < net.n_vertices(); ++v) {
      const auto f = static_cast<std::size_t>(lib.first[static_cast<std::size_t>(lib.group[v])]);
      EXPECT_EQ(mine.group[v], mine.group[f]);
      EXPECT_LE(f, v);
      for (std::size_t a = 0; a < du; ++a) EXPECT_EQ(lib.shift[v * du + a], mine.at[v][a] - mine.at[f][a]);
    }
    std::set<int> groups(mine.group.begin(), mine.group.end());
    EXPECT_EQ(groups.size(), lib.n_groups());
    tessera::FaceSet bad = net;
    bad.vertex_key_shifts.pop_back();
    EXPECT_THROW(tessera::vertex_copies(bad), std::invalid_argument);
  }
}

TEST(Periodic, FaceSetsOfAFewPointsTakeFacesWithTheirOwnImagesOnce) {
  // Boxes of 1-3 points: faces between a cell and its own images, each
  // taken from the side whose shift is positive, so once.
  const auto box = make_bounds({0, 0, 0}, {1, 1, 1});
  for (int dim : {2, 3})
    for (std::size_t n : {1u, 2u, 3u}) {
      SCOPED_TRACE(dim * 10 + static_cast<int>(n));
      const auto pts = grid_aligned(n, dim, 47 + n, box);
      auto o = periodic_options(dim, box, {true, true, dim == 3});
      o.build_mesh = true;
      const tessera::Cells c = tessera::voronoi(pts, dim, {}, o);
      tessera::FaceSetOptions fo;
      fo.kind = tessera::FaceSetKind::complex;
      const tessera::FaceSet fs = tessera::extract_faces(c, {}, fo);
      const auto want = all_entries(c);
      EXPECT_EQ(face_entries(fs), want);
      EXPECT_EQ(2 * fs.n_faces(), want.size());
    }
}

TEST(Periodic, FlowersLieWhereTheirCellsAre) {
  // Flowers of periodic cells (triclinic 3D, 2D): the site is the point as
  // wrapped; each face's corners are equidistant from the site and the
  // neighbour's image across it, which is where the flower puts that
  // neighbour; petals reach the site; the circumflower holds every neighbour.
  for (int dim : {2, 3}) {
    SCOPED_TRACE(dim);
    const auto box = make_bounds({0, 0, 0}, {1, 1, 1});
    const Tilt tilt = dim == 3 ? Tilt{0.25, -0.125, 0.375} : Tilt{0.375, 0, 0};
    const auto du = static_cast<std::size_t>(dim);
    auto pts = in_parallelepiped(200, dim, 48, box, tilt);
    for (std::size_t a = 0; a < du; ++a) pts[a] += 1.0 * (a == 0);  // point 0 given a period out: wrapped back
    auto o = periodic_options(dim, box, {true, true, dim == 3}, 1, tilt);
    o.build_mesh = true;
    const tessera::Cells c = tessera::voronoi(pts, dim, {}, o);
    std::vector<std::int32_t> ids(200);
    for (std::int32_t i = 0; i < 200; ++i) ids[static_cast<std::size_t>(i)] = i;
    const auto fl = tessera::flowers(c, pts, ids);
    for (const tessera::Flower& f : fl) {
      const auto i = static_cast<std::size_t>(f.generator);
      for (std::size_t a = 0; a < du; ++a) ASSERT_EQ(f.site[a], c.periodic_points[i * du + a]);
      ASSERT_EQ(f.neighbor_shifts.size(), f.neighbors.size() * du);
      ASSERT_EQ(f.face_shifts.size(), f.face_neighbor.size() * du);
      auto dist = [&](const double* x, const double* y) {
        double d2 = 0;
        for (std::size_t a = 0; a < du; ++a) d2 += (x[a] - y[a]) * (x[a] - y[a]);
        return std::sqrt(d2);
      };
      for (std::size_t p = 0; p < f.n_petals(); ++p)
        EXPECT_NEAR(dist(&f.petal_centres[p * du], f.site.data()), f.petal_radii[p], 1e-15);
      for (std::size_t e = 0; e < f.neighbors.size(); ++e)
        EXPECT_LE(dist(&f.neighbor_positions[e * du], f.site.data()), f.circumflower_radius);
      for (std::size_t face = 0; face + 1 < f.face_offsets.size(); ++face) {
        const std::int32_t j = f.face_neighbor[face];
        ASSERT_GE(j, 0);
        // The neighbour entry of this face: same id and shift.
        std::size_t e = 0;
        while (e < f.neighbors.size() &&
               !(f.neighbors[e] == j && std::equal(&f.neighbor_shifts[e * du], &f.neighbor_shifts[e * du] + du,
                                                   &f.face_shifts[face * du])))
          ++e;
        ASSERT_LT(e, f.neighbors.size());
        const double* q = &f.neighbor_positions[e * du];
        for (auto t = f.face_offsets[face]; t < f.face_offsets[face + 1]; ++t) {
          const double* x = &f.petal_centres[static_cast<std::size_t>(f.face_vertices[static_cast<std::size_t>(t)]) * du];
          EXPECT_NEAR(dist(x, f.site.data()), dist(x, q), 1e-12);
        }
      }
    }
  }
}

TEST(Periodic, SurfaceNetFacesOfSlabsInALatticeAreTwoPlanes) {
  // Voxel centres of a periodic 6^3 lattice, labelled by slabs along x:
  // the interfaces are the planes x = 1/2 and x = 0 (= 1), area 1 each.
  const auto box = make_bounds({0, 0, 0}, {1, 1, 1});
  std::vector<double> pts;
  std::vector<std::int32_t> labels;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j)
      for (int l = 0; l < 6; ++l) {
        pts.insert(pts.end(), {(l + 0.5) / 6, (j + 0.5) / 6, (i + 0.5) / 6});
        labels.push_back(l < 3 ? 0 : 1);
      }
  auto o = periodic_options(3, box, {true, true, true});
  o.build_mesh = true;
  const tessera::Cells c = tessera::voronoi(pts, 3, labels, o);
  tessera::FaceSetOptions fo;
  fo.kind = tessera::FaceSetKind::surface_net;
  const tessera::FaceSet net = tessera::extract_faces(c, labels, fo);
  double area = 0, at_half = 0;
  for (std::size_t f = 0; f < net.n_faces(); ++f) {
    double s[3] = {0, 0, 0};
    auto at = [&](std::int64_t q) { return &net.vertices[static_cast<std::size_t>(net.face_vertices[static_cast<std::size_t>(q)]) * 3]; };
    const double* o0 = at(net.face_offsets[f]);
    for (auto q = net.face_offsets[f] + 1; q + 1 < net.face_offsets[f + 1]; ++q) {
      const V3 n = cross(sub({at(q)[0], at(q)[1], at(q)[2]}, {o0[0], o0[1], o0[2]}),
                         sub({at(q + 1)[0], at(q + 1)[1], at(q + 1)[2]}, {o0[0], o0[1], o0[2]}));
      for (int a = 0; a < 3; ++a) s[a] += n[a];
    }
    const double a = 0.5 * std::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    area += a;
    if (std::fabs(o0[0] - 0.5) < 1e-12) at_half += a;
  }
  EXPECT_NEAR(area, 2.0, 1e-12);
  EXPECT_NEAR(at_half, 1.0, 1e-12);
  EXPECT_EQ(open_edges_modulo_lattice(net, 0), 0u);
  EXPECT_EQ(open_edges_modulo_lattice(net, 1), 0u);
}

TEST(Periodic, AdjacencyGraphHasShiftedSpokes) {
  // The graph of periodic cells (orthogonal and triclinic): spokes are the
  // cells' neighbour entries with their shifts, each with its twin
  // j -> (i, -s) of the same measure; every cell's pyramids over its faces
  // (height: half the distance to the neighbour's image) fill it; edges
  // list each face once; 1 and 2 threads give the same graph.
  for (const Tilt& tilt : {Tilt{0, 0, 0}, Tilt{0.25, -0.125, 0.375}}) {
    SCOPED_TRACE(tilt[0]);
    const auto box = make_bounds({0, 0, 0}, {1, 1, 1});
    const auto pts = in_parallelepiped(400, 3, 45, box, tilt);
    const auto v = lattice(box, tilt);
    const tessera::Cells c = run_periodic(pts, 3, box, {true, true, true}, 1, {}, tilt);
    const tessera::Cells c2 = run_periodic(pts, 3, box, {true, true, true}, 2, {}, tilt);
    const tessera::AdjacencyGraph g = tessera::adjacency_graph(c);
    const tessera::AdjacencyGraph g2 = tessera::adjacency_graph(c2);
    EXPECT_EQ(g.spokes, g2.spokes);
    EXPECT_EQ(g.spoke_shift, g2.spoke_shift);
    EXPECT_EQ(g.spoke_measure, g2.spoke_measure);
    ASSERT_EQ(g.spoke_shift.size(), 3 * g.n_spokes());
    // The spokes are the neighbour entries (no walls here).
    EXPECT_EQ(std::vector<std::int32_t>(g.spokes.begin(), g.spokes.end()),
              std::vector<std::int32_t>(c.neighbors.begin(), c.neighbors.end()));
    EXPECT_EQ(std::vector<std::int8_t>(g.spoke_shift.begin(), g.spoke_shift.end()),
              std::vector<std::int8_t>(c.neighbor_shifts.begin(), c.neighbor_shifts.end()));
    std::map<std::tuple<std::int32_t, std::int32_t, Shift>, double> measure;
    for (std::size_t i = 0; i < 400; ++i) {
      double total = 0;
      for (auto s = g.wheel_offsets[i]; s < g.wheel_offsets[i + 1]; ++s) {
        const auto su = static_cast<std::size_t>(s);
        const auto j = static_cast<std::size_t>(g.spokes[su]);
        const Shift sh{g.spoke_shift[3 * su], g.spoke_shift[3 * su + 1], g.spoke_shift[3 * su + 2]};
        double d2 = 0;
        for (std::size_t a = 0; a < 3; ++a) {
          double x = pts[3 * j + a] - pts[3 * i + a];
          for (std::size_t b = a; b < 3; ++b) x += sh[b] * v[b][a];
          d2 += x * x;
        }
        total += g.spoke_measure[su] * 0.5 * std::sqrt(d2) / 3;
        measure[{static_cast<std::int32_t>(i), g.spokes[su], sh}] = g.spoke_measure[su];
      }
      const double vol = c.volume[static_cast<std::size_t>(c.cell_of[i])];
      EXPECT_NEAR(total, vol, 1e-12 * vol) << "point " << i;
    }
    for (const auto& [key, m] : measure) {
      const auto& [i, j, s] = key;
      const auto twin = measure.find({j, i, Shift{-s[0], -s[1], -s[2]}});
      ASSERT_NE(twin, measure.end());
      EXPECT_EQ(twin->second, m);
    }
    const tessera::GraphEdges edges = tessera::graph_edges(g);
    EXPECT_EQ(2 * edges.size(), g.n_spokes());
    EXPECT_EQ(edges.shift.size(), 3 * edges.size());
  }
}

// ---- triclinic boxes (VoronoiOptions::tilt) ----

TEST(Triclinic, EqualsTheOracleAmongExplicitImages) {
  const auto box3 = make_bounds({-1, 0, 2}, {1, 1.5, 3});
  const Tilt t3{0.375, -0.5, 0.25};
  compare_with_oracle(in_parallelepiped(150, 3, 1, box3, t3), 3, box3, {true, true, true}, 1, "3D xyz", false, t3);
  const Tilt xy{0.75, 0, 0}, xz{0, -0.625, 0};
  compare_with_oracle(in_parallelepiped(150, 3, 2, box3, xy), 3, box3, {true, true, false}, 1, "3D xy, z walls",
                      false, xy);
  compare_with_oracle(in_parallelepiped(150, 3, 3, box3, xz), 3, box3, {true, false, true}, 1, "3D xz, y walls",
                      false, xz);
  // Sheared past half a period (LAMMPS would flip it; the lattice is the same).
  const Tilt far{1.625, 1.25, -0.875};
  compare_with_oracle(in_parallelepiped(150, 3, 4, box3, far), 3, box3, {true, true, true}, 2, "3D far sheared",
                      false, far);
  const auto box2 = make_bounds({0.5, -2, 0}, {1.5, 0, 0});
  const Tilt t2{-0.3125, 0, 0};
  compare_with_oracle(in_parallelepiped(300, 2, 5, box2, t2), 2, box2, {true, true, false}, 1, "2D xy", false, t2);
}

TEST(Triclinic, BoxesOfAFewPointsReachSeveralPeriods) {
  const auto box3 = make_bounds({0, 0, 0}, {1, 2, 1});
  const auto box2 = make_bounds({0, 0, 0}, {3, 1, 0});
  const Tilt t3{0.5, 0.25, -0.75}, t2{2.25, 0, 0};
  for (std::size_t n : {1, 2, 3, 5}) {
    compare_with_oracle(in_parallelepiped(n, 3, 60 + n, box3, t3), 3, box3, {true, true, true}, 3,
                        "3D, " + std::to_string(n) + " points", true, t3);
    compare_with_oracle(in_parallelepiped(n, 2, 70 + n, box2, t2), 2, box2, {true, true, false}, 4,
                        "2D, " + std::to_string(n) + " points", true, t2);
  }
}

TEST(Triclinic, ShearedLatticeTiesAgreeAcrossTheBox) {
  // A lattice sheared with its box: every vertex is a tie, settled alike
  // from either side of the slanted faces; the cells tile the box.
  for (int dim : {2, 3}) {
    SCOPED_TRACE(dim);
    const int k = dim == 3 ? 5 : 10;
    const auto box = make_bounds({0, 0, 0}, {k * 0.25, k * 0.25, dim == 3 ? k * 0.25 : 0});
    const Tilt tilt = dim == 3 ? Tilt{0.5, 0.25, -0.75} : Tilt{0.75, 0, 0};
    const auto v = lattice(box, tilt);
    const auto du = static_cast<std::size_t>(dim);
    std::vector<double> pts;
    const int kz = dim == 3 ? k : 1;
    for (int i = 0; i < k; ++i)
      for (int j = 0; j < k; ++j)
        for (int l = 0; l < kz; ++l) {
          const double f[3] = {(i + 0.5) / k, (j + 0.5) / k, dim == 3 ? (l + 0.5) / k : 0};
          for (std::size_t a = 0; a < du; ++a) {
            double x = 0;
            for (std::size_t b = a; b < du; ++b) x += f[b] * v[b][a];
            pts.push_back(x);
          }
        }
    const std::array<bool, 3> all{true, true, dim == 3};
    const tessera::Cells c = run_periodic(pts, dim, box, all, 1, {}, tilt);
    const tessera::Cells c2 = run_periodic(pts, dim, box, all, 2, {}, tilt);
    expect_same_cells(c, c2, "1 vs 2 threads");
    EXPECT_EQ(c.neighbor_shifts, c2.neighbor_shifts);
    ASSERT_EQ(c.n_cells(), pts.size() / du);
    EXPECT_EQ(asymmetric_entries(c), 0u);
    const double cell_volume = box_volume(box, dim) / static_cast<double>(c.n_cells());
    for (double vol : c.volume) EXPECT_NEAR(vol, cell_volume, 1e-12 * cell_volume);
    const tessera::ValidationReport r = tessera::validate(c, {}, pts);
    EXPECT_TRUE(r.ok) << (r.messages.empty() ? "" : r.messages[0]);
  }
}

TEST(Triclinic, RandomPointsThreadsAndValidation) {
  // Full mantissas (rounded to the box's grid), some outside the
  // parallelepiped (wrapped in), 1 and 2 threads.
  const auto box = make_bounds({0, 0, 0}, {1, 1, 1});
  const Tilt tilt{0.3, -0.2, 0.45};
  const auto pts = random_points(20000, 3, 8, box);
  const tessera::Cells a = run_periodic(pts, 3, box, {true, true, true}, 1, {}, tilt);
  const tessera::Cells b = run_periodic(pts, 3, box, {true, true, true}, 2, {}, tilt);
  expect_same_cells(a, b, "1 vs 2 threads");
  EXPECT_EQ(a.neighbor_shifts, b.neighbor_shifts);
  EXPECT_EQ(asymmetric_entries(a), 0u);
  const tessera::ValidationReport r = tessera::validate(a, {}, pts);
  EXPECT_TRUE(r.ok) << (r.messages.empty() ? "" : r.messages[0]);
  EXPECT_LT(r.volume_rel_error, 1e-12);
  // Each merged vertex is used by the cells of its key's points at shift 0
  // (Cells::vertex_key_shifts): validate counts it, and sees one entry
  // moved to another image.
  EXPECT_EQ(r.bad_vertex_degree, 0u);
  ASSERT_EQ(a.vertex_key_shifts.size(), a.vertex_keys.size() * 3);
  tessera::Cells moved = a;
  moved.vertex_key_shifts[0] = static_cast<std::int8_t>(moved.vertex_key_shifts[0] + 1);
  EXPECT_EQ(tessera::validate(moved, {}, pts).bad_vertex_degree, 1u);
  // Sampled cells are measured exactly among their keys' images (since stop
  // 76), and a volume off by 1e-6 relative is seen: the smallest cell's, one
  // the sample always takes.
  EXPECT_GT(r.measures_checked, 100u);
  EXPECT_LT(r.measure_rel_error, 1e-9);
  tessera::Cells off = a;
  const auto smallest = static_cast<std::size_t>(std::min_element(off.volume.begin(), off.volume.end()) - off.volume.begin());
  off.volume[smallest] *= 1 + 1e-6;
  const tessera::ValidationReport ro = tessera::validate(off, {}, pts);
  EXPECT_FALSE(ro.ok);
  EXPECT_EQ(ro.measure_worst, off.generator[smallest]);
  // The tilts as rounded to x's and y's grids (a few 2^-52 at a few box lengths).
  EXPECT_NEAR(a.tilt[0], 0.3, 0x1p-46);
  EXPECT_NEAR(a.tilt[1], -0.2, 0x1p-46);
  EXPECT_NEAR(a.tilt[2], 0.45, 0x1p-46);
  EXPECT_NE(a.tilt[0], 0.3);  // not a multiple of the grid: rounded
}

TEST(Triclinic, PointsMovedByLatticeVectorsAreWrappedBack) {
  const auto box = make_bounds({-1, 0, 2}, {1, 1.5, 3});
  const Tilt tilt{0.375, -0.5, 0.25};
  const auto v = lattice(box, tilt);
  const auto pts = in_parallelepiped(200, 3, 31, box, tilt);
  auto moved = pts;
  for (std::size_t i = 0; i < 200; ++i) {
    const int m[3] = {static_cast<int>(i % 5) - 2, static_cast<int>(i % 3) - 1, i % 7 == 0 ? 3 : 0};
    for (std::size_t a = 0; a < 3; ++a)
      for (std::size_t b = a; b < 3; ++b) moved[3 * i + a] += m[b] * v[b][a];  // exact: dyadic
  }
  const tessera::Cells a = run_periodic(moved, 3, box, {true, true, true}, 1, {}, tilt);
  const tessera::Cells b = run_periodic(pts, 3, box, {true, true, true}, 1, {}, tilt);
  expect_same_cells(a, b, "wrapped");
  EXPECT_EQ(a.neighbor_shifts, b.neighbor_shifts);
}

TEST(Triclinic, AnotherBasisOfTheSameLatticeGivesTheSameCells) {
  // b + a = (xy + Lx, Ly, 0) and c + a - b = (xz + Lx - xy, yz - Ly, Lz)
  // span the same lattice with a: the same cells (volumes, neighbour ids);
  // only the shifts count other vectors.
  const auto box = make_bounds({0, 0, 0}, {1, 1.25, 0.75});
  const Tilt t{0.25, 0.125, -0.375};
  const Tilt u{t[0] + 1, t[1] + 1 - t[0], t[2] - 1.25};
  const auto pts = in_parallelepiped(500, 3, 32, box, t);
  const tessera::Cells a = run_periodic(pts, 3, box, {true, true, true}, 1, {}, t);
  const tessera::Cells b = run_periodic(pts, 3, box, {true, true, true}, 1, {}, u);
  ASSERT_EQ(a.n_cells(), b.n_cells());
  for (std::size_t i = 0; i < 500; ++i) {
    const auto ca = static_cast<std::size_t>(a.cell_of[i]), cb = static_cast<std::size_t>(b.cell_of[i]);
    EXPECT_NEAR(a.volume[ca], b.volume[cb], 1e-12 * a.volume[ca]) << "point " << i;
    const std::vector<std::int32_t> na(a.neighbors.begin() + a.neighbor_offsets[ca],
                                       a.neighbors.begin() + a.neighbor_offsets[ca + 1]);
    const std::vector<std::int32_t> nb(b.neighbors.begin() + b.neighbor_offsets[cb],
                                       b.neighbors.begin() + b.neighbor_offsets[cb + 1]);
    EXPECT_EQ(na, nb) << "point " << i;
  }
}

TEST(Triclinic, Refused) {
  const auto box = make_bounds({0, 0, 0}, {1, 1, 1});
  const auto pts = random_points(50, 3, 40, box);
  const std::array<bool, 3> all{true, true, true};
  auto refused = [&](std::array<bool, 3> per, Tilt t, int dim = 3) {
    const auto p = dim == 3 ? pts : random_points(50, 2, 41, box);
    EXPECT_THROW(tessera::voronoi(p, dim, {}, periodic_options(dim, box, per, 1, t)), tessera::InputError)
        << t[0] << " " << t[1] << " " << t[2];
  };
  refused({false, false, false}, {0.5, 0, 0});               // no periodic axis
  refused({true, false, true}, {0.5, 0, 0});                 // xy with y a wall
  refused({false, true, true}, {0, 0.5, 0});                 // xz with x a wall
  refused(all, {std::nan(""), 0, 0});
  refused(all, {0, std::numeric_limits<double>::infinity(), 0});
  refused(all, {2000.0, 0, 0});                              // over 1024 box lengths
  refused({true, true, false}, {0.25, 0.5, 0}, 2);           // xz in 2D
  tessera::DelaunayOptions dopt;
  dopt.dim = 3;
  dopt.bounds = box;
  dopt.tilt = {0.5, 0, 0};
  EXPECT_THROW(tessera::delaunay(pts, 3, {}, dopt), tessera::InputError);
}

// A slab a millionth as thick as wide, sheared so that its third vector
// lies nearly in its plane: every height of the box is tiny, and its layer
// of images would hold billions (a hostile fuzz case ran out of memory at
// 51 GB). Refused at once, naming the box; the same slab unsheared keeps
// its own refusal (cells reaching past 127 box lengths).
TEST(Periodic, BoxesNeedingMillionsOfImagesRefusedAtOnce) {
  // A fuzz of the Python module: 30 points in a box 2e16 long and 3 wide
  // took ~6e6 images, whose cells each reach across them all (it ran for
  // minutes). Refused now by the images they would need. (Tilts of 1000
  // box lengths, which took 3 GB and were then refused the same way, are
  // reduced since stop 83: Triclinic.LargeTiltsReducedByWholeBoxLengths.)
  const auto pts = random_points(30, 3, 1, make_bounds({0, 0, 0}, {1, 1, 1}));
  try {
    tessera::voronoi(pts, 3, {}, periodic_options(3, make_bounds({-1e16, -1, -1}, {1e16, 2, 2}), {true, true, true}, 1));
    ADD_FAILURE() << "not refused";
  } catch (const tessera::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("images of its 30 points"), std::string::npos) << e.what();
  }
  // A blob filling a millionth of a unit cube: its outer cells span the box,
  // and the refusal says so (it said the cube was "far thinner than wide").
  std::vector<double> blob = random_points(20000, 3, 2, make_bounds({0, 0, 0}, {1, 1, 1}));
  for (double& x : blob) x = 0.5 + 1e-3 * x;
  try {
    tessera::voronoi(blob, 3, {}, periodic_options(3, make_bounds({0, 0, 0}, {1, 1, 1}), {true, true, true}, 1));
    ADD_FAILURE() << "not refused";
  } catch (const tessera::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("box heights (distances between opposite faces) across it (points gathered "
                                         "in a small part of the box, whose outer cells span it"),
              std::string::npos)
        << e.what();
  }
}

TEST(Triclinic, LargeTiltsReducedByWholeBoxLengths) {
  // Tilts of more than a box length are reduced by whole lengths (b - k a,
  // c - k b, c - k a): the same lattice in a thick box. One point at tilts
  // of 10.3 was refused ("some cell reaches past 127 box lengths"), 30 at
  // 1000 after 3 GB of images. The cells are those of the reduced tilts
  // given directly, byte for byte, which Cells::tilt reports; whole-length
  // tilts reduce to the orthogonal box. Tilts within a length are kept.
  const auto box = make_bounds({0, 0, 0}, {1, 1, 1});
  const std::array<bool, 3> all{true, true, true};
  struct Case {
    std::size_t n;
    Tilt given, reduced;
  };
  const double xy = 10.3 - 10.0, yz = 20.3 - 20.0;
  const Case cases[] = {
      {1, {10.3, 10.3, 10.3}, {xy, 10.3 - 10 * xy - 10.0, 10.3 - 10.0}},
      {10, {20.3, 0.25, 20.3}, {20.3 - 20.0, 0.25 - 20 * (20.3 - 20.0), yz}},
      {30, {1e3, 1e3, 1e3}, {0, 0, 0}},
      {20, {0.9, -0.75, 0.6}, {0.9, -0.75, 0.6}},
  };
  for (const Case& k : cases) {
    const auto pts = random_points(k.n, 3, 7, box);
    tessera::VoronoiOptions o = periodic_options(3, box, all, 1, k.given);
    o.build_mesh = true;
    const tessera::Cells a = tessera::voronoi(pts, 3, {}, o);
    Tilt expect = k.reduced;
    // (xz reduced again where the first step left it past a length)
    if (std::fabs(expect[1]) > 1) expect[1] -= std::nearbyint(expect[1]);
    // (as used: rounded to the coordinates' grid, within an ulp or so)
    for (std::size_t t = 0; t < 3; ++t) EXPECT_NEAR(a.tilt[t], expect[t], 1e-14) << "n " << k.n << " tilt " << t;
    const tessera::Cells b = tessera::voronoi(pts, 3, {}, [&] {
      tessera::VoronoiOptions r = periodic_options(3, box, all, 1, a.tilt);
      r.build_mesh = true;
      return r;
    }());
    EXPECT_EQ(a.volume, b.volume) << "n " << k.n;
    EXPECT_EQ(a.neighbors, b.neighbors) << "n " << k.n;
    EXPECT_EQ(a.neighbor_shifts, b.neighbor_shifts) << "n " << k.n;
    EXPECT_EQ(a.periodic_points, b.periodic_points) << "n " << k.n;
    double total = 0;
    for (const double v : a.volume) total += v;
    EXPECT_NEAR(total, 1.0, 1e-12) << "n " << k.n;
    const tessera::ValidationReport r = tessera::validate(a, {}, pts);
    EXPECT_TRUE(r.ok) << (r.messages.empty() ? "" : r.messages[0]);
  }
}

TEST(Triclinic, FarFromTheOrigin) {
  // A sheared box 0.19 wide at 1e14, where an ulp is 2^-6: the pass's
  // domain, the layer's bounding box, was summed with the corner and rounded
  // inward past its margin, an image fell outside, and the cells were
  // refused with "point 24890 lies outside the bounds". The input is the
  // hostile-input fuzz's (seed 9506, case 130): 1,665 points on a 7^3 grid
  // of step 2^-6, with duplicates.
  const std::vector<double> pts =
      tessera::io::read_points(std::string(TESSERA_TEST_DATA_DIR) + "/periodic_sheared_far_from_origin_3d.npy").coords;
  const auto box = make_bounds({99999999999999.95, 99999999999999.95, 99999999999999.95},
                               {100000000000000.14, 100000000000000.14, 100000000000000.14});
  const Tilt tilt{0.056249999999999994, 0.037500000000000006, -0.046875};
  std::vector<std::int32_t> neighbors[2];
  int m = 0;
  for (const auto method : {tessera::CellMethod::search, tessera::CellMethod::insertion}) {
    tessera::VoronoiOptions opt = periodic_options(3, box, {true, true, true}, 1, tilt);
    opt.cell_method = method;
    opt.build_mesh = true;
    const tessera::Cells c = tessera::voronoi(pts, 3, {}, opt);
    EXPECT_EQ(asymmetric_entries(c), 0u);
    const tessera::ValidationReport r = tessera::validate(c, {}, pts);
    EXPECT_TRUE(r.ok) << (r.messages.empty() ? "" : r.messages[0]);
    neighbors[m++].assign(c.neighbors.begin(), c.neighbors.end());
  }
  EXPECT_EQ(neighbors[0], neighbors[1]);
}

TEST(Triclinic, NearlyFlatShearRefused) {
  const auto box = make_bounds({0, 0, 0}, {2, 2, 2e-9});
  auto pts = random_points(120, 3, 42, make_bounds({0, 0, 0}, {2, 2, 1}));
  for (std::size_t i = 0; i < 120; ++i) pts[3 * i + 2] *= 2e-9;
  const std::array<bool, 3> all{true, true, true};
  try {
    tessera::voronoi(pts, 3, {}, periodic_options(3, box, all, 1, {0.6, 0.4, -0.5}));
    ADD_FAILURE() << "not refused";
  } catch (const tessera::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("images"), std::string::npos) << e.what();
  }
  EXPECT_THROW(tessera::voronoi(pts, 3, {}, periodic_options(3, box, all, 1)), tessera::InputError);
}

}  // namespace

namespace {

// Periodic boxes at the ends of double's range: the points and the box
// scaled by 2^k give the unit box's cells, neighbours and shifts exactly
// (scaling by a power of two is exact). The box's volume, squared lengths
// and areas under- and overflowed from ~1e-100 and ~1e100 on: a box 2^-615
// (1e-185) wide lost its images' reach (wrong neighbours, validated), a
// sheared one got NaN heights, and one 2^665 (1e200) wide an infinite first
// layer, refused. They are now taken in a frame scaled near 1.
TEST(Periodic, BoxesAtTheEndsOfTheRange) {
  struct Case {
    int dim;
    std::array<bool, 3> per;
    Tilt tilt;
  };
  const Case cases[] = {{3, {true, true, true}, {0, 0, 0}},
                        {3, {true, true, true}, {0.25, 0.125, -0.375}},
                        {3, {true, false, true}, {0, 0, 0}},
                        {2, {true, true, false}, {0.375, 0, 0}},
                        {2, {false, true, false}, {0, 0, 0}}};
  for (const Case& cs : cases) {
    const auto unit = make_bounds({0, 0, 0}, {1, 1, 1});
    const auto pts = in_parallelepiped(300, cs.dim, 77, unit, cs.tilt);
    std::vector<double> radii(300);
    for (std::size_t i = 0; i < 300; ++i) radii[i] = std::ldexp(static_cast<double>((i * 37) % 11), -6);
    for (const bool power : {false, true}) {
      auto o = periodic_options(cs.dim, unit, cs.per, 2, cs.tilt);
      if (power) o.radii = radii;
      const tessera::Cells ref = tessera::voronoi(pts, cs.dim, {}, o);
      for (const int k : {-1000, -615, -330, 330, 665, 1000}) {
        SCOPED_TRACE(::testing::Message() << cs.dim << "D, tilt " << cs.tilt[0] << ", power " << power << ", 2^" << k);
        auto scaled = pts;
        for (double& x : scaled) x = std::ldexp(x, k);
        auto so = o;
        so.bounds = make_bounds({0, 0, 0}, {std::ldexp(1.0, k), std::ldexp(1.0, k), std::ldexp(1.0, k)});
        for (double& t : so.tilt) t = std::ldexp(t, k);
        std::vector<double> scaled_radii = radii;
        for (double& r : scaled_radii) r = std::ldexp(r, k);
        if (power) so.radii = scaled_radii;
        tessera::Cells c;
        try {
          c = tessera::voronoi(scaled, cs.dim, {}, so);
        } catch (const tessera::InputError& e) {
          // Past ~2^1020 the images themselves overflow; radii need a frame.
          ADD_FAILURE() << e.what();
          continue;
        }
        EXPECT_EQ(c.cell_of, ref.cell_of);
        EXPECT_EQ(c.neighbor_offsets, ref.neighbor_offsets);
        EXPECT_EQ(c.neighbors, ref.neighbors);
        EXPECT_EQ(c.neighbor_shifts, ref.neighbor_shifts);
      }
    }
  }
}

}  // namespace
