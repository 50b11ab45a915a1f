// Point preparation: probe — sample an image's scalars at arbitrary points by
// linear interpolation (bilinear in 2D, trilinear in 3D) between voxel
// centres, so a field given on a grid can be thresholded into labels at
// scattered points.
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <span>
#include <vector>

#include "tessera/image.hpp"

namespace tessera {

struct ProbeOptions {
  /// Value for points outside the image's voxel-centre box (farther than
  /// 1e-9 voxel spacings from it, plus a few ulps of the image's largest
  /// coordinate: nearer, a point takes the face's value).
  double outside_value = std::numeric_limits<double>::quiet_NaN();
  int threads = 0;
  /// A point with a NaN coordinate (an organized cloud's missing return) is
  /// outside (outside_value, not valid) instead of refused. An infinite
  /// coordinate is outside either way.
  bool keep_non_finite = false;
  /// As VoronoiOptions::progress: called between chunks of points, it may
  /// throw Cancelled to stop.
  std::function<void(double)> progress;
};

struct ProbeResult {
  std::vector<double> values;       ///< one per point
  std::vector<std::uint8_t> valid;  ///< 1 where the point lies in the image box
};

/// `coords` has n * image.geometry.dim entries. A point exactly on the box's
/// far face is inside. Throws InputError on NaN coordinates (unless
/// keep_non_finite) or an empty image.
ProbeResult probe(const ScalarImage& image, std::span<const double> coords, const ProbeOptions& options = {});

}  // namespace tessera
