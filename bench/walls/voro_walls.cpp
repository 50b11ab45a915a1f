// Voro++'s cells cut by plane walls (wall_plane: n.x < d), timed as the
// shared peers' voro_cells times ordinary cells: every cell with
// voronoicell_neighbor (volume and neighbour list), in the given box, one
// thread (Voro++ 0.4.6 is sequential). Prints one JSON line in the peers'
// format, op "voronoi3".
//
// usage: voro_walls POINTS.npy X0 X1 Y0 Y1 Z0 Z1 WALLS.npy   (walls: (k, 4) rows nx, ny, nz, d)
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <voro++/voro++.hh>

#include "../power/npy_f8.hpp"

using power_bench::read_f8;

int main(int argc, char** argv) {
  if (argc != 9) {
    std::fprintf(stderr, "usage: voro_walls POINTS.npy X0 X1 Y0 Y1 Z0 Z1 WALLS.npy\n");
    return 2;
  }
  std::vector<std::size_t> ps, ws;
  const std::vector<double> p = read_f8(argv[1], ps), w = read_f8(argv[8], ws);
  if (ps.size() != 2 || ps[1] != 3 || ws.size() != 2 || ws[1] != 4) {
    std::fprintf(stderr, "voro_walls: need (N,3) points and (k,4) walls\n");
    return 2;
  }
  const std::size_t n = ps[0];
  double b[6];
  for (int k = 0; k < 6; ++k) b[k] = std::stod(argv[2 + k]);
  // Blocks as voro++'s guess_optimal: about optimal_particles per block of the box.
  const double dx = b[1] - b[0], dy = b[3] - b[2], dz = b[5] - b[4];
  const double s = std::cbrt(double(n) / (voro::optimal_particles * dx * dy * dz));
  const int nx = int(dx * s + 1), ny = int(dy * s + 1), nz = int(dz * s + 1);
  const auto t0 = std::chrono::steady_clock::now();
  voro::container con(b[0], b[1], b[2], b[3], b[4], b[5], nx, ny, nz, false, false, false, 8);
  std::vector<voro::wall_plane> walls;
  walls.reserve(ws[0]);
  for (std::size_t k = 0; k < ws[0]; ++k) walls.emplace_back(w[4 * k], w[4 * k + 1], w[4 * k + 2], w[4 * k + 3], -7 - int(k));
  for (auto& wall : walls) con.add_wall(wall);
  for (std::size_t i = 0; i < n; ++i) con.put(int(i), p[3 * i], p[3 * i + 1], p[3 * i + 2]);
  const auto t1 = std::chrono::steady_clock::now();
  voro::voronoicell_neighbor c;
  voro::c_loop_all loop(con);
  std::vector<int> nb;
  std::size_t cells = 0, links = 0;
  double vsum = 0;
  if (loop.start()) do {
      if (!con.compute_cell(c, loop)) continue;
      ++cells;
      vsum += c.volume();
      c.neighbors(nb);
      for (int k : nb) links += k >= 0;
    } while (loop.inc());
  const auto t2 = std::chrono::steady_clock::now();
  std::printf("{\"tool\":\"voro++\",\"op\":\"voronoi3\",\"n\":%zu,\"threads\":1,\"seconds\":%.6f,\"simplices\":%zu,"
              "\"extra\":{\"insert_seconds\":%.6f,\"neighbors\":%zu,\"volume_sum\":%.17g}}\n",
              n, std::chrono::duration<double>(t2 - t1).count(), cells,
              std::chrono::duration<double>(t1 - t0).count(), links, vsum);
  return 0;
}
