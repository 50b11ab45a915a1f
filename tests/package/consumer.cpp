// Eight points at the corners of a cube: eight equal cells of the padded box.
#include <cmath>
#include <cstdio>
#include <tessera/cells.hpp>

int main() {
  std::vector<double> p;
  for (int i = 0; i < 8; ++i) p.insert(p.end(), {double(i & 1), double((i >> 1) & 1), double((i >> 2) & 1)});
  tessera::VoronoiOptions opt;
  opt.bounds = tessera::Bounds{{-0.5, -0.5, -0.5}, {1.5, 1.5, 1.5}};
  const tessera::Cells c = tessera::voronoi(p, 3, {}, opt);
  for (double v : c.volume)
    if (std::fabs(v - 1.0) > 1e-12) return 1;
  std::printf("consumer: %zu cells of volume 1\n", c.n_cells());
  return c.n_cells() == 8 ? 0 : 1;
}
