// Helpers for the surface-net tests: labelled synthetic point sets (nested
// spheres, touching boxes, a three-label junction), the surface of one region
// out of a net, triangle normals and a brute-force self-intersection count.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <numbers>
#include <random>
#include <span>
#include <utility>
#include <vector>

#include "dual/surface_checks.hpp"
#include "tessera/surface_nets.hpp"

namespace net_test {

using V3 = std::array<double, 3>;
inline V3 sub(const V3& a, const V3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline V3 cross(const V3& a, const V3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double dot(const V3& a, const V3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline double norm(const V3& a) { return std::sqrt(dot(a, a)); }

struct Labelled {
  int dim = 3;
  std::vector<double> points;
  std::vector<std::int32_t> labels;
};

/// k^dim points on the cell centres of a grid over the unit box, each moved
/// by up to `jitter` grid spacings per axis (0: exact voxel centres), labelled
/// by `label(x)`.
inline Labelled grid_points(int k, int dim, double jitter, std::uint64_t seed,
                            const std::function<std::int32_t(const V3&)>& label) {
  Labelled r;
  r.dim = dim;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double h = 1.0 / k;
  const int kz = dim == 3 ? k : 1;
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < k; ++j)
      for (int l = 0; l < kz; ++l) {
        V3 p{(i + 0.5) * h, (j + 0.5) * h, dim == 3 ? (l + 0.5) * h : 0.0};
        for (int a = 0; a < dim; ++a) p[a] += jitter * h * u(rng);
        for (int a = 0; a < dim; ++a) r.points.push_back(p[a]);
        r.labels.push_back(label(p));
      }
  return r;
}

inline double radius_from_centre(const V3& p, int dim) {
  double s = 0;
  for (int a = 0; a < dim; ++a) s += (p[a] - 0.5) * (p[a] - 0.5);
  return std::sqrt(s);
}

/// Nested spheres (circles in 2D) about the box centre: 2 inside r < r2,
/// 1 for r2 <= r < r1, 0 outside.
inline std::function<std::int32_t(const V3&)> nested(int dim, double r1 = 0.35, double r2 = 0.2) {
  return [=](const V3& p) {
    const double r = radius_from_centre(p, dim);
    return r < r2 ? 2 : r < r1 ? 1 : 0;
  };
}

/// Two boxes touching at x = 0.5: label 1 in [0.2,0.5) x [0.25,0.75]^2,
/// label 2 in [0.5,0.8] x [0.25,0.75]^2, 0 elsewhere.
inline std::int32_t touching_boxes(const V3& p) {
  const bool yz = p[1] > 0.25 && p[1] < 0.75 && p[2] > 0.25 && p[2] < 0.75;
  if (!yz || p[0] < 0.2 || p[0] > 0.8) return 0;
  return p[0] < 0.5 ? 1 : 2;
}

/// Three sectors of 120 degrees about the line x = y = 0.5 (parallel to z).
inline std::int32_t three_sectors(const V3& p) {
  const double a = std::atan2(p[1] - 0.5, p[0] - 0.5) + std::numbers::pi;  // [0, 2pi]
  return static_cast<std::int32_t>(std::min(2.0, std::floor(a / (2 * std::numbers::pi / 3))));
}

/// The surface of `label`: its faces on side 0 as they are, its faces on
/// side 1 reversed (so the whole surface should face outward).
inline std::vector<dual_test::Loop> region_loops(const tessera::FaceSet& m, std::int32_t label) {
  return dual_test::loops_of(
      m, [&](std::size_t f) { return m.boundary_labels[2 * f] == label || m.boundary_labels[2 * f + 1] == label; },
      [&](std::size_t f) { return m.boundary_labels[2 * f] != label; });
}

inline dual_test::SurfaceReport region_surface(const tessera::FaceSet& m, std::int32_t label) {
  const auto loops = region_loops(m, label);
  return dual_test::check_surface(loops, m.vertices, m.dim, {0.5, 0.5, 0.5});
}

inline V3 vertex(const tessera::FaceSet& m, std::int32_t v) {
  V3 p{0, 0, 0};
  for (int a = 0; a < m.dim; ++a) p[a] = m.vertices[static_cast<std::size_t>(v) * m.dim + a];
  return p;
}

/// Area vector (twice the area times the unit normal) of a 3D face.
inline V3 face_normal(const tessera::FaceSet& m, std::size_t f) {
  const auto b = m.face_offsets[f], e = m.face_offsets[f + 1];
  const V3 o = vertex(m, m.face_vertices[b]);
  V3 s{0, 0, 0};
  for (auto q = b + 1; q + 1 < e; ++q) {
    const V3 c = cross(sub(vertex(m, m.face_vertices[q]), o), sub(vertex(m, m.face_vertices[q + 1]), o));
    for (int a = 0; a < 3; ++a) s[a] += c[a];
  }
  return s;
}

/// Faces of `after` whose normal does not keep a positive dot product with
/// the same face (same vertex ids) before smoothing, i.e. on the vertex
/// positions of `before` (an unsmoothed net of the same input). Faces of
/// zero area before (exact lattices have some: coincident vertices) have no
/// normal to keep and are skipped.
inline std::size_t flipped_faces(const tessera::FaceSet& before, const tessera::FaceSet& after, double h) {
  std::size_t flips = 0;
  tessera::FaceSet same = after;
  same.vertices = before.vertices;
  for (std::size_t f = 0; f < after.n_faces(); ++f) {
    const V3 n0 = face_normal(same, f);
    const V3 n1 = face_normal(after, f);
    if (norm(n0) < 1e-9 * h * h) continue;
    if (!(dot(n0, n1) > 0)) ++flips;
  }
  return flips;
}

// ---- triangle-triangle intersection (brute force over bounding boxes)

/// Does segment pq cross triangle abc (proper crossing of the interior)?
inline bool segment_hits_triangle(const V3& p, const V3& q, const V3& a, const V3& b, const V3& c) {
  const V3 n = cross(sub(b, a), sub(c, a));
  const double dp = dot(n, sub(p, a)), dq = dot(n, sub(q, a));
  if ((dp > 0 && dq > 0) || (dp < 0 && dq < 0) || dp == dq) return false;
  const double t = dp / (dp - dq);
  const V3 x{p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1]), p[2] + t * (q[2] - p[2])};
  const double s0 = dot(n, cross(sub(b, a), sub(x, a)));
  const double s1 = dot(n, cross(sub(c, b), sub(x, b)));
  const double s2 = dot(n, cross(sub(a, c), sub(x, c)));
  return (s0 > 0 && s1 > 0 && s2 > 0) || (s0 < 0 && s1 < 0 && s2 < 0);
}

/// Pairs of triangles (of a triangulated 3D net) that share no vertex and
/// intersect; pairs sharing exactly one vertex that intersect away from it
/// are counted too (an edge of one crossing the other's interior).
inline std::size_t self_intersections(const tessera::FaceSet& m,
                                      std::vector<std::pair<std::size_t, std::size_t>>* pairs = nullptr) {
  const std::size_t nt = m.n_faces();
  std::vector<std::array<V3, 3>> tri(nt);
  std::vector<std::array<double, 6>> box(nt);
  for (std::size_t t = 0; t < nt; ++t) {
    for (int k = 0; k < 3; ++k) tri[t][k] = vertex(m, m.face_vertices[3 * t + k]);
    for (int a = 0; a < 3; ++a) {
      box[t][a] = std::min({tri[t][0][a], tri[t][1][a], tri[t][2][a]});
      box[t][3 + a] = std::max({tri[t][0][a], tri[t][1][a], tri[t][2][a]});
    }
  }
  std::vector<std::size_t> order(nt);
  for (std::size_t t = 0; t < nt; ++t) order[t] = t;
  std::sort(order.begin(), order.end(), [&](auto x, auto y) { return box[x][0] < box[y][0]; });
  std::size_t hits = 0;
  for (std::size_t i = 0; i < nt; ++i) {
    const auto s = order[i];
    for (std::size_t j = i + 1; j < nt && box[order[j]][0] <= box[s][3]; ++j) {
      const auto t = order[j];
      bool overlap = true;
      for (int a = 1; a < 3; ++a) overlap = overlap && box[t][a] <= box[s][3 + a] && box[s][a] <= box[t][3 + a];
      if (!overlap) continue;
      int shared = 0;
      for (int x = 0; x < 3; ++x)
        for (int y = 0; y < 3; ++y) shared += m.face_vertices[3 * s + x] == m.face_vertices[3 * t + y];
      if (shared >= 2) continue;  // neighbours across an edge
      bool hit = false;
      // Edges not touching a shared vertex: any proper crossing is an intersection.
      for (int k = 0; k < 3 && !hit; ++k) {
        const auto e0 = m.face_vertices[3 * s + k], e1 = m.face_vertices[3 * s + (k + 1) % 3];
        const bool touches = shared && std::count(&m.face_vertices[3 * t], &m.face_vertices[3 * t] + 3, e0) +
                                               std::count(&m.face_vertices[3 * t], &m.face_vertices[3 * t] + 3, e1);
        if (touches) continue;
        hit = segment_hits_triangle(tri[s][k], tri[s][(k + 1) % 3], tri[t][0], tri[t][1], tri[t][2]);
      }
      for (int k = 0; k < 3 && !hit; ++k) {
        const auto e0 = m.face_vertices[3 * t + k], e1 = m.face_vertices[3 * t + (k + 1) % 3];
        const bool touches = shared && std::count(&m.face_vertices[3 * s], &m.face_vertices[3 * s] + 3, e0) +
                                               std::count(&m.face_vertices[3 * s], &m.face_vertices[3 * s] + 3, e1);
        if (touches) continue;
        hit = segment_hits_triangle(tri[t][k], tri[t][(k + 1) % 3], tri[s][0], tri[s][1], tri[s][2]);
      }
      hits += hit;
      if (hit && pairs) pairs->emplace_back(s, t);
    }
  }
  return hits;
}

/// Sum of the cell volumes (areas) of one region, from a tessellation of the
/// same points with unselected labels as outside points.
inline tessera::SurfaceNetsOptions net_options(int dim, int iterations, bool triangles = false, int threads = 1) {
  tessera::SurfaceNetsOptions o;
  o.voronoi.dim = dim;
  tessera::Bounds b;
  b.lo = {0, 0, 0};
  b.hi = {1, 1, dim == 3 ? 1.0 : 0.0};
  o.voronoi.bounds = b;
  o.voronoi.threads = threads;
  o.smoothing.iterations = iterations;
  o.triangles = triangles;
  return o;
}

inline tessera::SurfaceNet run(const Labelled& in, const tessera::SurfaceNetsOptions& o) {
  return tessera::surface_nets(in.points, in.labels, o);
}

}  // namespace net_test
