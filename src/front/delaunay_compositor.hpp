// The compositor behind tessera::delaunay: reads the Delaunay simplices off
// the cells' topological coordinates, plus what hull completion needs.
//
// Every vertex of cell g whose planes are all bisectors (no box plane) is the
// circumcentre of the simplex {g, plane ids}. Each such simplex is seen by all
// D+1 of its cells and emitted by the lowest id only, so no global
// deduplication is needed. For hull completion the compositor also reports
// the *open facets* of the found complex: a Voronoi edge (3D; a Voronoi vertex
// pair in 2D) that runs from a found simplex's circumcentre to the box is a
// facet whose other simplex was not found, and the generators whose cells
// reach the box (the only candidates for the missing simplices: a missing
// circumcentre lies outside the box, inside the cells of all its generators).
//
// Each simplex is oriented as it is emitted, from the cell's topology alone
// (emit): no predicate, no coordinates.
//
// With skipped cells (DelaunayOptions::skip_cells; docs/design.md, "Skipped
// cells") a simplex is emitted by its lowest *built* id; a row whose lowest
// id is a skipped point is kept apart (`foreign`) and laid out under that
// point by write(). A simplex of skipped points only is found by no cell:
// the facets of skipped points only that some found simplex holds are
// recorded, and those held once are open facets, which completion closes.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include "tessera/buffer.hpp"
#include "tessera/kernels/cell_builder.hpp"
#include "tessera/kernels/hull.hpp"
#include "tessera/kernels/tile.hpp"
#include "point_buckets.hpp"

namespace tessera::front {

template <int D>
struct OpenFacet {
  std::array<std::int32_t, D> facet;  ///< ids, ascending
  std::int32_t apex;                  ///< the found simplex's other vertex
  auto operator<=>(const OpenFacet&) const = default;
};

/// A row's sort key: its first id (the lowest), then the others ascending; the
/// key of an oriented row is its ascending form.
template <int D>
std::array<std::int32_t, D + 1> simplex_key(const std::int32_t* row) {
  std::array<std::int32_t, D + 1> k;
  std::copy(row, row + D + 1, k.begin());
  std::sort(k.begin() + 1, k.end());
  return k;
}

/// What the compositor leaves for the front end after the pass (finish);
/// the simplices themselves stay in the compositor until write().
template <int D>
struct DelaunayPassResult {
  std::size_t found = 0;                   ///< simplices the cells found
  std::vector<OpenFacet<D>> open;          ///< ascending
  std::vector<std::uint8_t> touches_box;   ///< per point (hull info only)
  /// With labels: some inside cell has a face on the domain box (it reaches
  /// beyond the box: hull simplices may have circumcentres there).
  bool labelled_cell_touches_box = false;
  std::vector<std::pair<std::int32_t, std::int32_t>> duplicates;
  /// Simplices whose lowest id is a skipped point (oriented rows, their
  /// lowest id first: that point has no cell to lay them out under).
  std::vector<std::array<std::int32_t, D + 1>> foreign;
};

template <class CellT>
class DelaunayCompositor {
 public:
  static constexpr int D = CellT::dim;
  using Simplex = std::array<std::int32_t, D + 1>;

  struct Pending {  // a simplex in ascending order and its orientation
    Simplex row;
    int sign;
  };
  struct Batch {
    std::vector<std::int32_t> gen, dup_of;
    std::vector<std::uint32_t> simplex_end;  // running end into simplices, per generator
    std::vector<Simplex> simplices;
    std::vector<OpenFacet<D>> open;
    std::vector<std::int32_t> touches_box;
    bool labelled_touch = false;             // labels: a cell of this batch has a box face
    std::vector<Simplex> foreign;            // rows whose lowest id is skipped
    std::vector<OpenFacet<D>> skipped_facets;  // facets of skipped points only, apex the generator
    std::vector<Pending> pending;  // scratch of add()
    std::vector<std::uint8_t> plane_skipped;  // scratch of add(): per plane of the cell
  };

