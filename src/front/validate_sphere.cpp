// validate_spherical_voronoi (spherical_voronoi.hpp): checks of a spherical
// Voronoi result that do not trust the pass that made it. The empty-circle
// test is brute force over every point for a sample of vertices, by the same
// exact perturbed predicate the cells used (what "empty" means for a tie).
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include "tessera/kernels/sphere_predicates.hpp"
#include "tessera/spherical_voronoi.hpp"

namespace tessera {

SphereReport validate_spherical_voronoi(const SphericalVoronoi& sv, std::span<const double> points, std::size_t sample) {
  SphereReport r;
  const std::size_t n = sv.n_points;
  auto fail = [&](std::size_t& counter, const std::string& what) {
    if (counter++ < 3) r.messages.push_back(what);
    r.ok = false;
  };
  if (points.size() != 3 * n || sv.neighbor_offsets.size() != n + 1 || sv.region_offsets.size() != n + 1 ||
      sv.areas.size() != n || sv.status.size() != n || sv.triangles.size() != 3 * sv.n_vertices()) {
    r.ok = false;
    r.messages.push_back("array sizes do not match the points");
    return r;
  }
  const std::size_t nv = sv.n_vertices();
  auto ring = [&](std::size_t i) {
    return std::span<const std::int32_t>(sv.neighbors.data() + sv.neighbor_offsets[i],
                                         static_cast<std::size_t>(sv.neighbor_offsets[i + 1] - sv.neighbor_offsets[i]));
  };
  // Symmetric adjacency, each pair once.
  std::vector<std::pair<std::int32_t, std::int32_t>> pairs;
  pairs.reserve(sv.neighbors.size());
  for (std::size_t i = 0; i < n; ++i)
    for (std::int32_t j : ring(i)) {
      if (j < 0 || static_cast<std::size_t>(j) >= n || static_cast<std::size_t>(j) == i) {
        fail(r.asymmetric_neighbors, "cell " + std::to_string(i) + " lists " + std::to_string(j));
        continue;
      }
      pairs.emplace_back(static_cast<std::int32_t>(i), j);
    }
  std::sort(pairs.begin(), pairs.end());
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const auto [a, b] = pairs[k];
    if (k > 0 && pairs[k - 1] == pairs[k]) fail(r.asymmetric_neighbors, "cell " + std::to_string(a) + " lists " + std::to_string(b) + " twice");
    if (!std::binary_search(pairs.begin(), pairs.end(), std::pair{b, a}))
      fail(r.asymmetric_neighbors, "cell " + std::to_string(a) + " lists " + std::to_string(b) + ", not the reverse");
  }
  // Rings: vertex k of cell i is the facet (i, ring[k-1], ring[k]) in that cyclic order.
  std::vector<int> seen(nv, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const auto rg = ring(i);
    const auto m = static_cast<std::size_t>(sv.region_offsets[i + 1] - sv.region_offsets[i]);
    if (m == 0) continue;
    if (m != rg.size()) {
      fail(r.bad_rings, "cell " + std::to_string(i) + " has " + std::to_string(m) + " vertices and " + std::to_string(rg.size()) + " neighbours");
      continue;
    }
    for (std::size_t k = 0; k < m; ++k) {
      const std::int32_t v = sv.region_vertices[static_cast<std::size_t>(sv.region_offsets[i]) + k];
      if (v < 0 || static_cast<std::size_t>(v) >= nv) {
        fail(r.bad_rings, "cell " + std::to_string(i) + " has vertex " + std::to_string(v));
        continue;
      }
      ++seen[static_cast<std::size_t>(v)];
      const std::int32_t* t = &sv.triangles[3 * static_cast<std::size_t>(v)];
      const std::int32_t want[3] = {static_cast<std::int32_t>(i), rg[(k + m - 1) % m], rg[k]};
      bool cyclic = false;
      for (int rot = 0; rot < 3; ++rot)
        cyclic = cyclic || (t[rot] == want[0] && t[(rot + 1) % 3] == want[1] && t[(rot + 2) % 3] == want[2]);
      if (!cyclic) fail(r.bad_rings, "cell " + std::to_string(i) + "'s vertex " + std::to_string(k) + " is not its facet");
    }
  }
  for (std::size_t v = 0; v < nv; ++v)
    if (seen[v] != 3) fail(r.bad_vertex_cells, "vertex " + std::to_string(v) + " is in " + std::to_string(seen[v]) + " cells");
  // Status: duplicates on their owner; cells only for points that have one.
  std::size_t cells = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const bool has = sv.status[i] == SphereCellStatus::cell;
    cells += has;
    if (!has && (ring(i).size() != 0 || sv.areas[i] != 0))
      fail(r.bad_status, "point " + std::to_string(i) + " has no cell but a ring or an area");
    if (sv.status[i] == SphereCellStatus::duplicate) {
      const auto o = static_cast<std::size_t>(sv.duplicate_of[i]);
      if (o >= n || o >= i || !std::equal(&points[3 * i], &points[3 * i] + 3, &points[3 * o]))
        fail(r.bad_status, "point " + std::to_string(i) + " is no duplicate of " + std::to_string(sv.duplicate_of[i]));
    }
  }
  if (nv > 0) {
    r.euler = static_cast<long long>(nv) - static_cast<long long>(sv.neighbors.size() / 2) + static_cast<long long>(cells);
    if (r.euler != 2) {
      r.ok = false;
      r.messages.push_back("V - E + F = " + std::to_string(r.euler));
    }
  }
  // Areas.
  const double full = 4 * std::numbers::pi * sv.radius * sv.radius;
  r.area_rel_error = std::fabs(sv.area_sum - full) / full;
  if (!(r.area_rel_error <= 1e-9)) {
    r.ok = false;
    r.messages.push_back("the areas add to " + std::to_string(sv.area_sum) + ", not 4 pi R^2 = " + std::to_string(full));
  }
  // Empty circles: sampled facets against every point but the duplicates
  // (not in the perturbed set: their owner stands for them); a hidden point
  // lies strictly below every facet.
  const std::size_t step = nv <= sample ? 1 : nv / sample;
  std::vector<std::size_t> picked;
  for (std::size_t v = 0; v < nv && picked.size() < std::max<std::size_t>(sample, 1); v += step) picked.push_back(v);
  r.vertices_checked = picked.size();
  const std::size_t above = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, picked.size()), std::size_t{0},
      [&](const tbb::blocked_range<std::size_t>& b, std::size_t count) {
        for (std::size_t k = b.begin(); k != b.end(); ++k) {
          const std::int32_t* t = &sv.triangles[3 * picked[k]];
          const double* a = &points[3 * static_cast<std::size_t>(t[0])];
          const double* bb = &points[3 * static_cast<std::size_t>(t[1])];
          const double* c = &points[3 * static_cast<std::size_t>(t[2])];
          for (std::size_t s = 0; s < n; ++s) {
            if (sv.status[s] == SphereCellStatus::duplicate) continue;
            const auto is = static_cast<std::int32_t>(s);
            if (is == t[0] || is == t[1] || is == t[2]) continue;
            if (kernels::orientation_sos(a, bb, c, &points[3 * s], t[0], t[1], t[2], is) > 0) {
              ++count;
              break;
            }
          }
        }
        return count;
      },
      [](std::size_t x, std::size_t y) { return x + y; });
  if (above > 0) {
    r.nonempty_facets = above;
    r.ok = false;
    r.messages.push_back(std::to_string(above) + " of " + std::to_string(picked.size()) + " sampled vertices have a point above their facet");
  }
  return r;
}

}  // namespace tessera
