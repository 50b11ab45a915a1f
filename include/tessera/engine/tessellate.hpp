// The parallel driver: every generator builds its own cell (the meshless
// method), in fixed batches of generators in bin order, on oneTBB workers.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <span>
#include <stdexcept>
#include <vector>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "tessera/buffer.hpp"
#include "tessera/engine/concepts.hpp"
#include "tessera/engine/thread_arena.hpp"
#include "tessera/kernels/cell_builder.hpp"
#include "tessera/kernels/exact_predicates.hpp"
#include "tessera/kernels/locator.hpp"
#include "tessera/kernels/wall_index.hpp"

namespace tessera::engine {

/// Every located point's Delaunay star (front/delaunay_stars.hpp), by
/// locator slot: `rows` holds the simplices, D + 1 slots each, positively
/// oriented (2D counter-clockwise, 3D det > 0); slot s's simplices are
/// `simplices[first[s] .. first[s + 1])`, ascending, so in an order
/// independent of the thread count. Slots, not ids: the cells run in slot
/// order, and the locator's copies of ids and coordinates are in it too.
/// Located points are distinct (front::Pass leaves duplicates out).
struct DelaunayStars {
  Buffer<std::int32_t> rows;  ///< slots (below 2^31), as the insertion's rows were ids
  Buffer<std::uint32_t> first;
  Buffer<std::uint32_t> simplices;  ///< filled in scattered order: on huge pages (Buffer)
};

/// What the driver needs: input, domain, locator and the generators whose
/// cells are wanted, listed in the order to process them (bin order).
template <int D>
struct Generators {
  const double* coords = nullptr;                 ///< n * D
  const kernels::BinLocator<D>* locator = nullptr; ///< holds every point that clips
  std::array<double, D> lo{}, hi{};               ///< domain box
  std::span<const std::int32_t> order;            ///< generators to build, bin order
  /// Optional: order[g]'s slot in the locator. Then cells read their
  /// generator from the locator's bin-ordered copy, which they stream
  /// through, rather than from `coords` in input order, where each one
  /// missed the cache (2D 1M on 2 threads: 4%).
  std::span<const std::uint32_t> slots;
  const kernels::ExactContext* exact = nullptr;
  /// The points' k-d tree, for cells of overfull bins and long cells (CellBuilder).
  const kernels::SharedKdTree<D>* tree = nullptr;
  /// Optional: then each cell comes from its Delaunay star
  /// (CellBuilder::build_from_star), with no search. Needs `slots`.
  const DelaunayStars* stars = nullptr;
  /// Optional: bit g set (skip[g / 64] >> g % 64) for a generator whose cell
  /// is not built (the pilot built it already: front/pilot.hpp, PilotKeep).
  /// A set of generator ids, so that `order` stays as it is.
  std::span<const std::uint64_t> skip;
};

struct EngineOptions {
  int threads = 1;
  std::size_t batch_size = 512;   ///< fixed: results never depend on the thread count
  std::function<void(double)> progress;
  /// Cells whose search passes this are abandoned (CellBuilder::set_work_cap).
  std::uint64_t work_cap = std::numeric_limits<std::uint64_t>::max();
  /// Optional: the arena to run in (of `threads` threads), kept by a caller
  /// that runs many short loops (the pilot's parts). A fresh arena per call
  /// lets a loop of a few dozen cells end before the second thread joins.
  ThreadArena* arena = nullptr;
};

/// clip_walls' lists, one set per thread (the engine's workspace).
struct WallScratch {
  std::vector<std::int32_t> list, done;
  std::vector<std::array<std::uint32_t, 3>> kept;  // vertices a round found a wall for, by their planes
};

namespace detail {

/// p + y (a point relative to generator p) rounded into x; returns r grown
/// by that rounding, so that the ball B(x, result) holds B(p + y, r).
template <int D>
double absolute(const double* p, const double* y, double r, double* x) {
  double m = 0;
  for (int a = 0; a < D; ++a) {
    x[a] = p[a] + y[a];
    m = std::fmax(m, std::fabs(x[a]));
  }
  return r + 4 * kernels::filter::u * m;
}

/// The cut of a cell that reaches past many walls (clip_walls: the ball of
/// its vertices lists more than a few). The cell of a point on a sphere,
/// cut by the hull of the samples, is a cone from the centre out to the
/// box, and after its cuts a needle from the point to the centre, whose
/// ball is tangent to the sphere inside: hundreds of the hull's tangent
/// planes pass through that ball, where none but the point's own facets
/// meets the needle. By convexity a wall cuts the cell only where some
/// vertex lies beyond it. So the cell is cut first by the walls through its
/// generator (a hull point's facets), then, round by round, by the wall
/// each vertex lies farthest beyond (Index::deepest), until no vertex lies
/// beyond any wall not cut by yet. A wall cut by stays out of the later
/// rounds: the cell lies inside it (its vertices on it would be found
/// again). A vertex that a round found beyond no wall is beyond none in the
/// later rounds either: only the vertices of the round's new faces are
/// asked again, and those a round found a wall for that its cut kept (found
/// within the index's margins, not beyond: it may lie beyond another).
/// `cut(k)` cuts by wall k, false where that empties the cell; returns
/// false then.
template <class CellT, class Cut>
bool cut_by_vertex_rounds(CellT& cell, Cut&& cut, const kernels::walls::Index& index, const double* p,
                          std::size_t limit, WallScratch& scratch) {
  constexpr int D = CellT::dim;
  std::vector<std::int32_t>& done = scratch.done;
  if (index.near(p, 0.0, done, limit)) {
    for (const std::int32_t k : done)
      if (!cut(k)) return false;
  } else {  // p lies beyond many walls (domain_volume's boxes outside the domain): the rounds alone
    done.clear();
  }
  auto is_done = [&](std::int32_t k) { return std::binary_search(done.begin(), done.end(), k); };
  auto key = [](const auto& v) {  // a vertex by its planes (a simple polytope's vertex has its own)
    std::array<std::uint32_t, 3> k{0, 0, 0};
    for (int a = 0; a < D; ++a) k[static_cast<std::size_t>(a)] = static_cast<std::uint32_t>(v.p[a]);
    std::sort(k.begin(), k.begin() + D);
    return k;
  };
  auto& kept = scratch.kept;
  auto& list = scratch.list;
  kept.clear();
  for (std::size_t old_planes = 0;;) {
    cell.solve_deferred();  // (a deferred vertex's bound is wide)
    list.clear();
    const auto last_round = static_cast<std::ptrdiff_t>(kept.size());  // kept[0, last_round); this round's appended
    for (const auto& v : cell.vertices()) {
      bool fresh = false;
      for (int a = 0; a < D; ++a) fresh |= v.p[a] >= old_planes;
      const auto vk = key(v);
      if (!fresh && std::find(kept.begin(), kept.begin() + last_round, vk) == kept.begin() + last_round) continue;
      double x[3] = {0, 0, 0};
      const double r = absolute<D>(p, v.y, v.e * std::sqrt(static_cast<double>(D)), x);
      const std::int32_t k = index.deepest(x, std::isfinite(r) ? r : std::numeric_limits<double>::infinity(), is_done);
      if (k >= 0) {
        list.push_back(k);
        kept.push_back(vk);
      }
    }
    kept.erase(kept.begin(), kept.begin() + last_round);
    if (list.empty()) return true;
    old_planes = cell.planes().size();
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
    for (const std::int32_t k : list) {
      done.insert(std::lower_bound(done.begin(), done.end(), k), k);
      if (!cut(k)) return false;
    }
  }
}

}  // namespace detail

/// Cut a built cell of generator p by the exact context's walls
/// (kernels/walls.hpp): every wall, in ascending order, or with a wall index
/// those it finds near the cell; a cell they leave empty has none
/// (st.has_cell false). The cut may have deferred new vertices' exact
/// solves: solved here.
template <class CellT>
[[gnu::noinline]] void clip_walls(CellT& cell, kernels::BuildStatus& st, const kernels::ExactContext& ctx,
                                  const double* p, WallScratch& scratch) {
  constexpr int D = CellT::dim;
  // Each cut shrinks the cell: its ball is taken again after it, so that
  // later walls are passed over sooner. Until then the ball of its reach
  // about the generator serves (a bound the cell keeps already): most cells
  // are cut by no wall.
  kernels::walls::Ball<D> ball;
  for (int a = 0; a < D; ++a) ball.c[a] = 0;
  ball.r = cell.vertex_reach();
  auto cut = [&](std::int32_t k) {
    const kernels::ClipResult r = cell.clip_wall(k, ball);
    if (r == kernels::ClipResult::emptied) {
      st.has_cell = false;
      return false;
    }
    if (r == kernels::ClipResult::clipped) ball = cell.vertex_ball();
    return true;
  };
  const kernels::walls::Index* index = ctx.wall_index;
  if (index == nullptr) {
    for (std::int32_t k = 0; k < ctx.num_walls; ++k)
      if (!cut(k)) return;
    cell.solve_deferred();
    return;
  }
  // Most cells lie deep inside: no wall comes within their reach.
  bool any = false;
  index->visit(p, ball.r, [&](std::int32_t) { return !(any = true); });
  if (any) {
    // The walls near the vertices' ball (asked about its centre p + c),
    // ascending; a ball under half the one the list was taken for takes a
    // shorter list (from the next wall on: walls before k are behind the
    // cell). Where they are many, the vertices are asked instead.
    constexpr std::size_t few = 64;
    ball = cell.vertex_ball();
    double q[3] = {0, 0, 0};
    std::vector<std::int32_t>& list = scratch.list;
    if (!index->near(q, detail::absolute<D>(p, ball.c, ball.r, q), list, few)) {
      if (!detail::cut_by_vertex_rounds(cell, cut, *index, p, few, scratch)) return;
    } else {
      double listed_for = ball.r;
      for (std::size_t i = 0; i < list.size(); ++i) {
        const std::int32_t k = list[i];
        if (!cut(k)) return;
        if (ball.r < 0.5 * listed_for) {
          listed_for = ball.r;
          index->near(q, detail::absolute<D>(p, ball.c, ball.r, q), list);
          i = static_cast<std::size_t>(std::upper_bound(list.begin(), list.end(), k) - list.begin()) - 1;  // (++i next)
        }
      }
    }
  }
  cell.solve_deferred();
}

/// Build every cell of `gens.order` and hand each to the compositor; returns
/// the number of exact predicate evaluations. `earlier`: batches the same
/// compositor was given before, by another loop over other generators (the
/// pilot's sample, front/pilot.hpp), finished together with these (placed
/// before them; the compositors order their output by generator, not by
/// batch).
template <class CellT, class Comp>
  requires Compositor<Comp, CellT>
std::uint64_t tessellate(const Generators<CellT::dim>& gens, Comp& comp, const EngineOptions& opt,
                         std::vector<typename Comp::Batch> earlier = {}) {
  const std::size_t n = gens.order.size();
  if (!gens.slots.empty() && gens.slots.size() != n)
    throw std::invalid_argument("tessera: Generators::slots must be empty or as long as Generators::order");
  if (gens.stars != nullptr && gens.slots.size() != n)
    throw std::invalid_argument("tessera: Generators::stars needs Generators::slots");
  std::size_t bs = std::max<std::size_t>(1, opt.batch_size);
  // A short loop gets smaller batches (eight, of at least 128 cells), so
  // that both threads get a share: the pass after the pilot's kept cells of
  // 1,000 points was one batch of 512, on one thread. From the count alone,
  // never the threads; no output depends on the batching.
  bs = std::min(bs, std::max<std::size_t>(128, (n + 7) / 8));
  const std::size_t nb = (n + bs - 1) / bs;
  const std::size_t first_own = earlier.size();
  std::vector<typename Comp::Batch> batches = std::move(earlier);
  batches.resize(first_own + nb);

  struct Workspace {
    kernels::CellBuilder<CellT> builder;
    CellT cell;
    std::uint64_t exact_calls = 0;
    WallScratch walls;
  };
  tbb::enumerable_thread_specific<Workspace> workspaces([&] {
    Workspace ws{kernels::CellBuilder<CellT>(*gens.locator, gens.coords, gens.lo.data(), gens.hi.data(),
                                             gens.exact, gens.tree),
                 CellT{}, 0, {}};
    ws.builder.set_work_cap(opt.work_cap);
    return ws;
  });

  constexpr std::size_t star_ahead = 4;  // cells whose star rows are prefetched ahead of their turn
  auto run_batch = [&](std::size_t k) {
    Workspace& ws = workspaces.local();
    auto& batch = batches[first_own + k];
    const std::size_t end = std::min(n, (k + 1) * bs);
    for (std::size_t g = k * bs; g < end; ++g) {
      const std::int32_t gen = gens.order[g];
      if (!gens.skip.empty() && (gens.skip[static_cast<std::size_t>(gen) >> 6] >> (gen & 63) & 1) != 0) continue;
      const double* p = gens.slots.empty() ? gens.coords + static_cast<std::size_t>(gen) * CellT::dim
                                           : gens.locator->point(gens.slots[g]).data();
      kernels::BuildStatus st;
      if (const DelaunayStars* ds = gens.stars) {
        const std::uint32_t at = gens.slots[g];
        // A star's simplices lie all over the rows (they are in id order):
        // ask for those of a later cell now.
        if (g + star_ahead < end) {
          const std::uint32_t later = gens.slots[g + star_ahead];
          for (std::uint32_t t = ds->first[later]; t < ds->first[later + 1]; ++t)
            __builtin_prefetch(ds->rows.data() + (CellT::dim + 1) * static_cast<std::size_t>(ds->simplices[t]));
        }
        const std::uint32_t a = ds->first[at], e = ds->first[at + 1];
        st = ws.builder.build_from_star(gen, p, at, reinterpret_cast<const std::uint32_t*>(ds->rows.data()),
                                        std::span<const std::uint32_t>(ds->simplices.data() + a, e - a), ws.cell);
      } else {
        st = ws.builder.build_any(gen, p, ws.cell);
      }
      if (gens.exact != nullptr && gens.exact->num_walls > 0 && st.has_cell) [[unlikely]]
        clip_walls(ws.cell, st, *gens.exact, p, ws.walls);
      ws.exact_calls += ws.cell.exact_calls();
      comp.add(batch, gen, st, ws.cell);
    }
  };

  std::optional<ThreadArena> own;
  ThreadArena& arena = opt.arena != nullptr ? *opt.arena : own.emplace(opt.threads);
  // Progress is reported (and cancellation honoured) between chunks of batches,
  // from the calling thread.
  const std::size_t chunk = opt.progress ? std::max<std::size_t>(1, nb / 100) : nb;
  for (std::size_t first = 0; first < nb; first += chunk) {
    const std::size_t last = std::min(nb, first + chunk);
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(first, last, 1),
                        [&](const tbb::blocked_range<std::size_t>& r) {
                          for (std::size_t k = r.begin(); k != r.end(); ++k) run_batch(k);
                        });
    });
    if (opt.progress) opt.progress(static_cast<double>(last) / static_cast<double>(nb));
  }
  std::uint64_t exact_calls = 0;
  for (auto& ws : workspaces) exact_calls += ws.exact_calls;
  // In the arena too: the compositor's own parallel loops honour --threads.
  arena.execute([&] { comp.finish(std::span<typename Comp::Batch>(batches)); });
  return exact_calls;
}

}  // namespace tessera::engine
