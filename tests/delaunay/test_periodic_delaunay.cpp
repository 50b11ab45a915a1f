// The Delaunay triangulation of a periodic box (every axis periodic).
//
// What this proves:
// * the simplices, as (point, image) tuples up to a common translation,
//   equal CGAL's Periodic_3_Delaunay_triangulation_3 on random points in a
//   cube (general position);
// * triclinic and 2D boxes give valid periodic triangulations (validate():
//   orientation with the shifts, every facet in two simplices and locally
//   Delaunay, volumes tiling the box), with the counts a torus has (2D:
//   2n triangles; 3D: V - E + T = 0);
// * a lattice (all ties) too, and 1 and 2 threads give identical rows;
// * what is refused: walls, outside points, the helpers that match facets
//   or edges by ids alone.
#include <gtest/gtest.h>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Periodic_3_Delaunay_triangulation_3.h>
#include <CGAL/Periodic_3_Delaunay_triangulation_traits_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <set>
#include <vector>

#include "random_points.hpp"
#include "tessera/delaunay.hpp"
#include "tessera/locate.hpp"

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Gt = CGAL::Periodic_3_Delaunay_triangulation_traits_3<K>;
using VbDs = CGAL::Triangulation_vertex_base_3<Gt, CGAL::Periodic_3_triangulation_ds_vertex_base_3<>>;
using Vb = CGAL::Triangulation_vertex_base_with_info_3<std::int32_t, Gt, VbDs>;
using Cb = CGAL::Triangulation_cell_base_3<Gt, CGAL::Periodic_3_triangulation_ds_cell_base_3<>>;
using Tds = CGAL::Triangulation_data_structure_3<Vb, Cb>;
using P3DT = CGAL::Periodic_3_Delaunay_triangulation_3<Gt, Tds>;

using Entry = std::pair<std::int32_t, std::array<int, 3>>;
using Simplex = std::vector<Entry>;

/// A simplex up to translation: its least (id, shift) entry moved to shift 0.
Simplex canonical(Simplex s) {
  std::sort(s.begin(), s.end());
  const std::array<int, 3> first = s[0].second;
  for (auto& [id, sh] : s)
    for (std::size_t a = 0; a < 3; ++a) sh[a] -= first[a];
  return s;
}

/// Row r of D+1 (id, shift) entries from parallel arrays of ids and shifts.
Simplex row_of(const std::int32_t* ids, const std::int8_t* shifts, std::size_t r, std::size_t du) {
  Simplex x;
  for (std::size_t k = 0; k <= du; ++k) {
    std::array<int, 3> sh{0, 0, 0};
    for (std::size_t a = 0; a < du; ++a) sh[a] = shifts[(r * (du + 1) + k) * du + a];
    x.push_back({ids[r * (du + 1) + k], sh});
  }
  return x;
}

std::set<Simplex> ours(const tessera::Delaunay& dt) {
  const auto du = static_cast<std::size_t>(dt.dim);
  std::set<Simplex> out;
  for (std::size_t s = 0; s < dt.n_simplices(); ++s) {
    const Simplex x = row_of(dt.simplices.data(), dt.simplex_shifts.data(), s, du);
    const Simplex c = canonical(x);
    Simplex sorted = x;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(sorted, c) << "row " << s << " is not in canonical form";
    out.insert(c);
  }
  EXPECT_EQ(out.size(), dt.n_simplices()) << "a simplex listed twice";
  return out;
}

tessera::DelaunayOptions periodic_options(int dim, const std::array<double, 3>& hi, const std::array<double, 3>& tilt,
                                          int threads = 1) {
  tessera::DelaunayOptions o;
  o.dim = dim;
  o.bounds = tessera::Bounds{{0, 0, 0}, hi};
  o.periodic = {true, true, dim == 3};
  o.tilt = tilt;
  o.threads = threads;
  return o;
}

void expect_valid(const tessera::Delaunay& dt) {
  const tessera::DelaunayReport r = tessera::validate(dt, {}, {});
  EXPECT_TRUE(r.ok) << (r.messages.empty() ? "" : r.messages[0]);
  EXPECT_EQ(r.boundary_facets, 0u);
  EXPECT_EQ(r.local_delaunay_violations, 0u);
  EXPECT_NEAR(r.volume_sum, r.enclosed_volume, 1e-12 * r.enclosed_volume);
}

