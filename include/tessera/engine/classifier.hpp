// The default spoke classifier: by region label (label < 0 = outside).
#pragma once

#include <cstdint>
#include <span>

#include "tessera/cells.hpp"

namespace tessera::engine {

class RegionClassifier {
 public:
  explicit RegionClassifier(std::span<const std::int32_t> labels) : labels_(labels) {}
  SpokeClass operator()(std::int32_t gen, std::int32_t neighbor) const {
    if (neighbor < 0) return SpokeClass::domain_boundary;
    if (labels_.empty()) return SpokeClass::same_region;
    std::int32_t ln = labels_[static_cast<std::size_t>(neighbor)];
    if (ln < 0) return SpokeClass::outside;
    return ln == labels_[static_cast<std::size_t>(gen)] ? SpokeClass::same_region
                                                         : SpokeClass::region_boundary;
  }

 private:
  std::span<const std::int32_t> labels_;
};

}  // namespace tessera::engine
