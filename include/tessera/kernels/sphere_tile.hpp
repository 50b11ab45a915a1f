// One spherical Voronoi cell, clipped from the whole sphere by one candidate
// at a time (the 2D tile's method on the sphere).
//
// The cell of generator p is the cone of directions u with u.(p - q) >= 0
// for every other point q: for points on a sphere, the directions closer to
// p than to any q (u.p >= u.q is |u - p| <= |u - q| when |p| = |q|); for any
// points, the normal cone of their convex hull at p, which is what the
// spherical Delaunay triangulation (the hull) is dual to. Every plane goes
// through the origin, so the cone needs no centre and the topology is
// decided on the input coordinates alone (sphere_predicates.hpp).
//
// A cell passes through four states: the whole sphere (no candidate yet), a
// hemisphere (one plane, no vertex), then a polygon: two planes make a lune
// (two antipodal vertices), every later plane removes a contiguous run of
// vertices and adds two. Edges are kept counter-clockwise seen from outside
// the sphere; edge k lies on the plane of neighbour edge_[k], and vertex k is
// where edge k ends and edge k + 1 begins, the hull facet (p, edge_[k],
// edge_[k+1]) whose outward normal is (edge_[k] - p) x (edge_[k+1] - p). A
// clip removes vertex k iff orientation(p, edge_[k], edge_[k+1], s) > 0;
// the float filter decides that from the normal stored with the vertex, the
// exact predicate where it cannot. If every vertex goes, p lies inside the
// hull (in the perturbed sense): its cell is empty.
//
// Termination (the security radius of the meshless method): s removes
// vertex v only if v.(s - p) > 0 with v the unit normal, i.e. s lies in the
// cap of the ball |x - c| <= R_max above the plane through p normal to v.
// With h = v.(p - c) >= 0 every point of that cap lies within
// sqrt(|p - c|^2 - h^2) + sqrt(R_max^2 - h^2) of p (for points on a sphere,
// the diameter of the facet's circumcircle); with h < 0, within
// |p - c| + R_max. Candidates taken nearest first stop at the largest such
// radius over the vertices, computed when asked (security2) and, where the
// facet's corner at p is too thin for its normal, from its widest corner.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <stdexcept>
#include <vector>

#include "tessera/kernels/filter.hpp"
#include "tessera/kernels/sphere_predicates.hpp"

namespace tessera::kernels {

/// The outward normal (y - x) x (z - x) of facet (x, y, z), computed from
/// the corner with the largest angle (opposite the longest edge): the normal
/// is the same vector from every corner of the cyclic order, but its
/// rounding error relative to its length is ~u / sin(the corner's angle),
/// and a facet of two points 1e-13 apart and a third far away (a pole given
/// once per longitude) has two corners of angle ~1e-16. Returns a bound on
/// the error of each component (the differences and products rounded).
inline double widest_corner_normal(const double* x, const double* y, const double* z, double* u) {
  double e[3][3];  // e[0] = y - x, e[1] = z - y, e[2] = x - z
  for (int d = 0; d < 3; ++d) {
    e[0][d] = y[d] - x[d];
    e[1][d] = z[d] - y[d];
    e[2][d] = x[d] - z[d];
  }
  double len2[3];
  for (int k = 0; k < 3; ++k) len2[k] = e[k][0] * e[k][0] + e[k][1] * e[k][1] + e[k][2] * e[k][2];
  // The longest edge k is opposite corner k + 2 (edge 1, y-z, is opposite
  // x); the normal is (edge leaving the corner) x -(edge arriving at it).
  const int k = static_cast<int>(std::max_element(len2, len2 + 3) - len2);
  const double* f = e[(k + 2) % 3];
  const double* g = e[(k + 1) % 3];
  u[0] = -(f[1] * g[2] - f[2] * g[1]);
  u[1] = -(f[2] * g[0] - f[0] * g[2]);
  u[2] = -(f[0] * g[1] - f[1] * g[0]);
  return 16 * filter::u * std::sqrt(len2[(k + 2) % 3] * len2[(k + 1) % 3]);
}

class SphereTile {
 public:
  enum class State : std::uint8_t { sphere, hemisphere, polygon, empty };