/// Distinct edges up to translation.
std::size_t edges(const tessera::Delaunay& dt) {
  const auto du = static_cast<std::size_t>(dt.dim), w = du + 1;
  std::set<Simplex> out;
  for (std::size_t s = 0; s < dt.n_simplices(); ++s) {
    const Simplex x = row_of(dt.simplices.data(), dt.simplex_shifts.data(), s, du);
    for (std::size_t i = 0; i < w; ++i)
      for (std::size_t j = i + 1; j < w; ++j) out.insert(canonical({x[i], x[j]}));
  }
  return out.size();
}

TEST(PeriodicDelaunay, EqualsCgalsPeriodicTriangulation) {
  const std::size_t n = 2000;
  const auto pts = uniform_points(n, 3, 71);
  P3DT cgal(P3DT::Iso_cuboid(0, 0, 0, 1, 1, 1));
  for (std::size_t i = 0; i < n; ++i)
    cgal.insert(K::Point_3(pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]))->info() = static_cast<std::int32_t>(i);
  ASSERT_TRUE(cgal.is_1_cover());
  std::set<Simplex> want;
  for (auto c = cgal.cells_begin(); c != cgal.cells_end(); ++c) {
    Simplex s;
    for (int k = 0; k < 4; ++k) {
      const auto off = cgal.get_offset(c, k);
      s.push_back({c->vertex(k)->info(), {off.x(), off.y(), off.z()}});
    }
    want.insert(canonical(s));
  }
  // The points lie on a grid finer than the box's (2^-51): as given.
  const tessera::Delaunay dt = tessera::delaunay(pts, 3, {}, periodic_options(3, {1, 1, 1}, {0, 0, 0}));
  EXPECT_EQ(ours(dt), want);
  EXPECT_EQ(dt.n_simplices(), cgal.number_of_cells());
  expect_valid(dt);
}

TEST(PeriodicDelaunay, EqualsThePeriodicCellsMergedVertices) {
  // The cells' merged vertices with their keys' shifts (Cells::
  // vertex_key_shifts), each simplex taken where its key starts at shift 0:
  // the same simplices as the triangulation's, which comes from the cells
  // pass instead (triclinic 3D and 2D).
  for (int dim : {2, 3}) {
    SCOPED_TRACE(dim);
    const auto pts = uniform_points(1500, dim, 75);
    const auto o = periodic_options(dim, {1, 1.25, dim == 3 ? 0.75 : 0}, {0.25, dim == 3 ? -0.375 : 0, 0});
    const tessera::Delaunay dt = tessera::delaunay(pts, dim, {}, o);
    tessera::VoronoiOptions vo = o;
    vo.build_mesh = true;
    const tessera::Cells c = tessera::voronoi(pts, dim, {}, vo);
    const auto du = static_cast<std::size_t>(dim);
    ASSERT_EQ(c.vertex_key_shifts.size(), c.vertex_keys.size() * du);
    std::set<Simplex> from_keys;
    for (std::size_t v = 0; v < c.n_vertices(); ++v) {
      const Simplex s = row_of(c.vertex_keys.data(), c.vertex_key_shifts.data(), v, du);
      EXPECT_TRUE(std::is_sorted(s.begin(), s.end())) << "key " << v << " not ascending by (id, shift)";
      from_keys.insert(canonical(s));
    }
    EXPECT_EQ(ours(dt), from_keys);
  }
}

