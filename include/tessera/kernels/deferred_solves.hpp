// The vertices of a 2D cell whose exact solve was deferred (Tile::
// solve_deferred, filter::deferred_vertex_condition), by the key of their
// lines: the tile's slots move as clips fill holes, the lines do not. (The
// hull flags its vertices instead, in what was padding; the tile's vertex
// has none left.)
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace tessera::kernels {

class DeferredSolves {
 public:
  void clear() { keys_.clear(); }
  bool empty() const { return keys_.empty(); }
  /// A deferred vertex's key (never 0: a vertex's planes are distinct).
  void add(std::uint64_t key) { keys_.push_back(key); }

  /// Build the lookup once the cell is built: an open-addressing set at
  /// most half full (a sorted list and a binary search per vertex, in the
  /// hull, cost a helix's assembled cells 12% of their time).
  void seal() {
    const std::size_t cap = std::bit_ceil(2 * keys_.size() + 2);
    table_.assign(cap, 0);
    shift_ = 64 - std::countr_zero(cap);
    for (const std::uint64_t k : keys_) {
      std::size_t h = slot(k);
      while (table_[h] != 0 && table_[h] != k) h = (h + 1) & (cap - 1);
      table_[h] = k;
    }
  }
  /// Whether `key` was deferred (after seal).
  bool contains(std::uint64_t key) const {
    for (std::size_t h = slot(key);; h = (h + 1) & (table_.size() - 1)) {
      if (table_[h] == key) return true;
      if (table_[h] == 0) return false;
    }
  }

 private:
  std::size_t slot(std::uint64_t k) const { return static_cast<std::size_t>((k * 0x9E3779B97F4A7C15ull) >> shift_); }
  std::vector<std::uint64_t> keys_, table_;
  int shift_ = 63;
};

}  // namespace tessera::kernels
