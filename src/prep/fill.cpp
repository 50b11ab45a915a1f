// Fill (include/tessera/prep/fill.hpp).
//
// Bins. The region is cut into c_0 x c_1 (x c_2) equal bins of edge
// e_d = extent_d / c_d, with c_d = round(extent_d / h) and h the edge of a cube
// holding `points_per_bin` input points on average. An axis shorter than h
// gets one bin and h is recomputed over the other axes, so a thin slab is not
// cut into (much) more bins than asked for. Bin b = i + c_0 * (j + c_1 * k)
// covers [lo + i e, lo + (i+1) e) per axis; points on the far face of the
// region fall in the last bin.
//
// Both strategies put their points at bin centres lo + (i + 1/2) e (VTK's
// adaptive strategy puts them on bin corners, notes §6.8) and both joggle by
// the same rule: `joggle` times the smallest bin edge, default 0 (VTK's
// effective default is an absolute 0.001 whatever its documentation says).
// All randomness is seeded by (seed, bin index), so the result does not depend
// on the thread count.
#include "tessera/prep/fill.hpp"

#include <algorithm>
#include <atomic>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "random.hpp"
#include "tessera/engine/thread_arena.hpp"
#include "tessera/finite_points.hpp"
#include "tessera/image.hpp"
#include "tessera/prep/sample_image.hpp"
#include "../message_text.hpp"
#include "../progress_chunks.hpp"

namespace tessera {
namespace {

constexpr std::size_t kGrain = 4096;
/// At most this many bins (one byte each, and as many added points): beyond
/// it the bins are far smaller than any sensible use of fill.
constexpr double kMaxBins = 268435456.0;  // 2^28



struct Grid {
  int dim = 3;
  double lo[3] = {0, 0, 0};
  double edge[3] = {1, 1, 1};
  double inv_edge[3] = {1, 1, 1};
  std::int64_t count[3] = {1, 1, 1};
  std::size_t n_bins() const {
    return static_cast<std::size_t>(count[0]) * static_cast<std::size_t>(count[1]) *
           static_cast<std::size_t>(count[2]);
  }
  std::size_t bin_of(const double* p) const {
    std::size_t b = 0;
    for (int d = dim - 1; d >= 0; --d) {
      auto i = static_cast<std::int64_t>(std::floor((p[d] - lo[d]) * inv_edge[d]));
      i = std::clamp<std::int64_t>(i, 0, count[d] - 1);
      b = b * static_cast<std::size_t>(count[d]) + static_cast<std::size_t>(i);
    }
    return b;
  }
  void centre(std::size_t b, double* out) const {
    for (int d = 0; d < dim; ++d) {
      const auto c = static_cast<std::size_t>(count[d]);
      out[d] = lo[d] + (static_cast<double>(b % c) + 0.5) * edge[d];
      b /= c;
    }
  }
  double min_edge() const {
    double m = edge[0];
    for (int d = 1; d < dim; ++d) m = std::min(m, edge[d]);
    return m;
  }
};

/// Bin counts for `n` points in the box [lo, hi] (every extent > 0).
Grid make_grid(int dim, const double* lo, const double* hi, std::size_t n, double points_per_bin) {
  Grid g;
  g.dim = dim;
  double extent[3] = {0, 0, 0};
  for (int d = 0; d < dim; ++d) {
    g.lo[d] = lo[d];
    extent[d] = hi[d] - lo[d];
    // Points spanning more than double's range: one infinite bin added
    // nothing (uniform), or the adaptive grid's image refused its spacing.
    if (!std::isfinite(extent[d]))
      throw InputError(std::string("fill: the region's ") + detail::axis_name(d) + " extent [" + detail::number_text(lo[d]) + ", " +
                       detail::number_text(hi[d]) + "] overflows double: scale the points down");
  }
  const double target = std::max(1.0, static_cast<double>(n) / points_per_bin);
  if (target > kMaxBins) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", target);
    throw InputError(std::string("fill: ") + buf + " bins asked (points per bin " + detail::number_text(points_per_bin) +
                     "); at most 2^28: raise the points per bin");
  }
  bool active[3] = {dim > 0, dim > 1, dim > 2};
  double h = 0;
  for (;;) {
    // Cube edge over the active axes; an axis shorter than it gets one bin.
    double log_v = 0;
    int k = 0;
    for (int d = 0; d < dim; ++d) {
      if (!active[d]) continue;
      log_v += std::log(extent[d]);
      ++k;
    }
    if (k == 0) break;
    h = std::exp((log_v - std::log(target)) / k);
    bool changed = false;
    for (int d = 0; d < dim; ++d) {
      if (active[d] && extent[d] < h) {
        active[d] = false;
        changed = true;
      }
    }
    if (!changed) break;
  }
  double total = 1;
  for (int d = 0; d < dim; ++d) {
    double c = active[d] ? std::max(1.0, std::round(extent[d] / h)) : 1.0;
    total *= c;
    if (total > 2 * kMaxBins)
      throw InputError("fill: too many bins (points per bin " + detail::number_text(points_per_bin) + "): raise the points per bin");
    g.count[d] = static_cast<std::int64_t>(c);
    g.edge[d] = extent[d] / c;
    g.inv_edge[d] = c / extent[d];
    // A bin centre lies half an edge inside its bin, so it cannot round onto
    // an input point of another bin while the edge is far above the
    // coordinates' last place; at a few ulps it can, and fill would add
    // points coinciding with the input's.
    const double magnitude = std::max(std::fabs(lo[d]), std::fabs(hi[d]));
    const double ulp = std::nextafter(magnitude, INFINITY) - magnitude;
    if (c > 1 && g.edge[d] < 1024 * ulp)
      throw InputError(std::string("fill: bins along ") + detail::axis_name(d) + " would be " + detail::number_text(g.edge[d]) +
                       " wide, within 1024 steps of double's resolution at " + detail::number_text(magnitude) +
                       ": raise the points per bin, or give larger bounds");
  }
  return g;
}

/// `body` over [0, n) in parallel, in chunks between which `progress` (may
/// be empty) is called.
template <class F>
void parallel_range(std::size_t n, int threads, const std::function<void(double)>& progress, F&& body) {
  detail::parallel_in_progress_chunks(threads, n, kGrain, progress, body);
}

}  // namespace

