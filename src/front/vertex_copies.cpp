// tessera::vertex_copies: copies of one vertex in a periodic face set
// (include/tessera/faces.hpp).
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <numeric>
#include <stdexcept>
#include <tuple>
#include <vector>

#include "tessera/faces.hpp"

namespace tessera {

/// Groups of copies of one vertex, by keys equal up to a common shift: each
/// key with its points' shifts taken relative to its first point's (box
/// planes, walls, have no shift). Every vertex its own group in a face set
/// that is not periodic.
VertexCopies vertex_copies(const FaceSet& fs) {
  const std::size_t nv = fs.n_vertices();
  VertexCopies out;
  out.group.resize(nv);
  if (!fs.is_periodic()) {
    std::iota(out.group.begin(), out.group.end(), 0);
    out.first = out.group;
    return out;
  }
  const auto du = static_cast<std::size_t>(fs.dim), kn = du + 1;
  if ((du != 2 && du != 3) || fs.vertex_keys.size() != nv * kn || fs.vertex_key_shifts.size() != nv * kn * du)
    throw std::invalid_argument("vertex_copies: a periodic face set needs dim 2 or 3 and a shift per key entry");
  // Per vertex: its key, relative shifts, and the first point's shift t.
  struct Row {
    std::array<std::int32_t, 4> id{};
    std::array<std::int32_t, 12> rel{};
    std::array<std::int32_t, 3> t{};
  };
  std::vector<Row> row(nv);
  for (std::size_t v = 0; v < nv; ++v) {
    Row& r = row[v];
    const std::int32_t* key = &fs.vertex_keys[v * kn];
    const std::int8_t* s = &fs.vertex_key_shifts[v * kn * du];
    std::size_t lead = 0;
    while (lead < kn && key[lead] < 0) ++lead;  // box planes sort first; a vertex has a point
    for (std::size_t a = 0; a < du && lead < kn; ++a) r.t[a] = s[lead * du + a];
    for (std::size_t e = 0; e < kn; ++e) {
      r.id[e] = key[e];
      for (std::size_t a = 0; a < du; ++a) r.rel[e * du + a] = key[e] < 0 ? 0 : s[e * du + a] - r.t[a];
    }
  }
  std::vector<std::int32_t> order(nv);
  std::iota(order.begin(), order.end(), 0);
  auto same = [&](std::int32_t a, std::int32_t b) {
    const Row& x = row[static_cast<std::size_t>(a)];
    const Row& y = row[static_cast<std::size_t>(b)];
    return x.id == y.id && x.rel == y.rel;
  };
  std::stable_sort(order.begin(), order.end(), [&](std::int32_t a, std::int32_t b) {
    const Row& x = row[static_cast<std::size_t>(a)];
    const Row& y = row[static_cast<std::size_t>(b)];
    return std::tie(x.id, x.rel) < std::tie(y.id, y.rel);
  });
  // Groups numbered by their first vertex: mark each run's lowest id.
  std::vector<std::int32_t> lead_of(nv);
  for (std::size_t b = 0; b < nv;) {
    std::size_t e = b + 1;
    while (e < nv && same(order[b], order[e])) ++e;
    for (std::size_t k = b; k < e; ++k) lead_of[static_cast<std::size_t>(order[k])] = order[b];  // stable: lowest id
    b = e;
  }
  std::vector<std::int32_t> number(nv, -1);
  for (std::size_t v = 0; v < nv; ++v) {
    const auto l = static_cast<std::size_t>(lead_of[v]);
    if (number[l] < 0) {
      number[l] = static_cast<std::int32_t>(out.first.size());
      out.first.push_back(static_cast<std::int32_t>(l));
    }
    out.group[v] = number[l];
  }
  out.shift.resize(nv * du);
  for (std::size_t v = 0; v < nv; ++v) {
    const Row& lead = row[static_cast<std::size_t>(out.first[static_cast<std::size_t>(out.group[v])])];
    for (std::size_t a = 0; a < du; ++a) out.shift[v * du + a] = row[v].t[a] - lead.t[a];
  }
  return out;
}

}  // namespace tessera
