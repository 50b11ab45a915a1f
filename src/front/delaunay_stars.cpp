#include "delaunay_stars.hpp"

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include <tbb/parallel_for.h>

#include "insertion.hpp"
#include "tessera/buffer.hpp"
#include "tessera/engine/thread_arena.hpp"

namespace tessera::front {

template <int D>
std::optional<engine::DelaunayStars> delaunay_stars(const Pass<D>& pass, const std::function<void(double)>& progress) {
  constexpr int W = D + 1;
  const auto& loc = *pass.locator;
  const std::size_t n = pass.points.size() / D, located = loc.size();
  engine::DelaunayStars out;
  bool flat = false;
  engine::ThreadArena(pass.engine_options.threads).execute([&] {
    LocatedInsertion ins = insert_located(pass, progress);
    if (!ins.rows) {
      flat = true;
      return;
    }
    out.rows = std::move(*ins.rows);
    // Rows of slots from here on: the cells run in slot order, where
    // neighbouring points share most of their simplices, and read the
    // locator's slot-ordered copies.
    // Buffers: read and written at random over n entries, through huge
    // pages (Buffer) rather than 4 KiB ones; only located ids are read.
    Buffer<std::uint32_t> slot_of(n);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, located), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t k = r.begin(); k != r.end(); ++k) slot_of[static_cast<std::size_t>(loc.id(k))] = static_cast<std::uint32_t>(k);
    });
    const std::size_t m = out.rows.size();
    auto* const rows = reinterpret_cast<std::uint32_t*>(out.rows.data());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, m), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t k = r.begin(); k != r.end(); ++k) rows[k] = slot_of[rows[k]];
    });
    // Each slot's simplices, ascending (m < 2^32: the insertion holds
    // fewer than 2^29 simplices). The rows are cut into one part per
    // thread (at most 8: each has a count per slot); each part counts its
    // entries per slot, and fills them after those of the parts before it,
    // so every slot's list is ascending whatever the number of parts.
    const std::size_t nparts = std::clamp<std::size_t>(static_cast<std::size_t>(pass.engine_options.threads), 1, 8);
    std::vector<Buffer<std::uint32_t>> at(nparts, Buffer<std::uint32_t>(located, 0));
    auto part_range = [&](std::size_t c) { return std::pair{m * c / nparts, m * (c + 1) / nparts}; };
    tbb::parallel_for(std::size_t{0}, nparts, [&](std::size_t c) {
      const auto [a, e] = part_range(c);
      std::uint32_t* const cnt = at[c].data();
      for (std::size_t k = a; k < e; ++k) ++cnt[rows[k]];
    });
    out.first.assign(located + 1, 0);
    for (std::size_t k = 0; k < located; ++k) {
      std::uint32_t next = out.first[k];
      for (std::size_t c = 0; c < nparts; ++c) {  // counts become each part's first place
        const std::uint32_t n_c = at[c][k];
        at[c][k] = next;
        next += n_c;
      }
      out.first[k + 1] = next;
    }
    out.simplices.resize(m);
    tbb::parallel_for(std::size_t{0}, nparts, [&](std::size_t c) {
      const auto [a, e] = part_range(c);
      std::uint32_t* const place = at[c].data();
      for (std::size_t k = a; k < e; ++k) out.simplices[place[rows[k]]++] = static_cast<std::uint32_t>(k / W);
    });
  });
  if (flat) return std::nullopt;
  return out;
}

template std::optional<engine::DelaunayStars> delaunay_stars(const Pass<2>&, const std::function<void(double)>&);
template std::optional<engine::DelaunayStars> delaunay_stars(const Pass<3>&, const std::function<void(double)>&);

}  // namespace tessera::front
