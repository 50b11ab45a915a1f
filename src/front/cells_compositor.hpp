// The compositor behind tessera::voronoi: per-cell measures, neighbour lists
// and (optionally) the conformal mesh merged by topological coordinate.
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <string>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numeric>
#include <span>
#include <stdexcept>
#include <utility>
#include <vector>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "cell_geometry.hpp"
#include "release_memory.hpp"
#include "tessera/cells.hpp"
#include "tessera/engine/classifier.hpp"
#include "tessera/kernels/cell_builder.hpp"
#include "tessera/kernels/dual_faces.hpp"

namespace tessera::front {

template <class CellT>
class CellsCompositor {
 public:
  static constexpr int D = CellT::dim;
  /// Batch::dup_of of a generator whose power cell came out empty (Cells::empty_cells).
  static constexpr std::int32_t empty_cell = -2;

  /// A cell's measures. add() appends them to its thread's store, in batch
  /// order, and finish() places them by cell: written by generator id from
  /// the cell loop (until stop 64), they landed all over three arrays, on
  /// input in no spatial order a cache miss each, and cells took 4% (3D)
  /// to 8% (2D) longer than with the same writes in order.
  struct Measures {
    double volume;  // in the input's units
    double centroid[D];
    std::int32_t faces;
  };

  /// A thread's variable-length output: the batches it built, one after
  /// another, each a contiguous run in every array. One growing Buffer per
  /// array (on huge pages once large) in place of small vectors per batch:
  /// fewer first-touch page faults (docs/design.md, stop 49).
  struct Store {
    Buffer<std::int32_t> nbrs;             // neighbour ids, ascending per cell
    Buffer<Measures> measures;             // one per generator (zero: no cell)
    // mesh: each cell in dual form (kernels/dual_faces.hpp), its faces numbered
    // within the cell: a vertex is its D faces, a face its neighbour id
    Buffer<kernels::Corners<D>> corners;   // (Buffers: resized, then written)
    Buffer<double> pos;                    // absolute coordinates: every vertex's, or the owned ones'
    Buffer<std::int32_t> face_nbr;
  };

  struct Batch {
    std::vector<std::int32_t> gen;          // every generator of the batch, in order
    std::vector<std::int32_t> dup_of;       // -1; the owner it duplicates (no cell); empty_cell

    // Per generator, running ends into the batch's runs in its thread's
    // store, which start at the bases. (One thread builds a whole batch, and
    // no other batch in between: the engine's workspaces rely on the same.)
    std::vector<std::uint32_t> nbr_end;
    std::vector<std::uint32_t> vert_end;    // into corners
    std::vector<std::uint32_t> pos_end;     // into pos, in vertices
    std::vector<std::uint32_t> face_end;    // into face_nbr
    Store* store = nullptr;
    std::size_t nbr_base = 0, corner_base = 0, pos_base = 0, face_base = 0, measure_base = 0;
    std::vector<std::uint32_t> face_of;     // add()'s scratch: a local plane's face number
    std::size_t assembled = 0;              // cells assembled from their stars
    // 3D cells of more than 65,535 faces (the centre of a sphere's points):
    // their corners keep the low 16 bits of each face number, and
    // high_corners the high ones, from wide[i].second for entry
    // wide[i].first (ascending). Corners of 32 bits for every vertex would
    // take 1M uniform cells' mesh 160 MB more.
    std::vector<std::pair<std::uint32_t, std::uint32_t>> wide;
    std::vector<kernels::Corners<D>> high_corners;

    const std::int32_t* nbrs() const { return store->nbrs.data() + nbr_base; }
    const Measures* measures() const { return store->measures.data() + measure_base; }
    const kernels::Corners<D>* corners() const { return store->corners.data() + corner_base; }
    const double* pos() const { return store->pos.data() + pos_base * D; }
    const std::int32_t* face_nbr() const { return store->face_nbr.data() + face_base; }
    /// Entry t's high corner halves (its first vertex's), or null: not a wide cell.
    const kernels::Corners<D>* high_of(std::size_t t) const {
      if (wide.empty()) [[likely]] return nullptr;
      const std::pair<std::uint32_t, std::uint32_t> sought{static_cast<std::uint32_t>(t), 0};
      const auto at = std::lower_bound(wide.begin(), wide.end(), sought);
      return at != wide.end() && at->first == t ? high_corners.data() + at->second : nullptr;
    }
  };

