#include "delaunay_neighbours.hpp"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <utility>
#include <vector>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "insertion.hpp"

namespace tessera::front {

namespace {

/// Appends to `out` the vertices of the simplices `tets` (rows of W: 4 in
/// 3D, 3 in 2D) other than s, each once, in order of first appearance (the
/// simplices ascending: an order that does not depend on the thread count).
template <int W>
void collect(std::uint32_t s, const std::uint32_t* rows, const std::uint32_t* tets, std::size_t count,
             std::vector<std::uint32_t>& out) {
  const std::size_t start = out.size();
  // A vertex has ~27 tetrahedra and ~15 neighbours on uniform input: each
  // vertex met is compared with the neighbours so far, four at a time (marks
  // in an array by point would need one such array per thread). Past the
  // last neighbour the list holds s itself, so s is never taken either.
  constexpr std::size_t most = 96;
  if (count <= most) {
    using Quad = std::uint32_t __attribute__((vector_size(16)));
    std::uint32_t have[3 * most + 8];
    const Quad own = {s, s, s, s};
    std::memcpy(have, &own, sizeof own);
    std::size_t m = 0;
    for (std::size_t t = 0; t < count; ++t) {
      const std::uint32_t* row = rows + W * static_cast<std::size_t>(tets[t]);
      for (int c = 0; c < W; ++c) {
        const std::uint32_t v = row[c];
        const Quad vv = {v, v, v, v};
        Quad seen = {};
        for (std::size_t g = 0; g <= m; g += 4) {
          Quad h;
          std::memcpy(&h, have + g, sizeof h);
          seen |= h == vv;
        }
        if ((seen[0] | seen[1] | seen[2] | seen[3]) == 0) {
          have[m++] = v;
          std::memcpy(have + m, &own, sizeof own);
        }
      }
    }
    out.insert(out.end(), have, have + m);
    return;
  }
  // A vertex of high degree (points in convex position can have hundreds):
  // sorted instead, no less deterministic.
  for (std::size_t t = 0; t < count; ++t) {
    const std::uint32_t* row = rows + W * static_cast<std::size_t>(tets[t]);
    for (int c = 0; c < W; ++c)
      if (row[c] != s) out.push_back(row[c]);
  }
  std::sort(out.begin() + static_cast<std::ptrdiff_t>(start), out.end());
  out.erase(std::unique(out.begin() + static_cast<std::ptrdiff_t>(start), out.end()), out.end());
}

}  // namespace

template <int D>
std::optional<engine::NeighbourLists> delaunay_neighbours(const Pass<D>& pass,
                                                          const std::function<void(double)>& progress) {
  constexpr int W = D + 1;
  const auto& loc = *pass.locator;
  const std::size_t n = pass.points.size() / D, located = loc.size();
  engine::NeighbourLists out;
  bool flat = false;
  tbb::task_arena(pass.engine_options.threads).execute([&] {
    LocatedInsertion ins = insert_located(pass, progress);
    out.duplicate_of = std::move(ins.lowest);
    auto& simplices = ins.rows;
    if (!simplices) {
      flat = true;
      return;
    }
    // Rows of slots from here on: the lists are built in slot order (the
    // cells' order), where neighbouring points share most of their
    // tetrahedra, and the cells read the locator's slot-ordered copies.
    std::vector<std::uint32_t> slot_of(n, 0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, located), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t k = r.begin(); k != r.end(); ++k) slot_of[static_cast<std::size_t>(loc.id(k))] = static_cast<std::uint32_t>(k);
    });
    const std::size_t m = simplices->size();
    auto* const rows = reinterpret_cast<std::uint32_t*>(simplices->data());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, m), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t k = r.begin(); k != r.end(); ++k) rows[k] = slot_of[rows[k]];
    });
    // Each slot's tetrahedra, ascending (m < 2^32: the insertion holds
    // fewer than 2^29 tetrahedra). The rows are cut into one part per
    // thread (at most 8: each has a count per slot); each part counts its
    // entries per slot, and fills them after those of the parts before it,
    // so every slot's list is ascending whatever the number of parts.
    const std::size_t nparts = std::clamp<std::size_t>(static_cast<std::size_t>(pass.engine_options.threads), 1, 8);
    std::vector<std::vector<std::uint32_t>> at(nparts, std::vector<std::uint32_t>(located, 0));
    auto part_range = [&](std::size_t c) { return std::pair{m * c / nparts, m * (c + 1) / nparts}; };
    tbb::parallel_for(std::size_t{0}, nparts, [&](std::size_t c) {
      const auto [a, e] = part_range(c);
      std::uint32_t* const cnt = at[c].data();
      for (std::size_t k = a; k < e; ++k) ++cnt[rows[k]];
    });
    std::vector<std::uint32_t> first(located + 1, 0);
    for (std::size_t k = 0; k < located; ++k) {
      std::uint32_t next = first[k];
      for (std::size_t c = 0; c < nparts; ++c) {  // counts become each part's first place
        const std::uint32_t n_c = at[c][k];
        at[c][k] = next;
        next += n_c;
      }
      first[k + 1] = next;
    }
    std::vector<std::uint32_t> tets(m);
    tbb::parallel_for(std::size_t{0}, nparts, [&](std::size_t c) {
      const auto [a, e] = part_range(c);
      std::uint32_t* const place = at[c].data();
      for (std::size_t k = a; k < e; ++k) tets[place[rows[k]]++] = static_cast<std::uint32_t>(k / W);
    });
    at.clear();
    at.shrink_to_fit();
    // The lists per fixed chunk of slots, then laid end to end.
    constexpr std::size_t chunk = 4096;
    constexpr std::size_t ahead = 4;  // slots whose rows are prefetched ahead of their turn
    const std::size_t chunks = (located + chunk - 1) / chunk;
    std::vector<std::vector<std::uint32_t>> parts(chunks);
    std::vector<std::int64_t> count(located + 1, 0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, chunks, 1), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t c = r.begin(); c != r.end(); ++c) {
        auto& part = parts[c];
        const std::size_t end = std::min(located, (c + 1) * chunk);
        for (std::size_t k = c * chunk; k < end; ++k) {
          // A point's tetrahedra lie all over the rows: ask for those of a
          // later slot now (its list of them is at hand, in slot order).
          if (k + ahead < end)
            for (std::uint32_t t = first[k + ahead]; t < first[k + ahead + 1]; ++t)
              __builtin_prefetch(rows + W * static_cast<std::size_t>(tets[t]));
          if (out.duplicate_of[k] >= 0) continue;
          const std::size_t before = part.size();
          collect<W>(static_cast<std::uint32_t>(k), rows, tets.data() + first[k], first[k + 1] - first[k], part);
          count[k + 1] = static_cast<std::int64_t>(part.size() - before);
        }
      }
    });
    for (std::size_t k = 0; k < located; ++k) count[k + 1] += count[k];
    out.offsets = std::move(count);
    out.slots.resize(static_cast<std::size_t>(out.offsets[located]));
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, chunks, 1), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t c = r.begin(); c != r.end(); ++c)
        std::copy(parts[c].begin(), parts[c].end(), out.slots.begin() + out.offsets[c * chunk]);
    });
  });
  if (flat) return std::nullopt;
  return out;
}

template std::optional<engine::NeighbourLists> delaunay_neighbours(const Pass<2>&, const std::function<void(double)>&);
template std::optional<engine::NeighbourLists> delaunay_neighbours(const Pass<3>&, const std::function<void(double)>&);

}  // namespace tessera::front