TEST(PeriodicDelaunay, TriclinicAnd2DBoxesAreValidTori) {
  {
    const auto pts = uniform_points(3000, 3, 72);
    const auto o = periodic_options(3, {1, 1.5, 0.75}, {0.3, -0.2, 0.45});
    const tessera::Delaunay a = tessera::delaunay(pts, 3, {}, o);
    auto o2 = o;
    o2.threads = 2;
    const tessera::Delaunay b = tessera::delaunay(pts, 3, {}, o2);
    EXPECT_EQ(a.simplices, b.simplices);
    EXPECT_EQ(a.simplex_shifts, b.simplex_shifts);
    ours(a);
    expect_valid(a);
    // Euler characteristic of the 3-torus: V - E + F - T = 0 with F = 2T.
    EXPECT_EQ(static_cast<long>(3000) - static_cast<long>(edges(a)) + static_cast<long>(a.n_simplices()), 0);
    // validate() sees a vertex moved to another image, and a dropped simplex.
    tessera::Delaunay moved = a;
    moved.simplex_shifts[3 * 100 + 1] = static_cast<std::int8_t>(moved.simplex_shifts[3 * 100 + 1] + 1);
    EXPECT_FALSE(tessera::validate(moved, {}, {}).ok);
    tessera::Delaunay dropped = a;
    dropped.simplices.resize(dropped.simplices.size() - 4);
    dropped.simplex_shifts.resize(dropped.simplex_shifts.size() - 12);
    const tessera::DelaunayReport r = tessera::validate(dropped, {}, {});
    EXPECT_FALSE(r.ok);
    EXPECT_EQ(r.boundary_facets, 4u);
  }
  {
    const auto pts = uniform_points(3000, 2, 73);
    const tessera::Delaunay dt = tessera::delaunay(pts, 2, {}, periodic_options(2, {2, 1, 0}, {-0.625, 0, 0}));
    ours(dt);
    expect_valid(dt);
    EXPECT_EQ(dt.n_simplices(), 2u * 3000u);  // a triangulated torus: F = 2V
  }
}

// Boxes at the ends of double's range (the points, box and tilts scaled by
// 2^k, exactly): the unit box's rows and shifts, validated. The periodic
// setup's heights and first layer under- and overflowed there (wrong or
// refused, as for the cells: Periodic.BoxesAtTheEndsOfTheRange), and
// validate's volume sum read 2^1995 as infinity and failed.
TEST(PeriodicDelaunay, BoxesAtTheEndsOfTheRange) {
  for (int dim : {2, 3}) {
    const auto pts = uniform_points(400, dim, 74);
    const std::array<double, 3> tilt = dim == 3 ? std::array<double, 3>{0.25, 0.125, -0.375}
                                                : std::array<double, 3>{0.375, 0, 0};
    const tessera::Delaunay ref = tessera::delaunay(pts, dim, {}, periodic_options(dim, {1, 1, 1}, tilt));
    for (const int k : {-1000, -615, 665, 1000}) {
      SCOPED_TRACE(::testing::Message() << dim << "D, 2^" << k);
      auto scaled = pts;
      for (double& x : scaled) x = std::ldexp(x, k);
      std::array<double, 3> t = tilt;
      for (double& x : t) x = std::ldexp(x, k);
      const double l = std::ldexp(1.0, k);
      const tessera::Delaunay dt = tessera::delaunay(scaled, dim, {}, periodic_options(dim, {l, l, l}, t, 2));
      EXPECT_EQ(dt.simplices, ref.simplices);
      EXPECT_EQ(dt.simplex_shifts, ref.simplex_shifts);
      const tessera::DelaunayReport r = tessera::validate(dt, {}, {});
      EXPECT_TRUE(r.ok) << (r.messages.empty() ? "" : r.messages[0]);
    }
  }
}

TEST(PeriodicDelaunay, LatticeTiesAndFewPoints) {
  // A cubic lattice: every Delaunay ball holds 8 points, split alike from
  // every cell by the perturbation. Boxes of 1-3 points: simplices meet
  // several images of one point.
  std::vector<double> lattice;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 4; ++k) lattice.insert(lattice.end(), {(i + 0.5) / 4, (j + 0.5) / 4, (k + 0.5) / 4});
  const tessera::Delaunay dt = tessera::delaunay(lattice, 3, {}, periodic_options(3, {1, 1, 1}, {0, 0, 0}));
  ours(dt);
  expect_valid(dt);
  for (std::size_t n : {1, 2, 3}) {
    const auto pts = uniform_points(n, 3, 80 + n);
    const tessera::Delaunay few = tessera::delaunay(pts, 3, {}, periodic_options(3, {1, 1, 1}, {0.25, 0, 0.5}));
    ours(few);
    expect_valid(few);
    const auto pts2 = uniform_points(n, 2, 90 + n);
    const tessera::Delaunay few2 = tessera::delaunay(pts2, 2, {}, periodic_options(2, {1, 1, 0}, {0.375, 0, 0}));
    ours(few2);
    expect_valid(few2);
    EXPECT_EQ(few2.n_simplices(), 2 * n);
  }
}

