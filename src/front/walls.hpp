// Walls (VoronoiOptions::walls) as the kernels take them: checked, each
// scaled exactly to a normal whose largest component is in [1, 2), and put
// in the computation's frame; and the exact test of a point against them.
#pragma once

#include <memory>
#include <span>
#include <vector>

#include "tessera/cells.hpp"
#include "tessera/kernels/exact_predicates.hpp"
#include "tessera/kernels/wall_index.hpp"

namespace tessera::front {

/// The walls in the computation's frame (coordinates scaled by 2^k: the
/// offsets are scaled alike). Throws InputError naming the wall where a
/// normal is not finite or is zero (in 2D: or normal[2] != 0), an offset is
/// not finite, a scaled offset is not exact (beyond double's range), or
/// there are more than kernels::max_walls.
std::vector<kernels::Wall> kernel_walls(const std::vector<Wall>& given, int dim, int k);

/// Which points lie outside walls, decided exactly: the float n.p - d where
/// its rounding, bounded once for all points of the largest magnitude given,
/// cannot change its sign, else in rationals.
class WallTest {
 public:
  /// For points whose coordinates are at most `largest` in magnitude; with
  /// `index`, only the walls it finds that a point may lie outside of are
  /// tested.
  WallTest(std::span<const kernels::Wall> walls, int dim, double largest,
           const kernels::walls::Index* index = nullptr);
  /// The first wall that point p (dim coordinates, at most `largest` each)
  /// lies strictly outside of (n.p > d), or -1.
  int outside(const double* p) const;

 private:
  std::span<const kernels::Wall> walls_;
  int dim_;
  std::vector<double> error_;  // per wall: a bound on the float d - n.p's error
  const kernels::walls::Index* index_;
  int side(std::size_t k, const double* p) const;
};

/// An index over `walls` (offsets from the box's centre, computation
/// frame), or none where they are few (below 16 walls a test of each is as
/// quick).
std::unique_ptr<const kernels::walls::Index> make_wall_index(std::span<const kernels::Wall> walls, int dim,
                                                             const Bounds& box);

/// The largest magnitude among the values (for WallTest).
double largest_magnitude(std::span<const double> values);

/// The volume (area in 2D) of the domain: `box` inside the walls (as
/// given: the user's frame), 0 where they leave nothing; in double
/// precision, by the cell kernels (a cell with no neighbours, cut by the
/// walls; past 256 walls, sub-boxes of the box cut so on `threads`
/// threads, 0: TESSERA_NUM_THREADS or all) and their measure. For
/// validate(), the CLI's summary and Lloyd.
double domain_volume(const Bounds& box, const std::vector<Wall>& walls, int dim, int threads = 0);

}  // namespace tessera::front
