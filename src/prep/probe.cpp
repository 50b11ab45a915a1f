// probe: bilinear / trilinear interpolation of an image's voxel values at
// arbitrary points (see include/tessera/prep/probe.hpp).
//
// A point's continuous index along axis a is t = (p - origin) / spacing. It
// is inside when 0 <= t <= size - 1 on every axis, with a slack of 1e-9
// voxel plus the rounding of coordinates of the image's magnitude, so that a
// point computed as origin + (size - 1) * spacing (the far face) is inside
// despite rounding, also far from the origin of coordinates (a raster at
// northing 4.5e6 m with 0.1 m voxels: one ulp is 9e-9 voxel); t is then
// clamped into the box, and snapped to the nearest integer when within the
// same slack (so a voxel centre computed as origin + i * spacing hits voxel
// i exactly). Corners of zero weight are skipped, so a point at a voxel centre returns exactly
// that voxel's value (a NaN in a neighbouring voxel does not leak in), and a
// degenerate axis (size 1) needs no neighbour.
#include "tessera/prep/probe.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "../progress_chunks.hpp"
#include "tessera/cells.hpp"
#include "tessera/engine/thread_arena.hpp"

namespace tessera {

ProbeResult probe(const ScalarImage& image, std::span<const double> coords, const ProbeOptions& options) {
  const ImageGeometry& g = image.geometry;
  const int dim = g.dim;
  if (dim != 2 && dim != 3) throw InputError("probe: image dim must be 2 or 3, got " + std::to_string(dim));
  for (int a = 0; a < 3; ++a)
    if (g.size[static_cast<std::size_t>(a)] < 1) throw InputError("probe: the image is empty");
  if (image.values.size() != g.n_voxels())
    throw InputError("probe: the image has " + std::to_string(image.values.size()) + " values for " +
                     std::to_string(g.n_voxels()) + " voxels (mismatched sizes)");
  for (int a = 0; a < dim; ++a) {
    const double s = g.spacing[static_cast<std::size_t>(a)];
    if (!(s > 0) || !std::isfinite(s) || !std::isfinite(g.origin[static_cast<std::size_t>(a)]))
      throw InputError("probe: image spacing must be finite and > 0, origin finite");
  }
  if (coords.size() % static_cast<std::size_t>(dim) != 0)
    throw InputError("probe: " + std::to_string(coords.size()) + " coordinates is not a multiple of the image "
                     "dimension " + std::to_string(dim));
  const std::size_t n = coords.size() / static_cast<std::size_t>(dim);
  for (std::size_t k = 0; k < coords.size() && !options.keep_non_finite; ++k)
    if (std::isnan(coords[k]))
      throw InputError("probe: point " + std::to_string(k / static_cast<std::size_t>(dim)) +
                       " has a NaN coordinate (keep_non_finite counts such points as outside)");

  ProbeResult res;
  res.values.assign(n, options.outside_value);
  res.valid.assign(n, 0);
  // Per axis: 1e-9 voxel, plus what computing origin + i * spacing and then
  // (p - origin) / spacing may round away: a few ulps of the largest
  // coordinate in the image, in voxels.
  double slack[3] = {0, 0, 0};
  for (int a = 0; a < dim; ++a) {
    const auto au = static_cast<std::size_t>(a);
    const double far = g.origin[au] + static_cast<double>(g.size[au] - 1) * g.spacing[au];
    const double magnitude = std::max(std::fabs(g.origin[au]), std::fabs(far));
    slack[a] = 1e-9 + 8 * 0x1p-53 * magnitude / g.spacing[au];
  }
  const double* vals = image.values.data();

  auto one = [&](std::size_t p) {
    std::int64_t i0[3] = {0, 0, 0};
    double f[3] = {0, 0, 0};
    for (int a = 0; a < dim; ++a) {
      const std::size_t au = static_cast<std::size_t>(a);
      const double hi = static_cast<double>(g.size[au] - 1);
      double t = (coords[p * static_cast<std::size_t>(dim) + au] - g.origin[au]) / g.spacing[au];
      if (!(t >= -slack[a] && t <= hi + slack[a])) return;  // outside (also +-inf, and NaN)
      t = std::clamp(t, 0.0, hi);
      // Snap to a voxel index within the slack: (p - origin) / spacing at a
      // voxel centre is off by rounding, and exactness there matters more.
      if (const double r = std::round(t); std::abs(t - r) <= slack[a]) t = r;
      std::int64_t i = static_cast<std::int64_t>(std::floor(t));
      if (i > g.size[au] - 2) i = std::max<std::int64_t>(0, g.size[au] - 2);
      i0[a] = i;
      f[a] = t - static_cast<double>(i);  // in [0, 1]; 0 on a degenerate axis
    }
    double v = 0;
    const int corners = 1 << dim;
    for (int c = 0; c < corners; ++c) {
      double w = 1;
      std::int64_t idx[3] = {i0[0], i0[1], i0[2]};
      for (int a = 0; a < dim; ++a) {
        const bool up = (c >> a) & 1;
        w *= up ? f[a] : 1.0 - f[a];
        idx[a] += up;
      }
      if (w == 0) continue;
      v += w * vals[g.index(idx[0], idx[1], idx[2])];
    }
    res.values[p] = v;
    res.valid[p] = 1;
  };

  constexpr std::size_t kGrain = 4096;
  const int threads = resolve_threads(options.threads);
  detail::parallel_in_progress_chunks(
      threads, n, kGrain, options.progress,
      [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t p = r.begin(); p != r.end(); ++p) one(p);
      },
      std::size_t{1} << 18);
  return res;
}

}  // namespace tessera
