// tessera::flowers: petals, circumflower and clipping neighbours of chosen cells.
#include "tessera/flower.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "mesh_faces.hpp"

namespace tessera {
namespace {

/// Why point `id` owns no cell, in words.
std::string no_cell_reason(const Cells& c, std::int32_t id) {
  for (auto [dup, owner] : c.duplicates)
    if (dup == id) return "it duplicates point " + std::to_string(owner);
  if (std::find(c.ignored_outside_bounds.begin(), c.ignored_outside_bounds.end(), id) !=
      c.ignored_outside_bounds.end())
    return "it lies outside the bounds (or has a NaN or infinite coordinate)";
  if (std::binary_search(c.empty_cells.begin(), c.empty_cells.end(), id))
    return "its power cell is empty (other spheres' powers are less everywhere)";
  return "it is an outside point (label < 0)";
}

Flower flower_of(const Cells& c, std::span<const double> points, std::int32_t id) {
  const auto k = static_cast<std::size_t>(c.cell_of[static_cast<std::size_t>(id)]);
  const auto D = static_cast<std::size_t>(c.dim);
  Flower fl;
  fl.dim = c.dim;
  fl.generator = id;
  // A periodic box's cells lie where they took their points: wrapped into it.
  const bool periodic = c.is_periodic();
  const std::span<const double> at = periodic ? std::span<const double>(c.periodic_points) : points;
  for (std::size_t a = 0; a < D; ++a) fl.site[a] = at[static_cast<std::size_t>(id) * D + a];

  const auto f0 = static_cast<std::size_t>(c.cell_face_offsets[k]);
  const auto f1 = static_cast<std::size_t>(c.cell_face_offsets[k + 1]);
  const auto q0 = static_cast<std::size_t>(c.face_vertex_offsets[f0]);
  const auto q1 = static_cast<std::size_t>(c.face_vertex_offsets[f1]);
  fl.vertex_ids.assign(c.face_vertices.begin() + static_cast<std::ptrdiff_t>(q0),
                       c.face_vertices.begin() + static_cast<std::ptrdiff_t>(q1));
  std::sort(fl.vertex_ids.begin(), fl.vertex_ids.end());
  fl.vertex_ids.erase(std::unique(fl.vertex_ids.begin(), fl.vertex_ids.end()), fl.vertex_ids.end());

  double r_max = 0;
  for (std::int32_t v : fl.vertex_ids) {
    double r2 = 0, d[3] = {0, 0, 0};
    for (std::size_t a = 0; a < D; ++a) {
      const double x = c.vertices[static_cast<std::size_t>(v) * D + a];
      fl.petal_centres.push_back(x);
      d[a] = x - fl.site[a];
      r2 += d[a] * d[a];
    }
    // std::hypot (which scales) where a square under- or overflowed: petals
    // past ~1e154 were inf, below ~1e-154 wrong or zero.
    fl.petal_radii.push_back(r2 >= 0x1p-900 && r2 <= 0x1p900 ? std::sqrt(r2) : std::hypot(d[0], d[1], d[2]));
    r_max = std::max(r_max, fl.petal_radii.back());
  }
  fl.circumflower_radius = 2 * r_max;

  fl.face_offsets.push_back(0);
  for (std::size_t f = f0; f < f1; ++f) {
    for (auto q = c.face_vertex_offsets[f]; q < c.face_vertex_offsets[f + 1]; ++q) {
      const std::int32_t v = c.face_vertices[static_cast<std::size_t>(q)];
      fl.face_vertices.push_back(static_cast<std::int32_t>(
          std::lower_bound(fl.vertex_ids.begin(), fl.vertex_ids.end(), v) - fl.vertex_ids.begin()));
    }
    fl.face_offsets.push_back(static_cast<std::int64_t>(fl.face_vertices.size()));
    fl.face_neighbor.push_back(c.face_neighbor[f]);
  }
  fl.neighbors.assign(c.neighbors.begin() + c.neighbor_offsets[k], c.neighbors.begin() + c.neighbor_offsets[k + 1]);
  if (periodic) {
    fl.neighbor_shifts.assign(c.neighbor_shifts.begin() + c.neighbor_offsets[k] * c.dim,
                              c.neighbor_shifts.begin() + c.neighbor_offsets[k + 1] * c.dim);
    fl.face_shifts.assign(c.face_shift.begin() + static_cast<std::ptrdiff_t>(f0 * D),
                          c.face_shift.begin() + static_cast<std::ptrdiff_t>(f1 * D));
  }
  const auto lattice = periodic ? c.lattice() : std::array<std::array<double, 3>, 3>{};
  fl.neighbor_positions.resize(fl.neighbors.size() * D);
  for (std::size_t e = 0; e < fl.neighbors.size(); ++e) {
    const double* p = &at[static_cast<std::size_t>(fl.neighbors[e]) * D];
    if (periodic)
      periodic_image(lattice, c.dim, p, &fl.neighbor_shifts[e * D], &fl.neighbor_positions[e * D]);
    else
      std::copy_n(p, D, &fl.neighbor_positions[e * D]);
  }
  return fl;
}

}  // namespace

std::vector<Flower> flowers(const Cells& c, std::span<const double> points, std::span<const std::int32_t> ids) {
  front::require_mesh(c, "flowers", true);
  // A flower's petals are the balls through the generator: an ordinary
  // cell's. A power cell's would be wider by its weights (kernels/power.hpp).
  if (c.power) throw InputError("flowers of power cells (radii) are not supported");
  if (points.size() != c.n_points * static_cast<std::size_t>(c.dim))
    throw std::invalid_argument("flowers: points are not the array the cells were computed from");
  std::vector<Flower> out;
  out.reserve(ids.size());
  for (std::int32_t id : ids) {
    if (id < 0 || static_cast<std::size_t>(id) >= c.n_points)
      throw InputError("point " + std::to_string(id) + " does not exist (there are " + std::to_string(c.n_points) +
                       " points, ids 0.." + std::to_string(c.n_points - 1) + ")");
    if (c.cell_of[static_cast<std::size_t>(id)] < 0)
      throw InputError("point " + std::to_string(id) + " owns no cell: " + no_cell_reason(c, id));
    out.push_back(flower_of(c, points, id));
  }
  return out;
}

}  // namespace tessera
