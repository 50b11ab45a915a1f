// The one combinatorial question a spherical cell's clip asks, decided
// exactly and never tied.
//
// Points on a sphere: the spherical Voronoi cell of p is the set of
// directions u with u.p >= u.q for every other point q, the normal cone of
// the points' convex hull at p (sphere_tile.hpp). A vertex of that cone,
// where the planes u.(p - a) = 0 and u.(p - b) = 0 meet, is a hull facet
// (p, a, b); a candidate s removes it iff s lies strictly above that facet:
// orientation(p, a, b, s) = sign det[a - p, b - p, s - p] > 0. The sign is a
// function of the four points alone, so every cell sharing the facet agrees.
//
// Ties (four points on one circle of the sphere: a lon/lat grid's
// trapezoids, a cube's corners) are broken by Simulation of Simplicity
// (H. Edelsbrunner and E. P. Mücke, "Simulation of Simplicity", ACM Trans.
// Graph. 9(1), 1990): point i moves by eps^(2^(3 i + d)) along axis d, with i
// its rank by id among the four; the sign is that of the first non-zero
// coefficient of the perturbed determinant in increasing powers of eps. The
// perturbed points are in general position (no three on a line, no four on
// a plane), so the hull is simplicial and every cone vertex has exactly
// three generators.
#pragma once

#include <cstdint>


namespace tessera::kernels {

/// sign det[b - a, c - a, s - a] for the four points (coordinates and ids,
/// ids distinct), in the perturbed sense above: +1 or -1, never 0. Meant
/// for a caller whose float filter was undecided: it starts at the
/// extended-precision stage (orientation_past_filter).
int orientation_sos(const double* a, const double* b, const double* c, const double* s, std::int32_t ia,
                    std::int32_t ib, std::int32_t ic, std::int32_t is);

/// The perturbed sign once the exact determinant is known to be zero (the
/// part of orientation_sos past its exact stage; exposed for the tests).
int orientation_tie_break(const double* const* pts, const std::int32_t* ids);

}  // namespace tessera::kernels
