// tessera::validate: the invariants a correct tessellation satisfies.
#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "tessera/cells.hpp"
#include "validate_measures.hpp"

namespace tessera {

ValidationReport validate(const Cells& c, std::span<const std::int32_t> labels, std::span<const double> points) {
  ValidationReport r;
  const std::size_t nc = c.n_cells();
  const int D = c.dim;
  if (!points.empty() && points.size() != static_cast<std::size_t>(c.n_points) * static_cast<std::size_t>(D))
    throw std::invalid_argument("validate: " + std::to_string(points.size()) + " coordinates given for " +
                                std::to_string(c.n_points) + " points in " + std::to_string(D) + "D");

  // Volumes: with every point inside, the cells tile the domain exactly.
  // Checked only where the volumes are normal doubles (volumes_representable):
  // outside that the input's scale, not the tessellation, decides what a
  // double can hold.
  for (double v : c.volume) r.volume_sum += v;
  r.domain_volume = c.bounds.volume(D);
  r.volume_rel_error = std::fabs(r.volume_sum - r.domain_volume) / r.domain_volume;
  r.volumes_checked = volumes_representable(r.domain_volume, nc);
  const bool all_inside = c.ignored_outside_bounds.empty() &&
                          std::none_of(labels.begin(), labels.end(), [](std::int32_t l) { return l < 0; });
  if (r.volumes_checked && all_inside && r.volume_rel_error > 1e-9) {
    std::ostringstream m;
    m << "cell volumes sum to " << r.volume_sum << ", domain volume " << r.domain_volume
      << " (relative error " << r.volume_rel_error << ")";
    r.messages.push_back(m.str());
    r.ok = false;
  }
  // A cell's volume is exact where its float sum cancels (front/cell_geometry.hpp),
  // so it is never negative, and zero only when the exact volume is below
  // the smallest double (points within ~1e-160 of each other): counted, not
  // a failure.
  for (std::size_t k = 0; r.volumes_checked && k < nc; ++k) {
    if (c.volume[k] == 0) {
      ++r.underflowed_volumes;
    } else if (!(c.volume[k] > 0)) {
      r.messages.push_back("cell of point " + std::to_string(c.generator[k]) + " has negative volume");
      r.ok = false;
      break;
    }
  }

  // Symmetric spokes between cells.
  for (std::size_t k = 0; k < nc; ++k) {
    std::int32_t g = c.generator[k];
    for (auto e = c.neighbor_offsets[k]; e < c.neighbor_offsets[k + 1]; ++e) {
      std::int32_t j = c.neighbors[static_cast<std::size_t>(e)];
      std::int32_t cj = c.cell_of[static_cast<std::size_t>(j)];
      if (cj < 0) continue;  // outside point: one-sided by design
      auto b = c.neighbors.begin() + c.neighbor_offsets[static_cast<std::size_t>(cj)];
      auto en = c.neighbors.begin() + c.neighbor_offsets[static_cast<std::size_t>(cj) + 1];
      if (!std::binary_search(b, en, g)) ++r.asymmetric_spokes;
    }
  }
  if (r.asymmetric_spokes) {
    r.messages.push_back(std::to_string(r.asymmetric_spokes) + " one-sided spokes (i lists j, j does not list i)");
    r.ok = false;
  }

  if (!c.vertex_keys.empty()) {
    // Each merged vertex is used by exactly the cells of its key's generators.
    // With the points, the same pass takes each cell's radius (its farthest
    // vertex from its generator, squared) for the exact check's sample. A
    // vertex lies equally far from every generator of its key, so its
    // distance is computed once, by the first cell that meets it, and kept
    // beside its use counts: the merged vertices lie in no order a cell's
    // corners follow, and reading them at every corner cost 1M cells ~1 s.
    const std::size_t nv = c.n_vertices();
    const bool measuring = !points.empty() && r.volumes_checked;
    struct Use {
      std::int32_t users = 0, last_cell = -1;
      double dist2 = -1;  // from a generator of its key (measuring only)
    };
    std::vector<Use> use(nv);
    std::vector<double> radius2(measuring ? nc : 0, 0.0);
    std::size_t bad_euler = 0;
    for (std::size_t k = 0; k < nc; ++k) {
      std::int64_t f0 = c.cell_face_offsets[k], f1 = c.cell_face_offsets[k + 1];
      std::size_t corners = 0;
      std::int64_t half_edges = 0;
      const double* p = measuring ? points.data() + static_cast<std::size_t>(c.generator[k]) * static_cast<std::size_t>(D)
                                  : nullptr;
      for (auto f = f0; f < f1; ++f) {
        for (auto q = c.face_vertex_offsets[static_cast<std::size_t>(f)];
             q < c.face_vertex_offsets[static_cast<std::size_t>(f) + 1]; ++q) {
          std::int32_t v = c.face_vertices[static_cast<std::size_t>(q)];
          if (v < 0 || static_cast<std::size_t>(v) >= nv) continue;
          Use& u = use[static_cast<std::size_t>(v)];
          if (u.last_cell != static_cast<std::int32_t>(k)) {
            u.last_cell = static_cast<std::int32_t>(k);
            ++u.users;
            ++corners;
            if (measuring) {
              if (u.dist2 < 0) {
                u.dist2 = 0;
                for (int d = 0; d < D; ++d) {
                  const double x = c.vertices[static_cast<std::size_t>(v) * static_cast<std::size_t>(D) +
                                              static_cast<std::size_t>(d)] - p[d];
                  u.dist2 += x * x;
                }
              }
              radius2[k] = std::max(radius2[k], u.dist2);
            }
          }
          ++half_edges;
        }
      }
      if (D == 3) {
        std::int64_t F = f1 - f0, E = half_edges / 2, V = static_cast<std::int64_t>(corners);
        if (V - E + F != 2) ++bad_euler;
      }
    }
    for (std::size_t v = 0; v < nv; ++v) {
      std::int32_t expect = 0;
      for (int d = 0; d <= D; ++d) {
        std::int32_t id = c.vertex_keys[v * static_cast<std::size_t>(D + 1) + static_cast<std::size_t>(d)];
        if (id >= 0 && c.cell_of[static_cast<std::size_t>(id)] >= 0) ++expect;
      }
      if (use[v].users != expect) ++r.bad_vertex_degree;
    }
    r.bad_euler = bad_euler;
    if (r.bad_vertex_degree) {
      r.messages.push_back(std::to_string(r.bad_vertex_degree) +
                           " merged vertices not shared by exactly the cells of their generators");
      r.ok = false;
    }
    if (bad_euler) {
      r.messages.push_back(std::to_string(bad_euler) + " cells with Euler characteristic != 2");
      r.ok = false;
    }
    std::size_t unresolved = static_cast<std::size_t>(
        std::count_if(c.face_vertices.begin(), c.face_vertices.end(), [](std::int32_t v) { return v < 0; }));
    if (unresolved) {
      r.messages.push_back(std::to_string(unresolved) + " face corners refer to no merged vertex");
      r.ok = false;
    }
    // Every vertex used by exactly the cells of its key (so each first
    // meeting above measured its distance from a generator of its key) and
    // every corner resolved: the mesh can be measured exactly.
    if (measuring && r.bad_vertex_degree == 0 && unresolved == 0) front::check_measures(c, points, radius2, r);
  }
  return r;
}

}  // namespace tessera
