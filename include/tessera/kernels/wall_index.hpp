// Which walls can matter where (kernels/walls.hpp): a tree over the walls'
// normal directions. A cell is tested against each wall with a comparison
// (walls::misses), and a point against each wall with a dot product; a
// convex hull's walls (tessera::hull_walls) number in the thousands (8,936
// for a million points in a ball, two per point for points on a sphere),
// and every cell testing every wall made that run 5x slower than the box
// alone. With the index a cell tests only the walls whose plane passes
// within its vertices' ball (none inside the domain, tens near its
// boundary), or, where that ball is a poor fit (a needle from a sphere's
// point to its centre), the walls its vertices lie beyond
// (engine::clip_walls).
//
// The question asked is: which walls n.x <= d have a point of the ball
// B(q, r) outside (n.q + |n| r > d)? With every wall's normal scaled to unit
// length (nu = n / |n|, delta = d / |n|, measured from the box's centre o),
// that is nu.(q - o) + r > delta. A node of the tree holds walls whose
// normals lie within an angle alpha of an axis a, and the least delta among
// them. For x = q - o at angle phi from a, every wall of the node has
// nu.x <= |x| cos(max(0, phi - alpha)) (the angle between nu and x is at
// least phi - alpha), so the node is passed over where
//   |x| cos(max(0, phi - alpha)) + r < min delta.
// Walls tangent to a convex body (a hull's) sort by direction into nodes
// of nearby normals and nearly equal offsets, and a ball deep inside passes
// over the root; one near the boundary at direction u visits the nodes
// around u.
//
// Every bound is computed in floats with margins of 1e-12 of its terms (far
// above their rounding; norms are Wall::norm, an upper bound on |n|), so a
// wall is passed over only where it surely cannot matter. The nodes split
// the walls at the median of their normals' widest coordinate (leaves of up
// to 8); the walls found are reported in ascending order by `near`.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "tessera/kernels/exact_predicates.hpp"

namespace tessera::kernels::walls {

class Index {
 public:
  /// Over the walls (kernel walls, in the computation's frame, dim 2 or 3),
  /// with offsets measured from `origin` (the box's centre: any point is
  /// correct, one amid the domain prunes best).
  Index(std::span<const Wall> walls, int dim, const double* origin);

  /// Call f(k) for each wall k (in the tree's order) that may have a point
  /// of the ball B(q, r) strictly outside, or q on or beyond it (r = 0:
  /// the walls that q may lie outside of). Every wall that does is called;
  /// f returns false to stop.
  template <class F>
  void visit(const double* q, double r, F&& f) const;

  /// Of the walls `visit(q, r)` would find, other than those `skip(k)`
  /// names, the one q lies farthest beyond by the index's measure
  /// (nu.(q - o) - delta: a distance, rounded; ties to the first found), or
  /// -1 where there is none. A branch and bound over the tree: nodes whose
  /// bound falls below the best found are passed over.
  template <class Skip>
  std::int32_t deepest(const double* q, double r, Skip&& skip) const;

  /// The walls `visit` finds, ascending, into `out` (cleared); false where
  /// more than `limit` were found (then `out` holds limit + 1 of them).
  bool near(const double* q, double r, std::vector<std::int32_t>& out, std::size_t limit = SIZE_MAX) const;

  std::size_t size() const { return ids_.size(); }

