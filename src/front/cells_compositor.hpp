// The compositor behind tessera::voronoi: per-cell measures, neighbour lists
// and (optionally) the conformal mesh merged by topological coordinate.
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <string>
#include <cstdint>
#include <cstring>
#include <numeric>
#include <span>
#include <stdexcept>
#include <vector>

#include <tbb/parallel_for.h>

#include "cell_geometry.hpp"
#include "release_memory.hpp"
#include "tessera/cells.hpp"
#include "tessera/engine/classifier.hpp"
#include "tessera/kernels/cell_builder.hpp"

namespace tessera::front {

template <class CellT>
class CellsCompositor {
 public:
  static constexpr int D = CellT::dim;

  struct Batch {
    std::vector<std::int32_t> gen;          // every generator of the batch, in order
    std::vector<std::int32_t> dup_of;       // -1, or the owner it duplicates (no cell)
    std::vector<double> volume, centroid;
    std::vector<std::int32_t> num_faces;
    std::vector<std::uint32_t> nbr_end;     // running end into nbrs, per generator
    std::vector<std::int32_t> nbrs;
    // mesh
    std::vector<std::uint32_t> vert_end;    // running end into keys/pos, per generator
    Buffer<Key<D>> keys;                    // (Buffers: resized, then written)
    Buffer<double> pos;                     // absolute coordinates: every vertex's, or the owned ones'
    std::vector<std::uint32_t> pos_end;     // running end into pos (in vertices), per generator
    Buffer<std::int32_t> vglobal;           // merged vertex id per local vertex
    std::vector<std::uint32_t> face_end;    // running end into faces, per generator
    std::vector<std::int32_t> face_nbr;
    std::vector<std::uint32_t> face_vend;   // running end into fverts, per face
    std::vector<std::uint32_t> fverts;      // local vertex index (within the cell)
    std::size_t assembled = 0;              // cells assembled from their stars
  };

  /// `owners_known`: no two generators coincide, so a merged vertex's owner
  /// (the lowest generator of its key that owns a cell) is the lowest inside
  /// generator of its key, known when the cell is added; only the owner then
  /// keeps the vertex's position (a quarter of them: 3D vertices are shared
  /// by four cells). Otherwise every cell keeps all its positions.
  CellsCompositor(Cells& out, std::span<const std::int32_t> labels, bool mesh, bool owners_known = false)
      : out_(out), labels_(labels), classify_(labels), mesh_(mesh), owners_known_(owners_known) {}

  void add(Batch& b, std::int32_t gen, const kernels::BuildStatus& st, CellT& cell) {
    b.assembled += st.assembled;
    b.gen.push_back(gen);
    b.dup_of.push_back(st.has_cell ? -1 : st.duplicate_of);
    if (!st.has_cell) {
      b.volume.push_back(0);
      for (int d = 0; d < D; ++d) b.centroid.push_back(0);
      b.num_faces.push_back(0);
      b.nbr_end.push_back(static_cast<std::uint32_t>(b.nbrs.size()));
      if (mesh_) {
        b.vert_end.push_back(static_cast<std::uint32_t>(b.keys.size()));
        b.pos_end.push_back(static_cast<std::uint32_t>(b.pos.size() / D));
        b.face_end.push_back(static_cast<std::uint32_t>(b.face_nbr.size()));
      }
      return;
    }
    const double* p = cell.site();
    const std::size_t nb0 = b.nbrs.size();
    std::int32_t nf = 0;
    // Spokes from the face planes; the face loops are walked only for the mesh.
    if (mesh_) {
      for_each_face(cell, [&](std::int32_t id, const std::uint32_t* loop, std::size_t count) {
        ++nf;
        if (id >= 0) b.nbrs.push_back(id);
        b.face_nbr.push_back(id);
        b.fverts.insert(b.fverts.end(), loop, loop + count);
        b.face_vend.push_back(static_cast<std::uint32_t>(b.fverts.size()));
      });
    } else {
      for_each_spoke(cell, [&](std::int32_t id) {
        ++nf;
        if (id >= 0) b.nbrs.push_back(id);
      });
    }
    double vol;
    std::array<double, D> c;
    measure(cell, vol, c);
    b.volume.push_back(vol);
    for (int d = 0; d < D; ++d) b.centroid.push_back(c[d] + p[d]);
    std::sort(b.nbrs.begin() + static_cast<std::ptrdiff_t>(nb0), b.nbrs.end());
    b.num_faces.push_back(nf);
    b.nbr_end.push_back(static_cast<std::uint32_t>(b.nbrs.size()));
    if (mesh_) {
      const auto& v = cell.vertices();
      const std::size_t nv = v.size(), k0 = b.keys.size(), p0 = b.pos.size() / D;
      b.keys.resize(k0 + nv);
      b.pos.resize((p0 + nv) * D);  // at most; trimmed below
      Key<D>* key = b.keys.data() + k0;
      double* pos = b.pos.data() + p0 * D;
      std::size_t kept = 0;
      for (std::size_t t = 0; t < nv; ++t) {
        key[t] = vertex_key(cell, t);
        for (int d = 0; d < D; ++d) pos[kept * D + d] = v[t].y[d] + p[d];
        kept += !owners_known_ || first_inside(key[t]) == gen;
      }
      b.pos.resize((p0 + kept) * D);
      b.vert_end.push_back(static_cast<std::uint32_t>(b.keys.size()));
      b.pos_end.push_back(static_cast<std::uint32_t>(p0 + kept));
      b.face_end.push_back(static_cast<std::uint32_t>(b.face_nbr.size()));
    }
  }

