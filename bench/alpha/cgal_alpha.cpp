// CGAL's alpha shapes, the peer of `tessera bench delaunay --alpha R`: the
// Delaunay triangulation (Epick; 3D Parallel_tag with a spatial lock grid for
// more than one thread, as the shared peers' cgal_delaunay3), then the alpha
// shape at CGAL's alpha = R^2 (3D: Fixed_alpha_shape_3, CGAL's structure for
// one alpha; 2D: Alpha_shape_2 in GENERAL mode) and the extraction of its
// INTERIOR cells and REGULAR and SINGULAR facets (edges in 2D), which is
// what Tessera's timed call returns. Prints one JSON line in the peers'
// format: op alpha3|alpha2, seconds both steps, simplices the INTERIOR cells;
// extra.triangulate_s, alpha_s, boundary (REGULAR), singular.
//
// usage: cgal_alpha POINTS.npy R THREADS
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <utility>
#include <vector>

#include <CGAL/Alpha_shape_2.h>
#include <CGAL/Alpha_shape_face_base_2.h>
#include <CGAL/Alpha_shape_vertex_base_2.h>
#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/bounding_box.h>
#include <CGAL/Fixed_alpha_shape_3.h>
#include <CGAL/Fixed_alpha_shape_cell_base_3.h>
#include <CGAL/Fixed_alpha_shape_vertex_base_3.h>
#include <tbb/global_control.h>

#include "../power/npy_f8.hpp"

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

template <class Concurrency>
using Tds3 = CGAL::Triangulation_data_structure_3<CGAL::Fixed_alpha_shape_vertex_base_3<K>,
                                                  CGAL::Fixed_alpha_shape_cell_base_3<K>, Concurrency>;
using SeqDT3 = CGAL::Delaunay_triangulation_3<K, Tds3<CGAL::Sequential_tag>>;
using ParDT3 = CGAL::Delaunay_triangulation_3<K, Tds3<CGAL::Parallel_tag>, CGAL::Default,
                                              CGAL::Spatial_lock_grid_3<CGAL::Tag_priority_blocking>>;

using Tds2 = CGAL::Triangulation_data_structure_2<CGAL::Alpha_shape_vertex_base_2<K>, CGAL::Alpha_shape_face_base_2<K>>;
using DT2 = CGAL::Delaunay_triangulation_2<K, Tds2>;
using AS2 = CGAL::Alpha_shape_2<DT2>;

void report(int dim, std::size_t n, int threads, double tri_s, double alpha_s, std::size_t interior,
            std::size_t regular, std::size_t singular, const char* mode) {
  std::printf("{\"tool\":\"cgal\",\"op\":\"alpha%d\",\"n\":%zu,\"threads\":%d,\"seconds\":%.6f,\"simplices\":%zu,"
              "\"extra\":{\"triangulate_s\":%.6f,\"alpha_s\":%.6f,\"boundary\":%zu,\"singular\":%zu,\"mode\":\"%s\"}}\n",
              dim, n, threads, tri_s + alpha_s, interior, tri_s, alpha_s, regular, singular, mode);
}

template <class DT>
void alpha3(DT& dt, double r, std::size_t n, int threads, double tri_s) {
  using AS = CGAL::Fixed_alpha_shape_3<DT>;
  const auto t0 = Clock::now();
  AS as(dt, r * r);
  std::size_t interior = 0, regular = 0, singular = 0;
  for (auto c = as.finite_cells_begin(); c != as.finite_cells_end(); ++c) interior += as.classify(c) == AS::INTERIOR;
  for (auto f = as.finite_facets_begin(); f != as.finite_facets_end(); ++f) {
    const auto cls = as.classify(*f);
    regular += cls == AS::REGULAR;
    singular += cls == AS::SINGULAR;
  }
  report(3, n, threads, tri_s, since(t0), interior, regular, singular,
         threads > 1 ? "Parallel_tag Delaunay, Fixed_alpha_shape_3" : "Fixed_alpha_shape_3");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: cgal_alpha POINTS.npy R THREADS\n");
    return 2;
  }
  std::vector<std::size_t> shape;
  const std::vector<double> p = power_bench::read_f8(argv[1], shape);
  const double r = std::atof(argv[2]);
  const int threads = std::max(1, std::atoi(argv[3]));
  const std::size_t n = shape.at(0), dim = shape.at(1);
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
  if (dim == 3) {
    std::vector<K::Point_3> pts;
    pts.reserve(n);
    for (std::size_t i = 0; i < n; ++i) pts.emplace_back(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
    if (threads == 1) {
      const auto t0 = Clock::now();
      SeqDT3 dt(pts.begin(), pts.end());
      alpha3(dt, r, n, threads, since(t0));
    } else {
      const auto t0 = Clock::now();
      K::Iso_cuboid_3 box = CGAL::bounding_box(pts.begin(), pts.end());
      typename ParDT3::Lock_data_structure locks(box.bbox(), 50);
      ParDT3 dt(pts.begin(), pts.end(), &locks);
      alpha3(dt, r, n, threads, since(t0));
    }
    return 0;
  }
  std::vector<K::Point_2> pts;
  pts.reserve(n);
  for (std::size_t i = 0; i < n; ++i) pts.emplace_back(p[2 * i], p[2 * i + 1]);
  auto t0 = Clock::now();
  DT2 dt(pts.begin(), pts.end());
  const double tri_s = since(t0);
  t0 = Clock::now();
  AS2 as(dt, r * r, AS2::GENERAL);
  std::size_t interior = 0, regular = 0, singular = 0;
  for (auto f = as.finite_faces_begin(); f != as.finite_faces_end(); ++f) interior += as.classify(f) == AS2::INTERIOR;
  for (auto e = as.finite_edges_begin(); e != as.finite_edges_end(); ++e) {
    const auto cls = as.classify(*e);
    regular += cls == AS2::REGULAR;
    singular += cls == AS2::SINGULAR;
  }
  report(2, n, 1, tri_s, since(t0), interior, regular, singular, "Alpha_shape_2 GENERAL");
  return 0;
}
