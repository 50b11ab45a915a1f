// The predicates the Delaunay side needs beyond the clip predicate: the
// orientation of D+1 points and the in-sphere test of gift wrapping.
//
// Both are filtered (a float evaluation with a static forward error bound,
// after Shewchuk, "Adaptive Precision Floating-Point Arithmetic and Fast Robust
// Geometric Predicates", 1997) and fall back to exact arithmetic. The in-sphere
// test is the clip predicate in disguise (exact_predicates.hpp): "is q inside
// the sphere through a and the points of `planes`" is "does q clip the Voronoi
// vertex of a where those bisectors meet", so it carries the same symbolic
// perturbation and agrees with every decision the cells pass made.
#pragma once

#include <cstdint>

#include "tessera/kernels/exact_predicates.hpp"

namespace tessera::kernels {

/// Exact sign of det[p1-p0, ..., pD-p0] for D+1 points given by id (D = ctx.dim):
/// +1 counter-clockwise (2D) / positively oriented (3D), -1 the reverse, 0 when
/// the points are collinear / coplanar. No perturbation: flat is flat.
int orientation(const ExactContext& ctx, const std::int32_t* ids);

/// The same for D+1 points given by their coordinates (D = 2 or 3), which
/// need not be input points (hull completion asks it of box corners).
int orientation(int D, const double* const* pts);

/// Is q strictly inside the circumsphere of a and planes[0..D) (D = ctx.dim), in
/// the perturbed sense of the clip predicate? Never undecided. Precondition: a
/// and the planes are affinely independent, q is none of them.
bool in_sphere(const ExactContext& ctx, std::int32_t a, const std::int32_t* planes, std::int32_t q);

}  // namespace tessera::kernels
