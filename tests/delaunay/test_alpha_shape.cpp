// Alpha shapes (tessera::alpha_shape): the kept simplices, the boundary and
// the singular facets equal CGAL's Alpha_shape_2/3 (GENERAL mode: INTERIOR
// cells, REGULAR and SINGULAR facets) on points in general position, with
// and without radii; the boundary is closed and oriented outward and
// encloses the kept volume; lattices' equal radii go one way, decided
// exactly; 1 vs 2 threads identical; bad arguments refused.
#include <gtest/gtest.h>

#include <CGAL/Alpha_shape_2.h>
#include <CGAL/Alpha_shape_3.h>
#include <CGAL/Alpha_shape_cell_base_3.h>
#include <CGAL/Alpha_shape_face_base_2.h>
#include <CGAL/Alpha_shape_vertex_base_2.h>
#include <CGAL/Alpha_shape_vertex_base_3.h>
#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Regular_triangulation_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "random_points.hpp"
#include "simplex_set.hpp"
#include "tessera/alpha_shape.hpp"
#include "tessera/delaunay.hpp"

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;

using AVb3 = CGAL::Alpha_shape_vertex_base_3<K, CGAL::Triangulation_vertex_base_with_info_3<std::int32_t, K>>;
using ATds3 = CGAL::Triangulation_data_structure_3<AVb3, CGAL::Alpha_shape_cell_base_3<K>>;
using ADT3 = CGAL::Delaunay_triangulation_3<K, ATds3>;
using AS3 = CGAL::Alpha_shape_3<ADT3>;

using RVb3 = CGAL::Alpha_shape_vertex_base_3<
    K, CGAL::Triangulation_vertex_base_with_info_3<std::int32_t, K, CGAL::Regular_triangulation_vertex_base_3<K>>>;
using RCb3 = CGAL::Alpha_shape_cell_base_3<K, CGAL::Regular_triangulation_cell_base_3<K>>;
using RTds3 = CGAL::Triangulation_data_structure_3<RVb3, RCb3>;
using RT3 = CGAL::Regular_triangulation_3<K, RTds3>;
using RAS3 = CGAL::Alpha_shape_3<RT3>;

using AVb2 = CGAL::Alpha_shape_vertex_base_2<K, CGAL::Triangulation_vertex_base_with_info_2<std::int32_t, K>>;
using ATds2 = CGAL::Triangulation_data_structure_2<AVb2, CGAL::Alpha_shape_face_base_2<K>>;
using ADT2 = CGAL::Delaunay_triangulation_2<K, ATds2>;
using AS2 = CGAL::Alpha_shape_2<ADT2>;

/// An alpha shape's parts as sets of sorted id tuples.
struct Parts {
  SimplexSet interior, regular, singular;
};

template <class AS>
Parts cgal_parts_3(AS& as) {
  Parts out;
  for (auto c = as.finite_cells_begin(); c != as.finite_cells_end(); ++c)
    if (as.classify(c) == AS::INTERIOR) {
      std::vector<std::int32_t> s;
      for (int k = 0; k < 4; ++k) s.push_back(c->vertex(k)->info());
      std::sort(s.begin(), s.end());
      out.interior.insert(s);
    }
  for (auto f = as.finite_facets_begin(); f != as.finite_facets_end(); ++f) {
    const auto cls = as.classify(*f);
    if (cls != AS::REGULAR && cls != AS::SINGULAR) continue;
    std::vector<std::int32_t> s;
    for (int j = 1; j < 4; ++j) s.push_back(f->first->vertex((f->second + j) % 4)->info());
    std::sort(s.begin(), s.end());
    (cls == AS::REGULAR ? out.regular : out.singular).insert(s);
  }
  return out;
}

