// CGAL's periodic regular triangulation (Periodic_3_regular_triangulation_3,
// Epick; weights the squared radii) of points with radii in a cubic box
// [X0, X0 + L)^3: the peer of `tessera bench delaunay --radii --periodic xyz`.
// Sequential (CGAL has no parallel periodic triangulation); range insertion.
// Prints one JSON line in the peers' format, op "periodic_regular3",
// simplices the cells of the 1-cover, extra.hidden the points that are not
// vertices. CGAL requires every weight below L^2 / 64.
//
// usage: cgal_periodic_regular POINTS.npy RADII.npy X0 L
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Periodic_3_regular_triangulation_3.h>
#include <CGAL/Periodic_3_regular_triangulation_traits_3.h>

#include "npy_f8.hpp"

namespace {
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Gt = CGAL::Periodic_3_regular_triangulation_traits_3<K>;
using P3RT3 = CGAL::Periodic_3_regular_triangulation_3<Gt>;
}  // namespace

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: cgal_periodic_regular POINTS.npy RADII.npy X0 L\n");
    return 2;
  }
  std::vector<std::size_t> ps, rs;
  const std::vector<double> p = power_bench::read_f8(argv[1], ps), r = power_bench::read_f8(argv[2], rs);
  if (ps.size() != 2 || ps[1] != 3 || rs.size() != 1 || rs[0] != ps[0]) {
    std::fprintf(stderr, "cgal_periodic_regular: need (N,3) points and N radii\n");
    return 2;
  }
  const std::size_t n = ps[0];
  const double x0 = std::stod(argv[3]), len = std::stod(argv[4]);
  std::vector<P3RT3::Weighted_point> wp;
  wp.reserve(n);
  for (std::size_t i = 0; i < n; ++i) wp.emplace_back(P3RT3::Bare_point(p[3 * i], p[3 * i + 1], p[3 * i + 2]), r[i] * r[i]);
  const auto t0 = std::chrono::steady_clock::now();
  P3RT3 rt(P3RT3::Iso_cuboid(x0, x0, x0, x0 + len, x0 + len, x0 + len));
  rt.insert(wp.begin(), wp.end(), true);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("{\"tool\":\"cgal\",\"op\":\"periodic_regular3\",\"n\":%zu,\"threads\":1,\"seconds\":%.6f,\"simplices\":%zu,"
              "\"extra\":{\"hidden\":%zu,\"one_cover\":%s}}\n",
              n, seconds, static_cast<std::size_t>(rt.number_of_cells()), n - static_cast<std::size_t>(rt.number_of_vertices()),
              rt.is_1_cover() ? "true" : "false");
  return 0;
}
