// tessera::adjacency_graph: wheels and spokes read off the merged mesh.
#include "tessera/graph.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

#include "mesh_faces.hpp"

namespace tessera {
namespace {

/// A spoke's shift (periodic boxes; zeros otherwise), and the order of
/// spokes within a wheel: by neighbour, then shift.
struct SpokeShifts {
  const std::int8_t* shift = nullptr;  // dim per spoke, or null
  std::size_t dim = 3;
  std::array<int, 3> of(std::size_t f) const {
    std::array<int, 3> s{0, 0, 0};
    if (shift != nullptr)
      for (std::size_t a = 0; a < dim; ++a) s[a] = shift[f * dim + a];
    return s;
  }
};

std::array<int, 3> negated(const std::array<int, 3>& s) { return {-s[0], -s[1], -s[2]}; }

/// Of the two directions (i, j, s) and (j, i, -s) of a face, the one that
/// speaks for it (its measure, its edge): the lower triple.
bool speaks(std::int32_t i, std::int32_t j, const std::array<int, 3>& s) {
  return i < j || (i == j && !(negated(s) < s));
}

}  // namespace

AdjacencyGraph adjacency_graph(const Cells& c, const GraphOptions& options) {
  front::require_mesh(c, "adjacency_graph", true);
  if (!(options.prune_tolerance >= 0) || !std::isfinite(options.prune_tolerance))
    throw InputError("prune tolerance must be a finite number >= 0, got " + std::to_string(options.prune_tolerance));
  const std::size_t nc = c.n_cells();
  const std::size_t nf = static_cast<std::size_t>(c.cell_face_offsets.back());
  const auto& cfo = c.cell_face_offsets;

  AdjacencyGraph g;
  g.dim = c.dim;
  g.n_points = c.n_points;
  g.periodic = c.periodic;
  if (c.is_periodic()) g.lattice = c.lattice();
  const auto du = static_cast<std::size_t>(c.dim);
  const SpokeShifts shifts{c.is_periodic() ? c.face_shift.data() : nullptr, du};
  auto before = [&](std::int64_t x, std::int64_t y) {
    const auto xu = static_cast<std::size_t>(x), yu = static_cast<std::size_t>(y);
    if (c.face_neighbor[xu] != c.face_neighbor[yu]) return c.face_neighbor[xu] < c.face_neighbor[yu];
    return shifts.of(xu) < shifts.of(yu);
  };

  // Pass 1, per face: its measure; per cell: its faces in wheel order
  // (ascending neighbour id, then shift; a convex cell has one face per
  // neighbour and image).
  std::vector<double> measure(nf);
  std::vector<std::int64_t> wheel_order(nf);
  front::for_each_cell(c, [&](std::size_t k) {
    const auto b = wheel_order.begin() + cfo[k], e = wheel_order.begin() + cfo[k + 1];
    std::iota(b, e, cfo[k]);
    std::sort(b, e, before);
    for (auto f = cfo[k]; f < cfo[k + 1]; ++f) measure[static_cast<std::size_t>(f)] = front::face_measure(c, f);
  }, options.progress);

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
      const std::array<int, 3> s = shifts.of(fu);
      if (cj >= 0 && !speaks(gen, j, s)) {
        const auto b = wheel_order.begin() + cfo[static_cast<std::size_t>(cj)];
        const auto e = wheel_order.begin() + cfo[static_cast<std::size_t>(cj) + 1];
        const std::array<int, 3> back = negated(s);
        const auto twin = std::lower_bound(b, e, gen, [&](std::int64_t x, std::int32_t id) {
          const auto xu = static_cast<std::size_t>(x);
          return c.face_neighbor[xu] != id ? c.face_neighbor[xu] < id : shifts.of(xu) < back;
        });
        if (twin == e || c.face_neighbor[static_cast<std::size_t>(*twin)] != gen ||
            shifts.of(static_cast<std::size_t>(*twin)) != back)
          throw std::logic_error("adjacency_graph: one-sided spoke " + std::to_string(gen) + " -> " +
                                 std::to_string(j) + " (inconsistent cells)");
        m = measure[static_cast<std::size_t>(*twin)];
      }
      shared[fu] = m;
      if (!(m < g.prune_threshold)) ++kept;
    }
    counts[static_cast<std::size_t>(gen) + 1] = kept;
  }, options.progress);
  std::partial_sum(counts.begin(), counts.end(), counts.begin());
  g.wheel_offsets = std::move(counts);
  const std::size_t ns = static_cast<std::size_t>(g.wheel_offsets.back());
  g.pruned_spokes = nf - ns;
  g.spokes.resize(ns);
  g.spoke_class.resize(ns);
  g.spoke_measure.resize(ns);
  if (shifts.shift != nullptr) g.spoke_shift.resize(ns * du);

  // Pass 3: fill the wheels in wheel order.
  front::for_each_cell(c, [&](std::size_t k) {
    auto s = static_cast<std::size_t>(g.wheel_offsets[static_cast<std::size_t>(c.generator[k])]);
    for (auto w = cfo[k]; w < cfo[k + 1]; ++w) {
      const auto f = static_cast<std::size_t>(wheel_order[static_cast<std::size_t>(w)]);
      if (shared[f] < g.prune_threshold) continue;
      g.spokes[s] = c.face_neighbor[f];
      g.spoke_class[s] = c.face_class[f];
      g.spoke_measure[s] = shared[f];
      if (shifts.shift != nullptr)
        for (std::size_t a = 0; a < du; ++a) g.spoke_shift[s * du + a] = c.face_shift[f * du + a];
      ++s;
    }
  }, options.progress);
  return g;
}

GraphEdges graph_edges(const AdjacencyGraph& g) {
  GraphEdges edges;
  const auto du = static_cast<std::size_t>(g.dim);
  const SpokeShifts shifts{g.spoke_shift.empty() ? nullptr : g.spoke_shift.data(), du};
  for (std::size_t p = 0; p < g.n_points; ++p) {
    const auto i = static_cast<std::int32_t>(p);
    for (auto s = g.wheel_offsets[p]; s < g.wheel_offsets[p + 1]; ++s) {
      const auto su = static_cast<std::size_t>(s);
      const std::int32_t j = g.spokes[su];
      // An outside point has no wheel, so its spoke is listed once; between
      // two cells the lower direction speaks for the pair.
      if (j < 0 || (!speaks(i, j, shifts.of(su)) && g.spoke_class[su] != SpokeClass::outside)) continue;
      edges.ends.push_back(i);
      edges.ends.push_back(j);
      edges.spoke.push_back(s);
      if (shifts.shift != nullptr) edges.shift.insert(edges.shift.end(), &g.spoke_shift[su * du], &g.spoke_shift[su * du] + du);
    }
  }
  return edges;
}

}  // namespace tessera