Parts cgal_parts(const std::vector<double>& p, int dim, double alpha, const std::vector<double>& radii = {}) {
  const std::size_t n = p.size() / static_cast<std::size_t>(dim);
  if (dim == 3 && !radii.empty()) {
    std::vector<std::pair<K::Weighted_point_3, std::int32_t>> pts;
    for (std::size_t i = 0; i < n; ++i)
      pts.emplace_back(K::Weighted_point_3(K::Point_3(p[3 * i], p[3 * i + 1], p[3 * i + 2]), radii[i] * radii[i]),
                       static_cast<std::int32_t>(i));
    RT3 rt(pts.begin(), pts.end());
    RAS3 as(rt, alpha * alpha, RAS3::GENERAL);
    return cgal_parts_3(as);
  }
  if (dim == 3) {
    std::vector<std::pair<K::Point_3, std::int32_t>> pts;
    for (std::size_t i = 0; i < n; ++i)
      pts.emplace_back(K::Point_3(p[3 * i], p[3 * i + 1], p[3 * i + 2]), static_cast<std::int32_t>(i));
    ADT3 dt(pts.begin(), pts.end());
    AS3 as(dt, alpha * alpha, AS3::GENERAL);
    return cgal_parts_3(as);
  }
  std::vector<std::pair<K::Point_2, std::int32_t>> pts;
  for (std::size_t i = 0; i < n; ++i) pts.emplace_back(K::Point_2(p[2 * i], p[2 * i + 1]), static_cast<std::int32_t>(i));
  ADT2 dt(pts.begin(), pts.end());
  AS2 as(dt, alpha * alpha, AS2::GENERAL);
  Parts out;
  for (auto f = as.finite_faces_begin(); f != as.finite_faces_end(); ++f)
    if (as.classify(f) == AS2::INTERIOR) {
      std::vector<std::int32_t> s{f->vertex(0)->info(), f->vertex(1)->info(), f->vertex(2)->info()};
      std::sort(s.begin(), s.end());
      out.interior.insert(s);
    }
  for (auto e = as.finite_edges_begin(); e != as.finite_edges_end(); ++e) {
    const auto cls = as.classify(*e);
    if (cls != AS2::REGULAR && cls != AS2::SINGULAR) continue;
    std::vector<std::int32_t> s{e->first->vertex((e->second + 1) % 3)->info(), e->first->vertex((e->second + 2) % 3)->info()};
    std::sort(s.begin(), s.end());
    (cls == AS2::REGULAR ? out.regular : out.singular).insert(s);
  }
  return out;
}

SimplexSet facet_set(const std::vector<std::int32_t>& facets, int dim) {
  SimplexSet out;
  for (std::size_t f = 0; f < facets.size(); f += static_cast<std::size_t>(dim)) {
    std::vector<std::int32_t> s(facets.begin() + static_cast<std::ptrdiff_t>(f),
                                facets.begin() + static_cast<std::ptrdiff_t>(f) + dim);
    std::sort(s.begin(), s.end());
    out.insert(s);
  }
  return out;
}

Parts our_parts(const tessera::Delaunay& dt, const tessera::AlphaShape& a) {
  Parts out;
  const std::size_t w = static_cast<std::size_t>(dt.dim + 1);
  for (const std::int32_t r : a.simplex_rows) {
    std::vector<std::int32_t> s(dt.simplices.begin() + static_cast<std::ptrdiff_t>(static_cast<std::size_t>(r) * w),
                                dt.simplices.begin() + static_cast<std::ptrdiff_t>((static_cast<std::size_t>(r) + 1) * w));
    std::sort(s.begin(), s.end());
    out.interior.insert(s);
  }
  out.regular = facet_set(a.boundary, dt.dim);
  out.singular = facet_set(a.singular, dt.dim);
  return out;
}

tessera::Delaunay triangulate(const std::vector<double>& p, int dim, int threads = 2,
                              const std::vector<double>& radii = {}) {
  tessera::DelaunayOptions o;
  o.dim = dim;
  o.threads = threads;
  o.radii = radii;
  return tessera::delaunay(p, dim, {}, o);
}

