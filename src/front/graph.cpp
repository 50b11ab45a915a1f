// tessera::adjacency_graph: wheels and spokes read off the merged mesh.
#include "tessera/graph.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

#include <tbb/enumerable_thread_specific.h>

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
  front::refuse_partial(c, "adjacency_graph");
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
  const bool periodic = c.is_periodic();
  const SpokeShifts shifts{periodic ? c.face_shift.data() : nullptr, du};

  // Pass 1, per cell: its faces in wheel order (ascending neighbour id, then
  // shift; a convex cell has one face per neighbour and image), written at
  // the cell's own face range (cell_face_offsets) of the spoke arrays, each
  // with the measure of the cell's own copy of the face. The wheels are read
  // in pass 2 from these contiguous runs (ids in order), not through an
  // index into the mesh's face arrays: the twin lookup's binary search
  // touched a cache line per probe there.
  std::vector<std::int32_t> spokes(nf);
  std::vector<SpokeClass> spoke_class(nf);
  std::vector<double> measure(nf);
  std::vector<std::int8_t> spoke_shift(periodic ? nf * du : 0);
  {
    auto before = [&](std::int64_t x, std::int64_t y) {
      const auto xu = static_cast<std::size_t>(x), yu = static_cast<std::size_t>(y);
      if (c.face_neighbor[xu] != c.face_neighbor[yu]) return c.face_neighbor[xu] < c.face_neighbor[yu];
      return shifts.of(xu) < shifts.of(yu);
    };
    tbb::enumerable_thread_specific<std::vector<std::int64_t>> scratch;
    front::for_each_cell(c, [&](std::size_t k) {
      // The cell's merged vertices (a quarter its own, the rest its
      // neighbours', scattered) fetched at once, before the measures' fans.
      const auto v0 = static_cast<std::size_t>(c.face_vertex_offsets[static_cast<std::size_t>(cfo[k])]);
      const auto v1 = static_cast<std::size_t>(c.face_vertex_offsets[static_cast<std::size_t>(cfo[k + 1])]);
      for (std::size_t v = v0; v < v1; ++v)
        __builtin_prefetch(c.vertices.data() + static_cast<std::size_t>(c.face_vertices[v]) * du);
      std::vector<std::int64_t>& order = scratch.local();
      order.resize(static_cast<std::size_t>(cfo[k + 1] - cfo[k]));
      std::iota(order.begin(), order.end(), cfo[k]);
      std::sort(order.begin(), order.end(), before);
      auto w = static_cast<std::size_t>(cfo[k]);
      for (const std::int64_t f : order) {
        const auto fu = static_cast<std::size_t>(f);
        spokes[w] = c.face_neighbor[fu];
        spoke_class[w] = c.face_class[fu];
        measure[w] = front::face_measure(c, f);
        if (periodic)
          for (std::size_t a = 0; a < du; ++a) spoke_shift[w * du + a] = c.face_shift[fu * du + a];
        ++w;
      }
    }, options.progress);
  }
  const SpokeShifts wheel_shifts{periodic ? spoke_shift.data() : nullptr, du};

  if (options.prune_tolerance > 0 && nc > 0) {
    double total = 0;
    for (double v : c.volume) total += v;
    const double mean = total / static_cast<double>(nc);
    g.prune_threshold = options.prune_tolerance * std::pow(mean, (c.dim - 1.0) / c.dim);
  }

  // Pass 2: one measure per face for both directions (the lower generator's
  // copy; the two copies may differ in the last bits), the prune decision,
  // and the wheel sizes. A spoke that does not speak for its face takes the
  // measure of its twin, which does: it only reads speaking spokes' measures
  // and only writes its own, so the cells may run in any order.
  //
  // Each lookup is a few dependent cache misses in another cell's run (its
  // offsets, its ids, its measures; cells are in input order, scattered in
  // space), so a cell's lookups go in sweeps whose misses overlap: the twins'
  // cells and their offsets fetched, then their runs, then the search (a
  // count over the run's ids, without branches: ~15 in 3D).
  bool identity = nc == c.n_points;  // cell k is generator k: cell_of need not be read
  for (std::size_t k = 0; identity && k < nc; ++k) identity = c.generator[k] == static_cast<std::int32_t>(k);
  struct Lookup {
    std::size_t face, cell;
  };
  tbb::enumerable_thread_specific<std::vector<Lookup>> lookups;
  std::vector<std::int64_t> counts(c.n_points + 1, 0);
  front::for_each_cell(c, [&](std::size_t k) {
    const std::int32_t gen = c.generator[k];
    std::vector<Lookup>& look = lookups.local();
    look.clear();
    for (auto f = cfo[k]; f < cfo[k + 1]; ++f) {
      const auto fu = static_cast<std::size_t>(f);
      const std::int32_t j = spokes[fu];
      if (j < 0) continue;
      const auto ju = static_cast<std::size_t>(j);
      const std::int32_t cj = identity ? j : c.cell_of[ju];
      if (cj < 0 || speaks(gen, j, wheel_shifts.of(fu))) continue;
      look.push_back({fu, static_cast<std::size_t>(cj)});
      __builtin_prefetch(&cfo[static_cast<std::size_t>(cj)]);
    }
    for (const Lookup& l : look) {
      __builtin_prefetch(spokes.data() + cfo[l.cell]);
      __builtin_prefetch(measure.data() + cfo[l.cell]);
    }
    for (const Lookup& l : look) {
      const auto b = static_cast<std::size_t>(cfo[l.cell]), e = static_cast<std::size_t>(cfo[l.cell + 1]);
      std::size_t twin = b;
      bool found;
      if (!periodic) {
        for (std::size_t x = b; x < e; ++x) twin += spokes[x] < gen;
        found = twin != e && spokes[twin] == gen;
      } else {
        const std::array<int, 3> back = negated(wheel_shifts.of(l.face));
        while (twin != e && (spokes[twin] != gen ? spokes[twin] < gen : wheel_shifts.of(twin) < back)) ++twin;
        found = twin != e && spokes[twin] == gen && wheel_shifts.of(twin) == back;
      }
      if (!found)
        throw std::logic_error("adjacency_graph: one-sided spoke " + std::to_string(gen) + " -> " +
                               std::to_string(spokes[l.face]) + " (inconsistent cells)");
      measure[l.face] = measure[twin];
    }
    std::int64_t kept = 0;
    for (auto f = cfo[k]; f < cfo[k + 1]; ++f) kept += !(measure[static_cast<std::size_t>(f)] < g.prune_threshold);
    counts[static_cast<std::size_t>(gen) + 1] = kept;
  }, options.progress);
  std::partial_sum(counts.begin(), counts.end(), counts.begin());
  g.wheel_offsets = std::move(counts);
  const std::size_t ns = static_cast<std::size_t>(g.wheel_offsets.back());
  g.pruned_spokes = nf - ns;

  // The wheels are the cells' runs as they stand where nothing was pruned
  // and cells ascend by generator (they do: cell_of numbers them so), so
  // that a cell's run starts at its generator's wheel offset.
  bool in_place = ns == nf;
  for (std::size_t k = 0; in_place && k < nc; ++k)
    in_place = g.wheel_offsets[static_cast<std::size_t>(c.generator[k])] == cfo[k];
  if (in_place) {
    g.spokes = std::move(spokes);
    g.spoke_class = std::move(spoke_class);
    g.spoke_measure = std::move(measure);
    g.spoke_shift = std::move(spoke_shift);
    return g;
  }

  // Pass 3 (pruning): the kept spokes, in wheel order.
  g.spokes.resize(ns);
  g.spoke_class.resize(ns);
  g.spoke_measure.resize(ns);
  if (periodic) g.spoke_shift.resize(ns * du);
  front::for_each_cell(c, [&](std::size_t k) {
    auto s = static_cast<std::size_t>(g.wheel_offsets[static_cast<std::size_t>(c.generator[k])]);
    for (auto w = cfo[k]; w < cfo[k + 1]; ++w) {
      const auto f = static_cast<std::size_t>(w);
      if (measure[f] < g.prune_threshold) continue;
      g.spokes[s] = spokes[f];
      g.spoke_class[s] = spoke_class[f];
      g.spoke_measure[s] = measure[f];
      if (periodic)
        for (std::size_t a = 0; a < du; ++a) g.spoke_shift[s * du + a] = spoke_shift[f * du + a];
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
