// Voro++'s power cells (container_poly: the radical tessellation of spheres)
// of points with radii, timed as the shared peers' voro_cells times ordinary
// cells: every cell with voronoicell_neighbor (volume and neighbour list), in
// the given box, one thread (Voro++ 0.4.6 is sequential). Prints one JSON
// line in the peers' format, op "power3".
//
// usage: voro_poly POINTS.npy RADII.npy X0 X1 Y0 Y1 Z0 Z1
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <voro++/voro++.hh>

#include "npy_f8.hpp"

using power_bench::read_f8;

int main(int argc, char** argv) {
  if (argc != 9) {
    std::fprintf(stderr, "usage: voro_poly POINTS.npy RADII.npy X0 X1 Y0 Y1 Z0 Z1\n");
    return 2;
  }
  std::vector<std::size_t> ps, rs;
  const std::vector<double> p = read_f8(argv[1], ps), r = read_f8(argv[2], rs);
  if (ps.size() != 2 || ps[1] != 3 || rs.size() != 1 || rs[0] != ps[0]) {
    std::fprintf(stderr, "voro_poly: need (N,3) points and N radii\n");
    return 2;
  }
  const std::size_t n = ps[0];
  double b[6];
  for (int k = 0; k < 6; ++k) b[k] = std::stod(argv[3 + k]);
  // Blocks as voro++'s guess_optimal: about optimal_particles per block.
  const double dx = b[1] - b[0], dy = b[3] - b[2], dz = b[5] - b[4];
  const double s = std::cbrt(double(n) / (voro::optimal_particles * dx * dy * dz));
  const int nx = int(dx * s + 1), ny = int(dy * s + 1), nz = int(dz * s + 1);
  const auto t0 = std::chrono::steady_clock::now();
  voro::container_poly con(b[0], b[1], b[2], b[3], b[4], b[5], nx, ny, nz, false, false, false, 8);
  for (std::size_t i = 0; i < n; ++i) con.put(int(i), p[3 * i], p[3 * i + 1], p[3 * i + 2], r[i]);
  const auto t1 = std::chrono::steady_clock::now();
  voro::voronoicell_neighbor c;
  voro::c_loop_all loop(con);
  std::vector<int> nb;
  std::size_t cells = 0, links = 0;
  double vsum = 0;
  if (loop.start()) do {
      if (!con.compute_cell(c, loop)) continue;  // an empty power cell
      ++cells;
      vsum += c.volume();
      c.neighbors(nb);
      for (int k : nb) links += k >= 0;
    } while (loop.inc());
  const auto t2 = std::chrono::steady_clock::now();
  const double insert_s = std::chrono::duration<double>(t1 - t0).count();
  const double cells_s = std::chrono::duration<double>(t2 - t1).count();
  std::printf("{\"tool\":\"voro++\",\"op\":\"power3\",\"n\":%zu,\"threads\":1,\"seconds\":%.6f,\"simplices\":%zu,"
              "\"extra\":{\"insert_seconds\":%.6f,\"neighbors\":%zu,\"volume_sum\":%.17g,\"box_volume\":%.17g}}\n",
              n, cells_s, cells, insert_s, links, vsum, dx * dy * dz);
  return 0;
}
