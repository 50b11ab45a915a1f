// A bounding-volume tree over the candidate points of hull completion, and
// the one query gift wrapping asks of it: every point that may lie beyond a
// facet's plane and inside the current best ball.
//
// Median splits on the widest axis, leaves of up to 32 points, and each node's
// box shrunk to its points (not to a grid), so empty space is cut away: the
// candidates form a thin shell along the domain box, and the lens a query
// covers is thin too. (With skipped cells the skipped points are candidates
// as well, spread through the volume.) Built level by level, each level's
// nodes split in parallel. Written here rather than taken from a library because
// the pruning test (a ball that shrinks during the search, intersected with a
// half-space) is the whole point and no Debian-packaged tree (nanoflann, CGAL's
// Kd_tree) takes a custom, changing predicate cheaply.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include <tbb/parallel_for.h>

#include "tessera/kernels/slab.hpp"

namespace tessera::front {

template <int D>
class CandidateTree {
 public:
  /// The query: points p with normal.(p - origin) > -margin (beyond the
  /// plane, with a float margin) and |p - ball_centre|^2 <= ball_r2. Nodes
  /// nearer `near` are visited first. The visitor may shrink the ball.
  struct Query {
    double normal[D], origin[D], near[D];
    double margin = 0;
    double ball_centre[D] = {};
    double ball_r2 = std::numeric_limits<double>::infinity();
  };