  /// Start the cell of point `id` at `p`; `center` and `r_max` (at least
  /// the largest |x - center| over all points) serve the security radius.
  void reset(std::int32_t id, const double* p, const double* center, double r_max) {
    id_ = id;
    p_ = p;
    state_ = State::sphere;
    edge_.clear();
    edge_pt_.clear();
    vert_.clear();
    for (int d = 0; d < 3; ++d) pc_[d] = p[d] - center[d];
    pc2_ = pc_[0] * pc_[0] + pc_[1] * pc_[1] + pc_[2] * pc_[2];
    pc_len_ = std::sqrt(pc2_);
    r_max2_ = r_max * r_max;
    security2_ = std::numeric_limits<double>::infinity();
    security_known_ = true;
    exact_tests_ = 0;
  }

  /// Clip by the plane of candidate `sid` at `s` (not p, not a duplicate of
  /// it). Returns whether the cell changed.
  bool clip(std::int32_t sid, const double* s) {
    switch (state_) {
      case State::sphere:
        edge_.push_back(sid);
        edge_pt_.push_back(s);
        state_ = State::hemisphere;
        return true;
      case State::hemisphere:
        // Two planes through the origin always make a lune (perturbed
        // points are never collinear): vertices (a -> s) and (s -> a).
        edge_.push_back(sid);
        edge_pt_.push_back(s);
        vert_.resize(2);
        make_vertex(vert_[0], edge_pt_[0], edge_pt_[1]);
        make_vertex(vert_[1], edge_pt_[1], edge_pt_[0]);
        state_ = State::polygon;
        update_security();
        return true;
      case State::empty:
        return false;
      case State::polygon:
        break;
    }
    const std::size_t n = vert_.size();
    std::size_t removed = 0;
    for (std::size_t k = 0; k < n; ++k) {
      vert_[k].clipped = removes(k, sid, s);
      removed += vert_[k].clipped;
    }
    if (removed == 0) return false;
    if (removed == n) {
      state_ = State::empty;
      edge_.clear();
      edge_pt_.clear();
      vert_.clear();
      security2_ = 0;
      security_known_ = true;
      return true;
    }
    // The removed vertices are one cyclic run i .. j (the cone is convex and
    // every decision exact). Keep edges j+1 .. i and their vertices j+1 ..
    // i-1, then edge s between the new vertices (edge_i -> s), (s -> edge_j+1).
    std::size_t i = 0;
    while (!(vert_[i].clipped && !vert_[(i + n - 1) % n].clipped)) ++i;
    const std::size_t j = (i + removed - 1) % n;
    for (std::size_t k = 0; k < removed; ++k)
      if (!vert_[(i + k) % n].clipped) throw std::logic_error("SphereTile: removed vertices are not one run");
    const std::size_t kept = n - removed;
    new_edge_.clear();
    new_edge_pt_.clear();
    new_vert_.clear();
    for (std::size_t m = 0; m <= kept; ++m) {
      const std::size_t e = (j + 1 + m) % n;
      new_edge_.push_back(edge_[e]);
      new_edge_pt_.push_back(edge_pt_[e]);
      if (m < kept) new_vert_.push_back(vert_[e]);
    }
    new_edge_.push_back(sid);
    new_edge_pt_.push_back(s);
    new_vert_.resize(kept + 2);
    make_vertex(new_vert_[kept], edge_pt_[i], s);
    make_vertex(new_vert_[kept + 1], s, edge_pt_[(j + 1) % n]);
    edge_.swap(new_edge_);
    edge_pt_.swap(new_edge_pt_);
    vert_.swap(new_vert_);
    update_security();
    return true;
  }

  State state() const { return state_; }
  /// Squared distance from p beyond which no candidate can change the cell
  /// (infinite until the cell is a polygon with well-conditioned vertices).
  double security2() {
    if (!security_known_) {
      double worst = 0;
      for (Vertex& v : vert_) {
        if (v.rho2 < 0) v.rho2 = vertex_security2(v);
        worst = std::max(worst, v.rho2);
      }
      security2_ = worst;
      security_known_ = true;
    }
    return security2_;
  }
  /// Neighbours across the edges, counter-clockwise seen from outside.
  std::span<const std::int32_t> edges() const { return edge_; }
  /// The candidates' coordinates as given to clip(), per edge.
  std::span<const double* const> edge_points() const { return edge_pt_; }
  std::size_t exact_tests() const { return exact_tests_; }

 private:
  struct Vertex {
    double u[3];     // (a - p) x (b - p), from the rounded differences
    double perm[3];  // per component |a_y b_z| + |a_z b_y| etc.: the filter's scale
    double rho2;     // the squared security radius of this vertex (file comment)
    const double* a;  // the facet's other two points: (p, a, b)
    const double* b;
    bool clipped;
  };

