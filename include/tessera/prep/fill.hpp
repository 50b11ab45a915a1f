// Point preparation: fill a point cloud's empty space with background points
// (label < 0), so outside regions carve concave shapes out of the
// tessellation and the cells' neighbour searches stay short.
//
// The bounding region (the given bounds, else the input bounding box) is cut
// into cubic-ish bins; a bin holding no input point is "empty".
//   uniform:  one point per empty bin, at its centre (joggled by `joggle`).
//   adaptive: the bin occupancy becomes a label image (occupied / empty) that
//             the labelled-image sampler samples for background points only:
//             dense next to the data, sparse far from it. Points lie at bin
//             centres in both strategies.
// The input points come first in the output, unchanged and with their labels
// (or `in_label` when the input has none); the added points follow.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <span>

#include "tessera/cells.hpp"
#include "tessera/labelled_points.hpp"

namespace tessera {

enum class FillStrategy : std::uint8_t { uniform = 0, adaptive = 1 };

struct FillOptions {
  FillStrategy strategy = FillStrategy::uniform;
  std::int32_t background_label = -1;  ///< label of added points, must be < 0
  std::int32_t in_label = 0;            ///< label of input points when none are given
  /// Average input points per bin, which sets the bin size (> 0).
  double points_per_bin = 2.0;
  std::optional<Bounds> bounds;         ///< region to fill; must contain every input point
  /// Joggle of added points as a fraction of the bin edge (0 = exact bin
  /// centres; at most 0.5). Deterministic from `seed`.
  double joggle = 0.0;
  std::uint64_t seed = 0;
  int threads = 0;
  /// Points with a NaN or infinite coordinate (an organized cloud's missing
  /// returns) are kept in the output, in place with their labels, instead of
  /// refused; they mark no bin and are not held to the bounds. The bounding
  /// box is then the finite points', of which there must be one.
  bool keep_non_finite = false;
  /// As VoronoiOptions::progress: called between chunks of points (its
  /// fraction runs from 0 to 1 again for each pass: over the points, then
  /// over the added ones or the adaptive strategy's bins), it may
  /// throw Cancelled to stop.
  std::function<void(double)> progress;
};

/// Throws InputError on empty input, a NaN or infinite coordinate (unless
/// keep_non_finite), labels of the wrong length,
/// background_label >= 0, points outside the given bounds, bad options.
LabelledPoints fill(std::span<const double> coords, int dim, std::span<const std::int32_t> labels,
                    const FillOptions& options = {});

}  // namespace tessera
