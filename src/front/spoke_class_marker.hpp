// The first pass of VoronoiOptions::only_with_faces: which generators' cells
// have a spoke (a face) of some given classes. Nothing of the cells is kept
// but that bit, and the empty power cells.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "cell_geometry.hpp"
#include "tessera/cells.hpp"
#include "tessera/engine/classifier.hpp"
#include "tessera/kernels/cell_builder.hpp"

namespace tessera::front {

/// A compositor (engine/concepts.hpp) that marks each generator whose cell
/// has a spoke of one of `classes`, classified as the cells' mesh classifies
/// its faces (engine::RegionClassifier over the labels of the pass: a box
/// plane is domain_boundary, a point with label < 0 outside, one of another
/// label a region boundary). A cell's spokes are its face planes
/// (for_each_spoke), the mesh's faces one for one, box faces included.
template <class CellT>
class SpokeClassMarker {
 public:
  struct Batch {
    std::vector<std::int32_t> marked;  // generators with such a spoke, in batch order
    std::vector<std::int32_t> empty;   // generators whose power cell is empty
  };

  SpokeClassMarker(std::span<const std::int32_t> labels, SpokeClassSet classes, std::size_t n_points)
      : classify_(labels), classes_(classes), marked_((n_points + 63) / 64, 0) {}

  void add(Batch& b, std::int32_t gen, const kernels::BuildStatus& st, CellT& cell) {
    if (!st.has_cell) {
      // (A duplicate owns no cell either; Pass leaves them out of the order.)
      if (st.duplicate_of < 0) b.empty.push_back(gen);
      return;
    }
    bool any = false;
    for_each_spoke(cell, [&](std::int32_t id) { any |= (classes_ & spoke_class_bit(classify_(gen, id))) != 0; });
    if (any) b.marked.push_back(gen);
  }

  void finish(std::span<Batch> batches) {
    for (const Batch& b : batches) {
      for (const std::int32_t g : b.marked) marked_[static_cast<std::size_t>(g) >> 6] |= std::uint64_t{1} << (g & 63);
      count_ += b.marked.size();
      empty_.insert(empty_.end(), b.empty.begin(), b.empty.end());
    }
    std::sort(empty_.begin(), empty_.end());
  }

  /// Bit g set (marked[g / 64] >> g % 64) for each generator marked.
  std::vector<std::uint64_t>& marked() { return marked_; }
  std::size_t count() const { return count_; }
  /// Generators whose power cell is empty, ascending (Cells::empty_cells).
  std::vector<std::int32_t>& empty_cells() { return empty_; }

 private:
  engine::RegionClassifier classify_;
  SpokeClassSet classes_;
  std::vector<std::uint64_t> marked_;
  std::size_t count_ = 0;
  std::vector<std::int32_t> empty_;
};

}  // namespace tessera::front
