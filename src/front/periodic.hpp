// Periodic boxes (VoronoiOptions::periodic): the cells of points in a box
// that repeats along some axes, computed as the cells of the points among
// their images.
//
// The images are ordinary input to the pass: each point is followed, in the
// augmented input, by its images within a layer of width w around the box
// (PeriodicImages), and the images are outside points (label < 0: they clip,
// own no cell). The cells of the points are then their periodic cells as
// soon as each one's security sphere (the radius beyond which no point can
// clip it) lies within that layer; the driver (cells.cpp) checks it and
// widens the layer once where it does not.
//
// Triclinic boxes (VoronoiOptions::tilt) repeat by the lattice vectors
// a = (Lx, 0, 0), b = (xy, Ly, 0), c = (xz, yz, Lz). The same holds with
// "box length" read as "lattice vector" and the layer measured across the
// parallelepiped's faces: an image is in the layer when its fractional
// coordinate along each periodic lattice vector lies within w / h of
// [0, 1] (h: the parallelepiped's height across that vector's faces). The
// fractional coordinates are computed in floating point, so the layer takes
// a slack of `fraction_slack` either side and the check of the spheres adds
// it: an image the layer needs is never left out by a rounding.
//
// Exactness. Two things make the cells agree across the box's faces, ties
// included, as they agree inside it:
// * every image is exact: the box and the points' coordinates along a
//   periodic axis are rounded to a grid of doubles on which x + k L is a
//   double for every shift k used (PeriodicInput), so an image sits exactly
//   a box length from its point and every predicate on translated points
//   answers as on the points;
// * the symbolic perturbation, which orders points by id, orders images as
//   translation does not change: the augmented input lists each point's
//   images together, in lexicographic order of their shift vectors, with the
//   point itself among them at shift 0. Ordering by (point, shift)
//   lexicographically is invariant under a common translation of the shifts,
//   so a vertex seen from cell i (with an image of j) and from cell j (with
//   an image of i) is the same perturbed configuration.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "tessera/cells.hpp"
#include "tessera/delaunay.hpp"

