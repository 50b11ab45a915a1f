// The engine's customization points (DESIGN §2.2), as C++20 concepts.
//
// A *compositor* gathers what it needs from every finished cell into per-batch
// storage while the cells are built in parallel, then composites the batches
// into its result (counts, prefix sums, parallel copies) once all are done.
// Batches are fixed runs of generators in locator (bin) order, independent of
// the thread count, which is what makes every output identical for 1 and N
// threads.
//
// A *classifier* labels each spoke (the face between a generator and one
// neighbour) — same region, region boundary, domain boundary or outside.
#pragma once

#include <concepts>
#include <cstdint>
#include <span>

#include "tessera/cells.hpp"
#include "tessera/kernels/cell_builder.hpp"

namespace tessera::engine {

template <class C, class CellT>
concept Compositor = requires(C& c, typename C::Batch& batch, std::int32_t gen,
                              const kernels::BuildStatus& status, CellT& cell,
                              std::span<typename C::Batch> batches) {
  typename C::Batch;
  /// Called on a worker thread for every generator of a batch, in batch order.
  { c.add(batch, gen, status, cell) } -> std::same_as<void>;
  /// Called once on the calling thread after every batch is done.
  { c.finish(batches) } -> std::same_as<void>;
};

template <class F>
concept Classifier = requires(const F& f, std::int32_t gen, std::int32_t neighbor) {
  { f(gen, neighbor) } -> std::same_as<SpokeClass>;
};

}  // namespace tessera::engine
