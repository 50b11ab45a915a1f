// A k-d tree over the points, visited nearest first: the candidate search for
// cells whose bin holds far more points than the grid was sized for.
//
// The bin grid is sized for the mean density. A cluster much smaller than a
// bin (a tight blob plus a few outliers that set the box) falls into one bin,
// and every one of its cells would scan all of it: quadratic in the cluster's
// size. For those cells the builder asks this tree instead, which yields the
// points in increasing distance (best-first search over node boxes, Hjaltason
// & Samet, "Distance browsing in spatial databases", 1999), so the security
// radius ends the search after the few dozen candidates a cell needs.
//
// Order: by (squared distance, id) — exact ties in id order, as the cell
// builder's duplicate rule requires — with a node expanded before any point
// at its lower bound, so no point inside it can be passed over.
//
// Its second use: the long cells of points sampled on a surface ask it for
// the nearest point to a cell vertex inside the vertex's petal (`nearest`,
// CellBuilder::certify_by_petals). Those searches prune nodes by slab bounds
// too (slab.hpp), built only for such inputs.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/collaborative_call_once.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include "tessera/kernels/slab.hpp"

namespace tessera::kernels {

template <int D>
class KdTree {
 public:
  /// The points `ids` of `coords` (n * D, row-major). With `slabs`, flat
  /// nodes also get a slab bound (slab.hpp), which `nearest` uses: points
  /// sampled on a surface.
  KdTree(std::span<const double> coords, std::vector<std::int32_t> ids, bool slabs = false)
      : coords_(coords), ids_(std::move(ids)), with_slabs_(slabs) {
    for (const std::int32_t j : ids_) id_bound_ = std::max(id_bound_, static_cast<std::size_t>(j) + 1);
    if (ids_.empty()) return;
    // The build partitions the points with their coordinates beside them
    // (contiguous items rather than ids into the input: the selections then
    // stream instead of gathering a cache line per point), subtrees in
    // parallel; the leaves' coordinates stay in slot order (pts_), so a
    // leaf's scan reads one contiguous run.
    std::vector<Item> items(ids_.size());
    for (std::size_t k = 0; k < ids_.size(); ++k) {
      items[k].id = ids_[k];
      for (int d = 0; d < D; ++d) items[k].p[static_cast<std::size_t>(d)] = at(ids_[k])[d];
    }
    nodes_.resize(node_count(ids_.size()));
    build(items, 0, 0, static_cast<std::uint32_t>(items.size()));
    pts_.resize(ids_.size() * D);
    for (std::size_t k = 0; k < ids_.size(); ++k) {
      ids_[k] = items[k].id;
      for (int d = 0; d < D; ++d) pts_[k * D + static_cast<std::size_t>(d)] = items[k].p[static_cast<std::size_t>(d)];
    }
    slabs_.resize(nodes_.size());  // without slabs: never flat, never excludes
    // The slabs, in parallel: threads that wait for this tree
    // (SharedKdTree's collaborative_call_once) join in. Serial, they were
    // half of the build (0.6 s of CPU at 1M terrain points).
    if (with_slabs_)
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nodes_.size(), 256), [&](const auto& r) {
        for (std::size_t k = r.begin(); k != r.end(); ++k) {
          const Node& nd = nodes_[k];
          slabs_[k] = Slab<D>::fit(nd.end - nd.begin, [&](std::size_t m) { return slot_point(nd.begin + m); });
        }
      });
  }

  /// One entry of the search's queue: a node (lower bound of its box's
  /// squared distance) or a point (its squared distance).
  struct Entry {
    double key;
    std::int32_t id;     // point id, or -1 - node index
    bool operator>(const Entry& o) const {
      if (key != o.key) return key > o.key;
      const bool node = id < 0, onode = o.id < 0;
      if (node != onode) return !node;  // nodes first at equal keys
      return id > o.id;
    }
  };

  /// Visit points other than `self` nearest first from x: f(id, r2) with
  /// r2 = |p_id - x|^2 computed as sum of squared coordinate differences;
  /// continues while the next key is at most r2max() (re-read each step, it
  /// may shrink) and f returns true. A node for which prune(lo, hi) (its
  /// box, absolute) holds is skipped with all its points. `heap` is the
  /// caller's scratch. `work` grows by the search's own effort: one per
  /// node or leaf point whose distance it computes, two more per entry it
  /// queues (a heap push and pop, O(log heap) each); the cell builder's
  /// BuildStatus::work, which the pilot weighs against the grid's scans.
  template <class Radius, class F, class Prune>
  void nearest_first(const double* x, std::int32_t self, std::vector<Entry>& heap, Radius&& r2max, F&& f, Prune&& prune,
                     std::uint64_t& work) const {
    heap.clear();
    if (nodes_.empty()) return;
    auto push = [&](Entry e) {
      work += 2;
      heap.push_back(e);
      std::push_heap(heap.begin(), heap.end(), std::greater<>{});
    };
    push({box_distance2(0, x), -1});
    while (!heap.empty()) {
      const Entry e = heap.front();
      if (e.key > r2max()) return;
      std::pop_heap(heap.begin(), heap.end(), std::greater<>{});
      heap.pop_back();
      if (e.id >= 0) {
        if (!f(e.id, e.key)) return;
        continue;
      }
      // Entries beyond the radius as it is now are never visited (it only
      // shrinks): they are not queued.
      const double bound = r2max();
      const Node& nd = nodes_[static_cast<std::size_t>(-1 - e.id)];
      if (nd.left < 0) {
        work += nd.end - nd.begin;
        for (std::uint32_t k = nd.begin; k < nd.end; ++k) {
          const std::int32_t j = ids_[k];
          if (j == self) continue;
          const double* pj = slot_point(k);
          double r2 = 0;
          for (int d = 0; d < D; ++d) {
            const double q = pj[d] - x[d];
            r2 += q * q;
          }
          if (r2 <= bound) push({r2, j});
        }
      } else {
        work += 2;
        for (const std::int32_t c : {nd.left, nd.right}) {
          const double b2 = box_distance2(static_cast<std::size_t>(c), x);
          const Node& child = nodes_[static_cast<std::size_t>(c)];
          if (b2 <= bound && !prune(child.lo.data(), child.hi.data())) push({b2, -1 - c});
        }
      }
    }
  }

  /// The point nearest to x among those other than `self` for which
  /// skip(id) is false, if its squared distance (computed as in
  /// nearest_first) is at most r2max: its id; -1 when there is none. Each
  /// node visited costs one unit of `budget`; a search that would exceed it
  /// stops and returns -2 (nothing is known then). Exact ties go to the
  /// lower id.
  template <class Skip>
  std::int32_t nearest(const double* x, std::int32_t self, double r2max, Skip&& skip, std::size_t& budget) const {
    Search q{x, r2max, std::sqrt(r2max), -1};
    if (nodes_.empty() || box_distance2(0, x) > q.bound || slab_excludes(0, q)) return -1;
    return nearest_below(0, q, self, skip, budget) ? q.best : -2;
  }

  /// One more than the largest point id it holds (0 when empty).
  std::size_t id_bound() const { return id_bound_; }

 private:
  static constexpr std::uint32_t leaf_size = 16;

  struct Node {
    std::array<double, D> lo, hi;  // bounding box of its points
    std::uint32_t begin, end;      // its points: ids_[begin, end)
    std::int32_t left = -1, right = -1;  // children; -1 for a leaf
  };

  // Squared distance from x to node k's box, never above the true distance
  // of any of its points: each axis gap is computed from coordinates the
  // box holds exactly, by the rounding monotone differences and sums that
  // the point distances use, so it is at most any point's term.
  double box_distance2(std::size_t k, const double* x) const {
    const Node& nd = nodes_[k];
    double s = 0;
    for (int d = 0; d < D; ++d) {
      double g = 0;
      if (x[d] < nd.lo[d]) g = nd.lo[d] - x[d];
      else if (x[d] > nd.hi[d]) g = x[d] - nd.hi[d];
      s += g * g;
    }
    return s;
  }

  // A nearest search's state: the best point so far and its squared
  // distance (the search's bound; r its square root, rounded).
  struct Search {
    const double* x;
    double bound, r;
    std::int32_t best;
  };

  // nearest below node k, whose points may lie within the bound: the child
  // whose box is nearer first, the other only if it still may. False: out
  // of budget.
  template <class Skip>
  bool nearest_below(std::size_t k, Search& q, std::int32_t self, Skip& skip, std::size_t& budget) const {
    if (budget == 0) return false;
    --budget;
    const Node& nd = nodes_[k];
    if (nd.left < 0) {
      for (std::uint32_t s = nd.begin; s < nd.end; ++s) {
        const std::int32_t j = ids_[s];
        const double* pj = slot_point(s);
        double r2 = 0;
        for (int d = 0; d < D; ++d) {
          const double t = pj[d] - q.x[d];
          r2 += t * t;
        }
        if (r2 > q.bound || (r2 == q.bound && q.best >= 0 && j > q.best) || j == self || skip(j)) continue;
        q.bound = r2;
        q.r = std::sqrt(r2);
        q.best = j;
      }
      return true;
    }
    const auto l = static_cast<std::size_t>(nd.left), r = static_cast<std::size_t>(nd.right);
    const double bl = box_distance2(l, q.x), br = box_distance2(r, q.x);
    const std::size_t first = bl <= br ? l : r, second = bl <= br ? r : l;
    if (std::min(bl, br) <= q.bound && !slab_excludes(first, q) && !nearest_below(first, q, self, skip, budget))
      return false;
    return std::max(bl, br) > q.bound || slab_excludes(second, q) || nearest_below(second, q, self, skip, budget);
  }

  const double* at(std::int32_t id) const { return coords_.data() + static_cast<std::size_t>(id) * D; }
  const double* slot_point(std::size_t s) const { return pts_.data() + s * D; }

  // Whether node k's slab lies wholly beyond the search's bound (Slab).
  bool slab_excludes(std::size_t k, const Search& q) const { return slabs_[k].excludes(q.x, q.r); }

  // A point with its coordinates, as the build moves it.
  struct Item {
    std::array<double, D> p;
    std::int32_t id;
  };

  // Nodes of a subtree over n points: a full binary tree with L(n) leaves,
  // L(n) = 1 for n <= leaf_size, else L(floor(n/2)) + L(ceil(n/2)). Each
  // level holds subtrees of two consecutive sizes, so (L(m), L(m+1)) follows
  // from (L(h), L(h+1)), h = floor(m/2): O(log n).
  static std::size_t node_count(std::size_t n) { return 2 * leaf_pair(n).first - 1; }
  static std::pair<std::size_t, std::size_t> leaf_pair(std::size_t m) {
    if (m < leaf_size) return {1, 1};
    if (m == leaf_size) return {1, 2};
    const auto [a, b] = leaf_pair(m / 2);  // L(h), L(h + 1)
    return m % 2 == 0 ? std::pair{2 * a, a + b} : std::pair{a + b, 2 * b};
  }

  // Node `index` over items[begin, end): its box, then a median split on
  // the widest axis; the children follow in preorder (left at index + 1,
  // right after the left subtree's node_count), so the layout does not
  // depend on which thread builds what. Subtrees of many points are built
  // in parallel.
  void build(std::vector<Item>& items, std::size_t index, std::uint32_t begin, std::uint32_t end) {
    Node nd;
    nd.begin = begin;
    nd.end = end;
    nd.lo = nd.hi = items[begin].p;
    for (std::uint32_t k = begin + 1; k < end; ++k)
      for (int d = 0; d < D; ++d) {
        nd.lo[static_cast<std::size_t>(d)] = std::min(nd.lo[static_cast<std::size_t>(d)], items[k].p[static_cast<std::size_t>(d)]);
        nd.hi[static_cast<std::size_t>(d)] = std::max(nd.hi[static_cast<std::size_t>(d)], items[k].p[static_cast<std::size_t>(d)]);
      }
    if (end - begin > leaf_size) {
      std::size_t axis = 0;
      for (std::size_t d = 1; d < D; ++d)
        if (nd.hi[d] - nd.lo[d] > nd.hi[axis] - nd.lo[axis]) axis = d;
      const std::uint32_t mid = begin + (end - begin) / 2;
      // (coordinate, id): a strict order, so the tree does not depend on the
      // library's nth_element.
      std::nth_element(items.begin() + begin, items.begin() + mid, items.begin() + end, [axis](const Item& a, const Item& b) {
        return a.p[axis] < b.p[axis] || (a.p[axis] == b.p[axis] && a.id < b.id);
      });
      const std::size_t left = index + 1, right = left + node_count(mid - begin);
      nd.left = static_cast<std::int32_t>(left);
      nd.right = static_cast<std::int32_t>(right);
      if (end - begin >= parallel_build)
        tbb::parallel_invoke([&] { build(items, left, begin, mid); }, [&] { build(items, right, mid, end); });
      else {
        build(items, left, begin, mid);
        build(items, right, mid, end);
      }
    }
    nodes_[index] = nd;
  }
  /// Subtrees of at least this many points split their build among threads.
  static constexpr std::uint32_t parallel_build = 1 << 14;

  std::span<const double> coords_;
  std::vector<std::int32_t> ids_;
  std::vector<Node> nodes_;
  std::vector<double> pts_;  // coordinates of ids_[k] at k * D
  std::vector<Slab<D>> slabs_;  // per node, kept apart from the 64-byte nodes nearest_first walks
  bool with_slabs_ = false;
  std::size_t id_bound_ = 0;
};

