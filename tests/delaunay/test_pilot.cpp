// The pilot's measure (front/pilot.hpp) on uniform points: its rule is
// calibrated so that uniform input reads a ratio near 1 (3D: 307 work units
// per cell, 2D: 82). The automatic method choices (insertion from a ratio
// of 2) and Delaunay's skipped fraction rest on that calibration, so a
// change to what BuildStatus::work counts (stop 47's whole-shell scan
// raised it ~1.4x in 3D) must show up here.
#include <gtest/gtest.h>

#include <cstdio>
#include <vector>

#include "front/pass.hpp"
#include "front/pilot.hpp"
#include "random_points.hpp"
#include "tessera/cells.hpp"
#include "tessera/kernels/hull.hpp"
#include "tessera/kernels/tile.hpp"

namespace {

template <class CellT>
double uniform_ratio(std::size_t n, std::uint64_t seed) {
  constexpr int D = CellT::dim;
  const std::vector<double> pts = uniform_points(n, D, seed);
  tessera::VoronoiOptions opt;
  opt.dim = D;
  opt.threads = 2;
  const tessera::front::Pass<D> pass(pts, {}, opt);
  return tessera::front::pilot_estimate<CellT>(pass, 1e9, 0.5).ratio;
}

TEST(Pilot, UniformPointsReadAboutOne) {
  const double r3 = uniform_ratio<tessera::kernels::Hull>(60000, 5);
  EXPECT_GT(r3, 0.85);
  EXPECT_LT(r3, 1.15);
  const double r2 = uniform_ratio<tessera::kernels::Tile>(100000, 6);
  EXPECT_GT(r2, 0.9);
  EXPECT_LT(r2, 1.1);
  std::printf("[ pilot ] uniform ratio 3D %.3f 2D %.3f\n", r3, r2);
}

}  // namespace
