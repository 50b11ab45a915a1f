// tessera::voronoi: input checks, the domain, the locator, and the engine run
// with the cells compositor, for 2D tiles or 3D hulls.
#include "tessera/cells.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <thread>

#include <tbb/info.h>

#include "cells_compositor.hpp"
#include "tessera/engine/tessellate.hpp"
#include "tessera/kernels/hull.hpp"
#include "tessera/kernels/locator.hpp"
#include "tessera/kernels/tile.hpp"

namespace tessera {

double Bounds::volume(int dim) const {
  double v = 1;
  for (int d = 0; d < dim; ++d) v *= hi[static_cast<std::size_t>(d)] - lo[static_cast<std::size_t>(d)];
  return v;
}

int resolve_threads(int requested) {
  if (requested > 0) return requested;
  if (const char* env = std::getenv("TESSERA_NUM_THREADS")) {
    char* end = nullptr;
    long v = std::strtol(env, &end, 10);
    if (end != env && *end == '\0' && v > 0 && v < 4096) return static_cast<int>(v);
    throw InputError(std::string("TESSERA_NUM_THREADS must be a positive integer, got '") + env + "'");
  }
  return std::max(1, tbb::info::default_concurrency());
}

namespace {

const char* axis_name(int d) { return d == 0 ? "x" : (d == 1 ? "y" : "z"); }

/// The domain: explicit bounds checked, or the bounding box padded.
Bounds make_domain(std::span<const double> pts, int dim, std::size_t n, const VoronoiOptions& opt) {
  if (opt.bounds) {
    Bounds b = *opt.bounds;
    for (int d = 0; d < dim; ++d) {
      auto du = static_cast<std::size_t>(d);
      if (!std::isfinite(b.lo[du]) || !std::isfinite(b.hi[du]) || !(b.lo[du] < b.hi[du])) {
        std::ostringstream m;
        m << "bounds: " << axis_name(d) << " range [" << b.lo[du] << ", " << b.hi[du] << "] is empty or not finite";
        throw InputError(m.str());
      }
    }
    return b;
  }
  if (!(opt.padding >= 0) || !std::isfinite(opt.padding))
    throw InputError("padding must be a finite number >= 0");
  Bounds b;
  for (int d = 0; d < dim; ++d) {
    b.lo[static_cast<std::size_t>(d)] = INFINITY;
    b.hi[static_cast<std::size_t>(d)] = -INFINITY;
  }
  for (std::size_t i = 0; i < n; ++i)
    for (int d = 0; d < dim; ++d) {
      double x = pts[i * static_cast<std::size_t>(dim) + static_cast<std::size_t>(d)];
      b.lo[static_cast<std::size_t>(d)] = std::min(b.lo[static_cast<std::size_t>(d)], x);
      b.hi[static_cast<std::size_t>(d)] = std::max(b.hi[static_cast<std::size_t>(d)], x);
    }
  if (n == 1)
    throw InputError("a single point has no extent to make a domain from; give the domain with --bounds");
  double ext = 0;
  for (int d = 0; d < dim; ++d) {
    auto du = static_cast<std::size_t>(d);
    double e = b.hi[du] - b.lo[du];
    if (!(e > 0)) {
      std::ostringstream m;
      m << "all points have the same " << axis_name(d) << " coordinate (" << b.lo[du]
        << "): the bounding box has zero extent";
      if (dim == 3) m << "; for planar input use --dim 2, or give --bounds";
      else m << "; give --bounds";
      throw InputError(m.str());
    }
    ext = std::max(ext, e);
  }
  // Pad, then round outward to a multiple of a power of two near ext/64: the
  // box constants become short binary fractions (integer grids get the
  // half-integer box), so exact predicates on box vertices stay in the fast
  // 128-bit path. The margin is never smaller than asked.
  int e;
  std::frexp(ext, &e);
  const double step = std::ldexp(1.0, e - 7);
  for (int d = 0; d < dim; ++d) {
    auto du = static_cast<std::size_t>(d);
    b.lo[du] = std::floor((b.lo[du] - opt.padding * ext) / step) * step;
    b.hi[du] = std::ceil((b.hi[du] + opt.padding * ext) / step) * step;
  }
  return b;
}

/// Power-of-two exponent that brings the largest coordinate near 1 when the
/// input is so large or small that squared distances could overflow or
/// underflow in the float filter (0 otherwise). Scaling by 2^k is exact.
/// The shift is capped so that every non-zero coordinate stays a normal double
/// (no rounding into subnormals) and nothing overflows.
int normalizing_exponent(std::span<const double> points, const Bounds& b, int dim) {
  double m = 0, m_min = INFINITY;
  auto see = [&](double x) {
    x = std::fabs(x);
    m = std::max(m, x);
    if (x != 0) m_min = std::min(m_min, x);
  };
  for (double x : points) see(x);
  for (int d = 0; d < dim; ++d) {
    see(b.lo[static_cast<std::size_t>(d)]);
    see(b.hi[static_cast<std::size_t>(d)]);
  }
  if (m == 0 || (m < 0x1p200 && m > 0x1p-200)) return 0;
  int e_max, e_min;
  std::frexp(m, &e_max);
  std::frexp(m_min, &e_min);
  // x * 2^k stays normal iff e_min + k >= -1021, and finite iff e_max + k <= 1024.
  return std::clamp(-e_max, -1021 - e_min, 1000 - e_max);
}

template <class CellT>
Cells run(std::span<const double> input, std::span<const std::int32_t> labels, const VoronoiOptions& opt) {
  constexpr int D = CellT::dim;
  const std::size_t n = input.size() / D;
  Cells out;
  out.dim = D;
  out.n_points = n;
  out.bounds = make_domain(input, D, n, opt);
  // Extreme magnitudes: compute on an exactly rescaled copy, scale results back.
  const int k = normalizing_exponent(input, out.bounds, D);
  std::vector<double> scaled;
  std::span<const double> points = input;
  const Bounds user_bounds = out.bounds;
  if (k != 0) {
    scaled.resize(input.size());
    for (std::size_t i = 0; i < input.size(); ++i) scaled[i] = std::ldexp(input[i], k);
    for (int d = 0; d < D; ++d) {
      out.bounds.lo[static_cast<std::size_t>(d)] = std::ldexp(out.bounds.lo[static_cast<std::size_t>(d)], k);
      out.bounds.hi[static_cast<std::size_t>(d)] = std::ldexp(out.bounds.hi[static_cast<std::size_t>(d)], k);
    }
    points = scaled;
  }
  const Bounds& bx = out.bounds;

  // Which points take part (inside the box) and which get cells (also label >= 0).
  std::vector<std::uint8_t> in_box(n, 1);
  std::size_t n_in = n;
  for (std::size_t i = 0; i < n; ++i) {
    for (int d = 0; d < D; ++d) {
      double x = points[i * D + static_cast<std::size_t>(d)];
      if (x < bx.lo[static_cast<std::size_t>(d)] || x > bx.hi[static_cast<std::size_t>(d)]) {
        in_box[i] = 0;
        break;
      }
    }
    if (!in_box[i]) {
      if (!opt.ignore_outside_points) {
        std::ostringstream m;
        m << "point " << i << " lies outside the bounds (use --ignore-outside to drop such points)";
        throw InputError(m.str());
      }
      out.ignored_outside_bounds.push_back(static_cast<std::int32_t>(i));
      --n_in;
    }
  }
  if (n_in == 0) throw InputError("all points lie outside the bounds");

  std::array<double, D> lo, hi;
  for (int d = 0; d < D; ++d) {
    lo[static_cast<std::size_t>(d)] = bx.lo[static_cast<std::size_t>(d)];
    hi[static_cast<std::size_t>(d)] = bx.hi[static_cast<std::size_t>(d)];
  }
  const double ppb = opt.points_per_bin > 0 ? opt.points_per_bin : (D == 3 ? 2.0 : 2.0);
  kernels::BinLocator<D> locator(points, n_in == n ? std::span<const std::uint8_t>() : std::span<const std::uint8_t>(in_box),
                                 lo, hi, ppb);

  // Generators with cells, in bin order (neighbouring cells run together).
  std::vector<std::int32_t> order;
  order.reserve(locator.size());
  for (std::size_t k = 0; k < locator.size(); ++k) {
    std::int32_t id = locator.id(k);
    if (labels.empty() || labels[static_cast<std::size_t>(id)] >= 0) order.push_back(id);
  }

  kernels::ExactContext exact;
  exact.points = points.data();
  exact.dim = D;
  for (int d = 0; d < 3; ++d) {
    exact.lo[static_cast<std::size_t>(d)] = bx.lo[static_cast<std::size_t>(d)];
    exact.hi[static_cast<std::size_t>(d)] = bx.hi[static_cast<std::size_t>(d)];
  }
  engine::Generators<D> gens;
  gens.coords = points.data();
  gens.locator = &locator;
  gens.lo = lo;
  gens.hi = hi;
  gens.order = order;
  gens.exact = &exact;

  engine::EngineOptions eo;
  eo.threads = resolve_threads(opt.threads);
  eo.progress = opt.progress;
  out.threads_used = eo.threads;

  front::CellsCompositor<CellT> comp(out, points.data(), labels, opt.build_mesh);
  out.exact_predicate_calls = engine::tessellate<CellT>(gens, comp, eo);
  std::sort(out.duplicates.begin(), out.duplicates.end());
  if (k != 0) {
    for (double& v : out.volume) v = std::ldexp(v, -k * D);
    for (double& c : out.centroid) c = std::ldexp(c, -k);
    for (double& c : out.vertices) c = std::ldexp(c, -k);
    out.bounds = user_bounds;
  }
  return out;
}

}  // namespace

Cells voronoi(std::span<const double> points, int dim, std::span<const std::int32_t> labels,
              const VoronoiOptions& options) {
  if (dim != 2 && dim != 3) throw InputError("dimension must be 2 or 3, got " + std::to_string(dim));
  if (points.empty()) throw InputError("no input points");
  if (points.size() % static_cast<std::size_t>(dim) != 0)
    throw InputError("point array length " + std::to_string(points.size()) + " is not a multiple of dimension " +
                     std::to_string(dim));
  const std::size_t n = points.size() / static_cast<std::size_t>(dim);
  if (n > static_cast<std::size_t>(INT32_MAX - 1)) throw InputError("too many points (ids are 32-bit)");
  for (std::size_t k = 0; k < points.size(); ++k)
    if (!std::isfinite(points[k]))
      throw InputError("point " + std::to_string(k / static_cast<std::size_t>(dim)) + " has a NaN or infinite coordinate");
  if (!labels.empty() && labels.size() != n)
    throw InputError("labels: " + std::to_string(labels.size()) + " values for " + std::to_string(n) + " points");
  if (!labels.empty() && std::none_of(labels.begin(), labels.end(), [](std::int32_t l) { return l >= 0; }))
    throw InputError("labels: every point is outside (label < 0); nothing to tessellate");
  return dim == 3 ? run<kernels::Hull>(points, labels, options) : run<kernels::Tile>(points, labels, options);
}

}  // namespace tessera
