// Point preparation: threshold — a scalar per point becomes a region label by
// half-open intervals [lo, hi), the rest get the background label.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace tessera {

struct ThresholdInterval {
  double lo = 0, hi = 0;   ///< [lo, hi); lo < hi (hi may be +inf, lo -inf)
  std::int32_t label = 0;
};

struct ThresholdOptions {
  std::vector<ThresholdInterval> intervals;
  std::int32_t background_label = -1;  ///< for values in no interval (and NaN)
};

/// One label per scalar. Throws InputError on no intervals, an interval with
/// lo >= hi or NaN ends, or overlapping intervals (the answer would depend on
/// their order).
std::vector<std::int32_t> threshold(std::span<const double> scalars, const ThresholdOptions& options);

}  // namespace tessera
