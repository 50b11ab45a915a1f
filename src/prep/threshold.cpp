// Threshold (include/tessera/prep/threshold.hpp): the intervals are checked,
// sorted by their lower end, and each value finds its candidate interval by
// binary search (the last one starting at or below it). Unlike VTK's
// vtkThresholdScalars (notes §6.26), overlapping intervals are refused rather
// than resolved by an order the user cannot see, and NaN maps to the
// background label.
#include "tessera/prep/threshold.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <string>

#include "tessera/cells.hpp"
#include "../message_text.hpp"

namespace tessera {
namespace {


std::string interval_text(const ThresholdInterval& iv) {
  return "[" + detail::number_text(iv.lo) + ", " + detail::number_text(iv.hi) + ") -> " + std::to_string(iv.label);
}

}  // namespace

std::vector<std::int32_t> threshold(std::span<const double> scalars, const ThresholdOptions& options) {
  if (options.intervals.empty()) throw InputError("threshold: no intervals given");
  std::vector<ThresholdInterval> sorted = options.intervals;
  for (const ThresholdInterval& iv : sorted) {
    if (std::isnan(iv.lo) || std::isnan(iv.hi))
      throw InputError("threshold: interval " + interval_text(iv) + " has a NaN end");
    if (!(iv.lo < iv.hi))
      throw InputError("threshold: interval " + interval_text(iv) + " is empty (it needs lo < hi)");
  }
  std::stable_sort(sorted.begin(), sorted.end(),
                   [](const ThresholdInterval& a, const ThresholdInterval& b) { return a.lo < b.lo; });
  for (std::size_t k = 1; k < sorted.size(); ++k)
    if (sorted[k].lo < sorted[k - 1].hi)
      throw InputError("threshold: intervals " + interval_text(sorted[k - 1]) + " and " +
                       interval_text(sorted[k]) + " overlap");

  std::vector<std::int32_t> labels(scalars.size(), options.background_label);
  for (std::size_t i = 0; i < scalars.size(); ++i) {
    const double v = scalars[i];
    if (std::isnan(v)) continue;
    // First interval starting above v; the one before it is the only candidate.
    auto it = std::upper_bound(sorted.begin(), sorted.end(), v,
                               [](double x, const ThresholdInterval& iv) { return x < iv.lo; });
    if (it == sorted.begin()) continue;
    --it;
    if (v < it->hi) labels[i] = it->label;
  }
  return labels;
}

}  // namespace tessera
