// The tree of walls::Index (kernels/wall_index.hpp): built top down, each
// node splitting its walls at the median of their unit normals' widest
// coordinate, and bounding the cone of its normals and its least offset.
#include "tessera/kernels/wall_index.hpp"

#include <algorithm>
#include <numeric>

namespace tessera::kernels::walls {

namespace {
constexpr std::int32_t leaf_size = 8;
}

struct IndexBuilder {
  Index& ix;
  std::vector<std::int32_t> order;  // positions into the per-wall arrays being sorted
  std::vector<double> nu, delta, slack;

  // Node for order[b, e), appended depth first.
  void build(std::int32_t b, std::int32_t e, int depth) {
    const std::size_t at = ix.nodes_.size();
    ix.nodes_.emplace_back();
    Index::Node nd{};
    // The axis: the normals' mean direction (any unit vector would do; a
    // node whose normals spread past a right angle from it is wide).
    double m[3] = {0, 0, 0};
    double lo[3] = {2, 2, 2}, hi[3] = {-2, -2, -2};
    double least = std::numeric_limits<double>::infinity();
    for (std::int32_t i = b; i < e; ++i) {
      const double* v = nu.data() + 3 * static_cast<std::size_t>(order[static_cast<std::size_t>(i)]);
      for (int a = 0; a < 3; ++a) {
        m[a] += v[a];
        lo[a] = std::min(lo[a], v[a]);
        hi[a] = std::max(hi[a], v[a]);
      }
      const std::size_t w = static_cast<std::size_t>(order[static_cast<std::size_t>(i)]);
      least = std::min(least, delta[w] - slack[w]);
    }
    const double mn = std::sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
    if (mn > 0) {
      for (int a = 0; a < 3; ++a) nd.axis[a] = m[a] / mn;
    } else {
      nd.axis[0] = 1;
    }
    double cmin = 1, smax = 0;
    for (std::int32_t i = b; i < e; ++i) {
      const double* v = nu.data() + 3 * static_cast<std::size_t>(order[static_cast<std::size_t>(i)]);
      const double* u = nd.axis;
      const double vn = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
      const double c = (u[0] * v[0] + u[1] * v[1] + u[2] * v[2]) / vn;
      const double cx = u[1] * v[2] - u[2] * v[1], cy = u[2] * v[0] - u[0] * v[2], cz = u[0] * v[1] - u[1] * v[0];
      cmin = std::min(cmin, c);
      smax = std::max(smax, std::sqrt(cx * cx + cy * cy + cz * cz) / vn);
    }
    // Each cosine and sine within a few ulps: 1e-12 is far outside them.
    nd.cos_lo = cmin - 1e-12;
    nd.cos_hi = std::min(1.0, cmin + 1e-12);
    nd.sin_hi = std::min(1.0, smax + 1e-12);
    nd.offset = least;
    nd.begin = b;
    nd.end = e;
    nd.right = -1;
    if (e - b > leaf_size && depth < 60) {
      int axis = 0;
      for (int a = 1; a < 3; ++a)
        if (hi[a] - lo[a] > hi[axis] - lo[axis]) axis = a;
      const std::int32_t mid = b + (e - b) / 2;
      // Ties broken by position, so that the tree does not depend on the
      // library's nth_element.
      std::nth_element(order.begin() + b, order.begin() + mid, order.begin() + e, [&](std::int32_t s, std::int32_t t) {
        const double vs = nu[3 * static_cast<std::size_t>(s) + static_cast<std::size_t>(axis)];
        const double vt = nu[3 * static_cast<std::size_t>(t) + static_cast<std::size_t>(axis)];
        return vs < vt || (vs == vt && s < t);
      });
      build(b, mid, depth + 1);
      nd.right = static_cast<std::int32_t>(ix.nodes_.size());
      build(mid, e, depth + 1);
    }
    ix.nodes_[at] = nd;
  }
};

Index::Index(std::span<const Wall> walls, int dim, const double* origin) : dim_(dim) {
  for (int a = 0; a < dim; ++a) origin_[a] = origin[a];
  const std::size_t n = walls.size();
  IndexBuilder bld{*this, {}, std::vector<double>(3 * n, 0.0), std::vector<double>(n), std::vector<double>(n)};
  for (std::size_t k = 0; k < n; ++k) {
    const Wall& w = walls[k];
    // delta = (d - n.o) / norm: D products and D differences, each rounded
    // once, then the quotient; within gamma_{2D+1} of the magnitudes' sum
    // over norm (norm >= |n|_2 >= 1 for kernel walls, whose largest normal
    // component lies in [1, 2)). The slack is far above that.
    double d = w.d, mag = std::fabs(w.d);
    for (int a = 0; a < dim; ++a) {
      const double t = w.n[a] * origin_[a];
      d -= t;
      mag += std::fabs(t);
      bld.nu[3 * k + static_cast<std::size_t>(a)] = w.n[a] / w.norm;
    }
    bld.delta[k] = d / w.norm;
    bld.slack[k] = 1e-12 * mag / w.norm + 1e-300;
  }
  bld.order.resize(n);
  std::iota(bld.order.begin(), bld.order.end(), 0);
  if (n > 0) bld.build(0, static_cast<std::int32_t>(n), 0);
  nu_.resize(3 * n);
  delta_.resize(n);
  slack_.resize(n);
  ids_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(bld.order[i]);
    for (int a = 0; a < 3; ++a) nu_[3 * i + static_cast<std::size_t>(a)] = bld.nu[3 * k + static_cast<std::size_t>(a)];
    delta_[i] = bld.delta[k];
    slack_[i] = bld.slack[k];
    ids_[i] = static_cast<std::int32_t>(k);
  }
}

bool Index::near(const double* q, double r, std::vector<std::int32_t>& out, std::size_t limit) const {
  out.clear();
  bool fits = true;
  visit(q, r, [&](std::int32_t k) {
    out.push_back(k);
    if (out.size() > limit) {
      fits = false;
      return false;
    }
    return true;
  });
  std::sort(out.begin(), out.end());
  return fits;
}

}  // namespace tessera::kernels::walls
