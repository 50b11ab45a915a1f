// Point preparation: joggle — a small deterministic random displacement that
// breaks the exact ties of lattice-like input (the term is Qhull's).
//
// Tessera does not need joggling for correctness (every tie is decided
// exactly); it is offered for users who want general-position output.
// Each point's displacement depends only on (seed, point id), so the result
// is the same for any thread count and for any subset of points moved.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

namespace tessera {

enum class JoggleMode : std::uint8_t {
  ball = 0,  ///< uniform in the ball (3D) / disk (2D) of the radius
  xy = 1,    ///< uniform in the disk of that radius in the xy plane (3D input)
  xz = 2,
  yz = 3,
};

struct JoggleOptions {
  double radius = 1e-4;       ///< fraction of the bounding-box diagonal, or absolute
  bool absolute = false;
  JoggleMode mode = JoggleMode::ball;
  std::uint64_t seed = 0;
  int threads = 0;            ///< 0: TESSERA_NUM_THREADS, else all cores
  /// Points with a NaN or infinite coordinate (an organized cloud's missing
  /// returns) are copied through unmoved instead of refused, keeping every
  /// point's id; the relative radius then measures the finite points' box.
  /// VoronoiOptions::ignore_outside_points sets such points aside later.
  bool keep_non_finite = false;
  /// As VoronoiOptions::progress: called between chunks of points, it may
  /// throw Cancelled to stop.
  std::function<void(double)> progress;
};

/// Joggled copy of `coords` (n * dim, dim 2 or 3). With a non-empty `mask`
/// (one byte per point) only points with mask != 0 move; the others are
/// copied through bit for bit. Throws InputError on a negative / non-finite
/// radius, a plane mode with dim 2, a mask of the wrong length, or a NaN or
/// infinite coordinate (unless options.keep_non_finite).
std::vector<double> joggle(std::span<const double> coords, int dim, const JoggleOptions& options = {},
                           std::span<const std::uint8_t> mask = {});

}  // namespace tessera