 private:
  friend struct IndexBuilder;
  struct Node {
    double axis[3];  // unit (to rounding)
    // cos alpha within [cos_lo, cos_hi] and sin alpha <= sin_hi, alpha the
    // widest angle between axis and a normal; wide (cos_lo <= 0): no angle
    // bound is used.
    double cos_lo, cos_hi, sin_hi;
    double offset;        // below every wall's delta, margin included
    std::int32_t begin;   // walls [begin, end) in the arrays below
    std::int32_t end;
    std::int32_t right;   // the right child (the left is the next node); -1: a leaf
  };
  // q relative to the origin, its length, and the room its rounding needs.
  struct Query {
    double x[3] = {0, 0, 0};
    double xn = 0;
    double inv = 0;  // 1 / xn (0 where xn is)
    double room = 0;
    double reach = 0;
  };
  Query query(const double* q, double r) const {
    Query z;
    double xx = 0;
    for (int a = 0; a < dim_; ++a) {
      z.x[a] = q[a] - origin_[a];
      xx += z.x[a] * z.x[a];
    }
    z.xn = std::sqrt(xx);
    z.inv = z.xn > 0 ? 1 / z.xn : 0;
    // Room for every rounding below: the products with unit vectors, the
    // angle's sine and cosine (each within a few ulps), r.
    z.room = 1e-12 * (z.xn + r) + 1e-300;
    z.reach = r * (1 + 1e-12);
    return z;
  }
  // An upper bound on nu.x over node nd's walls, less the node's offset
  // (to the query's room).
  static double bound(const Node& nd, const Query& z) {
    double c = 1;  // an upper bound on cos(max(0, phi - alpha))
    if (nd.cos_lo > 0 && z.xn > 0) {
      const double* u = nd.axis;
      const double cphi = (u[0] * z.x[0] + u[1] * z.x[1] + u[2] * z.x[2]) * z.inv;
      if (cphi < nd.cos_lo) {  // phi > alpha: cos(phi - alpha) = cos phi cos alpha + sin phi sin alpha
        const double cx = u[1] * z.x[2] - u[2] * z.x[1], cy = u[2] * z.x[0] - u[0] * z.x[2],
                     cz = u[0] * z.x[1] - u[1] * z.x[0];
        const double sphi = std::sqrt(cx * cx + cy * cy + cz * cz) * z.inv;
        c = cphi * (cphi >= 0 ? nd.cos_hi : nd.cos_lo) + sphi * nd.sin_hi;
      }
    }
    return z.xn * c - nd.offset;
  }
  double measure(std::int32_t j, const Query& z) const {
    const double* nu = nu_.data() + 3 * static_cast<std::size_t>(j);
    return nu[0] * z.x[0] + nu[1] * z.x[1] + nu[2] * z.x[2] - delta_[static_cast<std::size_t>(j)];
  }
  bool found(std::int32_t j, const Query& z, double t) const {
    return !(t + z.reach < -(z.room + slack_[static_cast<std::size_t>(j)]));  // (NaN: found)
  }

  int dim_;
  double origin_[3] = {0, 0, 0};
  std::vector<Node> nodes_;          // depth first from the root
  std::vector<double> nu_;           // per wall (tree order): its unit normal (3 doubles)
  std::vector<double> delta_;        // per wall: its offset from origin_ over its norm
  std::vector<double> slack_;        // per wall: delta_'s rounding bound (and more)
  std::vector<std::int32_t> ids_;    // per wall: its index in the caller's walls
};

template <class F>
void Index::visit(const double* q, double r, F&& f) const {
  if (nodes_.empty()) return;
  const Query z = query(q, r);
  std::int32_t stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const std::int32_t at = stack[--top];
    const Node& nd = nodes_[static_cast<std::size_t>(at)];
    if (bound(nd, z) + z.reach < -z.room) continue;  // (NaN: visited)
    if (nd.right >= 0) {
      stack[top++] = nd.right;
      stack[top++] = at + 1;
      continue;
    }
    for (std::int32_t j = nd.begin; j < nd.end; ++j)
      if (found(j, z, measure(j, z)) && !f(ids_[static_cast<std::size_t>(j)])) return;
  }
}

template <class Skip>
std::int32_t Index::deepest(const double* q, double r, Skip&& skip) const {
  if (nodes_.empty()) return -1;
  const Query z = query(q, r);
  std::int32_t best = -1;
  double top_t = -std::numeric_limits<double>::infinity();
  struct Entry {
    std::int32_t at;
    double u;  // its bound, computed when its parent was split
  };
  Entry stack[64];
  int top = 0;
  stack[top++] = {0, bound(nodes_[0], z)};
  while (top > 0) {
    const Entry e = stack[--top];
    const Node& nd = nodes_[static_cast<std::size_t>(e.at)];
    if (e.u + z.reach < -z.room) continue;            // (NaN: visited)
    if (best >= 0 && e.u + z.room < top_t) continue;  // nothing here beats the best
    if (nd.right >= 0) {  // the child bounding higher first
      const Entry l{e.at + 1, bound(nodes_[static_cast<std::size_t>(e.at + 1)], z)};
      const Entry r{nd.right, bound(nodes_[static_cast<std::size_t>(nd.right)], z)};
      const bool right_first = r.u > l.u;
      stack[top++] = right_first ? l : r;
      stack[top++] = right_first ? r : l;
      continue;
    }
    for (std::int32_t j = nd.begin; j < nd.end; ++j) {
      const double t = measure(j, z);
      if (!found(j, z, t) || (best >= 0 && !(t > top_t))) continue;
      const std::int32_t k = ids_[static_cast<std::size_t>(j)];
      if (skip(k)) continue;
      best = k;
      top_t = t;
    }
  }
  return best;
}

}  // namespace tessera::kernels::walls
