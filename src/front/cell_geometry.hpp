// Measures of a finished cell: volume (area), centroid, faces with their
// vertex loops. One adapter per cell kernel so compositors stay dimension-free.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "tessera/kernels/hull.hpp"
#include "tessera/kernels/tile.hpp"

namespace tessera::front {

/// Topological coordinate of a vertex: the generator and the ids of its
/// planes, ascending (box planes negative, so they come first).
template <int D>
using Key = std::array<std::int32_t, D + 1>;

/// Where a float measure keeps fewer than ~20 correct bits: its terms cancel
/// to less than 2^-20 of their magnitudes (or to a non-positive sum). That
/// happens for slivers thinner than the rounding of their own vertices (points
/// a few ulps apart), whose float volume can come out zero or negative; such
/// cells are measured exactly instead (exact_cell_measure). Ordinary cells
/// keep a sum within a small factor of the magnitudes.
inline bool measure_cancelled(double sum, double magnitude) { return !(sum > 0x1p-20 * magnitude); }

/// The exact fallback: the cell's vertices by their planes and the same
/// terms as the float measure, in rationals.
template <class Cell>
void measure_exactly(const Cell& cell, const std::vector<kernels::MeasureTerm>& terms, double& volume,
                     double* centroid) {
  constexpr int D = Cell::dim;
  thread_local std::vector<std::int32_t> vertex_planes;
  vertex_planes.clear();
  for (const auto& v : cell.vertices())
    for (int k = 0; k < D; ++k) vertex_planes.push_back(cell.planes()[v.p[k]].id);
  volume = kernels::exact_cell_measure(*cell.exact_context(), cell.generator(), vertex_planes, terms, centroid);
}

/// Volume and centroid (relative to the generator) of a finished cell.
///
/// 3D, without walking the faces: the cell is the union of the tetrahedra
/// (generator, c_f, y_a, y_b) over every edge a -> b of every face f's loop
/// (counter-clockwise from outside), c_f being the foot of the perpendicular
/// from the generator to f's plane: q/2 for a bisector, n d for a box plane.
/// Each tetrahedron's signed volume is det(c_f, y_a, y_b) / 6, and those of
/// one face sum to its cone's volume whatever the polygon's shape. The edge
/// leaving triangle t within face p[k+1] is t's edge k, whose twin triangle is
/// across(t, k) (hull.hpp), so every term comes straight from a triangle and
/// its edge table: no face walk, no chain of dependent loads.
/// 2D: the shoelace formula over the polygon's edges.
/// Either falls back to exact arithmetic where the terms cancel (above).
inline void measure(const kernels::Hull& hull, double& volume, std::array<double, 3>& centroid) {
  const auto& verts = hull.vertices();
  const auto& planes = hull.planes();
  double vol = 0, mag = 0, c[3] = {0, 0, 0};
  for (std::size_t t = 0; t < verts.size(); ++t) {
    const auto& v = verts[t];
    const double* a = v.y;
    for (int k = 0; k < 3; ++k) {
      const auto& pl = planes[v.p[(k + 1) % 3]];
      // The foot n d / |n|^2: d = |n|^2 / 2 on a bisector, |n| = 1 on a box plane.
      const double w = pl.id >= 0 ? 0.5 : pl.d;
      const double f[3] = {pl.n[0] * w, pl.n[1] * w, pl.n[2] * w};
      const double* b = verts[hull.across(t, k)].y;
      const double s = f[0] * (a[1] * b[2] - a[2] * b[1]) + f[1] * (a[2] * b[0] - a[0] * b[2]) +
                       f[2] * (a[0] * b[1] - a[1] * b[0]);
      vol += s;
      mag += std::fabs(s);
      for (int i = 0; i < 3; ++i) c[i] += s * (f[i] + a[i] + b[i]);
    }
  }
  if (measure_cancelled(vol, mag) && hull.exact_context() != nullptr && !verts.empty()) [[unlikely]] {
    thread_local std::vector<kernels::MeasureTerm> terms;
    terms.clear();
    for (std::size_t t = 0; t < verts.size(); ++t)
      for (int k = 0; k < 3; ++k)
        terms.push_back({planes[verts[t].p[(k + 1) % 3]].id, static_cast<std::uint32_t>(t), hull.across(t, k)});
    measure_exactly(hull, terms, volume, centroid.data());
    return;
  }
  volume = vol / 6.0;
  for (int i = 0; i < 3; ++i) centroid[static_cast<std::size_t>(i)] = vol != 0 ? c[i] / (4.0 * vol) : 0.0;
}

inline void measure(const kernels::Tile& tile, double& area, std::array<double, 2>& centroid) {
  const auto& v = tile.vertices();
  const std::size_t m = v.size();
  double s = 0, mag = 0, cx = 0, cy = 0;
  for (std::size_t k = 0; k < m; ++k) {
    const double* a = v[k].y;
    const double* b = v[k + 1 == m ? 0 : k + 1].y;
    const double cr = a[0] * b[1] - a[1] * b[0];
    s += cr;
    mag += std::fabs(cr);
    cx += (a[0] + b[0]) * cr;
    cy += (a[1] + b[1]) * cr;
  }
  if (measure_cancelled(s, mag) && tile.exact_context() != nullptr && m != 0) [[unlikely]] {
    thread_local std::vector<kernels::MeasureTerm> terms;
    terms.clear();
    for (std::size_t k = 0; k < m; ++k)
      terms.push_back({0, static_cast<std::uint32_t>(k), static_cast<std::uint32_t>(k + 1 == m ? 0 : k + 1)});
    measure_exactly(tile, terms, area, centroid.data());
    return;
  }
  area = 0.5 * s;
  centroid = {s != 0 ? cx / (3 * s) : 0.0, s != 0 ? cy / (3 * s) : 0.0};
}

/// Sort a key's ids ascending by a sorting network (branch-free min/max;
/// std::sort's call and branches cost more on 3 or 4 ids).
template <std::size_t N>
[[gnu::always_inline]] inline void sort_key(std::array<std::int32_t, N>& k) {
  auto order = [&](std::size_t a, std::size_t b) {
    const std::int32_t lo = std::min(k[a], k[b]), hi = std::max(k[a], k[b]);
    k[a] = lo;
    k[b] = hi;
  };
  if constexpr (N == 4) {
    order(0, 1); order(2, 3); order(0, 2); order(1, 3); order(1, 2);
  } else {
    static_assert(N == 3);
    order(0, 1); order(1, 2); order(0, 1);
  }
}

inline Key<3> vertex_key(const kernels::Hull& hull, std::size_t t) {
  const auto& v = hull.vertices()[t];
  const auto& pl = hull.planes();
  Key<3> k{hull.generator(), pl[v.p[0]].id, pl[v.p[1]].id, pl[v.p[2]].id};
  sort_key(k);
  return k;
}

inline Key<2> vertex_key(const kernels::Tile& tile, std::size_t t) {
  const auto& v = tile.vertices()[t];
  const auto& pl = tile.planes();
  Key<2> k{tile.generator(), pl[v.p[0]].id, pl[v.p[1]].id};
  sort_key(k);
  return k;
}

/// Visit each face once as f(local plane index, neighbour id) (box planes
/// negative), in the order the mesh numbers a cell's faces: 3D by plane
/// index, 2D counter-clockwise (the edge leaving vertex k is face k).
template <class F>
void for_each_face_plane(kernels::Hull& hull, F&& f) {
  const auto& pl = hull.planes();
  hull.for_each_face_plane([&](std::uint16_t p) { f(p, pl[p].id); });
}

template <class F>
void for_each_face_plane(kernels::Tile& tile, F&& f) {
  const auto& v = tile.vertices();
  const auto& pl = tile.planes();
  for (std::size_t k = 0; k < v.size(); ++k) f(v[k].p[1], pl[v[k].p[1]].id);
}

/// Visit each face's neighbour id once, f(id), without the vertex loops:
/// what a cell's spokes need.
template <class CellT, class F>
void for_each_spoke(CellT& cell, F&& f) {
  for_each_face_plane(cell, [&](std::uint16_t, std::int32_t id) { f(id); });
}

}  // namespace tessera::front
