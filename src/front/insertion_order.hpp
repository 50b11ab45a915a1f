// The insertion order of Bowyer–Watson in 2D and 3D (insertion.hpp): BRIO
// (Amenta, Choi & Rote, "Incremental constructions con BRIO", 2003) — rounds
// of doubling size, each in Morton order — and each point's guide, a point
// of the previous round near it, where a walk may start when the Morton
// curve jumps.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "tessera/buffer.hpp"
#include "tessera/kernels/exact_predicates.hpp"

namespace tessera::front {

struct BrioOrder {
  std::vector<std::int32_t> ids;     ///< the points (ids into ctx.points), in insertion order
  std::vector<std::uint64_t> codes;  ///< each position's Morton code
  std::vector<std::size_t> rounds;   ///< each round's first position, then ids.size()
  Buffer<double> coords;             ///< each position's coordinates (ctx.dim each)
};

/// The points `ids` in BRIO order: a point joins round r with probability
/// 2^-(r+1), by its hash (the smallest rounds first), each round in Morton
/// order of the box lo..hi (ctx.dim coordinates each); ties go by id, so the
/// order depends on nothing but the input. `coords`, when not null, holds the
/// points of `ids` in that order (ctx.dim each), read in place of
/// ctx.points: a caller whose ids are in space order (a locator's slots)
/// spares the gathers by id, one cache miss each.
BrioOrder brio_order(const kernels::ExactContext& ctx, std::span<const std::int32_t> ids, const double* coords,
                     const double* lo, const double* hi);

/// Per position of `order`: of the previous round's two points around it in
/// Morton order, the nearer one's position; -1 in the first round.
std::vector<std::int32_t> brio_guides(int dim, const BrioOrder& order);

}  // namespace tessera::front
