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

namespace {

// A C-order little-endian float64 .npy array: its values and its shape.
std::vector<double> read_f8(const std::string& path, std::vector<std::size_t>& shape) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw std::runtime_error("cannot open " + path);
  char magic[8];
  f.read(magic, 8);
  std::uint16_t hlen = 0;
  f.read(reinterpret_cast<char*>(&hlen), 2);  // version 1 header
  std::string header(hlen, ' ');
  f.read(header.data(), hlen);
  if (header.find("'<f8'") == std::string::npos || header.find("'fortran_order': False") == std::string::npos)
    throw std::runtime_error(path + ": expected a C-order float64 array");
  const auto open = header.find('('), close = header.find(')');
  shape.clear();
  std::size_t total = 1, at = open + 1;
  while (at < close) {
    const std::size_t comma = std::min(header.find(',', at), close);
    const std::string part = header.substr(at, comma - at);
    if (part.find_first_of("0123456789") != std::string::npos) {
      shape.push_back(std::stoull(part));
      total *= shape.back();
    }
    at = comma + 1;
  }
  std::vector<double> v(total);
  f.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(total * sizeof(double)));
  if (!f) throw std::runtime_error(path + ": truncated");
  return v;
}

}  // namespace

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
