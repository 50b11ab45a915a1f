// Measures of a finished cell: volume (area), centroid, faces with their
// vertex loops. One adapter per cell kernel so compositors stay dimension-free.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "tessera/kernels/hull.hpp"
#include "tessera/kernels/tile.hpp"

namespace tessera::front {

/// Topological coordinate of a vertex: the generator and the ids of its
/// planes, ascending (box planes negative, so they come first).
template <int D>
using Key = std::array<std::int32_t, D + 1>;

/// Volume and centroid (relative to the generator) by a fan of simplices from
/// the generator: faces are counter-clockwise from outside, so every simplex
/// has positive orientation when the generator is inside.
inline void measure(kernels::Hull& hull, double& volume, std::array<double, 3>& centroid) {
  const auto& v = hull.vertices();
  double vol = 0, c[3] = {0, 0, 0};
  hull.for_each_face([&](std::uint16_t, const std::uint32_t* loop, std::size_t m) {
    const double* a = v[loop[0]].y;
    for (std::size_t k = 1; k + 1 < m; ++k) {
      const double* b = v[loop[k]].y;
      const double* d = v[loop[k + 1]].y;
      double t = (a[0] * (b[1] * d[2] - b[2] * d[1]) + a[1] * (b[2] * d[0] - b[0] * d[2]) +
                  a[2] * (b[0] * d[1] - b[1] * d[0])) / 6.0;
      vol += t;
      for (int i = 0; i < 3; ++i) c[i] += t * (a[i] + b[i] + d[i]) * 0.25;
    }
  });
  volume = vol;
  for (int i = 0; i < 3; ++i) centroid[i] = vol != 0 ? c[i] / vol : 0.0;
}

inline void measure(kernels::Tile& tile, double& area, std::array<double, 2>& centroid) {
  const auto& v = tile.vertices();
  const std::size_t m = v.size();
  double s = 0, cx = 0, cy = 0;
  for (std::size_t k = 0; k < m; ++k) {
    const double* a = v[k].y;
    const double* b = v[(k + 1) % m].y;
    double cr = a[0] * b[1] - a[1] * b[0];
    s += cr;
    cx += (a[0] + b[0]) * cr;
    cy += (a[1] + b[1]) * cr;
  }
  area = 0.5 * s;
  centroid = {s != 0 ? cx / (3 * s) : 0.0, s != 0 ? cy / (3 * s) : 0.0};
}

inline Key<3> vertex_key(const kernels::Hull& hull, std::size_t t) {
  const auto& v = hull.vertices()[t];
  const auto& pl = hull.planes();
  Key<3> k{hull.generator(), pl[v.p[0]].id, pl[v.p[1]].id, pl[v.p[2]].id};
  std::sort(k.begin(), k.end());
  return k;
}

inline Key<2> vertex_key(const kernels::Tile& tile, std::size_t t) {
  const auto& v = tile.vertices()[t];
  const auto& pl = tile.planes();
  Key<2> k{tile.generator(), pl[v.p[0]].id, pl[v.p[1]].id};
  std::sort(k.begin(), k.end());
  return k;
}

/// Visit faces as f(neighbour id, local vertex indices, count). In 2D a face is
/// the edge leaving vertex k, so the polygon order is preserved.
template <class F>
void for_each_face(kernels::Hull& hull, F&& f) {
  const auto& pl = hull.planes();
  hull.for_each_face([&](std::uint16_t p, const std::uint32_t* loop, std::size_t m) { f(pl[p].id, loop, m); });
}

template <class F>
void for_each_face(kernels::Tile& tile, F&& f) {
  const auto& v = tile.vertices();
  const auto& pl = tile.planes();
  const std::size_t m = v.size();
  for (std::size_t k = 0; k < m; ++k) {
    std::uint32_t e[2] = {static_cast<std::uint32_t>(k), static_cast<std::uint32_t>((k + 1) % m)};
    f(pl[v[k].p[1]].id, e, std::size_t{2});
  }
}

}  // namespace tessera::front