  /// `hull_info`: also collect open facets and box-touching generators.
  /// `skipped` (empty, or one flag per point; only with hull_info): points
  /// whose cells are not built (see docs/design.md, "Skipped cells"). A
  /// simplex is then emitted by its lowest id among the built points, and
  /// the facets of skipped points only that one found simplex holds are
  /// open facets too.
  DelaunayCompositor(DelaunayPassResult<D>& out, std::size_t n_points, std::span<const std::int32_t> labels,
                     bool hull_info, std::span<const std::uint8_t> skipped = {})
      : out_(out), n_(n_points), labels_(labels), hull_info_(hull_info), skipped_(skipped) {
    // The cells look their neighbours up in a bit set: an eighth of the
    // bytes, so it stays in cache (a byte per point cost a cache miss per
    // neighbour, on ids in input order).
    if (!skipped_.empty()) {
      skipped_bits_.assign((n_ + 63) / 64, 0);
      for (std::size_t i = 0; i < n_; ++i) skipped_bits_[i >> 6] |= std::uint64_t{skipped_[i] != 0} << (i & 63);
    }
  }

  /// Record each built cell's squared security radius at its generator's
  /// index (sized for every point), as CellsCompositor::record_reach: the
  /// periodic triangulation checks its images' layer by it.
  void record_reach(std::vector<double>* reach) { reach_ = reach; }

  void add(Batch& b, std::int32_t gen, const kernels::BuildStatus& st, CellT& cell) {
    b.gen.push_back(gen);
    b.dup_of.push_back(st.has_cell ? -1 : st.duplicate_of);
    if (st.has_cell && reach_ != nullptr) [[unlikely]]
      (*reach_)[static_cast<std::size_t>(gen)] = cell.security_radius2();
    if (st.has_cell) {
      const auto& verts = cell.vertices();
      const auto& planes = cell.planes();
      // Only a cell with a vertex on the box can hold an open facet: nearly
      // every cell of a large input has none and skips that search.
      bool touches = false;
      if (hull_info_ || !labels_.empty())
        for (const auto& v : verts)
          for (int k = 0; k < D; ++k) touches |= v.p[k] < CellT::box_planes;
      b.labelled_touch |= touches && !labels_.empty();
      b.pending.clear();
      // Per plane: whether its generator is skipped (one lookup per
      // neighbour, not one per vertex and id).
      if (!skipped_.empty()) {
        b.plane_skipped.resize(planes.size());
        for (std::size_t k = 0; k < planes.size(); ++k)
          b.plane_skipped[k] = planes[k].id >= 0 && is_skipped(planes[k].id);
      }
      for (std::size_t t = 0; t < verts.size(); ++t) {
        std::array<std::int32_t, D> ids;
        for (int k = 0; k < D; ++k) ids[k] = planes[verts[t].p[k]].id;
        const std::int32_t lowest = *std::min_element(ids.begin(), ids.end());
        // Ours to emit when every other generator has a higher id; box
        // planes have negative ids, so this also skips vertices on the box.
        // Three of a uniform cell's four vertices fail here.
        if (lowest > gen) {
          bool inside = true;
          if (!labels_.empty())
            for (int k = 0; k < D; ++k) inside &= labels_[static_cast<std::size_t>(ids[k])] >= 0;
          if (inside) emit(b, gen, ids);
          if (!skipped_.empty() && all_skipped(b, verts[t])) {
            auto asc = ids;
            std::sort(asc.begin(), asc.end());
            record_skipped_facet(b, gen, asc);
          }
        } else if (!skipped_.empty() && lowest >= 0) {
          // Ours all the same when every lower id is skipped: it has no cell.
          bool ours = true;
          for (int k = 0; k < D; ++k) ours &= ids[k] > gen || b.plane_skipped[verts[t].p[k]];
          if (ours) emit_beside_skipped(b, gen, ids, all_skipped(b, verts[t]));
        }
        if (hull_info_ && touches && lowest >= 0) open_facets(b, gen, cell, t);
      }
      place_in_order(b);
      if (hull_info_ && touches) b.touches_box.push_back(gen);
    } else if (st.duplicate_of < 0) {  // (no cell and no duplicate)
      // An empty power cell (within the box): the point may still be a
      // vertex of simplices whose orthocentres lie beyond the box, so it is
      // a candidate of completion like the cells that reach the box.
      if (hull_info_) b.touches_box.push_back(gen);
    }
    b.simplex_end.push_back(static_cast<std::uint32_t>(b.simplices.size()));
  }

