// Checks on oriented face lists (3D polygons, 2D segments) for the face-set
// tests: closedness, manifoldness and enclosed volume, computed from the raw
// vertex ids and coordinates only.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <span>
#include <utility>
#include <vector>

#include "tessera/faces.hpp"

namespace dual_test {

/// One oriented face: vertex ids in order (a 2D face is the segment a -> b).
using Loop = std::vector<std::int32_t>;

/// Faces of a FaceSet selected by `keep(face)`, flipped where `flip(face)`.
template <class Keep, class Flip>
std::vector<Loop> loops_of(const tessera::FaceSet& fs, Keep keep, Flip flip) {
  std::vector<Loop> out;
  for (std::size_t f = 0; f < fs.n_faces(); ++f) {
    if (!keep(f)) continue;
    Loop l(fs.face_vertices.begin() + fs.face_offsets[f], fs.face_vertices.begin() + fs.face_offsets[f + 1]);
    if (flip(f)) std::reverse(l.begin(), l.end());
    out.push_back(std::move(l));
  }
  return out;
}

inline std::vector<Loop> all_loops(const tessera::FaceSet& fs) {
  return loops_of(fs, [](std::size_t) { return true; }, [](std::size_t) { return false; });
}

struct SurfaceReport {
  /// 3D: directed edges (a,b) used a different number of times than (b,a);
  /// 2D: vertices where a different number of segments arrive than leave.
  std::size_t unbalanced_edges = 0;
  /// 3D: undirected edges not in exactly two faces; 2D: vertices without
  /// exactly one arriving and one leaving segment.
  std::size_t nonmanifold_edges = 0;
  std::size_t degenerate_faces = 0;  ///< repeated vertex in a face, or a 2D face without two vertices
  double volume = 0;                 ///< enclosed signed volume (area in 2D), positive when outward
  double measure = 0;                ///< total face area (length in 2D)
};

/// Closed & consistently oriented <=> unbalanced_edges == 0 (the faces bound
/// a region: 3D, every directed edge is matched by its reverse; 2D, the
/// segments chain into closed loops). A closed 2-manifold (2D: disjoint
/// simple loops) also has nonmanifold_edges == 0.
inline SurfaceReport check_surface(std::span<const Loop> loops, const std::vector<double>& xyz, int dim,
                                   const std::array<double, 3>& origin) {
  SurfaceReport r;
  auto at = [&](std::int32_t v) {
    std::array<double, 3> p{0, 0, 0};
    for (int a = 0; a < dim; ++a) p[a] = xyz[static_cast<std::size_t>(v) * dim + a] - origin[a];
    return p;
  };
  std::map<std::pair<std::int32_t, std::int32_t>, int> directed;
  for (const Loop& l : loops) {
    if (dim == 2) {
      if (l.size() != 2 || l[0] == l[1]) { ++r.degenerate_faces; continue; }
      directed[{l[0], l[1]}]++;
      const auto a = at(l[0]), b = at(l[1]);
      r.volume += 0.5 * (a[0] * b[1] - a[1] * b[0]);
      r.measure += std::hypot(b[0] - a[0], b[1] - a[1]);
      continue;
    }
    if (l.size() < 3) { ++r.degenerate_faces; continue; }
    for (std::size_t t = 0; t < l.size(); ++t) {
      if (l[t] == l[(t + 1) % l.size()]) ++r.degenerate_faces;
      directed[{l[t], l[(t + 1) % l.size()]}]++;
    }
    const auto o = at(l[0]);
    std::array<double, 3> s{0, 0, 0};
    for (std::size_t t = 1; t + 1 < l.size(); ++t) {
      const auto a = at(l[t]), b = at(l[t + 1]);
      const std::array<double, 3> u{a[0] - o[0], a[1] - o[1], a[2] - o[2]}, w{b[0] - o[0], b[1] - o[1], b[2] - o[2]};
      const std::array<double, 3> c{u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
      for (int q = 0; q < 3; ++q) s[q] += c[q];
      r.volume += (o[0] * (a[1] * b[2] - a[2] * b[1]) + o[1] * (a[2] * b[0] - a[0] * b[2]) +
                   o[2] * (a[0] * b[1] - a[1] * b[0])) / 6.0;
    }
    r.measure += 0.5 * std::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
  }
  if (dim == 3) {
    for (auto& [e, n] : directed) {
      auto rev = directed.find({e.second, e.first});
      const int m = rev == directed.end() ? 0 : rev->second;
      if (m != n) ++r.unbalanced_edges;
      if (e.first < e.second && (n != 1 || m != 1)) ++r.nonmanifold_edges;
    }
  } else {  // 2D: the segments form closed loops iff every vertex has in = out
    std::map<std::int32_t, std::pair<int, int>> degree;  // (in, out)
    for (auto& [e, n] : directed) {
      degree[e.first].second += n;
      degree[e.second].first += n;
    }
    for (auto& [v, io] : degree) {
      if (io.first != io.second) ++r.unbalanced_edges;
      if (io.first != 1 || io.second != 1) ++r.nonmanifold_edges;
    }
  }
  return r;
}

}  // namespace dual_test
