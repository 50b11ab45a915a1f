// An independent brute-force Voronoi oracle, written for the tests only.
//
// A cell is the domain box clipped by the bisector half-space of EVERY other
// point (no locator, no security radius, no exact arithmetic). 2D: convex
// polygon clipping (Sutherland-Hodgman) with a label per edge. 3D: a convex
// polyhedron kept as a list of labelled face polygons; clipping by a plane
// clips each face polygon and closes the hole with a cap polygon made of the
// points on the plane. Plain doubles: meant only for random inputs in general
// position, where it is accurate to ~1e-14 relative.
//
// With radii (power cells) each bisector is the radical plane: |y - d|^2 - r_j^2
// <= |y|^2 - r_i^2, i.e. y.d <= (|d|^2 + r_i^2 - r_j^2) / 2.
//
// Labels follow tessera's spoke convention: generator id >= 0, or a box plane
// -1-2*axis (lo) / -2-2*axis (hi), or wall k -7-k (walls clip after the points).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <map>
#include <numeric>
#include <vector>

namespace oracle {

struct Cell {
  double volume = 0;                 ///< area in 2D
  std::array<double, 3> centroid{0, 0, 0};
  std::map<int, double> face;        ///< label -> face area (3D) / edge length (2D)
};

using P3 = std::array<double, 3>;
/// A wall: keep x with (w[0], w[1], w[2]) . x <= w[3] (2D: w[2] = 0); its
/// faces are labelled -7 - k, as tessera's wall spokes.
using Wall = std::array<double, 4>;

namespace detail {

inline P3 sub(const P3& a, const P3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline P3 cross(const P3& a, const P3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double dot(const P3& a, const P3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/// The point where segment in->out crosses the plane, computed always from the
/// inside end so the two faces sharing an edge produce bit-identical points.
inline P3 cut(const P3& in, double s_in, const P3& out, double s_out) {
  const double t = s_in / (s_in - s_out);
  return {in[0] + t * (out[0] - in[0]), in[1] + t * (out[1] - in[1]), in[2] + t * (out[2] - in[2])};
}

/// Other points sorted by distance to point i (clipping the nearest first keeps
/// the polygon small; every point is still used).
inline std::vector<std::size_t> by_distance(const std::vector<double>& pts, int dim, std::size_t i) {
  const std::size_t n = pts.size() / dim;
  std::vector<std::pair<double, std::size_t>> d;
  d.reserve(n);
  for (std::size_t j = 0; j < n; ++j) {
    if (j == i) continue;
    double s = 0;
    for (int a = 0; a < dim; ++a) s += (pts[j * dim + a] - pts[i * dim + a]) * (pts[j * dim + a] - pts[i * dim + a]);
    d.push_back({s, j});
  }
  std::sort(d.begin(), d.end());
  std::vector<std::size_t> r;
  for (auto& e : d) r.push_back(e.second);
  return r;
}

}  // namespace detail

/// The 2D cell of point i in the box [lo, hi].
inline Cell cell2d(const std::vector<double>& pts, std::size_t i, const std::array<double, 3>& lo,
                   const std::array<double, 3>& hi, const std::vector<double>& radii = {},
                   const std::vector<Wall>& walls = {}) {
  using detail::cut;
  const double px = pts[2 * i], py = pts[2 * i + 1];
  // Vertices relative to the generator; lab[k] labels the edge v[k] -> v[k+1]. CCW.
  std::vector<P3> v = {{lo[0] - px, lo[1] - py, 0},
                       {hi[0] - px, lo[1] - py, 0},
                       {hi[0] - px, hi[1] - py, 0},
                       {lo[0] - px, hi[1] - py, 0}};
  std::vector<int> lab = {-3, -2, -4, -1};
  // Keep y with y.(dx, dy) <= h; the new edge gets `label`.
  auto clip = [&](double dx, double dy, double h, int label) {
    std::vector<double> s(v.size());
    bool any_out = false;
    for (std::size_t k = 0; k < v.size(); ++k) {
      s[k] = v[k][0] * dx + v[k][1] * dy - h;
      any_out |= s[k] > 0;
    }
    if (!any_out) return;
    std::vector<P3> nv;
    std::vector<int> nl;
    for (std::size_t k = 0; k < v.size(); ++k) {
      const std::size_t m = (k + 1) % v.size();
      const bool ain = s[k] <= 0, bin = s[m] <= 0;
      if (ain) {
        nv.push_back(v[k]);
        nl.push_back(lab[k]);
        if (!bin) {  // leaving: the edge from the exit point runs along the bisector
          nv.push_back(cut(v[k], s[k], v[m], s[m]));
          nl.push_back(label);
        }
      } else if (bin) {  // entering: the rest of the original edge
        nv.push_back(cut(v[m], s[m], v[k], s[k]));
        nl.push_back(lab[k]);
      }
    }
    v.swap(nv);
    lab.swap(nl);
  };
  for (std::size_t j : detail::by_distance(pts, 2, i)) {
    const double dx = pts[2 * j] - px, dy = pts[2 * j + 1] - py;
    double h = 0.5 * (dx * dx + dy * dy);  // keep y with y.d <= |d|^2/2
    if (!radii.empty()) h += 0.5 * (radii[i] * radii[i] - radii[j] * radii[j]);
    clip(dx, dy, h, int(j));
  }
  for (std::size_t k = 0; k < walls.size(); ++k)
    clip(walls[k][0], walls[k][1], walls[k][3] - walls[k][0] * px - walls[k][1] * py, -7 - int(k));
  Cell c;
  double a2 = 0, cx = 0, cy = 0;
  for (std::size_t k = 0; k < v.size(); ++k) {
    const P3& a = v[k];
    const P3& b = v[(k + 1) % v.size()];
    const double cr = a[0] * b[1] - a[1] * b[0];
    a2 += cr;
    cx += (a[0] + b[0]) * cr;
    cy += (a[1] + b[1]) * cr;
    const double len = std::hypot(b[0] - a[0], b[1] - a[1]);
    if (len > 0) c.face[lab[k]] += len;
  }
  c.volume = 0.5 * a2;
  c.centroid = a2 > 0 ? P3{px + cx / (3 * a2), py + cy / (3 * a2), 0} : P3{px, py, 0};
  return c;
}

/// The 3D cell of point i in the box [lo, hi].
inline Cell cell3d(const std::vector<double>& pts, std::size_t i, const std::array<double, 3>& lo,
                   const std::array<double, 3>& hi, const std::vector<double>& radii = {},
                   const std::vector<Wall>& walls = {}) {
  using namespace detail;
  const P3 p{pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]};
  const P3 a = sub(lo, p), b = sub(hi, p);  // box relative to the generator
  struct Face {
    int label;
    std::vector<P3> v;
  };
  auto corner = [&](int x, int y, int z) { return P3{x ? b[0] : a[0], y ? b[1] : a[1], z ? b[2] : a[2]}; };
  std::vector<Face> faces = {
      {-1, {corner(0, 0, 0), corner(0, 0, 1), corner(0, 1, 1), corner(0, 1, 0)}},
      {-2, {corner(1, 0, 0), corner(1, 1, 0), corner(1, 1, 1), corner(1, 0, 1)}},
      {-3, {corner(0, 0, 0), corner(1, 0, 0), corner(1, 0, 1), corner(0, 0, 1)}},
      {-4, {corner(0, 1, 0), corner(0, 1, 1), corner(1, 1, 1), corner(1, 1, 0)}},
      {-5, {corner(0, 0, 0), corner(0, 1, 0), corner(1, 1, 0), corner(1, 0, 0)}},
      {-6, {corner(0, 0, 1), corner(1, 0, 1), corner(1, 1, 1), corner(0, 1, 1)}},
  };
  // Keep y with y.d <= h; the cap face gets `label`.
  auto clip = [&](const P3& d, double h, int label) {
    bool any_out = false;
    for (auto& f : faces)
      for (auto& x : f.v) any_out |= dot(x, d) - h > 0;
    if (!any_out) return;
    std::vector<Face> kept;
    std::vector<P3> cap;  // points on the plane
    for (auto& f : faces) {
      const std::size_t m = f.v.size();
      std::vector<double> s(m);
      for (std::size_t k = 0; k < m; ++k) s[k] = dot(f.v[k], d) - h;
      Face g{f.label, {}};
      for (std::size_t k = 0; k < m; ++k) {
        const std::size_t q = (k + 1) % m;
        const bool ain = s[k] <= 0, bin = s[q] <= 0;
        if (ain) {
          g.v.push_back(f.v[k]);
          if (s[k] == 0) cap.push_back(f.v[k]);
          if (!bin) {
            g.v.push_back(cut(f.v[k], s[k], f.v[q], s[q]));
            cap.push_back(g.v.back());
          }
        } else if (bin) {
          g.v.push_back(cut(f.v[q], s[q], f.v[k], s[k]));
          cap.push_back(g.v.back());
        }
      }
      if (g.v.size() >= 3) kept.push_back(std::move(g));
    }
    std::sort(cap.begin(), cap.end());
    cap.erase(std::unique(cap.begin(), cap.end()), cap.end());
    if (cap.size() >= 3) {
      // Order the cap around its mean in a basis of the plane.
      P3 mean{0, 0, 0};
      for (auto& x : cap)
        for (int t = 0; t < 3; ++t) mean[t] += x[t] / double(cap.size());
      const P3 helper = std::abs(d[0]) < 0.6 * std::sqrt(dot(d, d)) ? P3{1, 0, 0} : P3{0, 1, 0};
      const P3 u = cross(d, helper), w = cross(d, u);
      std::vector<std::pair<double, P3>> ang;
      for (auto& x : cap) {
        const P3 r = sub(x, mean);
        ang.push_back({std::atan2(dot(r, w), dot(r, u)), x});
      }
      std::sort(ang.begin(), ang.end());
      Face capf{label, {}};
      for (auto& e : ang) capf.v.push_back(e.second);
      kept.push_back(std::move(capf));
    }
    faces.swap(kept);
  };
  for (std::size_t j : by_distance(pts, 3, i)) {
    const P3 d = sub({pts[3 * j], pts[3 * j + 1], pts[3 * j + 2]}, p);
    double h = 0.5 * dot(d, d);
    if (!radii.empty()) h += 0.5 * (radii[i] * radii[i] - radii[j] * radii[j]);
    clip(d, h, int(j));
  }
  for (std::size_t k = 0; k < walls.size(); ++k) {
    const P3 n{walls[k][0], walls[k][1], walls[k][2]};
    clip(n, walls[k][3] - dot(n, p), -7 - int(k));
  }
  // Volume and centroid: fan of tetrahedra from the mean o of the vertices
  // (inside the convex cell; a power cell need not hold its generator), so
  // every face's fan has one sign: take it per face.
  Cell c;
  P3 o{0, 0, 0};
  std::size_t corners = 0;
  for (auto& f : faces)
    for (auto& x : f.v) {
      for (int q = 0; q < 3; ++q) o[q] += x[q];
      ++corners;
    }
  if (corners != 0)
    for (int q = 0; q < 3; ++q) o[q] /= double(corners);
  double vol = 0;
  P3 mom{0, 0, 0};
  for (auto& f : faces) {
    double fv = 0;
    P3 fm{0, 0, 0};
    P3 area{0, 0, 0};
    for (std::size_t k = 1; k + 1 < f.v.size(); ++k) {
      const P3 cr = cross(sub(f.v[k], o), sub(f.v[k + 1], o));
      const double t = dot(sub(f.v[0], o), cr) / 6.0;
      fv += t;
      for (int q = 0; q < 3; ++q) fm[q] += t * (o[q] + f.v[0][q] + f.v[k][q] + f.v[k + 1][q]) / 4.0;
      const P3 tri = cross(sub(f.v[k], f.v[0]), sub(f.v[k + 1], f.v[0]));
      for (int q = 0; q < 3; ++q) area[q] += tri[q];
    }
    const double sign = fv < 0 ? -1.0 : 1.0;
    vol += sign * fv;
    for (int q = 0; q < 3; ++q) mom[q] += sign * fm[q];
    const double ar = 0.5 * std::sqrt(dot(area, area));
    if (ar > 0) c.face[f.label] += ar;
  }
  c.volume = vol;
  for (int q = 0; q < 3; ++q) c.centroid[q] = vol > 0 ? p[q] + mom[q] / vol : p[q];
  return c;
}

inline Cell cell(const std::vector<double>& pts, int dim, std::size_t i, const std::array<double, 3>& lo,
                 const std::array<double, 3>& hi, const std::vector<double>& radii = {},
                 const std::vector<Wall>& walls = {}) {
  return dim == 2 ? cell2d(pts, i, lo, hi, radii, walls) : cell3d(pts, i, lo, hi, radii, walls);
}

}  // namespace oracle
