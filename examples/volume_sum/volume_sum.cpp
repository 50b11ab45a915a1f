// Write your own compositor: the sum of all Voronoi cell volumes.
//
// tessera::engine::tessellate builds every cell in parallel (each generator
// clips its own cell: the meshless method) and hands each finished cell to a
// *compositor*, which keeps what it needs in per-batch storage and combines
// the batches once at the end (DESIGN §2). Batches are fixed runs of
// generators, independent of the thread count, so the result is bit-identical
// for 1 and N threads.
//
// The cells of points in a box partition the box, so the volumes must sum to
// the box volume: this program checks that, and doubles as a test.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <span>
#include <thread>
#include <vector>

#include "tessera/kernels/exact_predicates.hpp"
#include "tessera/kernels/hull.hpp"
#include "tessera/kernels/locator.hpp"
#include "tessera/engine/tessellate.hpp"

namespace kernels = tessera::kernels;

// Volume of a 3D cell: its faces are loops of vertices, counter-clockwise
// seen from outside, with coordinates relative to the generator (which lies
// inside). Fan every face into triangles; each triangle and the generator
// span a tetrahedron of volume det(a, b, c) / 6.
double cell_volume(kernels::Hull& cell) {
  const auto& v = cell.vertices();
  double six_v = 0;
  cell.for_each_face([&](std::uint16_t /*plane*/, const std::uint32_t* loop, std::size_t m) {
    const double* a = v[loop[0]].y;
    for (std::size_t k = 1; k + 1 < m; ++k) {
      const double* b = v[loop[k]].y;
      const double* c = v[loop[k + 1]].y;
      six_v += a[0] * (b[1] * c[2] - b[2] * c[1]) + a[1] * (b[2] * c[0] - b[0] * c[2]) +
               a[2] * (b[0] * c[1] - b[1] * c[0]);
    }
  });
  return six_v / 6;
}

// The compositor: a Batch type, add() for each cell, finish() once.
struct VolumeSum {
  struct Batch {
    double sum = 0;
  };
  double total = 0;

  // On a worker thread, for every generator of a batch, in batch order.
  // `cell` is only valid during the call.
  void add(Batch& batch, std::int32_t /*gen*/, const kernels::BuildStatus& status, kernels::Hull& cell) {
    if (!status.has_cell) return;  // an exact duplicate: a lower id owns the cell
    batch.sum += cell_volume(cell);
  }
  // On the calling thread, after every batch is done; batches in fixed order.
  void finish(std::span<Batch> batches) {
    for (const Batch& b : batches) total += b.sum;
  }
};

int main() {
  // Input: random points in the unit cube (fixed seed: a reproducible test).
  const std::size_t n = 20000;
  std::vector<double> points(3 * n);
  std::mt19937_64 rng(2024);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (double& x : points) x = uniform(rng);
  const std::array<double, 3> lo{0, 0, 0}, hi{1, 1, 1};

  // The neighbour search: a uniform bin grid, ~2 points per bin.
  kernels::BinLocator<3> locator(points, {}, lo, hi, 2.0);

  // The generators whose cells we want, in bin order (neighbouring cells are
  // built together, which keeps the caches warm): here, all of them.
  // Their slots in the locator let each cell read its generator from the
  // locator's bin-ordered copy of the points (optional, but faster).
  std::vector<std::int32_t> order(locator.size());
  std::vector<std::uint32_t> slots(locator.size());
  for (std::size_t k = 0; k < locator.size(); ++k) {
    order[k] = locator.id(k);
    slots[k] = static_cast<std::uint32_t>(k);
  }

  // What the exact predicates read: the raw input and the box.
  kernels::ExactContext exact;
  exact.points = points.data();
  exact.dim = 3;
  exact.lo = lo;
  exact.hi = hi;

  tessera::engine::Generators<3> gens;
  gens.coords = points.data();
  gens.locator = &locator;
  gens.lo = lo;
  gens.hi = hi;
  gens.order = order;
  gens.slots = slots;
  gens.exact = &exact;

  tessera::engine::EngineOptions options;
  options.threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));

  VolumeSum sum;
  tessera::engine::tessellate<kernels::Hull>(gens, sum, options);

  const double error = std::fabs(sum.total - 1.0);
  std::printf("%zu cells, volume sum %.17g (error %.3g)\n", n, sum.total, error);
  return error <= 1e-12 ? 0 : 1;
}