// Regular triangulations of a periodic box (radii): the same simplices as
// the non-periodic regular triangulation of the points' 3^D tiled copies
// (each copy with its point's radius), taken where they touch the central
// copy; the same hidden points as the central copy's. Points on a 2^-40
// grid, so the copies are exact; an orthogonal 3D box, a triclinic one, and
// a triclinic 2D one.
TEST(PeriodicDelaunay, RegularEqualsTheTiledRegularTriangulation) {
  for (int dim : {3, 2}) {
    for (const std::array<double, 3> tilt : {std::array<double, 3>{0, 0, 0}, std::array<double, 3>{0.25, -0.125, 0.375}}) {
      const std::size_t n = dim == 3 ? 400 : 600;
      auto pts = uniform_points(n, dim, 75);
      for (double& x : pts) x = std::ldexp(std::floor(std::ldexp(x, 40)), -40);
      std::mt19937_64 rng(76);
      std::uniform_real_distribution<double> u(0, (dim == 3 ? 1.2 : 1.5) * std::pow(double(n), -1.0 / dim));
      std::vector<double> radii(n);
      for (double& r : radii) r = u(rng);
      auto o = periodic_options(dim, {1, 1, 1}, dim == 3 ? tilt : std::array<double, 3>{tilt[0], 0, 0}, 2);
      o.radii = radii;
      const tessera::Delaunay dt = tessera::delaunay(pts, dim, {}, o);
      EXPECT_TRUE(dt.power);
      ASSERT_FALSE(dt.hidden.empty());
      const tessera::DelaunayReport rep = tessera::validate(dt, {}, {}, radii);
      EXPECT_TRUE(rep.ok) << (rep.messages.empty() ? "" : rep.messages[0]);

      // The tiled copies: copy c has shift (c % 3 - 1, c / 3 % 3 - 1, c / 9 - 1).
      const auto lattice = tessera::periodic_lattice(dt.bounds, dt.tilt);
      const int copies = dim == 3 ? 27 : 9;
      std::vector<double> tiled, tiled_radii;
      std::vector<std::array<int, 3>> shift_of;
      for (int c = 0; c < copies; ++c) {
        const std::array<int, 3> sh{c % 3 - 1, c / 3 % 3 - 1, dim == 3 ? c / 9 - 1 : 0};
        shift_of.push_back(sh);
        for (std::size_t i = 0; i < n; ++i) {
          double x[3];
          tessera::periodic_image(lattice, dim, &dt.periodic_points[i * static_cast<std::size_t>(dim)], sh, x);
          tiled.insert(tiled.end(), x, x + dim);
          tiled_radii.push_back(radii[i]);
        }
      }
      tessera::DelaunayOptions plain;
      plain.dim = dim;
      plain.radii = tiled_radii;
      const tessera::Delaunay big = tessera::delaunay(tiled, dim, {}, plain);
      std::set<Simplex> want;
      const std::size_t w = static_cast<std::size_t>(dim + 1);
      for (std::size_t s = 0; s < big.n_simplices(); ++s) {
        Simplex x;
        bool central = false;
        for (std::size_t k = 0; k < w; ++k) {
          const auto id = static_cast<std::size_t>(big.simplices[s * w + k]);
          x.push_back({static_cast<std::int32_t>(id % n), shift_of[id / n]});
          central |= shift_of[id / n] == std::array<int, 3>{0, 0, 0};
        }
        if (central) want.insert(canonical(x));
      }
      EXPECT_EQ(ours(dt), want) << dim << "D, tilt " << tilt[0];
      const std::size_t centre = static_cast<std::size_t>(copies / 2) * n;
      std::vector<std::int32_t> hidden;
      for (const std::int32_t h : big.hidden)
        if (static_cast<std::size_t>(h) >= centre && static_cast<std::size_t>(h) < centre + n)
          hidden.push_back(static_cast<std::int32_t>(static_cast<std::size_t>(h) - centre));
      EXPECT_EQ(dt.hidden, hidden);
      o.threads = 1;
      EXPECT_EQ(tessera::delaunay(pts, dim, {}, o).simplices, dt.simplices);
    }
  }
}

