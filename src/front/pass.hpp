// What every product's cells pass shares: input checks, the domain box, exact
// power-of-two rescaling of extreme inputs, the locator and the generator order.
// tessera::voronoi and tessera::delaunay each run one Pass with their own
// compositor (DESIGN §2: one engine, many compositors).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "tessera/buffer.hpp"
#include "tessera/cells.hpp"
#include "tessera/engine/tessellate.hpp"
#include "tessera/kernels/exact_predicates.hpp"
#include "tessera/kernels/locator.hpp"

namespace tessera::front {

/// Throws InputError unless points (n * dim values, n >= 1, ids 32-bit) and
/// labels (empty or n) have a valid shape; their values are not read.
void check_shape(std::span<const double> points, int dim, std::span<const std::int32_t> labels);

/// Throws InputError unless points/labels are a valid input of dimension dim.
void check_input(std::span<const double> points, int dim, std::span<const std::int32_t> labels);

/// Points with a NaN or infinite coordinate, where options.ignore_outside_points
/// says to drop points outside the domain, lie outside every box (organized
/// point clouds mark missing returns so). Where there are any, `cleaned`
/// receives a copy of `points` with each of them moved just outside the
/// domain (the given bounds, else the default domain of the finite points),
/// `points` is pointed at it and `options.bounds` set to that domain: the
/// pass then drops them as any point outside the bounds, keeping the ids
/// and listing them as ignored. Otherwise nothing changes (and check_input
/// refuses such points).
void set_aside_non_finite(std::span<const double>& points, int dim, VoronoiOptions& options,
                          std::vector<double>& cleaned);

/// What tessera::voronoi and tessera::delaunay compute on: the input after
/// set_aside_non_finite and check_input. Neither copied nor moved (`points`
/// may view `cleaned`).
template <class Options>
struct CheckedInput {
  std::span<const double> points;
  Options options;
  std::vector<double> cleaned;
  CheckedInput(std::span<const double> input, int dim, std::span<const std::int32_t> labels, const Options& given)
      : points(input), options(given) {
    set_aside_non_finite(points, dim, options, cleaned);
    check_input(points, dim, labels);
  }
  CheckedInput(const CheckedInput&) = delete;
  CheckedInput& operator=(const CheckedInput&) = delete;
};

/// Throws InputError unless `radii` (VoronoiOptions::radii) is empty, or n
/// finite radii >= 0.
void check_radii(std::span<const double> radii, std::size_t n);

/// The bounding box of the points, or of the inside ones (label >= 0) when
/// labels are given; +inf..-inf on an axis with none.
Bounds bounding_box(std::span<const double> points, int dim, std::span<const std::int32_t> labels = {});

/// The domain: explicit bounds checked, or the bounding box padded and rounded
/// outward to a short binary fraction (see cells.cpp).
Bounds make_domain(std::span<const double> points, int dim, const VoronoiOptions& opt);

/// How the computation's frame relates to the user's: coordinates are
/// scaled by 2^k (exact), and `may_underflow` says whether, even so, the
/// nonzero coordinates span so wide a range that float products of their
/// differences can round into the subnormal range (see Scaling's definition).
struct Scaling {
  int k = 0;
  bool may_underflow = false;
};

/// The scaling of the points and the box: k = 0 for input of ordinary range.
Scaling choose_scaling(std::span<const double> points, const Bounds& b, int dim);

/// Everything set up for one engine run over the input. Not movable: the
/// engine's Generators point into it.
template <int D>
struct Pass {
  Pass(std::span<const double> input, std::span<const std::int32_t> labels, const VoronoiOptions& opt);
  Pass(const Pass&) = delete;
  Pass& operator=(const Pass&) = delete;

  /// Coordinates from the computation's frame (scaled by 2^k) back to the user's.
  double unscale(double x) const { return k == 0 ? x : std::ldexp(x, -k); }

  Bounds user_bounds;                        ///< the domain in the user's frame
  Bounds bounds;                             ///< the domain in the computation's frame
  int k = 0;                                 ///< coordinates are scaled by 2^k (choose_scaling)
  std::vector<double> scaled;                ///< the scaled copy when k != 0
  std::span<const double> points;            ///< the computation's coordinates
  std::vector<std::uint8_t> in_box;          ///< per point: inside the domain
  std::vector<std::int32_t> ignored_outside; ///< points dropped (ignore_outside_points)
  /// VoronoiOptions::radii in the computation's frame (scaled by 2^k), or
  /// empty: none given, or all equal (the ordinary cells). exact.radii views it.
  std::span<const double> radii;
  std::vector<double> scaled_radii;          ///< radii's storage when k != 0
  /// Located points at exactly the coordinates of a lower id: (id, the
  /// group's lowest id), ascending. They are left out of the locator, so
  /// no cell meets them and none is built for them: a copy's bisectors are
  /// its group's, and the lowest id owns the cell (docs/design.md,
  /// "Duplicates leave the locator"). Callers report them.
  std::vector<std::pair<std::int32_t, std::int32_t>> duplicates;
  std::optional<kernels::BinLocator<D>> locator;  ///< the located points, duplicates left out
  std::optional<kernels::SharedKdTree<D>> tree;  ///< of the located points (CellBuilder)
  Buffer<std::int32_t> order;                ///< generators with cells wanted, bin order
  Buffer<std::uint32_t> slots;               ///< their slots in the locator
  kernels::ExactContext exact;
  std::vector<std::int32_t> grid;            ///< exact.grid's storage, when the input has one
  std::vector<kernels::Wall> walls;          ///< VoronoiOptions::walls in this frame (exact.walls)
  std::unique_ptr<const kernels::walls::Index> wall_index;  ///< where walls are many (exact.wall_index)
  engine::Generators<D> gens;
  engine::EngineOptions engine_options;

 private:
  // Sets `radii` from VoronoiOptions::radii, which voronoi() checked (check_radii).
  void set_radii(std::span<const double> given, std::size_t n, const Scaling& scaling);
};

/// Appends the pass's duplicates that a result reports: those that would
/// be generators (every one without labels, else label >= 0), whatever
/// their group's lowest id is.
template <int D>
void report_duplicates(const Pass<D>& pass, std::span<const std::int32_t> labels,
                       std::vector<std::pair<std::int32_t, std::int32_t>>& out) {
  for (const auto& d : pass.duplicates)
    if (labels.empty() || labels[static_cast<std::size_t>(d.first)] >= 0) out.push_back(d);
}

extern template struct Pass<2>;
extern template struct Pass<3>;

}  // namespace tessera::front