/// The boundary is closed and consistently oriented, every facet faces away
/// from its simplex's remaining vertex, and it encloses the kept volume.
void expect_closed_outward(const tessera::Delaunay& dt, const std::vector<double>& p, const tessera::AlphaShape& a) {
  const int D = dt.dim;
  const std::size_t w = static_cast<std::size_t>(D + 1);
  std::map<std::pair<std::int32_t, std::int32_t>, int> directed;  // 3D edges, 2D (vertex, 0)
  double enclosed = 0;
  for (std::size_t f = 0; f < a.n_boundary(); ++f) {
    const std::int32_t* v = a.boundary.data() + f * static_cast<std::size_t>(D);
    const auto r = static_cast<std::size_t>(a.boundary_simplex[f]);
    std::int32_t apex = -1;
    for (std::size_t k = 0; k < w; ++k)
      if (std::find(v, v + D, dt.simplices[r * w + k]) == v + D) apex = dt.simplices[r * w + k];
    ASSERT_GE(apex, 0);
    auto at = [&](std::int32_t id, int d) { return p[static_cast<std::size_t>(id) * static_cast<std::size_t>(D) + static_cast<std::size_t>(d)]; };
    if (D == 3) {
      double e[3][3];
      for (int d = 0; d < 3; ++d) {
        e[0][d] = at(v[1], d) - at(v[0], d);
        e[1][d] = at(v[2], d) - at(v[0], d);
        e[2][d] = at(apex, d) - at(v[0], d);
      }
      const double nx = e[0][1] * e[1][2] - e[0][2] * e[1][1], ny = e[0][2] * e[1][0] - e[0][0] * e[1][2],
                   nz = e[0][0] * e[1][1] - e[0][1] * e[1][0];
      EXPECT_LT(nx * e[2][0] + ny * e[2][1] + nz * e[2][2], 0) << "facet " << f << " faces its own simplex";
      enclosed += (at(v[0], 0) * nx + at(v[0], 1) * ny + at(v[0], 2) * nz) / 6;  // divergence theorem
      for (int j = 0; j < 3; ++j) ++directed[{v[j], v[(j + 1) % 3]}];
    } else {
      const double ex = at(v[1], 0) - at(v[0], 0), ey = at(v[1], 1) - at(v[0], 1);
      EXPECT_GT(ex * (at(apex, 1) - at(v[0], 1)) - ey * (at(apex, 0) - at(v[0], 0)), 0) << "segment " << f;
      enclosed += (at(v[0], 0) * at(v[1], 1) - at(v[1], 0) * at(v[0], 1)) / 2;  // shoelace
      ++directed[{v[0], -1}];
      ++directed[{-1, v[1]}];
    }
  }
  // Closed and oriented: each directed edge is matched by its reverse as
  // often (3D); each vertex is left as often as reached (2D).
  for (const auto& [e, c] : directed) {
    const auto rev = directed.find({e.second, e.first});
    EXPECT_TRUE(rev != directed.end() && rev->second == c) << e.first << "-" << e.second;
  }
  EXPECT_NEAR(enclosed, a.volume, 1e-12 * std::max(1.0, std::fabs(a.volume)));
}

TEST(AlphaShape, EqualsCgalIn3D) {
  const std::vector<double> p = uniform_points(1500, 3, 91);
  const tessera::Delaunay dt = triangulate(p, 3);
  for (const double alpha : {0.04, 0.07, 0.1, 0.15, 0.3}) {
    const tessera::AlphaShape a = tessera::alpha_shape(dt, p, alpha);
    const Parts ours = our_parts(dt, a), cgal = cgal_parts(p, 3, alpha);
    EXPECT_EQ(ours.interior, cgal.interior) << alpha;
    EXPECT_EQ(ours.regular, cgal.regular) << alpha;
    EXPECT_EQ(ours.singular, cgal.singular) << alpha;
    EXPECT_EQ(a.n_boundary(), ours.regular.size());
    EXPECT_FALSE(ours.interior.empty());
    expect_closed_outward(dt, p, a);
    // Pieces: numbered in the order of their lowest rows, and kept
    // simplices sharing a facet in one piece.
    ASSERT_EQ(a.piece.size(), a.n_simplices());
    std::int32_t next_piece = 0;
    std::map<std::int32_t, std::int32_t> piece_of;
    for (std::size_t i = 0; i < a.n_simplices(); ++i) {
      if (a.piece[i] == next_piece) ++next_piece;
      EXPECT_LT(a.piece[i], next_piece);
      piece_of[a.simplex_rows[i]] = a.piece[i];
    }
    EXPECT_EQ(static_cast<std::size_t>(next_piece), a.components);
    const std::vector<std::int32_t> nb = tessera::simplex_neighbors(dt);
    for (const auto& [r, piece] : piece_of)
      for (std::size_t k = 0; k < 4; ++k) {
        const auto o = piece_of.find(nb[static_cast<std::size_t>(r) * 4 + k]);
        if (o != piece_of.end()) EXPECT_EQ(o->second, piece);
      }
  }
}