  /// The points of `coords` (n*D) whose `use[id]` is set.
  CandidateTree(std::span<const double> coords, std::span<const std::uint8_t> use) {
    const std::size_t n = use.size();
    std::vector<Entry> entries;
    for (std::size_t i = 0; i < n; ++i)
      if (use[i]) {
        Entry& e = entries.emplace_back();
        for (int d = 0; d < D; ++d) e.p[d] = coords[i * D + static_cast<std::size_t>(d)];
        e.id = static_cast<std::int32_t>(i);
      }
    if (entries.empty()) return;
    build(entries);
    ids_.resize(entries.size());
    pts_.resize(entries.size());
    rank_.assign(n, std::numeric_limits<std::uint32_t>::max());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, entries.size(), 1 << 14), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t k = r.begin(); k != r.end(); ++k) {
        ids_[k] = entries[k].id;
        pts_[k] = entries[k].p;
        rank_[static_cast<std::size_t>(entries[k].id)] = static_cast<std::uint32_t>(k);
      }
    });
    slabs_.resize(nodes_.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nodes_.size(), 64), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i) {
        const Node& nd = nodes_[i];
        slabs_[i] = kernels::Slab<D>::fit(nd.end - nd.begin, [&](std::size_t k) { return pts_[nd.begin + k].data(); });
      }
    });
  }

  std::size_t size() const { return ids_.size(); }

  /// A spatial order key for point `id`: its position in the tree's leaf
  /// order (points not in the tree after all others). Searches issued in
  /// this order of their facets walk the same few branches one after
  /// another, which then stay in cache.
  std::uint32_t rank(std::int32_t id) const {
    const auto at = static_cast<std::size_t>(id);
    return at < rank_.size() ? rank_[at] : std::numeric_limits<std::uint32_t>::max();
  }

  /// Calls visit(id) for every point that may satisfy the query (a superset).
  /// A node whose box the float plane test puts on the plane, within the
  /// margin, is offered to `on_plane(lo, hi)`, which returns true when no
  /// point of the box can lie strictly beyond (decided exactly by the caller):
  /// whole coplanar hull faces (lattices, points on a box face) would
  /// otherwise be visited point by point for every facet of that face.
  template <class Visit, class OnPlane>
  void search(Query& q, Visit&& visit, OnPlane&& on_plane) const {
    if (nodes_.empty()) return;
    std::uint32_t stack[128];
    int top = 0;
    stack[top++] = 0;
    double r2_seen = std::numeric_limits<double>::infinity(), r = r2_seen;  // r = sqrt(ball_r2), kept current
    const typename kernels::Slab<D>::Plane plane(q.normal, q.origin, q.margin);
    while (top > 0) {
      const std::uint32_t at = stack[--top];
      const Node& nd = nodes_[at];
      if (distance2(q.ball_centre, nd) > q.ball_r2) continue;
      if (q.ball_r2 != r2_seen) {
        r2_seen = q.ball_r2;
        r = std::sqrt(r2_seen);
      }
      // A patch of a surface sample (a terrain) whose box the ball meets
      // may still lie wholly outside it: the ball of a thin simplex is a
      // huge sphere nearly tangent to the surface.
      if (r2_seen != std::numeric_limits<double>::infinity() && slabs_[at].excludes(q.ball_centre, r)) continue;
      // Largest value of the plane function over the box: beyond test.
      double g = 0;
      for (int d = 0; d < D; ++d)
        g += std::max(q.normal[d] * (nd.lo[d] - q.origin[d]), q.normal[d] * (nd.hi[d] - q.origin[d]));
      if (g < -q.margin) continue;
      // While no ball bounds the search (a hull facet, with nothing beyond
      // to find, keeps none), the slab's plane test: on a convex surface
      // sample every hull facet's search is bounded by the plane alone.
      if (r2_seen == std::numeric_limits<double>::infinity() && slabs_[at].below(plane)) continue;
      if (g <= q.margin && on_plane(nd.lo, nd.hi)) continue;
      if (nd.left == 0) {
        for (std::uint32_t k = nd.begin; k < nd.end; ++k) {
          if (q.ball_r2 != std::numeric_limits<double>::infinity()) {
            double s = 0;
            for (int d = 0; d < D; ++d) s += (pts_[k][d] - q.ball_centre[d]) * (pts_[k][d] - q.ball_centre[d]);
            if (s > q.ball_r2) continue;
          }
          visit(ids_[k]);
        }
        continue;
      }
      // Push the farther child first so the nearer one is searched first:
      // the one on q.near's side of the split.
      const std::uint32_t l = nd.left, r = nd.left + 1;
      const bool left_first = q.near[nd.axis] <= nd.split;
      stack[top++] = left_first ? r : l;
      stack[top++] = left_first ? l : r;
    }
  }

 private:
  struct Node {
    double lo[D], hi[D];
    std::uint32_t begin, end;
    std::uint32_t left = 0;  // children at left, left+1; 0 for a leaf
    std::uint32_t axis = 0;  // inner nodes: the left child holds the points at or below `split` on `axis`
    double split = 0;
  };
  // Leaves of up to 32 points: on a terrain's completion, where a thin
  // simplex's ball runs along the surface for a dozen leaves, each opened
  // through a root-to-leaf path of node tests (cache misses), 32 was 10-20%
  // faster than 8 (100k terrain 7.3-7.5 -> 6.1-6.8 s, 50k torus 10.2-11.0 ->
  // 9.2-9.3 s); 64 was no better, uniform input indifferent.
  static constexpr std::uint32_t kLeaf = 32;

  static double distance2(const double* x, const Node& nd) {
    double s = 0;
    for (int d = 0; d < D; ++d) {
      double g = std::max({0.0, nd.lo[d] - x[d], x[d] - nd.hi[d]});
      s += g * g;
    }
    return s;
  }

  // A point while the tree is built: the splits move points and ids together
  // (nth_element on these directly, not on a permutation of indices whose
  // every comparison loads two scattered points).
  struct Entry {
    std::array<double, D> p;
    std::int32_t id;
  };

  // Builds the node for [begin, end) at the end of nodes_, then its children
  // (pairs, adjacent), one level at a time: a level's nodes own disjoint
  // ranges of the points, so they are split in parallel, and their children
  // are numbered afterwards in level order (the same tree for any thread
  // count). Depth is about log2(n / kLeaf): far below the stack size.
  void build(std::vector<Entry>& entries) {
    nodes_.push_back({});
    nodes_[0].begin = 0;
    nodes_[0].end = static_cast<std::uint32_t>(entries.size());
    std::vector<std::uint32_t> level{0}, next;
    while (!level.empty()) {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, level.size(), 1), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t w = r.begin(); w != r.end(); ++w) split(nodes_[level[w]], entries);
      });
      next.clear();
      for (std::uint32_t at : level) {
        Node& nd = nodes_[at];
        if (nd.end - nd.begin <= kLeaf) continue;
        const std::uint32_t mid = nd.begin + (nd.end - nd.begin) / 2;
        nd.left = static_cast<std::uint32_t>(nodes_.size());
        Node l{}, r{};
        l.begin = nd.begin;
        l.end = mid;
        r.begin = mid;
        r.end = nd.end;
        next.push_back(nd.left);
        next.push_back(nd.left + 1);
        nodes_.push_back(l);  // may move nodes_: nd is not used after this
        nodes_.push_back(r);
      }
      level.swap(next);
    }
  }

  // The node's box; and for an inner node, its points ordered about the
  // median on the widest axis (ties by id), which sets its split.
  static void split(Node& nd, std::vector<Entry>& entries) {
    for (int d = 0; d < D; ++d) {
      nd.lo[d] = std::numeric_limits<double>::infinity();
      nd.hi[d] = -std::numeric_limits<double>::infinity();
    }
    for (std::uint32_t k = nd.begin; k < nd.end; ++k)
      for (int d = 0; d < D; ++d) {
        nd.lo[d] = std::min(nd.lo[d], entries[k].p[d]);
        nd.hi[d] = std::max(nd.hi[d], entries[k].p[d]);
      }
    if (nd.end - nd.begin <= kLeaf) return;
    int axis = 0;
    for (int d = 1; d < D; ++d)
      if (nd.hi[d] - nd.lo[d] > nd.hi[axis] - nd.lo[axis]) axis = d;
    const std::uint32_t mid = nd.begin + (nd.end - nd.begin) / 2;
    const auto first = entries.begin() + nd.begin;
    std::nth_element(first, entries.begin() + mid, entries.begin() + nd.end, [axis](const Entry& x, const Entry& y) {
      return x.p[axis] != y.p[axis] ? x.p[axis] < y.p[axis] : x.id < y.id;
    });
    nd.axis = static_cast<std::uint32_t>(axis);
    nd.split = entries[mid].p[axis];  // the median: an order for the search, nothing more
  }

  std::vector<std::int32_t> ids_;
  std::vector<std::array<double, D>> pts_;
  std::vector<Node> nodes_;
  std::vector<kernels::Slab<D>> slabs_;  // per node (slab.hpp)
  std::vector<std::uint32_t> rank_;      // per input id: position in ids_
};

}  // namespace tessera::front
