// BRIO order and guides; see insertion_order.hpp.
#include "insertion_order.hpp"

#include <algorithm>
#include <bit>
#include <limits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include "id_hash.hpp"
#include "tessera/buffer.hpp"

namespace tessera::front {
namespace {

// 21 bits of x spread to every third bit.
std::uint64_t spread3(std::uint64_t x) {
  x &= 0x1FFFFF;
  x = (x | x << 32) & 0x1F00000000FFFFull;
  x = (x | x << 16) & 0x1F0000FF0000FFull;
  x = (x | x << 8) & 0x100F00F00F00F00Full;
  x = (x | x << 4) & 0x10C30C30C30C30C3ull;
  x = (x | x << 2) & 0x1249249249249249ull;
  return x;
}

// 32 bits of x spread to every second bit.
std::uint64_t spread2(std::uint64_t x) {
  x &= 0xFFFFFFFF;
  x = (x | x << 16) & 0x0000FFFF0000FFFFull;
  x = (x | x << 8) & 0x00FF00FF00FF00FFull;
  x = (x | x << 4) & 0x0F0F0F0F0F0F0F0Full;
  x = (x | x << 2) & 0x3333333333333333ull;
  x = (x | x << 1) & 0x5555555555555555ull;
  return x;
}

}  // namespace

BrioOrder brio_order(const kernels::ExactContext& ctx, std::span<const std::int32_t> ids, const double* coords,
                     const double* lo, const double* hi) {
  // One 64-bit key per point: the round in the top bits (smallest rounds
  // first), then a Morton code of 19 bits per axis in 3D, 28 in 2D; ties go
  // by id. `at` is the point's place in ids, for its coordinates.
  struct Key {
    std::uint64_t key;
    std::int32_t id;
    std::uint32_t at;
  };
  const int D = ctx.dim;
  const auto uD = static_cast<std::size_t>(D);
  auto point = [&](std::size_t i) {
    return coords != nullptr ? coords + i * uD : ctx.points + static_cast<std::size_t>(ids[i]) * uD;
  };
  constexpr int max_round = 24;
  const int bits = D == 3 ? 19 : 28, code_bits = D * bits;
  const double top = static_cast<double>((std::uint64_t{1} << bits) - 1);
  Buffer<Key> keys(ids.size());  // every one written below
  // One scale for every axis, so that the curve's cells are cubes (squares):
  // scaled per axis, a box 1e4 times longer on one axis had its points
  // inserted in long thin columns, consecutive points far apart across each,
  // and the walks that locate them took 15 (2D) to 19 (3D) times a cube's
  // steps (400k points: 5.6 s, against 1.2 s for the same points in cubes).
  double extent = 0;
  for (int d = 0; d < D; ++d) extent = std::max(extent, hi[d] - lo[d]);
  const double scale = extent > 0 ? top / extent : 0.0;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, ids.size(), 1 << 14), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const double* p = point(i);
      std::uint64_t code = 0;
      for (int d = 0; d < D; ++d) {
        const auto c = static_cast<std::uint64_t>(std::clamp((p[d] - lo[d]) * scale, 0.0, top));
        code |= (D == 3 ? spread3(c) : spread2(c)) << d;
      }
      const int round = std::min(std::countl_zero(id_hash(ids[i])), max_round);
      keys[i] = {static_cast<std::uint64_t>(max_round - round) << code_bits | code, ids[i], static_cast<std::uint32_t>(i)};
    }
  });
  tbb::parallel_sort(keys.begin(), keys.end(),
                     [](const Key& a, const Key& b) { return a.key != b.key ? a.key < b.key : a.id < b.id; });
  BrioOrder order;
  order.ids.resize(ids.size());
  order.codes.resize(ids.size());
  order.coords.resize(ids.size() * uD);  // every one written below
  const std::uint64_t code_mask = (std::uint64_t{1} << code_bits) - 1;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, keys.size(), 1 << 14), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      order.ids[i] = keys[i].id;
      order.codes[i] = keys[i].key & code_mask;
      const double* p = point(keys[i].at);
      for (std::size_t d = 0; d < uD; ++d) order.coords[i * uD + d] = p[d];
    }
  });
  for (std::size_t i = 0; i < keys.size(); ++i) {
    if (i == 0 || keys[i].key >> code_bits != keys[i - 1].key >> code_bits) order.rounds.push_back(i);
  }
  order.rounds.push_back(ids.size());
  return order;
}

std::vector<std::int32_t> brio_guides(int dim, const BrioOrder& order) {
  const auto D = static_cast<std::size_t>(dim);
  auto at = [&](std::size_t k) { return order.coords.data() + k * D; };
  std::vector<std::int32_t> guide(order.ids.size(), -1);
  for (std::size_t r = 1; r + 1 < order.rounds.size(); ++r) {
    const std::size_t pa = order.rounds[r - 1], a = order.rounds[r], b = order.rounds[r + 1];
    tbb::parallel_for(tbb::blocked_range<std::size_t>(a, b, 1 << 13), [&](const tbb::blocked_range<std::size_t>& range) {
      // The first of the previous round with a code above q's.
      std::size_t j = static_cast<std::size_t>(
          std::upper_bound(order.codes.begin() + static_cast<std::ptrdiff_t>(pa), order.codes.begin() + static_cast<std::ptrdiff_t>(a),
                           order.codes[range.begin()]) - order.codes.begin());
      for (std::size_t i = range.begin(); i != range.end(); ++i) {
        while (j < a && order.codes[j] <= order.codes[i]) ++j;
        double best = std::numeric_limits<double>::infinity();
        for (const std::size_t k : {j - 1, j}) {
          if (k < pa || k >= a) continue;
          double r2 = 0;
          for (std::size_t e = 0; e < D; ++e) r2 += (at(k)[e] - at(i)[e]) * (at(k)[e] - at(i)[e]);
          if (r2 < best) {
            best = r2;
            guide[i] = static_cast<std::int32_t>(k);
          }
        }
      }
    });
  }
  return guide;
}

}  // namespace tessera::front