  void finish(std::span<Batch> batches) {
    Cells& o = out_;
    const std::size_t n = o.n_points;
    for (const Batch& b : batches)
      for (std::size_t t = 0; t < b.gen.size(); ++t)
        if (b.dup_of[t] >= 0) o.duplicates.emplace_back(b.gen[t], b.dup_of[t]);
    std::sort(o.duplicates.begin(), o.duplicates.end());
    // Cells in generator-id order: when every point is a generator (no
    // outside labels, none ignored) and none is a duplicate, cell g is
    // generator g.
    std::size_t generators = 0;
    for (const Batch& b : batches) {
      generators += b.gen.size();
      o.assembled_from_stars += b.assembled;
    }
    dense_ = o.duplicates.empty() && generators == n;
    const bool dense = dense_;
    o.cell_of.assign(n, dense ? 1 : 0);
    // cell_of first holds 1 for a generator with a cell. Every generator
    // lies in exactly one batch, so all batches write at once.
    if (!dense)
      tbb::parallel_for(std::size_t(0), batches.size(), [&](std::size_t k) {
        const Batch& b = batches[k];
        for (std::size_t t = 0; t < b.gen.size(); ++t) o.cell_of[static_cast<std::size_t>(b.gen[t])] = b.dup_of[t] < 0;
      });
    std::int32_t nc = 0;
    for (std::size_t g = 0; g < n; ++g) o.cell_of[g] = o.cell_of[g] ? nc++ : -1;
    const std::size_t ncell = static_cast<std::size_t>(nc);
    // Generators come in bin order, so their cells' fields land all over
    // the output: the loops below fetch a cell's destinations some
    // generators ahead (and, with duplicates, its cell index before that).
    auto ahead = [&](const Batch& b, std::size_t t, auto&& fetch) {
      if (!dense && t + 2 * prefetch_ahead < b.gen.size())
        __builtin_prefetch(&o.cell_of[static_cast<std::size_t>(b.gen[t + 2 * prefetch_ahead])]);
      if (t + prefetch_ahead < b.gen.size()) {
        const std::int32_t c = cell_at(b.gen[t + prefetch_ahead]);
        if (c >= 0) fetch(static_cast<std::size_t>(c));
      }
    };
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

    auto range_of = [](const std::vector<std::uint32_t>& ends, std::size_t t) {
      std::uint32_t lo = t == 0 ? 0 : ends[t - 1];
      return std::pair<std::uint32_t, std::uint32_t>(lo, ends[t]);
    };

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
        ahead(b, t, [&](std::size_t c) {
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
        o.volume[cu] = b.volume[t];
        for (int d = 0; d < D; ++d) o.centroid[cu * D + d] = b.centroid[t * D + d];
        o.num_faces[cu] = b.num_faces[t];
        auto [n0, n1] = range_of(b.nbr_end, t);
        o.neighbor_offsets[cu + 1] = n1 - n0;
        if (mesh_) {
          auto [f0, f1] = range_of(b.face_end, t);
          o.cell_face_offsets[cu + 1] = f1 - f0;
          std::uint32_t v0 = f0 == 0 ? 0 : b.face_vend[f0 - 1];
          std::uint32_t v1 = f1 == 0 ? 0 : b.face_vend[f1 - 1];
          face_count_vertices[cu + 1] = v1 - v0;
        }
      }
    });
    std::partial_sum(o.neighbor_offsets.begin(), o.neighbor_offsets.end(), o.neighbor_offsets.begin());
    o.neighbors.resize(static_cast<std::size_t>(o.neighbor_offsets.back()));
    tbb::parallel_for(std::size_t(0), batches.size(), [&](std::size_t k) {
      const Batch& b = batches[k];
      for (std::size_t t = 0; t < b.gen.size(); ++t) {
        ahead(b, t, [&](std::size_t c) { __builtin_prefetch(&o.neighbor_offsets[c]); });
        std::int32_t c = cell_at(b.gen[t]);
        if (c < 0) continue;
        if (t + prefetch_ahead / 2 < b.gen.size()) {
          const std::int32_t c2 = cell_at(b.gen[t + prefetch_ahead / 2]);
          if (c2 >= 0) __builtin_prefetch(o.neighbors.data() + o.neighbor_offsets[static_cast<std::size_t>(c2)], 1);
        }
        auto [n0, n1] = range_of(b.nbr_end, t);
        std::copy(b.nbrs.begin() + n0, b.nbrs.begin() + n1,
                  o.neighbors.begin() + o.neighbor_offsets[static_cast<std::size_t>(c)]);
      }
    });
    if (mesh_) build_mesh(batches, face_count_vertices);
  }