namespace tessera::front {

/// The most periods an image lies from its point (Cells::neighbor_shifts are int8).
inline constexpr int max_periodic_shift = 127;

/// The points as the periodic computation takes them.
struct PeriodicInput {
  int dim = 3;
  std::array<bool, 3> periodic{};
  Bounds box;                          ///< the user's box, rounded to the grid along periodic axes
  std::array<double, 3> length{};      ///< box length along each axis (exact on periodic ones)
  /// Triclinic: VoronoiOptions::tilt rounded to the grid (xy and xz to x's,
  /// yz to y's); all zero for an orthogonal box.
  std::array<double, 3> tilt{};
  bool sheared = false;                ///< some tilt is not zero
  /// lattice[i]: the box's edge vector along axis i (b = (xy, Ly, 0), ...;
  /// length[i] e_i along a wall, and (0, 0, 1) for 2D's z).
  std::array<std::array<double, 3>, 3> lattice{};
  /// The parallelepiped's height across the faces that lattice[i] leaves
  /// (its volume over the area of the other two): length[i] when orthogonal.
  std::array<double, 3> height{};
  /// The most box lengths (lattice vectors) an image may lie from its point along each
  /// periodic axis: enough for any cell (a priori_reach), and the grid is
  /// chosen so that all those images are exact.
  std::array<int, 3> max_shift{};
  std::array<double, 3> grid{};        ///< the rounding grid's step along each periodic axis (a power of two)
  /// The widest layer any cell needs along each periodic axis (its
  /// security sphere's a-priori reach; max_shift box lengths at most).
  std::array<double, 3> reach_cap{};
  /// reach_cap is below the a-priori bound, held to max_periodic_shift
  /// periods: a cell that reaches past it is an error, not final.
  std::array<bool, 3> reach_clamped{};
  std::vector<double> points;          ///< n * dim: wrapped into the box and rounded (rows of dropped points as given)
  std::vector<std::uint8_t> takes_part;  ///< per point
  std::vector<std::int32_t> ignored;   ///< points set aside (non-finite, or outside a wall with ignore_outside)
  std::size_t n = 0;
};

/// Checks the options (bounds given, periodic axes within dim), sets aside
/// non-finite points and points outside the walls (with
/// ignore_outside_points; otherwise an InputError), wraps and rounds the rest.
PeriodicInput periodic_input(std::span<const double> points, int dim, std::span<const std::int32_t> labels,
                             const VoronoiOptions& options);

/// Slack of a triclinic layer's test, in fractional coordinates (periodic.hpp).
inline constexpr double fraction_slack = 0x1p-24;

/// p's fractional coordinates along the lattice vectors (PeriodicInput::lattice),
/// from the box's lower corner: in [0, 1) inside the box, up to rounding.
void fractional(const PeriodicInput& in, const double* p, double f[3]);

/// The augmented input for a layer of widths `width` (per periodic axis;
/// across the faces of a triclinic box).
struct PeriodicImages {
  std::vector<double> points;          ///< augmented, m * dim
  std::vector<std::int32_t> labels;    ///< the point's label (0 without labels) at shift 0; -1 for images
  std::vector<std::int32_t> base;      ///< per augmented point: the input point it is an image of
  std::vector<std::int8_t> shift;      ///< per augmented point: dim shifts, in box lengths
  std::vector<std::int32_t> original;  ///< per input point: its augmented id at shift 0 (-1: takes no part)
  Bounds domain;                       ///< the box widened by the layer along periodic axes (its bounding box, triclinic)
  std::array<double, 3> width{};       ///< the layer's widths (what Cells::image_reach reports)
  std::size_t images = 0;              ///< augmented points that are images
};

/// `threads`: the computation's (resolved) thread count; the result is the
/// same for any.
PeriodicImages periodic_images(const PeriodicInput& in, std::span<const std::int32_t> labels,
                               const std::array<double, 3>& width, int threads);

/// The layer's initial widths: four mean spacings of the points, at most
/// what any cell needs.
std::array<double, 3> initial_image_reach(const PeriodicInput& in);

/// The widths the cells need (each periodic axis: how far beyond the box
/// the farthest security sphere reaches; infinite where one is unbounded),
/// from `reach` (per augmented point: the cell's security radius, 0 without
/// a cell). A computation whose widths are at least these, or at an
/// unclamped reach_cap, is final.
std::array<double, 3> needed_image_reach(const PeriodicInput& in, const PeriodicImages& im,
                                         std::span<const double> reach);

/// Runs `run(images, reach)`, a pass over the augmented input that records
/// each built cell's security radius (input units) in `reach` (sized for the
/// augmented points, zeros), on a layer of images that starts at
/// initial_image_reach and is widened once to what the cells asked for
/// (which suffices: more images never grow a cell). Returns {its result,
/// the images}. InputError where a cell reaches past 127 periods.
template <class Run>
auto run_in_final_layer(const PeriodicInput& in, std::span<const std::int32_t> labels, int threads, Run&& run) {
  std::array<double, 3> width = initial_image_reach(in);
  for (int round = 0;; ++round) {
    PeriodicImages im = periodic_images(in, labels, width, threads);
    std::vector<double> reach(im.base.size(), 0.0);
    auto result = run(im, reach);
    const std::array<double, 3> need = needed_image_reach(in, im, reach);
    bool enough = true;
    for (std::size_t a = 0; a < 3; ++a) {
      if (!in.periodic[a] || need[a] <= width[a]) continue;
      if (width[a] >= in.reach_cap[a]) {
        // At the a-priori bound every cell is final; held below it, some
        // cell reaches farther than the images go.
        if (in.reach_clamped[a])
          throw InputError(std::string("periodic along ") + "xyz"[a] + ": some cell reaches past " +
                           std::to_string(max_periodic_shift) +
                           " box lengths (a few points in a box far longer along its walls than its period, or in a thin "
                           "sheared one)");
        continue;
      }
      enough = false;
      width[a] = std::min(need[a] * 1.0625, in.reach_cap[a]);
    }
    if (enough) return std::pair{std::move(result), std::move(im)};
    if (round == 2)  // the second layer covers what the first one's cells asked for
      throw std::logic_error("tessera: periodic cells still reach past their images' layer after widening it");
  }
}

/// Augmented ids (>= 0) mapped in place to the points they are images of,
/// each one's dim shifts written to `shifts` (sized ids.size() * dim), on
/// `threads`. Augmented ids ascend by (point, shift), so ascending ids stay
/// ascending by (point, shift).
void to_points(const PeriodicImages& im, int dim, std::span<std::int32_t> ids, std::span<std::int8_t> shifts,
               int threads);

/// What a periodic result (Cells, Delaunay) says of its box and points: the
/// dimension, point count, box as rounded, periodic axes, tilts, the points
/// as wrapped, and those set aside.
template <class Result>
void describe_box(const PeriodicInput& in, Result& out) {
  out.dim = in.dim;
  out.n_points = in.n;
  out.bounds = in.box;
  out.periodic = in.periodic;
  out.tilt = in.tilt;
  out.periodic_points = in.points;
  out.ignored_outside_bounds = in.ignored;
}

/// A pass's (duplicate, owner) pairs as point ids, sorted. The pass reports
/// generators only, so not their images' copies; an owner is the lowest id
/// of its group, at shift 0.
std::vector<std::pair<std::int32_t, std::int32_t>> duplicates_as_points(
    const PeriodicImages& im, std::span<const std::pair<std::int32_t, std::int32_t>> duplicates);

/// The cells of the augmented input, as the cells of the input points: ids
/// and keys mapped back, neighbour shifts, face classes by the user's labels.
Cells periodic_cells(Cells&& augmented, const PeriodicInput& in, const PeriodicImages& im,
                     std::span<const std::int32_t> labels, int threads);

/// A regular triangulation's (Delaunay::power) hidden points: those in no
/// simplex, neither duplicates nor set aside (Delaunay::hidden, ascending);
/// nothing without radii (delaunay.cpp). Call once the simplices are final.
void list_hidden(Delaunay& dt);

/// The simplices the cells of an augmented input's points (label >= 0)
/// find, images (label < 0) among their vertices: each from its lowest id's
/// cell, oriented, rows ascending (delaunay.cpp). `reach` as for
/// run_in_final_layer.
Delaunay delaunay_of_images(std::span<const double> points, int dim, std::span<const std::int32_t> labels,
                            const VoronoiOptions& options, std::vector<double>& reach);

/// The Delaunay triangulation of a periodic box (every axis periodic), from
/// the points' cells among their images (periodic_delaunay.cpp). Throws
/// InputError for walls and outside points.
Delaunay periodic_delaunay(std::span<const double> points, int dim, std::span<const std::int32_t> labels,
                           const DelaunayOptions& options);

/// validate() of a periodic triangulation: orientation with the shifts
/// applied, every facet (up to translation) in exactly two simplices with
/// apexes on opposite sides and locally Delaunay, every point a vertex,
/// volumes summing to the box's. A regular triangulation (dt.power) is
/// checked with `radii` (validate() checked them): power spheres, and each
/// hidden point under a translate of a simplex it is not in conflict with.
DelaunayReport validate_periodic(const Delaunay& dt, std::span<const double> radii);

}  // namespace tessera::front