  void finish(std::span<Batch> batches) {
    // Each generator's simplex count, at its id: every generator lies in
    // exactly one batch, so all batches write at once without conflict. The
    // batches' rows are kept (moved, not copied) for write().
    count_.assign(n_, 0);
    tbb::parallel_for(std::size_t(0), batches.size(), [&](std::size_t k) {
      const Batch& b = batches[k];
      for (std::size_t t = 0; t < b.gen.size(); ++t)
        count_[static_cast<std::size_t>(b.gen[t])] = b.simplex_end[t] - (t == 0 ? 0 : b.simplex_end[t - 1]);
    });
    kept_.resize(batches.size());
    for (std::size_t k = 0; k < batches.size(); ++k) {
      Batch& b = batches[k];
      out_.found += b.simplices.size();
      out_.labelled_cell_touches_box |= b.labelled_touch;
      for (std::size_t t = 0; t < b.gen.size(); ++t)
        if (b.dup_of[t] >= 0) out_.duplicates.emplace_back(b.gen[t], b.dup_of[t]);
      kept_[k].gen = std::move(b.gen);
      kept_[k].simplex_end = std::move(b.simplex_end);
      kept_[k].simplices = std::move(b.simplices);
    }
    if (hull_info_) {
      out_.touches_box.assign(n_, 0);
      std::vector<OpenFacet<D>> skipped_facets;
      for (const Batch& b : batches) {
        out_.open.insert(out_.open.end(), b.open.begin(), b.open.end());
        for (std::int32_t g : b.touches_box) out_.touches_box[static_cast<std::size_t>(g)] = 1;
        out_.foreign.insert(out_.foreign.end(), b.foreign.begin(), b.foreign.end());
        skipped_facets.insert(skipped_facets.end(), b.skipped_facets.begin(), b.skipped_facets.end());
      }
      out_.found += out_.foreign.size();
      // A facet of skipped points only is held by the found simplices on
      // each side that have a built point: both (two records, closed) or
      // one (open: the simplex beyond it has skipped points only, or its
      // circumcentre lies outside the box).
      tbb::parallel_sort(skipped_facets.begin(), skipped_facets.end());
      for (std::size_t i = 0; i < skipped_facets.size();) {
        std::size_t j = i + 1;
        while (j < skipped_facets.size() && skipped_facets[j].facet == skipped_facets[i].facet) ++j;
        if (j == i + 1) out_.open.push_back(skipped_facets[i]);
        i = j;
      }
      tbb::parallel_sort(out_.open.begin(), out_.open.end());
    }
  }