TEST(AlphaShape, EqualsCgalIn2D) {
  const std::vector<double> p = uniform_points(3000, 2, 92);
  const tessera::Delaunay dt = triangulate(p, 2);
  for (const double alpha : {0.005, 0.01, 0.02, 0.04}) {
    const tessera::AlphaShape a = tessera::alpha_shape(dt, p, alpha);
    const Parts ours = our_parts(dt, a), cgal = cgal_parts(p, 2, alpha);
    EXPECT_EQ(ours.interior, cgal.interior) << alpha;
    EXPECT_EQ(ours.regular, cgal.regular) << alpha;
    EXPECT_EQ(ours.singular, cgal.singular) << alpha;
    expect_closed_outward(dt, p, a);
  }
}

TEST(AlphaShape, WeightedEqualsCgalIn3D) {
  // Balls of radii up to about the spacing: the shape dual to their union
  // grown by alpha (alpha 0 included: the union itself).
  const std::vector<double> p = uniform_points(1200, 3, 93);
  std::mt19937_64 rng(94);
  std::uniform_real_distribution<double> u(0, 0.06);
  std::vector<double> radii(1200);
  for (double& r : radii) r = u(rng);
  const tessera::Delaunay dt = triangulate(p, 3, 2, radii);
  ASSERT_TRUE(dt.power);
  for (const double alpha : {0.0, 0.02, 0.05, 0.1}) {
    const tessera::AlphaShape a = tessera::alpha_shape(dt, p, alpha, radii);
    const Parts ours = our_parts(dt, a), cgal = cgal_parts(p, 3, alpha, radii);
    EXPECT_EQ(ours.interior, cgal.interior) << alpha;
    EXPECT_EQ(ours.regular, cgal.regular) << alpha;
    EXPECT_EQ(ours.singular, cgal.singular) << alpha;
    expect_closed_outward(dt, p, a);
  }
}

TEST(AlphaShape, InfiniteAlphaIsTheHull) {
  for (const int dim : {2, 3}) {
    const std::vector<double> p = uniform_points(800, dim, 95);
    const tessera::Delaunay dt = triangulate(p, dim);
    const tessera::AlphaShape a = tessera::alpha_shape(dt, p, std::numeric_limits<double>::infinity());
    EXPECT_EQ(a.n_simplices(), dt.n_simplices());
    EXPECT_EQ(a.components, 1u);
    EXPECT_EQ(a.nonmanifold_ridges, 0u);
    EXPECT_TRUE(a.singular.empty());
    // The hull: facets with no neighbour across them.
    const std::vector<std::int32_t> nb = tessera::simplex_neighbors(dt);
    EXPECT_EQ(a.n_boundary(), static_cast<std::size_t>(std::count(nb.begin(), nb.end(), -1)));
    expect_closed_outward(dt, p, a);
    const tessera::DelaunayReport rep = tessera::validate(dt, p, {});
    EXPECT_NEAR(a.volume, rep.volume_sum, 1e-12);
    // alpha 0 keeps nothing.
    const tessera::AlphaShape none = tessera::alpha_shape(dt, p, 0);
    EXPECT_EQ(none.n_simplices(), 0u);
    EXPECT_EQ(none.n_boundary(), 0u);
    EXPECT_EQ(none.volume, 0);
  }
}

TEST(AlphaShape, GrowsWithAlphaAndIsThreadIndependent) {
  const std::vector<double> p = height_field(3000, 96);  // surface samples: singular triangles
  const tessera::Delaunay dt1 = triangulate(p, 3, 1), dt2 = triangulate(p, 3, 2);
  std::vector<std::int32_t> before;
  for (const double alpha : {0.01, 0.02, 0.04, 0.08}) {
    const tessera::AlphaShape a = tessera::alpha_shape(dt1, p, alpha), b = tessera::alpha_shape(dt2, p, alpha);
    EXPECT_EQ(a.simplex_rows, b.simplex_rows);
    EXPECT_EQ(a.boundary, b.boundary);
    EXPECT_EQ(a.boundary_simplex, b.boundary_simplex);
    EXPECT_EQ(a.singular, b.singular);
    EXPECT_EQ(a.volume, b.volume);
    EXPECT_EQ(a.boundary_measure, b.boundary_measure);
    EXPECT_EQ(a.components, b.components);
    EXPECT_TRUE(std::includes(a.simplex_rows.begin(), a.simplex_rows.end(), before.begin(), before.end()));
    before = a.simplex_rows;
  }
  // The height field's samples give their surface as singular triangles.
  const tessera::AlphaShape s = tessera::alpha_shape(dt1, p, 0.04);
  EXPECT_GT(s.n_singular(), 3000u);
}

