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

/// Volume and centroid (relative to the generator), accumulated face by face
/// while the faces are walked once. 3D: a fan of tetrahedra from the generator
/// over each face (faces are counter-clockwise from outside, so every tetra is
/// positive when the generator is inside). 2D: the shoelace formula over edges.
template <int D>
class Measure;

template <>
class Measure<3> {
 public:
  explicit Measure(const kernels::Hull& hull) : v_(hull.vertices()) {}
  void add_face(const std::uint32_t* loop, std::size_t m) {
    const double* a = v_[loop[0]].y;
    for (std::size_t k = 1; k + 1 < m; ++k) {
      const double* b = v_[loop[k]].y;
      const double* d = v_[loop[k + 1]].y;
      double t = (a[0] * (b[1] * d[2] - b[2] * d[1]) + a[1] * (b[2] * d[0] - b[0] * d[2]) +
                  a[2] * (b[0] * d[1] - b[1] * d[0]));
      vol_ += t;
      for (int i = 0; i < 3; ++i) c_[i] += t * (a[i] + b[i] + d[i]);
    }
  }
  void result(double& volume, std::array<double, 3>& centroid) const {
    volume = vol_ / 6.0;
    for (int i = 0; i < 3; ++i) centroid[static_cast<std::size_t>(i)] = vol_ != 0 ? c_[i] / (4.0 * vol_) : 0.0;
  }

 private:
  const std::vector<kernels::Hull::Vertex>& v_;
  double vol_ = 0, c_[3] = {0, 0, 0};
};

template <>
class Measure<2> {
 public:
  explicit Measure(const kernels::Tile& tile) : v_(tile.vertices()) {}
  void add_face(const std::uint32_t* e, std::size_t) {  // the edge e[0] -> e[1]
    const double* a = v_[e[0]].y;
    const double* b = v_[e[1]].y;
    double cr = a[0] * b[1] - a[1] * b[0];
    s_ += cr;
    cx_ += (a[0] + b[0]) * cr;
    cy_ += (a[1] + b[1]) * cr;
  }
  void result(double& area, std::array<double, 2>& centroid) const {
    area = 0.5 * s_;
    centroid = {s_ != 0 ? cx_ / (3 * s_) : 0.0, s_ != 0 ? cy_ / (3 * s_) : 0.0};
  }

 private:
  const std::vector<kernels::Tile::Vertex>& v_;
  double s_ = 0, cx_ = 0, cy_ = 0;
};

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