 private:
  static constexpr std::size_t prefetch_ahead = 8;  // generators (finish)

  // Generator g's cell index (-1: none); read without a lookup when dense_.
  std::int32_t cell_at(std::int32_t g) const { return dense_ ? g : out_.cell_of[static_cast<std::size_t>(g)]; }

  std::int32_t labels_at(std::int32_t g) const { return labels_.empty() ? 0 : labels_[static_cast<std::size_t>(g)]; }

  // The lowest generator of the key that owns a cell owns the merged vertex;
  // when every generator owns one (dense_), that is the lowest of the key's
  // generators (keys ascend, box planes first), read without a lookup.
  std::int32_t owner(const Key<D>& key) const {
    return lowest_generator(key, [&](std::int32_t id) { return dense_ || out_.cell_of[static_cast<std::size_t>(id)] >= 0; });
  }

  // The key's lowest inside generator (label >= 0): its owner when no
  // generators coincide.
  std::int32_t first_inside(const Key<D>& key) const {
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

  void build_mesh(std::span<Batch> batches, std::vector<std::int64_t>& fcv) {
    Cells& o = out_;
    const std::size_t ncell = o.n_cells();
    // Owned vertices per cell -> global numbering in cell order.
    std::vector<std::int64_t> owned(ncell + 1, 0);
    tbb::parallel_for(std::size_t(0), batches.size(), [&](std::size_t k) {
      Batch& b = batches[k];
      b.vglobal.assign(b.keys.size(), -1);
      for (std::size_t t = 0; t < b.gen.size(); ++t) {
        std::int32_t c = cell_at(b.gen[t]);
        if (c < 0) continue;
        std::uint32_t v0 = t == 0 ? 0 : b.vert_end[t - 1], v1 = b.vert_end[t];
        std::int64_t cnt = 0;
        for (std::uint32_t v = v0; v < v1; ++v) cnt += owner(b.keys[v]) == b.gen[t];
        owned[static_cast<std::size_t>(c) + 1] = cnt;
      }
    });
    std::partial_sum(owned.begin(), owned.end(), owned.begin());
    if (owners_known_ && !o.duplicates.empty())
      throw std::logic_error("tessera: coincident generators were missed before the cells pass");
    const std::size_t nverts = static_cast<std::size_t>(owned.back());
    o.vertices.resize(nverts * D);
    o.vertex_keys.resize(nverts * (D + 1));
    std::atomic<bool> unowned{false};  // owners_known_ was wrong about a vertex
    tbb::parallel_for(std::size_t(0), batches.size(), [&](std::size_t k) {
      Batch& b = batches[k];
      for (std::size_t t = 0; t < b.gen.size(); ++t) {
        std::int32_t c = cell_at(b.gen[t]);
        if (c < 0) continue;
        std::uint32_t v0 = t == 0 ? 0 : b.vert_end[t - 1], v1 = b.vert_end[t];
        std::uint32_t pv = t == 0 ? 0 : b.pos_end[t - 1];  // the owned positions, in vertex order
        std::int64_t next = owned[static_cast<std::size_t>(c)];
        for (std::uint32_t v = v0; v < v1; ++v) {
          if (owner(b.keys[v]) != b.gen[t]) continue;
          std::size_t gid = static_cast<std::size_t>(next++);
          b.vglobal[v] = static_cast<std::int32_t>(gid);
          const std::size_t src = owners_known_ ? pv++ : v;
          if (src >= b.pos.size() / D) break;  // (reported below)
          for (int d = 0; d < D; ++d) o.vertices[gid * D + d] = b.pos[src * D + d];
          for (int d = 0; d <= D; ++d) o.vertex_keys[gid * (D + 1) + d] = b.keys[v][static_cast<std::size_t>(d)];
        }
        if (owners_known_ && pv != b.pos_end[t]) unowned.store(true, std::memory_order_relaxed);
      }
      Buffer<double>().swap(b.pos);  // copied out: freed before the face arrays are allocated
    });
    if (unowned.load())
      throw std::logic_error("tessera: a cell kept positions for other than its owned vertices");
    // Vertices owned elsewhere: found by key among the owner's owned
    // vertices, which the loop above wrote contiguously (global ids
    // owned[c] .. owned[c + 1] of the owner's cell c, keys in vertex_keys):
    // a quarter of the owner's vertices, found from its cell index alone. A
    // miss means two cells disagree about a vertex, which exact predicates
    // rule out.
    std::atomic<std::size_t> misses{0};
    tbb::parallel_for(std::size_t(0), batches.size(), [&](std::size_t k) {
      Batch& b = batches[k];
      const std::int32_t* const keys = o.vertex_keys.data();
      // A cell's lookups are independent, and each is two dependent cache
      // misses (the owner's range, then its keys): they run in three
      // sweeps, so that the misses of one sweep overlap.
      std::vector<std::uint32_t> slot;
      std::vector<std::size_t> at;
      for (std::size_t t = 0; t < b.gen.size(); ++t) {
        if (cell_at(b.gen[t]) < 0) continue;
        std::uint32_t v0 = t == 0 ? 0 : b.vert_end[t - 1], v1 = b.vert_end[t];
        slot.clear();
        at.clear();
        for (std::uint32_t v = v0; v < v1; ++v) {
          if (b.vglobal[v] >= 0) continue;
          const std::int32_t own = owner(b.keys[v]);
          const std::size_t oc = static_cast<std::size_t>(cell_at(own));
          __builtin_prefetch(&owned[oc]);
          slot.push_back(v);
          at.push_back(oc);
        }
        for (const std::size_t oc : at) __builtin_prefetch(keys + static_cast<std::size_t>(owned[oc]) * (D + 1));
        for (std::size_t m = 0; m < slot.size(); ++m) {
          const std::uint32_t v = slot[m];
          const std::size_t oc = at[m];
          const std::int64_t g1 = owned[oc + 1];
          std::int32_t found = -1;
          for (std::int64_t g = owned[oc]; g < g1; ++g) {
            Key<D> kg;
            std::memcpy(kg.data(), keys + static_cast<std::size_t>(g) * (D + 1), sizeof kg);
            if (same_key(kg, b.keys[v])) { found = static_cast<std::int32_t>(g); break; }
          }
          if (found < 0) misses.fetch_add(1, std::memory_order_relaxed);
          b.vglobal[v] = found;
        }
      }
      Buffer<Key<D>>().swap(b.keys);  // no longer read: lookups use vertex_keys
    });
    if (misses.load() != 0)
      throw std::logic_error("tessera: " + std::to_string(misses.load()) +
                             " cell vertices have no match in their owner cell (inconsistent topology)");
    // Faces.
    std::partial_sum(o.cell_face_offsets.begin(), o.cell_face_offsets.end(), o.cell_face_offsets.begin());
    // The batches' keys and positions, freed above, lie in malloc's arenas
    // (many allocations of a few MB each, below glibc's adaptive mmap
    // threshold), which keep them from the system; the face arrays below are
    // fresh mappings. Trimming hands those pages back first, so the peak
    // holds one of the two, not both (1M 3D cells: ~0.5 GB less).
    release_free_memory();
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
    tbb::parallel_for(std::size_t(0), batches.size(), [&](std::size_t k) {
      const Batch& b = batches[k];
      for (std::size_t t = 0; t < b.gen.size(); ++t) {
        std::int32_t c = cell_at(b.gen[t]);
        if (c < 0) continue;
        std::size_t cu = static_cast<std::size_t>(c);
        std::uint32_t f0 = t == 0 ? 0 : b.face_end[t - 1], f1 = b.face_end[t];
        std::uint32_t vbase = t == 0 ? 0 : b.vert_end[t - 1];
        std::size_t fo = static_cast<std::size_t>(o.cell_face_offsets[cu]);
        std::size_t vo = static_cast<std::size_t>(fcv[cu]);
        for (std::uint32_t f = f0; f < f1; ++f, ++fo) {
          std::uint32_t a = f == 0 ? 0 : b.face_vend[f - 1], e = b.face_vend[f];
          o.face_neighbor[fo] = b.face_nbr[f];
          o.face_class[fo] = classify_(b.gen[t], b.face_nbr[f]);
          for (std::uint32_t q = a; q < e; ++q) o.face_vertices[vo++] = b.vglobal[vbase + b.fverts[q]];
          o.face_vertex_offsets[fo + 1] = static_cast<std::int64_t>(vo);
        }
      }
    });
  }

  Cells& out_;
  std::span<const std::int32_t> labels_;
  engine::RegionClassifier classify_;
  bool mesh_;
  bool owners_known_;
  bool dense_ = false;  // set by finish: every generator owns a cell, cell g = generator g
};

}  // namespace tessera::front
