// Surface nets in a convex domain (VoronoiOptions::walls): every region's
// capped surface is closed, 2-manifold and encloses its cells' volume
// (unsmoothed exactly, smoothed within the smoothing's reach), the vertices
// on a wall stay on it through the smoothing, and the smoothed net does not
// cross itself. (Their stencils hold vertices on the same wall, so they stay
// on it but for rounding, which the smoothing's projection onto the wall,
// WallSlide, keeps to 3.3e-16 here; 1.1e-15 without it.)
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "net_test_util.hpp"

namespace {

using namespace net_test;

const std::vector<tessera::Wall> kWalls3 = {{{1, 1, 1}, 2.0}, {{1, -1, 0}, 0.6}, {{0.3, 0.2, -1}, 0.1}};
const std::vector<tessera::Wall> kWalls2 = {{{1, 1, 0}, 1.4}, {{1, -1, 0}, 0.6}, {{-0.3, -1, 0}, -0.1}};

/// The capped net of nested spheres (discs) on jittered grid points, in the
/// unit box cut by the walls; points outside dropped.
tessera::SurfaceNet net_in_walls(const Labelled& in, int iterations) {
  tessera::SurfaceNetsOptions o = net_options(in.dim, iterations, /*triangles=*/in.dim == 3);  // (self_intersections reads triangles)
  o.voronoi.walls = in.dim == 3 ? kWalls3 : kWalls2;
  o.voronoi.ignore_outside_points = true;
  o.capping = true;
  return run(in, o);
}

std::map<std::int32_t, double> walled_region_volumes(const Labelled& in) {
  tessera::VoronoiOptions o;
  o.dim = in.dim;
  tessera::Bounds b;
  b.hi = {1, 1, in.dim == 3 ? 1.0 : 0.0};
  o.bounds = b;
  o.walls = in.dim == 3 ? kWalls3 : kWalls2;
  o.ignore_outside_points = true;
  o.build_mesh = false;
  const tessera::Cells c = tessera::voronoi(in.points, in.dim, in.labels, o);
  std::map<std::int32_t, double> v;
  for (std::size_t k = 0; k < c.n_cells(); ++k) v[c.region[k]] += c.volume[k];
  return v;
}

TEST(SurfaceNetsInWalls, ClosedSurfacesEncloseTheCellsAndWallVerticesStayOnTheWalls) {
  for (int dim : {2, 3}) {
    const Labelled in = grid_points(dim == 3 ? 14 : 40, dim, 0.3, 7 + dim, nested(dim));
    const auto vol = walled_region_volumes(in);
    const auto& walls = dim == 3 ? kWalls3 : kWalls2;
    for (int iterations : {0, 20}) {
      const tessera::SurfaceNet net = net_in_walls(in, iterations);
      const auto& m = net.mesh;
      const std::string what = std::to_string(dim) + "D, " + std::to_string(iterations) + " iterations";
      std::size_t on_walls = 0;
      for (std::size_t v = 0; v < m.n_vertices(); ++v)
        for (int a = 0; a <= dim; ++a) {
          const std::int32_t id = m.vertex_keys[v * (dim + 1) + a];
          if (!tessera::is_wall_spoke(id)) continue;
          ++on_walls;
          const tessera::Wall& w = walls[static_cast<std::size_t>(-7 - id)];
          double s = -w.offset;
          for (int c = 0; c < dim; ++c) s += w.normal[c] * m.vertices[v * dim + c];
          EXPECT_LE(std::fabs(s), 1e-12) << what << ": vertex " << v << " left wall " << -7 - id;
        }
      EXPECT_GT(on_walls, 10u) << what;
      for (const auto& [label, want] : vol) {
        const auto r = region_surface(m, label);
        EXPECT_EQ(r.unbalanced_edges, 0u) << what << ", label " << label << ": not closed";
        EXPECT_EQ(r.nonmanifold_edges, 0u) << what << ", label " << label;
        EXPECT_EQ(r.degenerate_faces, 0u) << what << ", label " << label;
        EXPECT_NEAR(r.volume, want, (iterations == 0 ? 1e-9 : 0.15) * want) << what << ", label " << label;
      }
      if (dim == 3) EXPECT_EQ(self_intersections(m), 0u) << what;
    }
  }
}

}  // namespace