TEST(AlphaShape, LatticeRadiiAreDecidedExactly) {
  // Every Delaunay simplex of a cube (square) lattice has the cell's
  // circumsphere: r^2 = 0.75 (0.5) spacings^2. alpha the nearest double to
  // sqrt(0.75): all kept or none, as alpha^2 is above or below 0.75 exactly;
  // the doubles next to it go both ways.
  for (const int dim : {2, 3}) {
    std::vector<double> p;
    const int g = dim == 3 ? 6 : 12;
    // Spacing 0.5 away from the origin: the float filter cannot tell the
    // radii from alpha, rationals do.
    for (int i = 0; i < g; ++i)
      for (int j = 0; j < g; ++j)
        for (int k = 0; k < (dim == 3 ? g : 1); ++k) {
          p.push_back(3 + 0.5 * i);
          p.push_back(-7 + 0.5 * j);
          if (dim == 3) p.push_back(11 + 0.5 * k);
        }
    const tessera::Delaunay dt = triangulate(p, dim);
    const double r2 = dim == 3 ? 0.75 * 0.25 : 0.5 * 0.25;
    const double alpha = std::sqrt(r2);
    const bool above = std::fma(alpha, alpha, -r2) >= 0;  // alpha^2 >= r2, exactly
    const tessera::AlphaShape a = tessera::alpha_shape(dt, p, alpha);
    EXPECT_EQ(a.n_simplices(), above ? dt.n_simplices() : 0u) << dim;
    EXPECT_GT(a.exact_tests, 0u);
    const double up = std::nextafter(alpha, 1.0), down = std::nextafter(alpha, 0.0);
    EXPECT_EQ(tessera::alpha_shape(dt, p, std::fma(up, up, -r2) >= 0 ? up : std::nextafter(up, 1.0)).n_simplices(),
              dt.n_simplices());
    EXPECT_EQ(tessera::alpha_shape(dt, p, std::fma(down, down, -r2) < 0 ? down : std::nextafter(down, 0.0)).n_simplices(),
              0u);
    // The squared radii for inspection, in floats: within rounding of r2.
    for (const double s : tessera::simplex_squared_radii(dt, p)) EXPECT_NEAR(s, r2, 1e-12);
  }
}

TEST(AlphaShape, PiecesAndPinches) {
  // A bow tie (2D): two triangles (circumradius 0.589) meeting at a vertex,
  // and two thin ones (1.06) beside them: two pieces, one pinch.
  const std::vector<double> p{0, 0, 1, 0, 0.5, 0.9, 0, 1.8, 1, 1.8};
  const tessera::Delaunay dt = triangulate(p, 2);
  ASSERT_EQ(dt.n_simplices(), 4u);
  const tessera::AlphaShape a = tessera::alpha_shape(dt, p, 0.7);
  EXPECT_EQ(a.n_simplices(), 2u);
  EXPECT_EQ(a.components, 2u);
  EXPECT_EQ(a.nonmanifold_ridges, 1u);  // (0.5, 0.9)
  EXPECT_EQ(a.n_singular(), 0u);
  EXPECT_NEAR(a.volume, 0.9, 1e-15);
  EXPECT_NEAR(a.boundary_measure, 2 + 4 * std::sqrt(1.06), 1e-14);
  expect_closed_outward(dt, p, a);
}

