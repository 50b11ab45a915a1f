// Front end: a point set with an optional region label per point — what the
// point-preparation tools (sampler, fill, joggle, threshold) produce and the
// tessellations consume.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace tessera {

struct LabelledPoints {
  int dim = 3;
  std::vector<double> coords;         ///< size() * dim, row-major
  std::vector<std::int32_t> labels;   ///< empty, or one label per point

  std::size_t size() const { return dim > 0 ? coords.size() / static_cast<std::size_t>(dim) : 0; }
};

}  // namespace tessera
