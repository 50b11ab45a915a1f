// Point preparation: sample a label image into points concentrated near the
// label boundaries (the labelled-image point sampler).
//
// 1. Boundary distance. A voxel is a boundary voxel when one of its 2D/3D
//    face neighbours (4 / 6) has a different label and at least one of the
//    two labels is selected; boundary voxels have distance 1. Every other
//    voxel gets 1 + the exact city-block (L1) distance, in voxels, to the
//    nearest boundary voxel (computed separably, one 1D pass per axis, so
//    unlike VTK's sweep no boundary is missed along an earlier axis). Images
//    without any boundary have every distance = the largest representable.
// 2. Schedule. A voxel is a candidate when its distance d is
//    exponential: a power of `step` (1, N, N^2, ...; integer test), or
//    linear:      1 or a multiple of `step`.
// 3. Randomise (on by default): a candidate is kept with probability
//    clamp(1/d, probability_range), from a generator seeded by (seed, voxel
//    index) — the output does not depend on the thread count.
// 4. Output. Points at voxel centres (origin + index * spacing), optionally
//    joggled, in voxel-index order, with their labels. Voxels whose label is
//    not selected are "background" points; with `background_label` set their
//    label is replaced by it (it must be < 0 so they become outside points).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "tessera/image.hpp"
#include "tessera/labelled_points.hpp"

namespace tessera {

enum class SampleSchedule : std::uint8_t { exponential = 0, linear = 1 };
enum class SampleOutput : std::uint8_t {
  all = 0,         ///< selected and background voxels
  labelled = 1,    ///< selected labels only
  background = 2,  ///< the others only
};

struct SampleImageOptions {
  /// Selected labels; empty = every label >= 0.
  std::vector<std::int32_t> select;
  SampleSchedule schedule = SampleSchedule::exponential;
  int step = 2;                        ///< N of the schedule, >= 2 (exponential) / >= 1 (linear)
  bool randomize = true;
  std::array<double, 2> probability_range{0.0, 1.0};
  std::uint64_t seed = 0;
  SampleOutput output = SampleOutput::all;
  /// Label given to background (not selected) voxels' points; must be < 0.
  /// Unset: they keep their own label (which may be >= 0 if unselected).
  std::optional<std::int32_t> background_label;
  /// Joggle radius as a fraction of the smallest voxel spacing (0 = off).
  /// Capped at 0.5 so points never leave their voxel. Seeded per voxel.
  double joggle = 0.0;
  int threads = 0;                     ///< 0: TESSERA_NUM_THREADS, else all cores
  /// As VoronoiOptions::progress: called between the passes over the image
  /// (and chunks of them), it may throw Cancelled to stop.
  std::function<void(double)> progress;
};

/// Per-voxel boundary distance of step 1 (exposed for tests and tools).
/// Throws InputError for an empty selection that matches no voxel.
std::vector<std::int32_t> boundary_distance(const LabelImage& image, const std::vector<std::int32_t>& select);

/// Sample points from a label image. Throws InputError on an empty image,
/// labels in `select` that occur in no voxel ("unknown label"), a bad step or
/// probability range, or a background_label >= 0.
LabelledPoints sample_image(const LabelImage& image, const SampleImageOptions& options = {});

}  // namespace tessera