  /// Every simplex as rows of D+1 ids into `rows`, ascending by key
  /// (simplex_key): the found ones with `extra` merged in (oriented rows,
  /// each with its lowest id first, in any order: hull completion's, and
  /// the foreign ones of skipped generators). Extra rows are bucketed by
  /// their lowest id (a counting sort) and each bucket sorted by key; then
  /// each generator's rows, found and extra, hold it as their lowest id and
  /// come ascending, so laying them out in generator order sorts the whole
  /// list; generators are written in parallel, straight into their final
  /// place.
  void write(const std::vector<Simplex>& unsorted_extra, Buffer<std::int32_t>& rows) {
    // The extra rows by lowest id (bucket_rows: one histogram per chunk of
    // rows, no atomics; with an atomic counter per point, the ~2M foreign
    // rows of 1M points took 0.057 s to bucket, 0.039 s now).
    std::vector<std::int64_t> extra_begin;
    std::vector<Simplex> extra;
    bucket_rows(
        n_, unsorted_extra.size(), [](std::size_t) { return 1; },
        [&](std::size_t r, std::size_t) { return unsorted_extra[r][0]; },
        [&](std::size_t r, std::size_t) { return unsorted_extra[r]; }, extra_begin, extra);
    std::vector<std::int64_t> offset(n_ + 1, 0);
    for (std::size_t g = 0; g < n_; ++g) offset[g + 1] = offset[g] + count_[g] + (extra_begin[g + 1] - extra_begin[g]);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n_, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t g = r.begin(); g != r.end(); ++g)
        if (extra_begin[g + 1] - extra_begin[g] > 1)
          std::sort(extra.begin() + extra_begin[g], extra.begin() + extra_begin[g + 1], key_less);
    });
    rows.resize(static_cast<std::size_t>(offset[n_]) * (D + 1));  // every row is written below
    tbb::parallel_for(std::size_t(0), kept_.size(), [&](std::size_t k) {
      const Kept& b = kept_[k];
      const std::size_t m = b.gen.size();
      for (std::size_t t = 0; t < m; ++t) {
        // Generators come in bin order, so their rows land all over the
        // output (and their offsets all over the table): fetch both ahead,
        // the offset first, the rows once their offset has arrived.
        if (t + 2 * prefetch_ahead < m) __builtin_prefetch(&offset[static_cast<std::size_t>(b.gen[t + 2 * prefetch_ahead])]);
        if (t + prefetch_ahead < m)
          __builtin_prefetch(rows.data() + static_cast<std::size_t>(offset[static_cast<std::size_t>(b.gen[t + prefetch_ahead])]) * (D + 1), 1);
        const auto g = static_cast<std::size_t>(b.gen[t]);
        std::int32_t* o = rows.data() + static_cast<std::size_t>(offset[g]) * (D + 1);
        const Simplex* s = b.simplices.data() + (t == 0 ? 0 : b.simplex_end[t - 1]);
        const Simplex* s_end = b.simplices.data() + b.simplex_end[t];
        const Simplex* x = extra.data() + extra_begin[g];
        const Simplex* x_end = extra.data() + extra_begin[g + 1];
        while (s != s_end || x != x_end) {
          const bool take_extra = s == s_end || (x != x_end && simplex_key<D>(x->data()) < simplex_key<D>(s->data()));
          const Simplex& r = take_extra ? *x++ : *s++;
          o = std::copy(r.begin(), r.end(), o);
        }
      }
    });
    // Skipped generators have no batch: their rows are all extra.
    if (!skipped_.empty())
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n_, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t g = r.begin(); g != r.end(); ++g) {
          if (!is_skipped(static_cast<std::int32_t>(g))) continue;
          std::int32_t* o = rows.data() + static_cast<std::size_t>(offset[g]) * (D + 1);
          for (std::int64_t x = extra_begin[g]; x != extra_begin[g + 1]; ++x)
            o = std::copy(extra[x].begin(), extra[x].end(), o);
        }
      });
    kept_.clear();
  }

 private:
  static constexpr std::size_t prefetch_ahead = 8;  // generators (write)

  // simplex_key(x) < simplex_key(y) for oriented rows (ascending but for a
  // swap of the last two), without building the keys.
  static bool key_less(const Simplex& x, const Simplex& y) {
    for (int k = 0; k + 1 < D; ++k)
      if (x[k] != y[k]) return x[k] < y[k];
    const std::int32_t xa = std::min(x[D - 1], x[D]), ya = std::min(y[D - 1], y[D]);
    if (xa != ya) return xa < ya;
    return std::max(x[D - 1], x[D]) < std::max(y[D - 1], y[D]);
  }

  // Append the pending rows to b.simplices ascending by key, oriented. All
  // share row[0] (the generator), so the key is (row[1], row[2]) packed in
  // 64 bits, then row[D]. A cell emits a handful (~7 in 3D), so each row's
  // place is the count of rows below it: n^2 branch-free comparisons, which
  // beat a sort's mispredicted branches at this size (a rare larger set is
  // sorted).
  void place_in_order(Batch& b) {
    const std::size_t m = b.pending.size();
    const std::size_t base = b.simplices.size();
    b.simplices.resize(base + m);
    if (m > max_ranked) {
      std::sort(b.pending.begin(), b.pending.end(), [](const Pending& x, const Pending& y) { return x.row < y.row; });
      for (std::size_t i = 0; i < m; ++i) place(b, base + i, b.pending[i]);
      return;
    }
    std::int64_t key[max_ranked];
    std::int32_t last[max_ranked];
    for (std::size_t j = 0; j < m; ++j) {
      const Simplex& r = b.pending[j].row;
      key[j] = D == 3 ? (static_cast<std::int64_t>(r[1]) << 32) | r[2] : r[1];
      last[j] = r[D];
    }
    for (std::size_t i = 0; i < m; ++i) {
      std::size_t below = 0;
      for (std::size_t j = 0; j < m; ++j) below += (key[j] < key[i]) | ((key[j] == key[i]) & (last[j] < last[i]));
      place(b, base + below, b.pending[i]);
    }
  }
  static constexpr std::size_t max_ranked = 64;

  void place(Batch& b, std::size_t at, const Pending& e) {
    Simplex& r = b.simplices[at] = e.row;
    if (e.sign < 0) std::swap(r[D - 1], r[D]);
  }

  // Queue the simplex {gen, ids} of vertex v (ids in v's plane order),
  // oriented. The cell keeps every vertex's planes counter-clockwise seen
  // from outside (3D; in 2D the arriving edge's plane, then the leaving
  // one's, around a counter-clockwise polygon), so their outward normals
  // p_id - p_gen have a positive determinant: {gen, ids} in that order is
  // positively oriented, exactly, by the cell's exact topology. The ids are
  // sorted ascending and each swap flips the orientation. (A flat simplex
  // cannot arise: its three bisectors would not meet in a vertex.)
  void emit(Batch& b, std::int32_t gen, std::array<std::int32_t, D> ids) {
    int sign = 1;
    auto order = [&](int a, int c) {
      const bool swap = ids[c] < ids[a];
      const std::int32_t lo = swap ? ids[c] : ids[a], hi = swap ? ids[a] : ids[c];
      ids[a] = lo;
      ids[c] = hi;
      sign = swap ? -sign : sign;
    };
    order(0, 1);
    if constexpr (D == 3) {
      order(1, 2);
      order(0, 1);
    }
    Pending& e = b.pending.emplace_back();
    e.row[0] = gen;
    std::copy(ids.begin(), ids.end(), e.row.begin() + 1);
    e.sign = sign;
  }

  // Facets {gen, shared planes} of the found simplex at vertex t whose Voronoi
  // edge (3D) / neighbouring vertex (2D) ends on the box; emitted by the lowest id.
  void open_facets(Batch& b, std::int32_t gen, const CellT& cell, std::size_t t) {
    const auto& verts = cell.vertices();
    const auto& planes = cell.planes();
    auto emit = [&](std::array<std::int32_t, D - 1> shared, std::int32_t apex) {
      for (std::int32_t id : shared)  // reported by its lowest built id
        if (id < gen && (skipped_.empty() || !is_skipped(id))) return;
      OpenFacet<D> f;
      f.facet[0] = gen;
      std::copy(shared.begin(), shared.end(), f.facet.begin() + 1);
      std::sort(f.facet.begin(), f.facet.end());  // gen may follow skipped ids
      f.apex = apex;
      b.open.push_back(f);
    };
    if constexpr (D == 3) {
      const auto& v = verts[t];
      for (int k = 0; k < 3; ++k) {
        const auto& w = verts[cell.across(t, k)];
        bool box = false;
        for (int m = 0; m < 3; ++m) box |= planes[w.p[m]].id < 0;
        if (box) emit({planes[v.p[k]].id, planes[v.p[(k + 1) % 3]].id}, planes[v.p[(k + 2) % 3]].id);
      }
    } else {
      // Tile: vertex t sits between the edge on plane p[0] (from t-1) and the
      // edge on plane p[1] (to t+1).
      const std::size_t nv = verts.size();
      const auto& v = verts[t];
      const auto& next = verts[(t + 1) % nv];
      const auto& prev = verts[(t + nv - 1) % nv];
      if (planes[next.p[1]].id < 0) emit({planes[v.p[1]].id}, planes[v.p[0]].id);
      if (planes[prev.p[0]].id < 0) emit({planes[v.p[0]].id}, planes[v.p[1]].id);
    }
  }

  template <class Vertex>
  static bool all_skipped(const Batch& b, const Vertex& v) {
    bool all = true;
    for (int k = 0; k < D; ++k) all &= b.plane_skipped[v.p[k]] != 0;
    return all;
  }

  // The simplex {gen, ids} of a cell vertex whose lower ids are all skipped
  // points: ours to emit (emitted by its lowest built id). Its row goes to
  // `foreign`, fully ascending with the orientation's swap, as hull
  // completion's rows. When every other id is skipped, the facet they form
  // is recorded: if no other found simplex holds it, it is open.
  void emit_beside_skipped(Batch& b, std::int32_t gen, std::array<std::int32_t, D> ids, bool others_skipped) {
    // Orientation: {gen, ids} in the vertex's plane order is positive (emit).
    // Sort ids ascending, counting swaps, then move gen to its place.
    int sign = 1;
    for (int i = 1; i < D; ++i)
      for (int j = i; j > 0 && ids[j] < ids[j - 1]; --j) {
        std::swap(ids[j], ids[j - 1]);
        sign = -sign;
      }
    Simplex row;
    int below = 0;
    for (int k = 0; k < D; ++k) below += ids[k] < gen;
    for (int k = 0, m = 0; k <= D; ++k) row[k] = k == below ? gen : ids[m++];
    if (below & 1) sign = -sign;
    if (sign < 0) std::swap(row[D - 1], row[D]);
    b.foreign.push_back(row);
    if (others_skipped) record_skipped_facet(b, gen, ids);
  }

  void record_skipped_facet(Batch& b, std::int32_t gen, const std::array<std::int32_t, D>& ascending) {
    OpenFacet<D> f;
    f.facet = ascending;
    f.apex = gen;
    b.skipped_facets.push_back(f);
  }

  struct Kept {  // a batch's rows, from finish() to write()
    std::vector<std::int32_t> gen;
    std::vector<std::uint32_t> simplex_end;
    std::vector<Simplex> simplices;
  };

  DelaunayPassResult<D>& out_;
  std::vector<std::uint32_t> count_;  // per generator: its found simplices
  std::vector<Kept> kept_;
  std::size_t n_;
  std::span<const std::int32_t> labels_;
  std::vector<double>* reach_ = nullptr;  // record_reach
  bool hull_info_;
  std::span<const std::uint8_t> skipped_;
  std::vector<std::uint64_t> skipped_bits_;  // skipped_ as bits

  bool is_skipped(std::int32_t id) const {
    const auto i = static_cast<std::size_t>(id);
    return (skipped_bits_[i >> 6] >> (i & 63)) & 1;
  }
};

}  // namespace tessera::front