LabelledPoints fill(std::span<const double> coords, int dim, std::span<const std::int32_t> labels,
                    const FillOptions& options) {
  if (dim != 2 && dim != 3) throw InputError("fill: dimension must be 2 or 3, not " + std::to_string(dim));
  const auto sdim = static_cast<std::size_t>(dim);
  if (coords.size() % sdim != 0)
    throw InputError("fill: " + std::to_string(coords.size()) + " coordinates are not a whole number of " +
                     std::to_string(dim) + "D points");
  const std::size_t n = coords.size() / sdim;
  if (n == 0) throw InputError("fill: no input points");
  if (!labels.empty() && labels.size() != n)
    throw InputError("fill: " + std::to_string(labels.size()) + " labels for " + std::to_string(n) + " points");
  if (options.background_label >= 0)
    throw InputError("fill: the background label must be < 0 (outside points), not " +
                     std::to_string(options.background_label));
  if (!(options.points_per_bin > 0) || !std::isfinite(options.points_per_bin))
    throw InputError("fill: points per bin must be a finite number > 0, not " + detail::number_text(options.points_per_bin));
  if (!(options.joggle >= 0 && options.joggle <= 0.5))
    throw InputError("fill: joggle must be between 0 and 0.5 (a fraction of the bin edge), not " +
                     detail::number_text(options.joggle));
  if (options.strategy != FillStrategy::uniform && options.strategy != FillStrategy::adaptive)
    throw InputError("fill: unknown strategy");
  // Points that take part: all, or with keep_non_finite the finite ones.
  std::vector<std::uint8_t> finite;
  if (options.keep_non_finite) {
    finite.resize(n);
    for (std::size_t i = 0; i < n; ++i) finite[i] = finite_point(coords, i, dim);
  } else {
    for (std::size_t k = 0; k < coords.size(); ++k)
      if (!std::isfinite(coords[k]))
        throw InputError("fill: non-finite coordinate " + detail::number_text(coords[k]) + " in point " + std::to_string(k / sdim) +
                         " (keep_non_finite keeps such points, unbinned)");
  }
  auto takes_part = [&](std::size_t i) { return finite.empty() || finite[i] != 0; };
  const std::size_t taking =
      finite.empty() ? n : static_cast<std::size_t>(std::count(finite.begin(), finite.end(), std::uint8_t{1}));
  if (taking == 0) throw InputError("fill: all " + std::to_string(n) + " points have a NaN or infinite coordinate");

  // The region: the given bounds (containing every point) or the bounding box.
  double lo[3], hi[3];
  if (options.bounds) {
    for (int d = 0; d < dim; ++d) {
      lo[d] = options.bounds->lo[static_cast<std::size_t>(d)];
      hi[d] = options.bounds->hi[static_cast<std::size_t>(d)];
      if (!std::isfinite(lo[d]) || !std::isfinite(hi[d]) || !(lo[d] < hi[d]))
        throw InputError(std::string("fill: bounds along ") + detail::axis_name(d) + " must be finite with lo < hi, not [" +
                         detail::number_text(lo[d]) + ", " + detail::number_text(hi[d]) + "]");
    }
    for (std::size_t i = 0; i < n; ++i)
      for (int d = 0; d < dim && takes_part(i); ++d) {
        const double v = coords[i * sdim + static_cast<std::size_t>(d)];
        if (v < lo[d] || v > hi[d])
          throw InputError("fill: point " + std::to_string(i) + " lies outside the bounds (" + detail::axis_name(d) + " = " +
                           detail::number_text(v) + " not in [" + detail::number_text(lo[d]) + ", " + detail::number_text(hi[d]) + "])");
      }
  } else {
    bool first = true;
    for (std::size_t i = 0; i < n; ++i) {
      if (!takes_part(i)) continue;
      for (int d = 0; d < dim; ++d) {
        const double v = coords[i * sdim + static_cast<std::size_t>(d)];
        lo[d] = first ? v : std::min(lo[d], v);
        hi[d] = first ? v : std::max(hi[d], v);
      }
      first = false;
    }
    for (int d = 0; d < dim; ++d)
      if (!(lo[d] < hi[d]))
        throw InputError(std::string("fill: all ") + std::to_string(taking) + (taking < n ? " finite" : "") +
                         " points have " + detail::axis_name(d) + " = " + detail::number_text(lo[d]) + ": give bounds for the region to fill" +
                         (dim == 3 && d == 2 ? " (or use 2D points)" : ""));
  }

  const Grid grid = make_grid(dim, lo, hi, taking, options.points_per_bin);
  const int threads = resolve_threads(options.threads);

  // Occupancy, one byte per bin; concurrent stores of the same value.
  std::vector<std::uint8_t> occupied(grid.n_bins(), 0);
  parallel_range(n, threads, options.progress, [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i)
      if (takes_part(i))
        std::atomic_ref<std::uint8_t>(occupied[grid.bin_of(&coords[i * sdim])]).store(1, std::memory_order_relaxed);
  });

  LabelledPoints out;
  out.dim = dim;
  out.coords.assign(coords.begin(), coords.end());
  if (labels.empty())
    out.labels.assign(n, options.in_label);
  else
    out.labels.assign(labels.begin(), labels.end());

  if (options.strategy == FillStrategy::uniform) {
    std::vector<std::size_t> empty;
    for (std::size_t b = 0; b < occupied.size(); ++b)
      if (!occupied[b]) empty.push_back(b);
    const double radius = options.joggle * grid.min_edge();
    out.coords.resize((n + empty.size()) * sdim);
    double* added = out.coords.data() + n * sdim;
    parallel_range(empty.size(), threads, options.progress, [&](const tbb::blocked_range<std::size_t>& r) {
      double u[3];
      for (std::size_t k = r.begin(); k != r.end(); ++k) {
        double* p = added + k * sdim;
        grid.centre(empty[k], p);
        if (radius > 0) {
          detail::RandomStream rng(options.seed, empty[k], detail::kStreamFillJoggle);
          rng.in_unit_ball(dim, u);
          for (int d = 0; d < dim; ++d) p[d] += radius * u[d];
        }
      }
    });
    out.labels.resize(n + empty.size(), options.background_label);
    return out;
  }

  // Adaptive: the occupancy as a label image whose voxel centres are the bin
  // centres (occupied 0, empty background_label), sampled for background
  // points only: every empty bin next to an occupied one, sparser further out.
  LabelImage image;
  image.geometry.dim = dim;
  for (int d = 0; d < dim; ++d) {
    const auto du = static_cast<std::size_t>(d);
    image.geometry.size[du] = grid.count[d];
    image.geometry.spacing[du] = grid.edge[d];
    image.geometry.origin[du] = grid.lo[d] + 0.5 * grid.edge[d];
  }
  image.labels.resize(occupied.size());
  for (std::size_t b = 0; b < occupied.size(); ++b) image.labels[b] = occupied[b] ? 0 : options.background_label;
  occupied = {};

  SampleImageOptions so;
  so.select = {0};
  so.schedule = SampleSchedule::exponential;
  so.step = 2;
  so.randomize = true;
  so.seed = options.seed;
  so.output = SampleOutput::background;
  so.background_label = options.background_label;
  so.joggle = options.joggle;
  so.threads = threads;
  so.progress = options.progress;
  const LabelledPoints bg = sample_image(image, so);
  out.coords.insert(out.coords.end(), bg.coords.begin(), bg.coords.end());
  out.labels.resize(n + bg.size(), options.background_label);
  return out;
}

}  // namespace tessera
