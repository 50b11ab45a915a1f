// Crossing triangles of a smoothed surface net: the check behind the
// smoothing's untangling rounds (net_smoothing.cpp). Private to the library.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "tessera/buffer.hpp"

namespace tessera::front {

/// The pairs (i, j), i < j, ascending, of triangles that cross: they share a
/// point interior to one of them (so a triangle passing through another,
/// touching its interior with a corner or an edge, or overlapping it in one
/// plane), decided by exact orientation signs of the doubles
/// (kernels::orientation). Triangles that meet only on their boundaries (at
/// shared or coincident corners, along an edge) do not cross: a net before
/// smoothing, whose faces meet along edges and at distinct vertices that
/// coincide on exact lattices, has none. A triangle of zero area (collinear
/// corners) has no interior of its own, but crosses one whose interior it
/// meets. `xyz` holds 3
/// coordinates per vertex, `corners` 3 vertex indices per triangle.
/// Candidates come from a bounding volume hierarchy over the triangles'
/// boxes; the result does not depend on the thread count. With `changed` (one flag
/// per triangle) only pairs with a changed triangle are tested: the others
/// were found apart before. With `settled` (one flag per triangle) pairs of
/// two settled triangles are not tested: the caller takes them as they are.
/// The test crossing_triangles applies to one pair: corner positions `a`,
/// `b` and their vertex ids `ca`, `cb` (3 each).
bool triangle_pair_crosses(const double* const a[3], const std::int32_t* ca, const double* const b[3],
                           const std::int32_t* cb);

/// The same decision by exact signs alone, without triangle_pair_crosses's
/// float filters and shortcuts by vertex id (which tests compare it with):
/// `flat_a`, `flat_b` may tell that a triangle is known to have no interior.
bool triangle_pair_crosses_exactly(const double* const a[3], const double* const b[3], bool flat_a = false,
                                   bool flat_b = false);

std::vector<std::pair<std::size_t, std::size_t>> crossing_triangles(std::span<const double> xyz,
                                                                     std::span<const std::int32_t> corners,
                                                                     std::span<const std::uint8_t> changed = {},
                                                                     std::span<const std::uint8_t> settled = {});

/// crossing_triangles with its arrays kept from call to call: the rounds of
/// one untangling check nets of millions of triangles, whose arrays (~90
/// bytes per triangle) would otherwise be mapped and faulted in afresh each
/// time. A call with `changed` after one with as many triangles takes the
/// others to be as they were then (the same corners, where they were): it
/// keeps their boxes and the tree, refit to the changed boxes.
class CrossingCheck {
 public:
  std::vector<std::pair<std::size_t, std::size_t>> operator()(std::span<const double> xyz,
                                                              std::span<const std::int32_t> corners,
                                                              std::span<const std::uint8_t> changed = {},
                                                              std::span<const std::uint8_t> settled = {});

 private:
  using Box = std::array<double, 6>;  // lowest x, y, z, then highest
  /// A node of the bounding volume hierarchy over the triangles' boxes.
  struct Node {
    double box[6];
    std::uint32_t begin, end;  // its triangles: order_[begin, end)
    std::uint32_t right;       // its right child (the left is the next node); 0: a leaf
    std::uint32_t changed;     // holds a changed triangle (or all count as changed)
  };
  Buffer<Node> nodes_;
  Buffer<std::uint32_t> order_;  // the triangles in leaf order
  Buffer<Box> box_;              // their boxes, in that order
  struct Item {
    double centre[3];  // of its box
    std::uint32_t t;
  };
  void build(std::size_t node, std::uint32_t b, std::uint32_t e, Item* items);
  void fit(std::span<const std::uint8_t> changed);
};

}  // namespace tessera::front