  // Vertex (p, a, b): its normal (a - p) x (b - p) from p's corner, and the
  // permanent of each component for the filter.
  void make_vertex(Vertex& v, const double* a, const double* b) const {
    double da[3], db[3];
    for (int d = 0; d < 3; ++d) {
      da[d] = a[d] - p_[d];
      db[d] = b[d] - p_[d];
    }
    v.u[0] = da[1] * db[2] - da[2] * db[1];
    v.u[1] = da[2] * db[0] - da[0] * db[2];
    v.u[2] = da[0] * db[1] - da[1] * db[0];
    v.perm[0] = std::fabs(da[1] * db[2]) + std::fabs(da[2] * db[1]);
    v.perm[1] = std::fabs(da[2] * db[0]) + std::fabs(da[0] * db[2]);
    v.perm[2] = std::fabs(da[0] * db[1]) + std::fabs(da[1] * db[0]);
    v.clipped = false;
    v.rho2 = -1;  // not yet known (security2 computes it when asked)
    v.a = a;
    v.b = b;
  }

  // Does s remove vertex k: orientation(p, edge_k, edge_k+1, s) > 0, which
  // is det[s - p, a - p, b - p] = (s - p).u. The bound is orientation_filter's
  // (delaunay_predicates.hpp) on the same rounded rows.
  bool removes(std::size_t k, std::int32_t sid, const double* s) {
    const Vertex& v = vert_[k];
    const double ds[3] = {s[0] - p_[0], s[1] - p_[1], s[2] - p_[2]};
    const double det = ds[0] * v.u[0] + ds[1] * v.u[1] + ds[2] * v.u[2];
    const double perm = std::fabs(ds[0]) * v.perm[0] + std::fabs(ds[1]) * v.perm[1] + std::fabs(ds[2]) * v.perm[2];
    const double growth = 2 * (std::fabs(ds[0]) + std::fabs(ds[1]) + std::fabs(ds[2])) + 3;
    const double bound = 16 * filter::u * perm + filter::underflow_bound(growth);
    if (det > bound) return true;
    if (det < -bound) return false;
    ++exact_tests_;
    const std::size_t k1 = (k + 1) % edge_.size();
    return orientation_sos(p_, edge_pt_[k], edge_pt_[k1], s, id_, edge_[k], edge_[k1], sid) > 0;
  }

  // A vertex's security radius (file comment), squared, with room for the
  // rounding of its normal: a normal not known to 1e-3 relative (a facet of
  // nearly collinear points) makes it infinite.
  double vertex_security2(const Vertex& v) const {
    const double* u = v.u;
    double len2 = u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
    double err2 = 64 * filter::u * filter::u * (v.perm[0] * v.perm[0] + v.perm[1] * v.perm[1] + v.perm[2] * v.perm[2]);
    double wide[3];
    if (!(len2 > 1e6 * err2)) {
      // The corner at p is too thin: the same normal from the widest one.
      const double err = widest_corner_normal(p_, v.a, v.b, wide);
      u = wide;
      len2 = u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
      err2 = err * err;
    }
    if (!(len2 > 1e6 * err2) || !(len2 > 0) || !(len2 < std::numeric_limits<double>::infinity()))
      return std::numeric_limits<double>::infinity();
    const double len = std::sqrt(len2), err = std::sqrt(err2);
    // h lowered by what the normal's direction error (err / len radians,
    // doubled) and the sums' rounding can hide; a smaller h only widens.
    double h = (u[0] * pc_[0] + u[1] * pc_[1] + u[2] * pc_[2]) / len;
    h -= (2 * err / len + 8 * filter::u) * pc_len_;
    double rho;
    if (h >= 0)
      rho = std::sqrt(std::max(0.0, pc2_ - h * h)) + std::sqrt(std::max(0.0, r_max2_ - h * h));
    else
      rho = pc_len_ + std::sqrt(r_max2_);
    rho *= 1 + 1e-12;
    return rho * rho;
  }

  // Lazily (security2): most vertices are cut away by the next few clips,
  // and a vertex's radius costs three square roots.
  void update_security() { security_known_ = false; }

  std::int32_t id_ = -1;
  const double* p_ = nullptr;
  State state_ = State::sphere;
  double pc_[3] = {}, pc2_ = 0, pc_len_ = 0, r_max2_ = 0, security2_ = 0;
  bool security_known_ = true;  // security2_ is up to date
  std::size_t exact_tests_ = 0;
  std::vector<std::int32_t> edge_, new_edge_;
  std::vector<const double*> edge_pt_, new_edge_pt_;
  std::vector<Vertex> vert_, new_vert_;
};

}  // namespace tessera::kernels