/// The pass's k-d tree of its located points, built at most once: up front
/// when a bin is overfull (the cells of such bins search it instead of the
/// grid), otherwise on first use, by the cell that first asks, while other
/// threads asking at the same time wait (tbb::collaborative_call_once). Most
/// inputs never ask: only cells whose security radius spans many bins (the
/// long cells of points sampled on a surface; CellBuilder) search it, and
/// only where the pass allows it (long_cells).
template <int D>
class SharedKdTree {
 public:
  /// `ids()` lists the points the tree holds, when it is built.
  SharedKdTree(std::span<const double> coords, std::function<std::vector<std::int32_t>()> ids, bool eager,
               bool long_cells)
      : coords_(coords), ids_(std::move(ids)), eager_(eager), long_cells_(long_cells) {
    if (eager_) get();
  }
  SharedKdTree(const SharedKdTree&) = delete;
  SharedKdTree& operator=(const SharedKdTree&) = delete;

  const KdTree<D>& get() const {
    tbb::collaborative_call_once(once_, [&] { tree_.emplace(coords_, ids_(), long_cells_); });
    return *tree_;
  }
  /// Built up front: some bin is overfull.
  bool eager() const { return eager_; }
  /// Long cells may search it (most bins are empty: a surface sample).
  bool long_cells() const { return long_cells_; }

 private:
  std::span<const double> coords_;
  std::function<std::vector<std::int32_t>()> ids_;
  bool eager_, long_cells_;
  mutable tbb::collaborative_once_flag once_;
  mutable std::optional<KdTree<D>> tree_;
};

}  // namespace tessera::kernels
