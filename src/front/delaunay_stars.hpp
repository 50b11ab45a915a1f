// Every point's Delaunay star from the triangulation by incremental
// insertion: the cells of inputs where the meshless search costs far more
// than the cells it finds (points nearly on a sphere, surface samples, dense
// clusters; in 2D every input without ties: docs/design.md, "Cells from
// Delaunay neighbours", "Cells assembled from their stars").
//
// The cells pass decides a clip by the exact clip predicate with symbolic
// perturbation; insertion decides conflicts by the same predicate in
// in-sphere form (kernels::in_sphere), so its simplices are the cells
// pass's vertices, ties included. A point clips a cell exactly when it
// shares a simplex with the cell's generator, and the cell's vertices are
// the circumcentres of the generator's simplices: a cell is its star's dual
// (CellBuilder::build_from_star).
#pragma once

#include <functional>
#include <optional>

#include "pass.hpp"
#include "tessera/engine/tessellate.hpp"

namespace tessera::front {

/// The Delaunay stars of the pass's located points (2D or 3D); exact
/// duplicates point to their lowest coincident id and are no vertex.
/// nullopt when the points are all on one plane, or in 2D on one line (no
/// simplex exists: the search serves them).
/// `progress`, when set, is told the fraction of the insertion done, from
/// the calling thread, and may throw (tessera::Cancelled) to stop.
template <int D>
std::optional<engine::DelaunayStars> delaunay_stars(const Pass<D>& pass,
                                                    const std::function<void(double)>& progress = {});

}  // namespace tessera::front
