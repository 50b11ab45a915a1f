// tessera::adjacency_graph: wheels and spokes read off the merged mesh.
#include "tessera/graph.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

#include "mesh_faces.hpp"

namespace tessera {

AdjacencyGraph adjacency_graph(const Cells& c, const GraphOptions& options) {
  front::require_mesh(c, "adjacency_graph");
  if (!(options.prune_tolerance >= 0) || !std::isfinite(options.prune_tolerance))
    throw InputError("prune tolerance must be a finite number >= 0, got " + std::to_string(options.prune_tolerance));
  const std::size_t nc = c.n_cells();
  const std::size_t nf = static_cast<std::size_t>(c.cell_face_offsets.back());
  const auto& cfo = c.cell_face_offsets;

  AdjacencyGraph g;
  g.dim = c.dim;
  g.n_points = c.n_points;

  // Pass 1, per face: its measure; per cell: its faces in wheel order
  // (ascending neighbour id; a convex cell has one face per neighbour).
  std::vector<double> measure(nf);
  std::vector<std::int64_t> wheel_order(nf);
  front::for_each_cell(c, [&](std::size_t k) {
    const auto b = wheel_order.begin() + cfo[k], e = wheel_order.begin() + cfo[k + 1];
    std::iota(b, e, cfo[k]);
    std::sort(b, e, [&](std::int64_t x, std::int64_t y) {
      return c.face_neighbor[static_cast<std::size_t>(x)] < c.face_neighbor[static_cast<std::size_t>(y)];
    });
    for (auto f = cfo[k]; f < cfo[k + 1]; ++f) measure[static_cast<std::size_t>(f)] = front::face_measure(c, f);
  });

  if (options.prune_tolerance > 0 && nc > 0) {
    double total = 0;
    for (double v : c.volume) total += v;
    const double mean = total / static_cast<double>(nc);
    g.prune_threshold = options.prune_tolerance * std::pow(mean, (c.dim - 1.0) / c.dim);
  }

  // Pass 2: one measure per face for both directions (the lower generator's
  // copy; the two copies may differ in the last bits), the prune decision,
  // and the wheel sizes.
  std::vector<double> shared(nf);
  std::vector<std::int64_t> counts(c.n_points + 1, 0);
  front::for_each_cell(c, [&](std::size_t k) {
    const std::int32_t gen = c.generator[k];
    std::int64_t kept = 0;
    for (auto f = cfo[k]; f < cfo[k + 1]; ++f) {
      const auto fu = static_cast<std::size_t>(f);
      const std::int32_t j = c.face_neighbor[fu];
      double m = measure[fu];
      const std::int32_t cj = j >= 0 ? c.cell_of[static_cast<std::size_t>(j)] : -1;
      if (cj >= 0 && j < gen) {
        const auto b = wheel_order.begin() + cfo[static_cast<std::size_t>(cj)];
        const auto e = wheel_order.begin() + cfo[static_cast<std::size_t>(cj) + 1];
        const auto twin = std::lower_bound(b, e, gen, [&](std::int64_t x, std::int32_t id) {
          return c.face_neighbor[static_cast<std::size_t>(x)] < id;
        });
        if (twin == e || c.face_neighbor[static_cast<std::size_t>(*twin)] != gen)
          throw std::logic_error("adjacency_graph: one-sided spoke " + std::to_string(gen) + " -> " +
                                 std::to_string(j) + " (inconsistent cells)");
        m = measure[static_cast<std::size_t>(*twin)];
      }
      shared[fu] = m;
      if (!(m < g.prune_threshold)) ++kept;
    }
    counts[static_cast<std::size_t>(gen) + 1] = kept;
  });
  std::partial_sum(counts.begin(), counts.end(), counts.begin());
  g.wheel_offsets = std::move(counts);
  const std::size_t ns = static_cast<std::size_t>(g.wheel_offsets.back());
  g.pruned_spokes = nf - ns;
  g.spokes.resize(ns);
  g.spoke_class.resize(ns);
  g.spoke_measure.resize(ns);

  // Pass 3: fill the wheels in wheel order.
  front::for_each_cell(c, [&](std::size_t k) {
    auto s = static_cast<std::size_t>(g.wheel_offsets[static_cast<std::size_t>(c.generator[k])]);
    for (auto w = cfo[k]; w < cfo[k + 1]; ++w) {
      const auto f = static_cast<std::size_t>(wheel_order[static_cast<std::size_t>(w)]);
      if (shared[f] < g.prune_threshold) continue;
      g.spokes[s] = c.face_neighbor[f];
      g.spoke_class[s] = c.face_class[f];
      g.spoke_measure[s] = shared[f];
      ++s;
    }
  });
  return g;
}

GraphEdges graph_edges(const AdjacencyGraph& g) {
  GraphEdges edges;
  for (std::size_t p = 0; p < g.n_points; ++p) {
    const auto i = static_cast<std::int32_t>(p);
    for (auto s = g.wheel_offsets[p]; s < g.wheel_offsets[p + 1]; ++s) {
      const auto su = static_cast<std::size_t>(s);
      const std::int32_t j = g.spokes[su];
      // An outside point has no wheel, so its spoke is listed once; between
      // two cells the lower id speaks for the pair.
      if (j < 0 || (j < i && g.spoke_class[su] != SpokeClass::outside)) continue;
      edges.ends.push_back(i);
      edges.ends.push_back(j);
      edges.spoke.push_back(s);
    }
  }
  return edges;
}

}  // namespace tessera
