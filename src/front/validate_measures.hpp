// validate()'s exact check of sampled cells' measures (validate_measures.cpp).
#pragma once

#include <span>
#include <vector>

#include "tessera/cells.hpp"

namespace tessera::front {

/// Compares the volume and centroid of a sample of cells with their exact
/// values, computed in rationals from `points` (n_points x dim) and the
/// merged vertices' keys, and the cells' merged vertices with their exact
/// positions, and records the outcome in `r` (measures_checked,
/// measure_rel_error, measure_worst, vertex_rel_error, vertex_worst; a
/// message and ok = false for each cell past measure_tolerance).
/// `radius2`: each cell's squared radius (its farthest vertex from its
/// generator), which ranks the cells by elongation and scales the
/// tolerances of the centroid and the corners. Needs the mesh, every vertex used by
/// exactly the cells of its key; the caller checks that volumes are
/// representable.
///
/// Why: the volume sum cannot see a cell's error when the domain is far
/// larger than the cells it would show in (one point far off a row of
/// points: stop 64's strips were off by up to 14%, their sum still within
/// 1e-9 of the domain's), nor errors that cancel between neighbours.
/// `radii`: power cells' radii (Cells::power), else empty.
void check_measures(const Cells& c, std::span<const double> points, std::span<const double> radii,
                    const std::vector<double>& radius2, ValidationReport& r);

}  // namespace tessera::front
