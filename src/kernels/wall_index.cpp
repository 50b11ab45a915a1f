// The nested grids of walls::Index (kernels/wall_index.hpp), built level by
// level: each node filters its parent's list, in parallel over the nodes
// (a count pass, then a fill pass into the level's CSR).
#include "tessera/kernels/wall_index.hpp"

#include <algorithm>
#include <limits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace tessera::kernels::walls {

Index::Index(std::span<const Wall> walls, int dim, const double* lo, const double* hi, double leaf) : dim_(dim) {
  double extent = 0;
  for (int a = 0; a < dim; ++a) {
    lo_[a] = lo[a];
    extent = std::max(extent, hi[a] - lo[a]);
  }
  const int max_depth = 18 / dim;  // at most 2^18 leaves
  while (depth_ < max_depth && extent / static_cast<double>(std::int64_t{1} << depth_) > leaf) ++depth_;
  levels_.resize(static_cast<std::size_t>(depth_) + 1);

  for (int l = 0; l <= depth_; ++l) {
    Level& lv = levels_[static_cast<std::size_t>(l)];
    const std::int64_t side = std::int64_t{1} << l;
    double diag2 = 0;
    for (int a = 0; a < dim; ++a) {
      lv.size[a] = (hi[a] - lo[a]) / static_cast<double>(side);
      diag2 += lv.size[a] * lv.size[a];
    }
    const double h = 0.5 * std::sqrt(diag2) * (1 + 1e-12);
    lv.cap = l == 0 ? std::numeric_limits<double>::infinity() : 2 * h;
    std::size_t nodes = 1;
    for (int a = 0; a < dim; ++a) nodes *= static_cast<std::size_t>(side);
    lv.offset.assign(nodes + 1, 0);
    lv.outside.assign(nodes, 0);

    // Node `at`'s walls, from its parent's list (every wall at the root):
    // each kept one passed to `keep`; false where the node lies wholly
    // outside a wall.
    auto filter = [&](std::size_t at, auto&& keep) {
      double x[3] = {0, 0, 0};
      std::size_t parent = 0, rest = at;
      for (int a = 0, stride = 1; a < dim; ++a, stride *= static_cast<int>(side / 2 > 0 ? side / 2 : 1)) {
        const auto i = static_cast<std::int64_t>(rest % static_cast<std::size_t>(side));
        rest /= static_cast<std::size_t>(side);
        x[a] = lo[a] + (static_cast<double>(i) + 0.5) * lv.size[a];
        parent += static_cast<std::size_t>(i / 2) * static_cast<std::size_t>(stride);
      }
      auto test = [&](std::int32_t k) {
        const Wall& w = walls[static_cast<std::size_t>(k)];
        double s = w.d, mag = std::fabs(w.d);
        for (int a = 0; a < dim; ++a) {
          s -= w.n[a] * x[a];
          mag += std::fabs(w.n[a] * x[a]);
        }
        const double m = 1e-12 * mag + 1e-300;  // (far above s's rounding)
        s /= w.norm;  // (norm >= |n|_2 >= 1: |s| at most the distance)
        if (s + m < -h) return -1;              // the node lies outside the wall
        return s - m > h + lv.cap ? 0 : 1;      // too far inside to matter, or listed
      };
      if (l == 0) {
        for (std::int32_t k = 0; k < static_cast<std::int32_t>(walls.size()); ++k) {
          const int t = test(k);
          if (t < 0) return false;
          if (t > 0) keep(k);
        }
        return true;
      }
      const Level& up = levels_[static_cast<std::size_t>(l - 1)];
      if (up.outside[parent]) return false;
      for (std::int64_t e = up.offset[parent]; e < up.offset[parent + 1]; ++e) {
        const std::int32_t k = up.ids[static_cast<std::size_t>(e)];
        const int t = test(k);
        if (t < 0) return false;
        if (t > 0) keep(k);
      }
      return true;
    };
    using Range = tbb::blocked_range<std::size_t>;
    tbb::parallel_for(Range(0, nodes, 1024), [&](const Range& r) {
      for (std::size_t at = r.begin(); at != r.end(); ++at) {
        std::int64_t count = 0;
        if (filter(at, [&](std::int32_t) { ++count; }))
          lv.offset[at + 1] = count;
        else
          lv.outside[at] = 1;
      }
    });
    for (std::size_t at = 0; at < nodes; ++at) lv.offset[at + 1] += lv.offset[at];
    lv.ids.resize(static_cast<std::size_t>(lv.offset[nodes]));
    tbb::parallel_for(Range(0, nodes, 1024), [&](const Range& r) {
      for (std::size_t at = r.begin(); at != r.end(); ++at) {
        if (lv.outside[at]) continue;
        auto slot = lv.offset[at];
        filter(at, [&](std::int32_t k) { lv.ids[static_cast<std::size_t>(slot++)] = k; });
      }
    });
  }
}

}  // namespace tessera::kernels::walls
