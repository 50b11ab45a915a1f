// CGAL's Delaunay triangulation (Debian libcgal-dev, used only by tests) as an
// oracle for the adjacency graph: its edges and, per finite simplex, the
// circumcentre (the Voronoi vertex dual to it).
#pragma once

#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <set>
#include <utility>
#include <vector>

namespace dual_test {

struct OracleSimplex {
  std::vector<std::int32_t> ids;       ///< D+1 point ids
  std::array<double, 3> circumcentre;  ///< z = 0 in 2D
};

struct OracleTriangulation {
  std::set<std::pair<std::int32_t, std::int32_t>> edges;  ///< (lower id, higher id)
  std::vector<OracleSimplex> simplices;
};

inline OracleTriangulation cgal_delaunay(const std::vector<double>& p, int dim) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  OracleTriangulation out;
  auto add = [&](std::vector<std::int32_t> ids, std::array<double, 3> cc) {
    std::sort(ids.begin(), ids.end());
    for (std::size_t a = 0; a < ids.size(); ++a)
      for (std::size_t b = a + 1; b < ids.size(); ++b) out.edges.insert({ids[a], ids[b]});
    out.simplices.push_back({std::move(ids), cc});
  };
  const std::size_t n = p.size() / static_cast<std::size_t>(dim);
  if (dim == 3) {
    using Vb = CGAL::Triangulation_vertex_base_with_info_3<std::int32_t, K>;
    using DT = CGAL::Delaunay_triangulation_3<K, CGAL::Triangulation_data_structure_3<Vb>>;
    std::vector<std::pair<K::Point_3, std::int32_t>> pts;
    for (std::size_t i = 0; i < n; ++i)
      pts.emplace_back(K::Point_3(p[3 * i], p[3 * i + 1], p[3 * i + 2]), static_cast<std::int32_t>(i));
    DT dt(pts.begin(), pts.end());
    for (auto c = dt.finite_cells_begin(); c != dt.finite_cells_end(); ++c) {
      const auto cc = CGAL::circumcenter(c->vertex(0)->point(), c->vertex(1)->point(), c->vertex(2)->point(),
                                         c->vertex(3)->point());
      add({c->vertex(0)->info(), c->vertex(1)->info(), c->vertex(2)->info(), c->vertex(3)->info()},
          {cc.x(), cc.y(), cc.z()});
    }
  } else {
    using Vb = CGAL::Triangulation_vertex_base_with_info_2<std::int32_t, K>;
    using DT = CGAL::Delaunay_triangulation_2<K, CGAL::Triangulation_data_structure_2<Vb>>;
    std::vector<std::pair<K::Point_2, std::int32_t>> pts;
    for (std::size_t i = 0; i < n; ++i)
      pts.emplace_back(K::Point_2(p[2 * i], p[2 * i + 1]), static_cast<std::int32_t>(i));
    DT dt(pts.begin(), pts.end());
    for (auto f = dt.finite_faces_begin(); f != dt.finite_faces_end(); ++f) {
      const auto cc = CGAL::circumcenter(f->vertex(0)->point(), f->vertex(1)->point(), f->vertex(2)->point());
      add({f->vertex(0)->info(), f->vertex(1)->info(), f->vertex(2)->info()}, {cc.x(), cc.y(), 0.0});
    }
  }
  return out;
}

}  // namespace dual_test
