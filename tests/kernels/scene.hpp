// Test scenes for the cell clippers: point sets in a box with the exact
// context the clippers need, random and lattice generators.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <utility>
#include <vector>

#include "tessera/kernels/exact_predicates.hpp"
#include "tessera/kernels/hull.hpp"

namespace kernels_test {

using tessera::kernels::ClipResult;
using tessera::kernels::ExactContext;

/// A point set in a box, with the exact context the clippers need.
template <int D>
struct Scene {
  std::vector<double> pts;
  std::array<double, D> lo{}, hi{};
  ExactContext ctx;

  Scene(std::vector<double> p, std::array<double, D> l, std::array<double, D> h) : pts(std::move(p)), lo(l), hi(h) {
    ctx.points = pts.data();
    ctx.dim = D;
    for (int d = 0; d < D; ++d) { ctx.lo[d] = lo[d]; ctx.hi[d] = hi[d]; }
  }
  Scene(const Scene&) = delete;
  std::int32_t size() const { return static_cast<std::int32_t>(pts.size() / D); }
  const double* p(std::int32_t i) const { return &pts[static_cast<std::size_t>(i) * D]; }
  double box_volume() const {
    double v = 1;
    for (int d = 0; d < D; ++d) v *= hi[d] - lo[d];
    return v;
  }
  double scale() const {
    double m = 0;
    for (int d = 0; d < D; ++d) m = std::max(m, hi[d] - lo[d]);
    return m;
  }
  template <class CellT>
  void reset(CellT& c, std::int32_t i) const { c.reset(i, p(i), lo.data(), hi.data(), &ctx); }
  /// Point i's cell clipped by every other point: the brute-force oracle.
  template <class CellT>
  void clip_by_all(CellT& c, std::int32_t i) const {
    reset(c, i);
    for (std::int32_t j = 0; j < size(); ++j)
      if (j != i) clip(c, j);
  }
  template <class CellT>
  ClipResult clip(CellT& c, std::int32_t j) const {
    double q[D];
    for (int d = 0; d < D; ++d) q[d] = p(j)[d] - p(c.generator())[d];
    return c.clip(j, q);
  }
};

template <int D>
std::vector<double> random_points(int n, std::uint64_t seed, double lo = 0, double hi = 1) {
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> u(lo, hi);
  std::vector<double> p(static_cast<std::size_t>(n) * D);
  for (auto& x : p) x = u(g);
  return p;
}

/// k^D lattice, coordinate (0.5 + index) * h (cells are cubes/squares of
/// side h in the box [0, k h]^D), every vertex of the diagram maximally
/// degenerate. With h = 0.1 the coordinates are rounded: near-degenerate.
/// `jitter` moves every coordinate that many ulp (random direction).
template <int D>
std::vector<double> lattice(int k, double h = 1, int jitter = 0, std::uint64_t seed = 0) {
  std::mt19937_64 g(seed);
  std::vector<double> p;
  const int n = D == 2 ? k * k : k * k * k;
  for (int m = 0; m < n; ++m) {
    int r = m;
    for (int d = 0; d < D; ++d) {
      double x = (0.5 + r % k) * h;
      for (int u = 0; u < jitter; ++u) x = std::nextafter(x, (g() & 1) ? INFINITY : -INFINITY);
      p.push_back(x);
      r /= k;
    }
  }
  return p;
}

}  // namespace kernels_test