// Weights far above the box's size (fuzz, stop 78): two spheres of radius
// 2 in a unit box hide the 60 small ones, and the triangles join one of
// them to images of the other up to two box lengths away. validate() used
// to look for the hidden points' triangles only among translates by -1..1
// and reported them in conflict. The triangles equal those of the 7x7 tiled
// copies' regular triangulation that touch the central copy.
TEST(PeriodicDelaunay, RegularWithWeightsBeyondTheBox) {
  const std::size_t n = 62;
  auto pts = uniform_points(n, 2, 77);
  for (double& x : pts) x = std::ldexp(std::floor(std::ldexp(x, 40)), -40);
  // The two large ones where their triangles' canonical translates reach
  // the second image up (found by a search over positions).
  pts[0] = 0.125, pts[1] = 0.796875, pts[2] = 0.078125, pts[3] = 0.078125;
  std::vector<double> radii(n, 0.02);
  radii[0] = radii[1] = 2.0;
  auto o = periodic_options(2, {1, 1, 1}, {0.25, 0, 0}, 2);
  o.radii = radii;
  const tessera::Delaunay dt = tessera::delaunay(pts, 2, {}, o);
  const tessera::DelaunayReport rep = tessera::validate(dt, {}, {}, radii);
  EXPECT_TRUE(rep.ok) << (rep.messages.empty() ? "" : rep.messages[0]);
  EXPECT_EQ(dt.hidden.size(), n - 2);
  int far = 0;
  for (const std::int8_t s : dt.simplex_shifts) far = std::max(far, std::abs(int{s}));
  EXPECT_GE(far, 2) << "the triangles should span two box lengths";
  const auto lattice = tessera::periodic_lattice(dt.bounds, dt.tilt);
  std::vector<double> tiled, tiled_radii;
  std::vector<std::array<int, 3>> shift_of;
  for (int i = -3; i <= 3; ++i)
    for (int j = -3; j <= 3; ++j)
      for (std::size_t k = 0; k < n; ++k) {
        const std::array<int, 3> sh{i, j, 0};
        double x[3];
        tessera::periodic_image(lattice, 2, &dt.periodic_points[2 * k], sh, x);
        tiled.insert(tiled.end(), x, x + 2);
        tiled_radii.push_back(radii[k]);
        shift_of.push_back(sh);
      }
  tessera::DelaunayOptions plain;
  plain.dim = 2;
  plain.radii = tiled_radii;
  const tessera::Delaunay big = tessera::delaunay(tiled, 2, {}, plain);
  std::set<Simplex> want;
  for (std::size_t s = 0; s < big.n_simplices(); ++s) {
    Simplex x;
    bool central = false;
    for (std::size_t k = 0; k < 3; ++k) {
      const auto id = static_cast<std::size_t>(big.simplices[s * 3 + k]);
      x.push_back({static_cast<std::int32_t>(id % n), shift_of[id]});
      central |= shift_of[id] == std::array<int, 3>{0, 0, 0};
    }
    if (central) want.insert(canonical(x));
  }
  EXPECT_EQ(ours(dt), want);
}

TEST(PeriodicDelaunay, Refused) {
  const auto pts = uniform_points(200, 3, 74);
  auto walls = periodic_options(3, {1, 1, 1}, {0, 0, 0});
  walls.periodic = {true, true, false};
  EXPECT_THROW(tessera::delaunay(pts, 3, {}, walls), tessera::InputError);
  std::vector<std::int32_t> labels(200, 0);
  labels[5] = -1;
  EXPECT_THROW(tessera::delaunay(pts, 3, labels, periodic_options(3, {1, 1, 1}, {0, 0, 0})), tessera::InputError);
  const tessera::Delaunay dt = tessera::delaunay(pts, 3, {}, periodic_options(3, {1, 1, 1}, {0, 0, 0}));
  EXPECT_THROW(tessera::simplex_neighbors(dt), tessera::InputError);
  EXPECT_THROW(tessera::vertex_neighbors(dt), tessera::InputError);
  EXPECT_THROW(tessera::SimplexLocator(dt, pts), tessera::InputError);
  EXPECT_EQ(tessera::vertex_to_simplex(dt).size(), 200u);  // ids alone: served
}

}  // namespace