/// boundary_polygons' rings use every boundary segment once, in its
/// direction; each piece is one polygon whose first ring is outer
/// (positive area) and the rest holes; and its rings' signed areas add up to
/// the piece's triangles' area.
void expect_polygons(const tessera::Delaunay& dt, const std::vector<double>& p, const tessera::AlphaShape& a) {
  const tessera::BoundaryPolygons poly = tessera::boundary_polygons(dt, p, a);
  ASSERT_EQ(poly.n_polygons(), a.components);
  std::multiset<std::pair<std::int32_t, std::int32_t>> segs, traced;
  for (std::size_t f = 0; f < a.n_boundary(); ++f) segs.insert({a.boundary[2 * f], a.boundary[2 * f + 1]});
  std::vector<double> piece_area(a.components, 0);
  for (std::size_t i = 0; i < a.n_simplices(); ++i) {
    const std::int32_t* t = dt.simplices.data() + 3 * static_cast<std::size_t>(a.simplex_rows[i]);
    auto x = [&](int k, int d) { return p[2 * static_cast<std::size_t>(t[k]) + static_cast<std::size_t>(d)]; };
    piece_area[static_cast<std::size_t>(a.piece[i])] +=
        ((x(1, 0) - x(0, 0)) * (x(2, 1) - x(0, 1)) - (x(1, 1) - x(0, 1)) * (x(2, 0) - x(0, 0))) / 2;
  }
  for (std::size_t k = 0; k < poly.n_polygons(); ++k) {
    double area = 0;
    for (auto r = poly.polygon_rings[k]; r != poly.polygon_rings[k + 1]; ++r) {
      const auto b = poly.ring_points[static_cast<std::size_t>(r)], e = poly.ring_points[static_cast<std::size_t>(r) + 1];
      double ring = 0;
      const double* o = &p[2 * static_cast<std::size_t>(poly.points[static_cast<std::size_t>(b)])];
      for (auto i = b; i != e; ++i) {
        const std::int32_t u = poly.points[static_cast<std::size_t>(i)];
        const std::int32_t v = poly.points[static_cast<std::size_t>(i + 1 == e ? b : i + 1)];
        traced.insert({u, v});
        const double* pu = &p[2 * static_cast<std::size_t>(u)];
        const double* pv = &p[2 * static_cast<std::size_t>(v)];
        ring += ((pu[0] - o[0]) * (pv[1] - o[1]) - (pu[1] - o[1]) * (pv[0] - o[0])) / 2;
      }
      EXPECT_EQ(ring > 0, r == poly.polygon_rings[k]) << "polygon " << k << " ring " << r;
      area += ring;
    }
    EXPECT_NEAR(area, piece_area[k], 1e-12 * std::max(1.0, std::fabs(piece_area[k]))) << "polygon " << k;
  }
  EXPECT_EQ(traced, segs);
}

TEST(AlphaShape, BoundaryPolygons) {
  // An annulus: one piece with a hole, and at smaller alphas many pieces,
  // holes, and vertices where the shape touches itself.
  std::mt19937_64 rng(98);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<double> p;
  for (int i = 0; i < 3000; ++i) {
    const double t = 2 * M_PI * u(rng), r = std::sqrt(0.25 + 0.75 * u(rng));
    p.push_back(r * std::cos(t));
    p.push_back(r * std::sin(t));
  }
  const tessera::Delaunay dt = triangulate(p, 2);
  std::size_t pinched = 0;
  for (const double alpha : {0.012, 0.016, 0.02, 0.03, 0.06, 1e9}) {
    const tessera::AlphaShape a = tessera::alpha_shape(dt, p, alpha);
    expect_polygons(dt, p, a);
    pinched += a.nonmanifold_ridges;
  }
  EXPECT_GT(pinched, 20u);  // the sector walks ran
  const tessera::AlphaShape one = tessera::alpha_shape(dt, p, 0.06);
  const tessera::BoundaryPolygons poly = tessera::boundary_polygons(dt, p, one);
  ASSERT_EQ(poly.n_polygons(), 1u);
  EXPECT_EQ(poly.n_rings(), 2u);  // the outer circle and the hole
  // The bow tie: two triangles, two polygons of one ring each.
  const std::vector<double> q{0, 0, 1, 0, 0.5, 0.9, 0, 1.8, 1, 1.8};
  const tessera::Delaunay bt = triangulate(q, 2);
  const tessera::AlphaShape b = tessera::alpha_shape(bt, q, 0.7);
  expect_polygons(bt, q, b);
  const tessera::BoundaryPolygons bp = tessera::boundary_polygons(bt, q, b);
  EXPECT_EQ(bp.n_polygons(), 2u);
  EXPECT_EQ(bp.n_rings(), 2u);
  // 3D shapes have no polygons.
  const std::vector<double> p3 = uniform_points(100, 3, 99);
  const tessera::Delaunay d3 = triangulate(p3, 3);
  EXPECT_THROW(tessera::boundary_polygons(d3, p3, tessera::alpha_shape(d3, p3, 0.3)), tessera::InputError);
}