  /// The mesh: no two located points coincide (front::Pass leaves
  /// duplicates out), so a merged vertex's owner (the lowest generator of
  /// its key that owns a cell) is the lowest inside generator of its key,
  /// known when the cell is added. A cell lists its owned vertices first (a
  /// quarter of them: 3D vertices are shared by four cells) and keeps only
  /// their positions, and the mesh numbers them without finding their
  /// owners again.
  /// `frame_k`: the cells are computed on the input scaled by 2^frame_k
  /// (front/pass.cpp); volumes are stored in the input's units, the rest in
  /// the scaled frame. `box`: the domain in that frame, whose planes the
  /// mesh's vertices on them are set on.
  CellsCompositor(Cells& out, std::span<const std::int32_t> labels, bool mesh, int frame_k, const Bounds& box)
      : out_(out), labels_(labels), classify_(labels), mesh_(mesh), frame_k_(frame_k), box_(box) {}

  /// Record each built cell's security radius, squared (in the pass's
  /// frame), at its generator's index of `reach` (sized for every point):
  /// no point farther than that from the generator can clip the cell. The
  /// periodic driver (front/periodic.cpp) checks by it that the images it
  /// placed reach far enough.
  void record_reach(std::vector<double>* reach) { reach_ = reach; }

  /// Build some cells only (VoronoiOptions::only): bit g of `built` set
  /// (built[g / 64] >> g % 64) for each generator whose cell the pass
  /// builds, and those alone own merged vertices: a vertex belongs to the
  /// lowest generator of its key that is built, which is its owner in the
  /// whole computation wherever that one is built (the vertices of the
  /// cells asked for, whose neighbours are built with them).
  void build_only(std::span<const std::uint64_t> built) { built_ = built; }

  void add(Batch& b, std::int32_t gen, const kernels::BuildStatus& st, CellT& cell) {
    Store& s = b.gen.empty() ? start_batch(b) : *b.store;
    Buffer<std::int32_t>& nbrs = s.nbrs;
    b.assembled += st.assembled;
    b.gen.push_back(gen);
    // No cell and no duplicate: a power cell that others' spheres emptied.
    b.dup_of.push_back(st.has_cell ? -1 : st.duplicate_of >= 0 ? st.duplicate_of : empty_cell);
    if (!st.has_cell) {
      s.measures.push_back(Measures{});
      close_cell(b, s);
      return;
    }
    if (reach_ != nullptr) [[unlikely]]
      (*reach_)[static_cast<std::size_t>(gen)] = cell.security_radius2();
    const double* p = cell.site();
    const std::size_t nb0 = nbrs.size();
    std::int32_t nf = 0;
    // Spokes from the face planes; the mesh numbers the faces too.
    if (mesh_) {
      if (b.face_of.size() < cell.planes().size()) b.face_of.resize(cell.planes().size());
      for_each_face_plane(cell, [&](auto pl, std::int32_t id) {
        b.face_of[pl] = static_cast<std::uint32_t>(nf++);
        if (id >= 0) nbrs.push_back(id);
        s.face_nbr.push_back(id);
      });
      add_vertices(b, s, gen, cell, static_cast<std::size_t>(nf));
    } else {
      for_each_spoke(cell, [&](std::int32_t id) {
        ++nf;
        if (id >= 0) nbrs.push_back(id);
      });
    }
    double vol;
    std::array<double, D> c;
    const std::int32_t shift = measure(cell, vol, c);
    Measures& m = s.measures.emplace_back();  // every field written below
    // In the input's units, rounded once (the frame's 2^-k and the measure's
    // shift together: either alone may leave double's range).
    m.volume = shift == 0 && frame_k_ == 0 ? vol : std::ldexp(vol, D * (shift - frame_k_));
    for (int d = 0; d < D; ++d) m.centroid[d] = c[d] + p[d];
    m.faces = nf;
    sort_ids(nbrs.data() + nb0, nbrs.data() + nbrs.size());
    close_cell(b, s);
  }

