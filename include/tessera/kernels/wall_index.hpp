// Which walls can matter where (kernels/walls.hpp): a tree of nested grids
// over the domain box, each node listing the walls that pass near it. A
// cell is tested against each wall with a comparison (walls::misses), and a
// point against each wall with a dot product; a convex hull's walls
// (tessera::hull_walls) number in the thousands (8,936 for a million points
// in a ball), and every cell testing every wall made that run 5x slower than
// the box alone. With the index a cell tests the walls listed at the
// deepest node holding its generator whose reach covers the cell's: mostly
// none inside the domain, tens near its boundary.
//
// Level l splits the box into 2^l nodes along each axis. Node N (centre x,
// half-diagonal h) at level l lists wall k unless the wall's plane is
// farther than h + cap_l from x on its inside (then every point in N is
// farther than cap_l from it, and a cell reaching at most cap_l from its
// generator in N misses it), where cap_l is N's diagonal (the root's is
// infinite: it lists every wall); and a node lying wholly outside some wall
// holds no point inside every wall, so it lists nothing and is marked
// outside. Distances are computed in floats with margins above their
// rounding (and with Wall::norm, an upper bound on |n|), so a wall is left
// out only where it surely cannot matter. Lists keep the walls' order.
#pragma once

#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "tessera/kernels/exact_predicates.hpp"

namespace tessera::kernels::walls {

class Index {
 public:
  /// Over the box [lo, hi] (dim 2 or 3, the computation's frame) for the
  /// walls (kernel walls, same frame), with leaves about `leaf` wide (at
  /// most 2^18 of them).
  Index(std::span<const Wall> walls, int dim, const double* lo, const double* hi, double leaf);

  /// The walls (ascending) that can cut the cell of a generator p (in the
  /// box, inside every wall) whose vertices lie within `reach` of p.
  std::span<const std::int32_t> candidates(const double* p, double reach) const {
    for (int l = depth_; l > 0; --l)
      if (levels_[static_cast<std::size_t>(l)].cap >= reach) return list(l, node(l, p));
    return list(0, 0);
  }

  /// The walls (ascending) that a point p in the box may lie outside of;
  /// `all` is set where p's leaf lies wholly outside some wall (then p does,
  /// and the caller tests every wall to name the first).
  std::span<const std::int32_t> may_hold_outside(const double* p, bool& all) const {
    const std::size_t at = node(depth_, p);
    all = levels_[static_cast<std::size_t>(depth_)].outside[at] != 0;
    return list(depth_, at);
  }

  int depth() const { return depth_; }

 private:
  struct Level {
    double size[3] = {0, 0, 0};  // a node's extent along each axis
    double cap = 0;              // the reach its lists cover
    std::vector<std::int64_t> offset;  // per node (CSR into ids), nodes x fastest
    std::vector<std::int32_t> ids;
    std::vector<std::uint8_t> outside;  // per node: wholly outside some wall
  };
  int dim_;
  int depth_ = 0;
  double lo_[3] = {0, 0, 0};
  std::vector<Level> levels_;

  std::size_t node(int l, const double* p) const {
    const Level& lv = levels_[static_cast<std::size_t>(l)];
    const std::int64_t side = std::int64_t{1} << l;
    std::size_t at = 0;
    for (int a = dim_ - 1; a >= 0; --a) {
      const double f = std::floor((p[a] - lo_[a]) / lv.size[a]);
      const std::int64_t i = f < 0 ? 0 : f >= static_cast<double>(side) ? side - 1 : static_cast<std::int64_t>(f);
      at = at * static_cast<std::size_t>(side) + static_cast<std::size_t>(i);
    }
    return at;
  }
  std::span<const std::int32_t> list(int l, std::size_t at) const {
    const Level& lv = levels_[static_cast<std::size_t>(l)];
    return {lv.ids.data() + lv.offset[at], static_cast<std::size_t>(lv.offset[at + 1] - lv.offset[at])};
  }
};

}  // namespace tessera::kernels::walls
