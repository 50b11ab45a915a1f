// Lloyd relaxation (include/tessera/prep/lloyd.hpp): iterations of one cells
// pass each (no mesh), every point that owns a cell moved to its centroid.
#include "tessera/prep/lloyd.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "../front/pass.hpp"
#include "../front/periodic.hpp"
#include "../front/walls.hpp"
#include "../message_text.hpp"

namespace tessera {
namespace {

/// The shape checks that hold whatever the iterations (voronoi() repeats
/// them, with the rest, on the first iteration's input).
void check_shape(std::span<const double> points, int dim, std::span<const std::int32_t> labels,
                 const VoronoiOptions& o) {
  front::check_shape(points, dim, labels);
  front::check_radii(o.radii, points.size() / static_cast<std::size_t>(dim));
}

/// (volume / generators)^(1 / dim), from the extents' logarithms: a domain
/// whose volume overflows or underflows double (extents near 1e120 or
/// 1e-120 in 3D) still has a spacing. (Half extents: a whole one may
/// overflow.)
double mean_spacing(const Bounds& domain, int dim, std::size_t generators) {
  double log_sum = -std::log(static_cast<double>(std::max<std::size_t>(generators, 1)));
  for (int a = 0; a < dim; ++a) {
    const auto k = static_cast<std::size_t>(a);
    log_sum += std::log(0.5 * domain.hi[k] - 0.5 * domain.lo[k]) + std::log(2.0);
  }
  return std::exp(log_sum / dim);
}

}  // namespace

LloydResult lloyd(std::span<const double> points, int dim, std::span<const std::int32_t> labels,
                  const LloydOptions& options) {
  if (options.iterations < 0)
    throw InputError("lloyd: iterations must be >= 0, not " + std::to_string(options.iterations));
  if (!(options.tolerance >= 0) || !std::isfinite(options.tolerance))
    throw InputError("lloyd: tolerance must be a finite number >= 0, not " + detail::number_text(options.tolerance));
  if (!options.voronoi.only.empty())
    throw InputError("lloyd: every cell moves its point; VoronoiOptions::only must be empty");
  check_shape(points, dim, labels, options.voronoi);

  LloydResult result;
  result.points.assign(points.begin(), points.end());
  const int iterations = options.iterations;
  if (iterations == 0) return result;

  const auto du = static_cast<std::size_t>(dim);
  VoronoiOptions vo = options.voronoi;
  vo.build_mesh = false;
  const std::function<void(double)> progress = options.voronoi.progress;
  std::vector<double> next, displacement;
  // The walls in the points' frame, for the test of each centroid, and
  // (many walls: a hull's) their index, built once the domain is known:
  // each centroid then tests the walls it may lie outside of, not all.
  const std::vector<kernels::Wall> walls = front::kernel_walls(vo.walls, dim, 0);
  std::unique_ptr<const kernels::walls::Index> wall_index;
  for (int it = 0; it < iterations; ++it) {
    if (progress)
      vo.progress = [&progress, it, iterations](double f) {
        progress((it + std::clamp(f, 0.0, 1.0)) / iterations);
      };
    const Cells cells = voronoi(result.points, dim, labels, vo);
    if (it == 0) {
      // The domain of every later iteration (lloyd.hpp): the default one
      // would shrink with the points.
      result.domain = cells.bounds;
      if (!vo.bounds) vo.bounds = cells.bounds;
      result.spacing = mean_spacing(cells.bounds, dim, cells.generators);
      if (!vo.walls.empty()) {  // the polytope's spacing: its volume per generator, rooted
        const double v = front::domain_volume(cells.bounds, vo.walls, dim, cells.threads_used);
        if (v > 0) result.spacing = std::pow(v / static_cast<double>(std::max<std::size_t>(cells.generators, 1)), 1.0 / dim);
      }
      result.threads_used = cells.threads_used;
      if (!walls.empty()) wall_index = front::make_wall_index(walls, dim, *vo.bounds);
    }
    const Bounds& box = *vo.bounds;
    const bool periodic = cells.is_periodic();
    // Displacements are measured from the points as the cells took them:
    // wrapped into a periodic box.
    const std::vector<double>& from = periodic ? cells.periodic_points : result.points;
    const std::size_t moved = cells.n_cells();
    // The centroids are clamped into the box: the box's corners bound them.
    std::optional<front::WallTest> inside_walls;
    if (!walls.empty()) {
      double largest = 0;
      for (std::size_t a = 0; a < du; ++a) largest = std::max({largest, std::fabs(box.lo[a]), std::fabs(box.hi[a])});
      inside_walls.emplace(walls, dim, largest, wall_index.get());  // (centroids are clamped into the box)
    }
    next = result.points;
    displacement.resize(moved);
    for (std::size_t c = 0; c < moved; ++c) {
      const auto i = static_cast<std::size_t>(cells.generator[c]);
      double d[3] = {0, 0, 0};
      for (std::size_t a = 0; a < du; ++a) {
        double x = cells.centroid[c * du + a];
        // Held within the walls (a centroid on one may round past it).
        if (!cells.periodic[a]) x = std::clamp(x, box.lo[a], box.hi[a]);
        d[a] = x - from[i * du + a];
        next[i * du + a] = x;
      }
      // A centroid on a wall may round past it: that point stays where it
      // was (within rounding of the same place), as the next cells pass
      // would refuse it.
      if (!walls.empty() && inside_walls->outside(next.data() + i * du) >= 0) {
        for (std::size_t a = 0; a < du; ++a) next[i * du + a] = result.points[i * du + a];
        d[0] = d[1] = d[2] = 0;
      }
      // (std::hypot: squares of displacements past ~1e154 overflow)
      displacement[c] = std::hypot(d[0], d[1], d[2]);
    }
    if (periodic && moved != 0) {
      // Back into the box as the cells wrap points (by whole lattice
      // vectors, rounded to the box's grid); the points that did not move
      // keep their bits.
      const front::PeriodicInput wrapped = front::periodic_input(next, dim, labels, vo);
      for (std::size_t c = 0; c < moved; ++c) {
        const auto i = static_cast<std::size_t>(cells.generator[c]);
        std::copy_n(wrapped.points.begin() + static_cast<std::ptrdiff_t>(i * du), du,
                    next.begin() + static_cast<std::ptrdiff_t>(i * du));
      }
    }
    result.points.swap(next);
    // In point order, on this thread: the same sums for any thread count.
    // The mean square is taken relative to the largest, which neither
    // overflows nor underflows.
    const double largest = displacement.empty() ? 0.0 : *std::max_element(displacement.begin(), displacement.end());
    double relative_squares = 0;
    if (largest > 0)
      for (const double d : displacement) relative_squares += (d / largest) * (d / largest);
    result.largest_displacement.push_back(largest);
    result.rms_displacement.push_back(moved == 0 ? 0.0
                                                 : largest * std::sqrt(relative_squares / static_cast<double>(moved)));
    result.moved.push_back(moved);
    result.iterations = it + 1;
    if (progress) progress(static_cast<double>(it + 1) / iterations);
    if (options.tolerance > 0 && result.largest_displacement.back() <= options.tolerance * result.spacing) break;
  }
  return result;
}

}  // namespace tessera
