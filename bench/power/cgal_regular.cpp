// CGAL's regular triangulation (Regular_triangulation_3, Epick; weights the
// squared radii) of points with radii: the peer of `tessera bench delaunay
// --radii`. Sequential, or Parallel_tag with a spatial lock grid (as the
// shared peers' cgal_delaunay3) for more than one thread; range insertion
// (spatial sort, then incremental). Prints one JSON line in the peers'
// format, op "regular3", simplices the finite cells, extra.hidden the
// points that are not vertices.
//
// usage: cgal_regular POINTS.npy RADII.npy THREADS
#include <chrono>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Regular_triangulation_3.h>
#include <tbb/global_control.h>

#include "npy_f8.hpp"

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
template <class Concurrency>
using Tds = CGAL::Triangulation_data_structure_3<CGAL::Regular_triangulation_vertex_base_3<K>,
                                                 CGAL::Regular_triangulation_cell_base_3<K>, Concurrency>;
using SeqRT = CGAL::Regular_triangulation_3<K, Tds<CGAL::Sequential_tag>>;
using ParRT = CGAL::Regular_triangulation_3<K, Tds<CGAL::Parallel_tag>, CGAL::Spatial_lock_grid_3<CGAL::Tag_priority_blocking>>;

template <class RT>
void report(const RT& rt, std::size_t n, int threads, double seconds) {
  std::printf("{\"tool\":\"cgal\",\"op\":\"regular3\",\"n\":%zu,\"threads\":%d,\"seconds\":%.6f,\"simplices\":%zu,"
              "\"extra\":{\"hidden\":%zu,\"mode\":\"%s\"}}\n",
              n, threads, seconds, static_cast<std::size_t>(rt.number_of_finite_cells()),
              n - static_cast<std::size_t>(rt.number_of_vertices()),
              threads > 1 ? "Parallel_tag+Spatial_lock_grid_3(50)" : "Sequential_tag");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: cgal_regular POINTS.npy RADII.npy THREADS\n");
    return 2;
  }
  std::vector<std::size_t> ps, rs;
  const std::vector<double> p = power_bench::read_f8(argv[1], ps), r = power_bench::read_f8(argv[2], rs);
  if (ps.size() != 2 || ps[1] != 3 || rs.size() != 1 || rs[0] != ps[0]) {
    std::fprintf(stderr, "cgal_regular: need (N,3) points and N radii\n");
    return 2;
  }
  const std::size_t n = ps[0];
  const int threads = std::stoi(argv[3]);
  std::vector<K::Weighted_point_3> wp;
  wp.reserve(n);
  for (std::size_t i = 0; i < n; ++i) wp.emplace_back(K::Point_3(p[3 * i], p[3 * i + 1], p[3 * i + 2]), r[i] * r[i]);
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
  const auto t0 = std::chrono::steady_clock::now();
  if (threads <= 1) {
    SeqRT rt(wp.begin(), wp.end());
    report(rt, n, 1, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  } else {
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
    for (std::size_t i = 0; i < n; ++i)
      for (int d = 0; d < 3; ++d) lo[d] = std::min(lo[d], p[3 * i + d]), hi[d] = std::max(hi[d], p[3 * i + d]);
    ParRT::Lock_data_structure locks(CGAL::Bbox_3(lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]), 50);
    ParRT rt(wp.begin(), wp.end(), &locks);
    report(rt, n, threads, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return 0;
}