  void finish(std::span<Batch> batches) {
    Cells& o = out_;
    const std::size_t n = o.n_points;
    for (const Batch& b : batches)
      for (std::size_t t = 0; t < b.gen.size(); ++t)
        if (b.dup_of[t] >= 0) o.duplicates.emplace_back(b.gen[t], b.dup_of[t]);
        else if (b.dup_of[t] == empty_cell) o.empty_cells.push_back(b.gen[t]);
    std::sort(o.duplicates.begin(), o.duplicates.end());
    std::sort(o.empty_cells.begin(), o.empty_cells.end());
    // Cells in generator-id order: when every point is a generator (no
    // outside labels, none ignored) and none is a duplicate, cell g is
    // generator g.
    std::size_t generators = 0;
    for (const Batch& b : batches) {
      generators += b.gen.size();
      o.assembled_from_stars += b.assembled;
    }
    dense_ = o.duplicates.empty() && o.empty_cells.empty() && generators == n;
    const bool dense = dense_;
    o.cell_of.assign(n, dense ? 1 : 0);
    // cell_of first holds 1 for a generator with a cell. Every generator
    // lies in exactly one batch, so all batches write at once.
    if (!dense)
      tbb::parallel_for(std::size_t(0), batches.size(), [&](std::size_t k) {
        const Batch& b = batches[k];
        for (std::size_t t = 0; t < b.gen.size(); ++t) o.cell_of[static_cast<std::size_t>(b.gen[t])] = b.dup_of[t] == -1;
      });
    std::int32_t nc = 0;
    for (std::size_t g = 0; g < n; ++g) o.cell_of[g] = o.cell_of[g] ? nc++ : -1;
    const std::size_t ncell = static_cast<std::size_t>(nc);
    // Output Buffers are sized, not zeroed: pass 1 writes every cell's
    // fields, the neighbour copy every entry.
    o.generator.resize(ncell);
    o.region.resize(ncell);
    o.volume.resize(ncell);
    o.centroid.resize(ncell * D);
    o.num_faces.resize(ncell);
    o.neighbor_offsets.assign(ncell + 1, 0);
    if (mesh_) o.cell_face_offsets.assign(ncell + 1, 0);
    std::vector<std::int64_t> face_count_vertices;  // per cell: total face-vertex entries
    if (mesh_) face_count_vertices.assign(ncell + 1, 0);


    // Pass 1: fixed-size fields and counts. Without duplicates the
    // generator and region columns are the identity and the labels, in order.
    if (dense)
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, ncell), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t c = r.begin(); c != r.end(); ++c) {
          o.generator[c] = static_cast<std::int32_t>(c);
          o.region[c] = labels_at(static_cast<std::int32_t>(c));
        }
      });
    tbb::parallel_for(std::size_t(0), batches.size(), [&](std::size_t k) {
      const Batch& b = batches[k];
      for (std::size_t t = 0; t < b.gen.size(); ++t) {
        fetch_ahead(b, t, [&](std::size_t c) {
          __builtin_prefetch(&o.volume[c], 1);
          __builtin_prefetch(&o.centroid[c * D], 1);
          __builtin_prefetch(&o.num_faces[c], 1);
          __builtin_prefetch(&o.neighbor_offsets[c + 1], 1);
        });
        std::int32_t g = b.gen[t];
        std::int32_t c = cell_at(g);
        if (c < 0) continue;
        std::size_t cu = static_cast<std::size_t>(c);
        if (!dense) {
          o.generator[cu] = g;
          o.region[cu] = labels_at(g);
        }
        const Measures& m = b.measures()[t];
        o.volume[cu] = m.volume;
        for (int d = 0; d < D; ++d) o.centroid[cu * D + d] = m.centroid[d];
        o.num_faces[cu] = m.faces;
        auto [n0, n1] = range_of(b.nbr_end, t);
        o.neighbor_offsets[cu + 1] = n1 - n0;
        if (mesh_) {
          auto [f0, f1] = range_of(b.face_end, t);
          o.cell_face_offsets[cu + 1] = f1 - f0;
          // Each vertex lies on D faces (a 2D face is an edge, two vertices).
          auto [v0, v1] = range_of(b.vert_end, t);
          face_count_vertices[cu + 1] = D * static_cast<std::int64_t>(v1 - v0);
        }
      }
    });
    for (Store& s : stores_) Buffer<Measures>().swap(s.measures);  // placed: freed before the neighbours' copy
    std::partial_sum(o.neighbor_offsets.begin(), o.neighbor_offsets.end(), o.neighbor_offsets.begin());
    o.neighbors.resize(static_cast<std::size_t>(o.neighbor_offsets.back()));
    tbb::parallel_for(std::size_t(0), batches.size(), [&](std::size_t k) {
      const Batch& b = batches[k];
      for (std::size_t t = 0; t < b.gen.size(); ++t) {
        fetch_ahead(b, t, [&](std::size_t c) { __builtin_prefetch(&o.neighbor_offsets[c]); });
        std::int32_t c = cell_at(b.gen[t]);
        if (c < 0) continue;
        if (t + prefetch_ahead / 2 < b.gen.size()) {
          const std::int32_t c2 = cell_at(b.gen[t + prefetch_ahead / 2]);
          if (c2 >= 0) __builtin_prefetch(o.neighbors.data() + o.neighbor_offsets[static_cast<std::size_t>(c2)], 1);
        }
        auto [n0, n1] = range_of(b.nbr_end, t);
        std::copy(b.nbrs() + n0, b.nbrs() + n1,
                  o.neighbors.begin() + o.neighbor_offsets[static_cast<std::size_t>(c)]);
      }
    });
    for (Store& s : stores_) Buffer<std::int32_t>().swap(s.nbrs);  // copied out: freed before the mesh's arrays
    if (mesh_) build_mesh(batches, face_count_vertices);
  }

 private:
  static constexpr std::size_t prefetch_ahead = 8;  // generators (finish)

  // Entry t's range in a batch array of running ends.
  static std::pair<std::uint32_t, std::uint32_t> range_of(const std::vector<std::uint32_t>& ends, std::size_t t) {
    return {t == 0 ? 0 : ends[t - 1], ends[t]};
  }

  // Generators come in bin order, so their cells' fields lie all over the
  // cell-ordered arrays: the loops over a batch fetch a cell's entries some
  // generators ahead, fetch(its cell index) (and, with duplicates, its cell
  // index before that).
  template <class Fetch>
  void fetch_ahead(const Batch& b, std::size_t t, Fetch&& fetch) const {
    if (!dense_ && t + 2 * prefetch_ahead < b.gen.size())
      __builtin_prefetch(&out_.cell_of[static_cast<std::size_t>(b.gen[t + 2 * prefetch_ahead])]);
    if (t + prefetch_ahead < b.gen.size()) {
      const std::int32_t c = cell_at(b.gen[t + prefetch_ahead]);
      if (c >= 0) fetch(static_cast<std::size_t>(c));
    }
  }

  // Batch b's runs start at the ends of this thread's store, returned (the
  // batch keeps it: no lookup per cell). A store's first
  // batch reserves room for its share of the cells and a half more (address
  // space only: pages are touched as they fill), so that a store seldom
  // doubles, whose copy would hold both sizes at once near the peak.
  Store& start_batch(Batch& b) {
    Store& s = stores_.local();
    if (s.nbrs.capacity() == 0) {
      const auto threads = static_cast<std::size_t>(std::max(1, tbb::this_task_arena::max_concurrency()));
      const std::size_t cells = out_.n_points / threads + out_.n_points / (2 * threads) + 64;
      // Typical counts per uniform cell (3D: 15.5 faces, 27 vertices, a
      // quarter of them owned; 2D: 6 of each), with room.
      s.nbrs.reserve(cells * (D == 3 ? 17 : 7));
      s.measures.reserve(cells);
      if (mesh_) {
        s.corners.reserve(cells * (D == 3 ? 30 : 7));
        s.pos.reserve(cells * D * (D == 3 ? 8 : 3));
        s.face_nbr.reserve(cells * (D == 3 ? 17 : 7));
      }
    }
    b.store = &s;
    b.nbr_base = s.nbrs.size();
    b.measure_base = s.measures.size();
    b.corner_base = s.corners.size();
    b.pos_base = s.pos.size() / D;
    b.face_base = s.face_nbr.size();
    return s;
  }

  // A cell's neighbour ids in ascending order. A cell has few (2D ~6, 3D
  // ~15): an insertion sort in registers, where std::sort's own insertion
  // step moved each new smallest id by a memmove call (2D cells ~7% of
  // their time, stop 50). Long lists (clustered input) go to std::sort.
  static void sort_ids(std::int32_t* first, std::int32_t* last) {
    if (last - first > 48) {
      std::sort(first, last);
      return;
    }
    for (std::int32_t* i = first + (first != last); i < last; ++i) {
      const std::int32_t v = *i;
      std::int32_t* j = i;
      for (; j > first && j[-1] > v; --j) *j = j[-1];
      *j = v;
    }
  }

  // The generator just added ends its runs here: each end relative to its
  // run's base (the mesh's ends only with the mesh).
  void close_cell(Batch& b, const Store& s) const {
    b.nbr_end.push_back(static_cast<std::uint32_t>(s.nbrs.size() - b.nbr_base));
    if (!mesh_) return;
    b.vert_end.push_back(static_cast<std::uint32_t>(s.corners.size() - b.corner_base));
    b.pos_end.push_back(static_cast<std::uint32_t>(s.pos.size() / D - b.pos_base));
    b.face_end.push_back(static_cast<std::uint32_t>(s.face_nbr.size() - b.face_base));
  }

  // The cell's vertices in dual form (faces numbered by b.face_of), the
  // owned ones first, and the owned ones' positions. A cell of more than
  // 65,535 faces (3D) is wide (Batch::wide).
  void add_vertices(Batch& b, Store& s, std::int32_t gen, CellT& cell, std::size_t nfaces) {
    const auto& v = cell.vertices();
    const double* p = cell.site();
    const std::size_t nv = v.size(), v0 = s.corners.size(), p0 = s.pos.size() / D;
    s.corners.resize(v0 + nv);
    s.pos.resize((p0 + nv) * D);  // at most; trimmed below
    kernels::Corners<D>* corners = s.corners.data() + v0;
    double* pos = s.pos.data() + p0 * D;
    const std::uint32_t* face_of = b.face_of.data();
    using Half = typename kernels::Corners<D>::value_type;
    constexpr bool may_be_wide = sizeof(Half) < sizeof(std::uint32_t);
    kernels::Corners<D>* high = nullptr;
    if (may_be_wide && nfaces > std::numeric_limits<Half>::max()) [[unlikely]] {
      // This cell is the batch's last entry (add() listed its generator).
      b.wide.emplace_back(static_cast<std::uint32_t>(b.gen.size() - 1),
                          static_cast<std::uint32_t>(b.high_corners.size()));
      b.high_corners.resize(b.high_corners.size() + nv);
      high = b.high_corners.data() + b.wide.back().second;
    }
    std::size_t kept = 0, back = nv;
    for (std::size_t t = 0; t < nv; ++t) {
      const bool owned = first_inside(vertex_key(cell, t)) == gen;
      const std::size_t at = owned ? kept : --back;
      for (int k = 0; k < D; ++k) {
        const std::uint32_t f = face_of[v[t].p[k]];
        corners[at][static_cast<std::size_t>(k)] = static_cast<Half>(f);
        if constexpr (may_be_wide)
          if (high) [[unlikely]] high[at][static_cast<std::size_t>(k)] = static_cast<Half>(f >> 16);
      }
      for (int d = 0; d < D; ++d) pos[kept * D + d] = v[t].y[d] + p[d];  // dropped unless owned
      kept += owned;
    }
    s.pos.resize((p0 + kept) * D);
  }

  // Face k of batch vertex v, the vertex of entry t whose high halves are
  // `high` (Batch::high_of) and whose first vertex is v0.
  static std::uint32_t corner_of(const Batch& b, const kernels::Corners<D>* high, std::uint32_t v0, std::uint32_t v,
                                 int k) {
    const std::uint32_t lo = b.corners()[v][static_cast<std::size_t>(k)];
    if (high == nullptr) [[likely]] return lo;
    return lo | static_cast<std::uint32_t>(high[v - v0][static_cast<std::size_t>(k)]) << 16;
  }

  // Vertex v's key (the generator and its faces' neighbour ids, ascending),
  // from batch entry t's dual form.
  Key<D> key_of(const Batch& b, std::size_t t, std::uint32_t v) const {
    const std::int32_t* nbr = b.face_nbr() + range_of(b.face_end, t).first;
    Key<D> k;
    k[0] = b.gen[t];
    if (!b.wide.empty()) [[unlikely]] {
      const auto* high = b.high_of(t);
      const std::uint32_t v0 = range_of(b.vert_end, t).first;
      for (int j = 0; j < D; ++j) k[static_cast<std::size_t>(j) + 1] = nbr[corner_of(b, high, v0, v, j)];
      sort_key(k);
      return k;
    }
    const kernels::Corners<D>& corner = b.corners()[v];
    for (int j = 0; j < D; ++j) k[static_cast<std::size_t>(j) + 1] = nbr[corner[static_cast<std::size_t>(j)]];
    sort_key(k);
    return k;
  }

  // Generator g's cell index (-1: none); read without a lookup when dense_.
  std::int32_t cell_at(std::int32_t g) const { return dense_ ? g : out_.cell_of[static_cast<std::size_t>(g)]; }

  std::int32_t labels_at(std::int32_t g) const { return labels_.empty() ? 0 : labels_[static_cast<std::size_t>(g)]; }

  // The lowest generator of the key that owns a cell owns the merged vertex;
  // when every generator owns one (dense_), that is the lowest of the key's
  // generators (keys ascend, box planes first), read without a lookup.
  std::int32_t owner(const Key<D>& key) const {
    return lowest_generator(key, [&](std::int32_t id) { return dense_ || out_.cell_of[static_cast<std::size_t>(id)] >= 0; });
  }

  // The key's lowest inside generator (label >= 0; with build_only, also
  // built): its owner, as no located points coincide.
  std::int32_t first_inside(const Key<D>& key) const {
    if (!built_.empty()) [[unlikely]]
      return lowest_generator(key, [&](std::int32_t id) {
        return labels_at(id) >= 0 && (built_[static_cast<std::size_t>(id) >> 6] >> (id & 63) & 1) != 0;
      });
    return lowest_generator(key, [&](std::int32_t id) { return labels_at(id) >= 0; });
  }

  // The key's lowest generator (ids ascend, box planes first) that passes
  // `take`; -1 when none does.
  template <class Take>
  static std::int32_t lowest_generator(const Key<D>& key, Take&& take) {
    for (std::int32_t id : key)
      if (id >= 0 && take(id)) return id;
    return -1;
  }

  // Key equality as two or three wide compares: std::array's == calls memcmp.
  static bool same_key(const Key<D>& a, const Key<D>& b) {
    if constexpr (D == 3) {
      std::uint64_t a0, a1, b0, b1;
      std::memcpy(&a0, a.data(), 8);
      std::memcpy(&a1, a.data() + 2, 8);
      std::memcpy(&b0, b.data(), 8);
      std::memcpy(&b1, b.data() + 2, 8);
      return ((a0 ^ b0) | (a1 ^ b1)) == 0;
    } else {
      return ((a[0] ^ b[0]) | (a[1] ^ b[1]) | (a[2] ^ b[2])) == 0;
    }
  }

  // Merged vertex g's key, from the mesh's vertex_keys (a copy: a
  // std::array compare on it is two wide loads, see same_key).
  static Key<D> key_at(const std::int32_t* keys, std::int64_t g) {
    Key<D> k;
    std::memcpy(k.data(), keys + static_cast<std::size_t>(g) * (D + 1), sizeof k);
    return k;
  }

  // Owners searched by key order (build_mesh): above this many owned
  // vertices (a uniform 3D cell owns ~7).
  static constexpr std::int64_t crowded_owner = 256;

  // The global vertex ids of each crowded owner (cells owning more than
  // crowded_owner vertices), sorted by key, for a binary search.
  struct CrowdedOwners {
    std::vector<std::size_t> cells;      // ascending
    std::vector<std::size_t> start;      // cells[i]'s ids: ids[start[i] .. start[i + 1])
    std::vector<std::int32_t> ids;

    std::int32_t find(std::size_t cell, const Key<D>& key, const std::int32_t* keys) const {
      const std::size_t i = static_cast<std::size_t>(std::lower_bound(cells.begin(), cells.end(), cell) - cells.begin());
      if (i == cells.size() || cells[i] != cell) return -1;
      const auto first = ids.begin() + static_cast<std::ptrdiff_t>(start[i]);
      const auto last = ids.begin() + static_cast<std::ptrdiff_t>(start[i + 1]);
      const auto it = std::lower_bound(first, last, key, [&](std::int32_t g, const Key<D>& k) { return key_at(keys, g) < k; });
      return it != last && same_key(key_at(keys, *it), key) ? *it : -1;
    }
  };

  CrowdedOwners crowded_owners(const std::vector<std::int64_t>& owned) const {
    CrowdedOwners c;
    const std::size_t ncell = owned.size() - 1;
    c.start.push_back(0);
    for (std::size_t k = 0; k < ncell; ++k)
      if (owned[k + 1] - owned[k] > crowded_owner) {
        c.cells.push_back(k);
        for (std::int64_t g = owned[k]; g < owned[k + 1]; ++g) c.ids.push_back(static_cast<std::int32_t>(g));
        c.start.push_back(c.ids.size());
      }
    const std::int32_t* keys = out_.vertex_keys.data();
    tbb::parallel_for(std::size_t(0), c.cells.size(), [&](std::size_t i) {
      std::sort(c.ids.begin() + static_cast<std::ptrdiff_t>(c.start[i]), c.ids.begin() + static_cast<std::ptrdiff_t>(c.start[i + 1]),
                [keys](std::int32_t a, std::int32_t b) { return key_at(keys, a) < key_at(keys, b); });
    });
    return c;
  }

  void build_mesh(std::span<Batch> batches, std::vector<std::int64_t>& fcv) {
    Cells& o = out_;
    const std::size_t ncell = o.n_cells();
    // Owned vertices per cell -> global numbering in cell order: a cell's
    // owned vertices are its first ones, as many as the positions it kept
    // (add_vertices).
    std::vector<std::int64_t> owned(ncell + 1, 0);
    tbb::parallel_for(std::size_t(0), batches.size(), [&](std::size_t k) {
      const Batch& b = batches[k];
      for (std::size_t t = 0; t < b.gen.size(); ++t) {
        const std::int32_t c = cell_at(b.gen[t]);
        if (c < 0) continue;
        auto [p0, p1] = range_of(b.pos_end, t);
        owned[static_cast<std::size_t>(c) + 1] = p1 - p0;
      }
    });
    std::partial_sum(owned.begin(), owned.end(), owned.begin());
    const std::size_t nverts = static_cast<std::size_t>(owned.back());
    o.vertices.resize(nverts * D);
    o.vertex_keys.resize(nverts * (D + 1));
    std::atomic<bool> unowned{false};  // a cell's kept positions were not its owned vertices
    tbb::parallel_for(std::size_t(0), batches.size(), [&](std::size_t k) {
      Batch& b = batches[k];
      for (std::size_t t = 0; t < b.gen.size(); ++t) {
        fetch_ahead(b, t, [&](std::size_t c) { __builtin_prefetch(&owned[c]); });
        const std::int32_t c = cell_at(b.gen[t]);
        if (c < 0) continue;
        auto [v0, v1] = range_of(b.vert_end, t);
        std::size_t gid = static_cast<std::size_t>(owned[static_cast<std::size_t>(c)]);
        const std::size_t end = static_cast<std::size_t>(owned[static_cast<std::size_t>(c) + 1]);
        std::uint32_t src = range_of(b.pos_end, t).first;  // the owned positions, in order
        for (std::uint32_t v = v0; v < v1 && gid < end; ++v) {
          const Key<D> key = key_of(b, t, v);
          if (owner(key) != b.gen[t]) {  // the owned vertices come first
            unowned.store(true, std::memory_order_relaxed);
            continue;
          }
          const std::size_t from = src++;
          for (int d = 0; d < D; ++d) o.vertices[gid * D + d] = b.pos()[from * D + d];
          // A vertex on a box plane (its key names it; ascending, so box
          // planes first) lies on it exactly: the solve left its coordinate
          // within an ulp or so, outside the box as often as not (a fuzz of
          // the surface nets: 5.6e-17 outside a unit box). The measures are
          // the kernel's, computed before.
          for (int e = 0; e <= D && key[static_cast<std::size_t>(e)] < 0; ++e) {
            const std::int64_t plane = -1 - std::int64_t{key[static_cast<std::size_t>(e)]};  // 2 axis (+1: upper)
            if (plane >= 2 * D) continue;  // (the far plane's id: the box cuts it away, never in a mesh)
            const auto axis = static_cast<std::size_t>(plane / 2);
            o.vertices[gid * D + axis] = plane % 2 ? box_.hi[axis] : box_.lo[axis];
          }
          // Id by id: the sorted key leaves its registers as 4-byte stores,
          // which a wider copy would have to wait for.
          for (int d = 0; d <= D; ++d) o.vertex_keys[gid * (D + 1) + d] = key[static_cast<std::size_t>(d)];
          ++gid;
        }
        if (gid != end) unowned.store(true, std::memory_order_relaxed);
      }
    });
    for (Store& s : stores_) Buffer<double>().swap(s.pos);  // copied out: freed before the face arrays are allocated
    if (unowned.load())
      throw std::logic_error("tessera: a cell kept positions for other than its owned vertices");
    // Memory freed above may lie in malloc's arenas (below glibc's adaptive
    // mmap threshold), which keep it from the system; the face arrays below
    // are fresh mappings. Trimming hands those pages back first, so that the
    // peak holds one of the two, not both.
    release_free_memory();
    std::partial_sum(o.cell_face_offsets.begin(), o.cell_face_offsets.end(), o.cell_face_offsets.begin());
    std::partial_sum(fcv.begin(), fcv.end(), fcv.begin());
    const std::size_t nfaces = static_cast<std::size_t>(o.cell_face_offsets.back());
    // Buffers: sized, not zeroed; the loop below writes every element
    // (each face its entries and its end offset), first-touching the pages
    // on both threads.
    o.face_vertex_offsets.resize(nfaces + 1);
    o.face_vertex_offsets[0] = 0;
    o.face_vertices.resize(static_cast<std::size_t>(fcv.back()));
    o.face_neighbor.resize(nfaces);
    o.face_class.resize(nfaces);
    // Each cell's vertex ids, then its faces. A vertex owned elsewhere is
    // found by key among its owner's owned vertices, which the loop above
    // wrote contiguously (global ids owned[c] .. owned[c + 1] of the owner's
    // cell c, keys in vertex_keys): a quarter of the owner's vertices, found
    // from its cell index alone. A miss means two cells disagree about a
    // vertex, which exact predicates rule out.
    // An owner of more than crowded_owner vertices (a point with thousands
    // of neighbours: the centre of points on a sphere) is searched through
    // its ids sorted by key instead: scanned, each of its neighbours' few
    // lookups cost its whole range, and 40,000 points on a sphere and their
    // centre took 1.7 s in this loop alone.
    const CrowdedOwners crowded = crowded_owners(owned);
    std::atomic<std::size_t> misses{0};
    tbb::parallel_for(std::size_t(0), batches.size(), [&](std::size_t k) {
      const Batch& b = batches[k];
      const std::int32_t* const keys = o.vertex_keys.data();
      // A cell's lookups are independent, and each is two dependent cache
      // misses (the owner's range, then its keys): they run in three
      // sweeps, so that the misses of one sweep overlap.
      std::vector<std::int32_t> gid;  // per vertex of the cell
      std::vector<std::uint32_t> slot;
      std::vector<std::size_t> at;
      std::vector<Key<D>> sought;
      kernels::FaceLoopScratch walk;
      for (std::size_t t = 0; t < b.gen.size(); ++t) {
        fetch_ahead(b, t, [&](std::size_t c) {
          __builtin_prefetch(&owned[c]);
          __builtin_prefetch(&o.cell_face_offsets[c]);
          __builtin_prefetch(&fcv[c]);
        });
        const std::int32_t c = cell_at(b.gen[t]);
        if (c < 0) continue;
        const std::size_t cu = static_cast<std::size_t>(c);
        // Not a structured binding: the lambdas below capture v0, which
        // Clang before 16 does not allow for bindings.
        const std::uint32_t v0 = range_of(b.vert_end, t).first, v1 = range_of(b.vert_end, t).second;
        gid.resize(v1 - v0);
        if (sought.size() < v1 - v0) sought.resize(v1 - v0);
        slot.clear();
        at.clear();
        std::int32_t next = static_cast<std::int32_t>(owned[cu]);
        for (std::uint32_t v = v0; v < v1; ++v) {
          if (next < owned[cu + 1]) {
            gid[v - v0] = next++;
            continue;
          }
          // Built in place: copied from a temporary, the key's 4-byte stores
          // stalled the copy's wider loads (2D: a quarter of this loop).
          Key<D>& key = sought[slot.size()];
          key = key_of(b, t, v);
          const std::int32_t own = owner(key);
          if (own == b.gen[t]) {
            gid[v - v0] = next++;
            continue;
          }
          const std::size_t oc = static_cast<std::size_t>(cell_at(own));
          __builtin_prefetch(&owned[oc]);
          slot.push_back(v);
          at.push_back(oc);
        }
        for (const std::size_t oc : at) __builtin_prefetch(keys + static_cast<std::size_t>(owned[oc]) * (D + 1));
        for (std::size_t m = 0; m < slot.size(); ++m) {
          const std::size_t oc = at[m];
          const std::int64_t g1 = owned[oc + 1];
          const Key<D>& key = sought[m];
          std::int32_t found = -1;
          if (g1 - owned[oc] > crowded_owner) [[unlikely]] {
            found = crowded.find(oc, key, keys);
          } else {
            for (std::int64_t g = owned[oc]; g < g1; ++g)
              if (same_key(key_at(keys, g), key)) { found = static_cast<std::int32_t>(g); break; }
          }
          if (found < 0) misses.fetch_add(1, std::memory_order_relaxed);
          gid[slot[m] - v0] = found;
        }
        auto [f0, f1] = range_of(b.face_end, t);
        const std::int32_t* nbr = b.face_nbr() + f0;
        std::size_t fo = static_cast<std::size_t>(o.cell_face_offsets[cu]);
        std::size_t vo = static_cast<std::size_t>(fcv[cu]);
        const std::size_t fend = static_cast<std::size_t>(o.cell_face_offsets[cu + 1]);
        const std::size_t vend = static_cast<std::size_t>(fcv[cu + 1]);
        auto face = [&](std::size_t f, const std::uint32_t* loop, std::size_t count) {
          if (fo == fend || count > vend - vo) return;  // (reported below)
          o.face_neighbor[fo] = nbr[f];
          o.face_class[fo] = classify_(b.gen[t], nbr[f]);
          for (std::size_t q = 0; q < count; ++q) o.face_vertices[vo++] = gid[loop[q]];
          o.face_vertex_offsets[++fo] = static_cast<std::int64_t>(vo);
        };
        const std::span<const kernels::Corners<D>> cell_corners(b.corners() + v0, v1 - v0);
        if constexpr (D == 3) {
          if (const kernels::Corners<D>* high = b.high_of(t)) [[unlikely]]
            kernels::for_each_face_loop(
                v1 - v0, f1 - f0,
                [&](std::size_t u, int k) { return corner_of(b, high, v0, v0 + static_cast<std::uint32_t>(u), k); },
                walk, face);
          else
            kernels::for_each_face_loop(cell_corners, f1 - f0, walk, face);
        } else {
          kernels::for_each_face_loop(cell_corners, f1 - f0, walk, face);
        }
        if (fo != fend || vo != vend) misses.fetch_add(1, std::memory_order_relaxed);  // faces that do not close
      }
    });
    if (misses.load() != 0)
      throw std::logic_error("tessera: " + std::to_string(misses.load()) +
                             " cell vertices have no match in their owner cell, or cells' faces do not close"
                             " (inconsistent topology)");
  }

  Cells& out_;
  std::span<const std::int32_t> labels_;
  engine::RegionClassifier classify_;
  bool mesh_;
  std::vector<double>* reach_ = nullptr;  // record_reach
  std::span<const std::uint64_t> built_;  // build_only (empty: every generator)
  int frame_k_;  // the scaled frame's 2^k (front/pass.cpp)
  Bounds box_;    // the domain in that frame
  bool dense_ = false;  // set by finish: every generator owns a cell, cell g = generator g
  // Per thread (element references stay valid until the compositor dies).
  tbb::enumerable_thread_specific<Store> stores_;
};

}  // namespace tessera::front