/// Simplices or facets (k entries each: ids and, periodic, shifts) up to
/// translation: entries (id mod n, shift) sorted, shifted so the first is at 0.
using Key = std::vector<std::pair<std::int32_t, std::array<int, 3>>>;
Key canonical(Key e) {
  std::sort(e.begin(), e.end());
  const std::array<int, 3> base = e[0].second;
  for (auto& x : e)
    for (std::size_t a = 0; a < 3; ++a) x.second[a] -= base[a];
  return e;
}

TEST(AlphaShape, PeriodicEqualsTiledCopies) {
  // The periodic triangulation's alpha shape against the plain one of the
  // points tiled 3^D times (the wrapped points, so the coordinates agree
  // exactly), read off near the middle copy where the tiling's triangulation
  // is the periodic one: the same kept simplices and singular facets up to
  // translation, and the same boundary facets.
  for (const int dim : {2, 3}) {
    const std::size_t n = dim == 3 ? 500 : 700;
    const std::vector<double> p = uniform_points(n, dim, 100);
    tessera::DelaunayOptions o;
    o.dim = dim;
    o.bounds = tessera::Bounds{{0, 0, 0}, {1, 1, 1}};
    o.periodic = {true, true, dim == 3};
    const tessera::Delaunay pd = tessera::delaunay(p, dim, {}, o);
    ASSERT_TRUE(pd.is_periodic());
    const std::size_t du = static_cast<std::size_t>(dim), w = du + 1;
    std::vector<double> tiled;
    std::vector<std::array<int, 3>> copy_of;
    const int copies = dim == 3 ? 27 : 9;
    for (int c = 0; c < copies; ++c) {
      const std::array<int, 3> off{c % 3 - 1, c / 3 % 3 - 1, c / 9 - 1};
      for (std::size_t i = 0; i < n; ++i)
        for (std::size_t a = 0; a < du; ++a) tiled.push_back(pd.periodic_points[i * du + a] + off[a]);
      copy_of.push_back(off);
    }
    const tessera::Delaunay td = triangulate(tiled, dim);
    const double alpha = dim == 3 ? 0.09 : 0.035;
    const tessera::AlphaShape pa = tessera::alpha_shape(pd, p, alpha);
    const tessera::AlphaShape ta = tessera::alpha_shape(td, tiled, alpha);
    ASSERT_GT(pa.n_simplices(), 0u);
    ASSERT_LT(pa.n_simplices(), pd.n_simplices());
    // Periodic: entries from the rows and shifts.
    auto periodic_keys = [&](const std::vector<std::int32_t>& ids, const std::vector<std::int8_t>& shifts, std::size_t k) {
      std::set<Key> out;
      for (std::size_t f = 0; f < ids.size() / k; ++f) {
        Key e;
        for (std::size_t j = 0; j < k; ++j) {
          std::array<int, 3> s{0, 0, 0};
          for (std::size_t a = 0; a < du; ++a) s[a] = shifts[(f * k + j) * du + a];
          e.push_back({ids[f * k + j], s});
        }
        out.insert(canonical(e));
      }
      return out;
    };
    // Tiled: entries from the copies, for those with every corner in [-0.5, 1.5)^D.
    auto tiled_keys = [&](const std::vector<std::int32_t>& ids, std::size_t k) {
      std::set<Key> out;
      for (std::size_t f = 0; f < ids.size() / k; ++f) {
        Key e;
        bool inner = true;
        for (std::size_t j = 0; j < k; ++j) {
          const auto id = static_cast<std::size_t>(ids[f * k + j]);
          for (std::size_t a = 0; a < du; ++a) inner = inner && std::fabs(tiled[id * du + a] - 0.5) < 1;
          e.push_back({static_cast<std::int32_t>(id % n), copy_of[id / n]});
        }
        if (inner) out.insert(canonical(e));
      }
      return out;
    };
    std::vector<std::int32_t> kept_rows, kept_tiled;
    std::vector<std::int8_t> kept_shifts;
    for (const std::int32_t r : pa.simplex_rows) {
      kept_rows.insert(kept_rows.end(), pd.simplices.begin() + static_cast<std::ptrdiff_t>(static_cast<std::size_t>(r) * w),
                       pd.simplices.begin() + static_cast<std::ptrdiff_t>((static_cast<std::size_t>(r) + 1) * w));
      kept_shifts.insert(kept_shifts.end(),
                         pd.simplex_shifts.begin() + static_cast<std::ptrdiff_t>(static_cast<std::size_t>(r) * w * du),
                         pd.simplex_shifts.begin() + static_cast<std::ptrdiff_t>((static_cast<std::size_t>(r) + 1) * w * du));
    }
    for (const std::int32_t r : ta.simplex_rows)
      kept_tiled.insert(kept_tiled.end(), td.simplices.begin() + static_cast<std::ptrdiff_t>(static_cast<std::size_t>(r) * w),
                        td.simplices.begin() + static_cast<std::ptrdiff_t>((static_cast<std::size_t>(r) + 1) * w));
    const std::set<Key> kp = periodic_keys(kept_rows, kept_shifts, w);
    EXPECT_EQ(kp.size(), pa.n_simplices());
    EXPECT_EQ(kp, tiled_keys(kept_tiled, w)) << dim;
    EXPECT_EQ(periodic_keys(pa.boundary, pa.boundary_shifts, du), tiled_keys(ta.boundary, du)) << dim;
    EXPECT_EQ(periodic_keys(pa.singular, pa.singular_shifts, du), tiled_keys(ta.singular, du)) << dim;
    EXPECT_EQ(pa.n_boundary() * du * du, pa.boundary_shifts.size());
    // The volume: the kept simplices' images, placed by their shifts.
    double volume = 0;
    for (std::size_t f = 0; f < kept_rows.size() / w; ++f) {
      double x[4][3] = {};
      for (std::size_t j = 0; j < w; ++j)
        for (std::size_t a = 0; a < du; ++a)
          x[j][a] = pd.periodic_points[static_cast<std::size_t>(kept_rows[f * w + j]) * du + a] +
                    kept_shifts[(f * w + j) * du + a];  // the unit box: shifts are lengths
      double e[3][3] = {};
      for (std::size_t j = 0; j < du; ++j)
        for (std::size_t a = 0; a < du; ++a) e[j][a] = x[j + 1][a] - x[0][a];
      volume += dim == 3 ? (e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
                            e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                            e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0])) / 6
                         : (e[0][0] * e[1][1] - e[0][1] * e[1][0]) / 2;
    }
    EXPECT_NEAR(pa.volume, volume, 1e-12);
    EXPECT_GT(pa.volume, 0.05);
    EXPECT_LT(pa.volume, 1);
    // Thread independence.
    o.threads = 1;
    const tessera::AlphaShape one = tessera::alpha_shape(tessera::delaunay(p, dim, {}, o), p, alpha);
    EXPECT_EQ(one.simplex_rows, pa.simplex_rows);
    EXPECT_EQ(one.boundary_shifts, pa.boundary_shifts);
    EXPECT_EQ(one.volume, pa.volume);
    EXPECT_EQ(one.components, pa.components);
    // At alpha = inf every simplex is kept: no boundary, one piece, the box's volume.
    const tessera::AlphaShape all = tessera::alpha_shape(pd, p, std::numeric_limits<double>::infinity());
    EXPECT_EQ(all.n_boundary(), 0u);
    EXPECT_EQ(all.components, 1u);
    EXPECT_NEAR(all.volume, 1, 1e-12);
  }
}

TEST(AlphaShape, RefusesBadArguments) {
  const std::vector<double> p = uniform_points(50, 3, 97);
  const tessera::Delaunay dt = triangulate(p, 3);
  EXPECT_THROW(tessera::alpha_shape(dt, p, -1), tessera::InputError);
  EXPECT_THROW(tessera::alpha_shape(dt, p, std::nan("")), tessera::InputError);
  EXPECT_THROW(tessera::alpha_shape(dt, std::vector<double>(p.begin(), p.end() - 3), 0.1), tessera::InputError);
  EXPECT_THROW(tessera::alpha_shape(dt, p, 0.1, std::vector<double>(50, 0.01)), tessera::InputError);
  std::vector<double> radii(50, 0.01);
  radii[3] = 0.02;
  const tessera::Delaunay rt = triangulate(p, 3, 2, radii);
  EXPECT_THROW(tessera::alpha_shape(rt, p, 0.1), tessera::InputError);
  radii[4] = -1;
  EXPECT_THROW(tessera::alpha_shape(rt, p, 0.1, radii), tessera::InputError);
}

}  // namespace
