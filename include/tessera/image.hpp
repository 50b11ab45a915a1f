// Front end: regular 2D/3D images — label volumes from segmentation, scalar
// fields to probe.
//
// Layout. Voxel (i, j, k) is stored at i + size[0] * (j + size[1] * k): x
// varies fastest, as in VTK, NRRD and MetaImage. A C-ordered NumPy array of
// shape (nz, ny, nx) — or (ny, nx) in 2D — has exactly this layout.
//
// Geometry. Voxel (i, j, k) sits at origin + (i, j, k) * spacing (voxel
// centres; no direction matrix: images are axis-aligned). A 2D image has
// dim = 2 and size[2] = 1; its third spacing/origin entries are ignored.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace tessera {

struct ImageGeometry {
  int dim = 3;                                  ///< 2 or 3
  std::array<std::int64_t, 3> size{1, 1, 1};    ///< voxels along x, y, z (all >= 1)
  std::array<double, 3> spacing{1, 1, 1};       ///< > 0
  std::array<double, 3> origin{0, 0, 0};        ///< position of voxel (0, 0, 0)

  std::size_t n_voxels() const {
    return static_cast<std::size_t>(size[0]) * static_cast<std::size_t>(size[1]) *
           static_cast<std::size_t>(size[2]);
  }
  std::size_t index(std::int64_t i, std::int64_t j, std::int64_t k = 0) const {
    return static_cast<std::size_t>(i + size[0] * (j + size[1] * k));
  }
};

/// An integer label per voxel (a segmentation). Labels < 0 are background.
struct LabelImage {
  ImageGeometry geometry;
  std::vector<std::int32_t> labels;  ///< n_voxels, x fastest
};

/// A scalar per voxel (intensity, distance field, ...).
struct ScalarImage {
  ImageGeometry geometry;
  std::vector<double> values;  ///< n_voxels, x fastest
};

}  // namespace tessera
