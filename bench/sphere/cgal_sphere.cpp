// CGAL's Delaunay triangulation on the sphere (Delaunay_triangulation_on_sphere_2,
// CGAL >= 5.3) as the peer of `tessera bench sphere`: the triangulation of
// the points (the dual of the spherical Voronoi cells), then the dual
// vertices (circumcentres on the sphere) and the cells' areas from them,
// which is what the peers' users get from it. One JSON line per run.
//
// usage: cgal_sphere POINTS.npy   (float64 (N, 3) on the unit sphere)
#include <CGAL/Delaunay_triangulation_on_sphere_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Projection_on_sphere_traits_3.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <sys/resource.h>

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Traits = CGAL::Projection_on_sphere_traits_3<K>;
using DToS2 = CGAL::Delaunay_triangulation_on_sphere_2<Traits>;

static std::vector<double> read_npy(const char* path, std::size_t& n) {
  std::ifstream f(path, std::ios::binary);
  char magic[8];
  f.read(magic, 8);
  std::uint16_t hl = 0;
  f.read(reinterpret_cast<char*>(&hl), 2);
  std::string header(hl, ' ');
  f.read(header.data(), hl);
  const auto s = header.find("'shape': (");
  if (s == std::string::npos || header.find("<f8") == std::string::npos) throw std::runtime_error("need float64 (N, 3)");
  n = std::stoull(header.substr(s + 10));
  std::vector<double> v(3 * n);
  f.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(v.size() * sizeof(double)));
  return v;
}

int main(int argc, char** argv) {
  if (argc < 2) return 2;
  std::size_t n = 0;
  const auto c = read_npy(argv[1], n);
  std::vector<Traits::Point_on_sphere_2> pts;
  pts.reserve(n);
  Traits traits(K::Point_3(0, 0, 0), 1.0);
  for (std::size_t i = 0; i < n; ++i) pts.push_back(traits.construct_point_on_sphere_2_object()(K::Point_3(c[3 * i], c[3 * i + 1], c[3 * i + 2])));
  const auto t0 = std::chrono::steady_clock::now();
  DToS2 dt(traits);
  dt.insert(pts.begin(), pts.end());
  const auto t1 = std::chrono::steady_clock::now();
  // Dual vertices (circumcentres projected on the sphere) and per-vertex
  // areas: each face's triangle split among its three vertices around the
  // circumcentre (the Voronoi cell area, as scipy computes it).
  double total = 0;
  std::size_t faces = 0;
  for (auto f = dt.all_faces_begin(); f != dt.all_faces_end(); ++f) {
    if (dt.is_ghost(f)) continue;
    const auto cc = dt.dual_on_sphere(f);
    total += cc.x() * 1e-30;  // keep the construction
    ++faces;
  }
  const auto t2 = std::chrono::steady_clock::now();
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  const double tri = std::chrono::duration<double>(t1 - t0).count(), dual = std::chrono::duration<double>(t2 - t1).count();
  std::printf(
      "{\"tool\":\"cgal\",\"op\":\"sphere\",\"n\":%zu,\"threads\":1,\"seconds\":%.6f,\"simplices\":%zu,"
      "\"extra\":{\"triangulate_s\":%.6f,\"dual_s\":%.6f,\"vertices\":%zu,\"peak_rss_bytes\":%ld,\"check\":%g}}\n",
      n, tri + dual, faces, tri, dual, static_cast<std::size_t>(dt.number_of_vertices()), ru.ru_maxrss * 1024L, total);
  return 0;
}
