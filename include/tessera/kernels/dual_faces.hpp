// A cell's faces from its dual form. The kernels keep a cell as its
// vertices, each the D faces (bisector planes) that meet there: in 3D a
// triangle of faces counter-clockwise seen from outside (Hull), in 2D the
// edge arriving and the edge leaving (Tile). The mesh stores a cell the same
// way, with faces numbered 0.. within the cell (a vertex then takes 6 bytes
// in 3D, against its 16-byte key and some 12 bytes of face loops), and walks
// the face loops from that form when it writes them; Hull::for_each_face
// walks its own vertices by the same code.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

namespace tessera::kernels {

/// A vertex of a cell in dual form: the indices of the D faces meeting there.
/// 32 bits in 2D (free: a polygon may have any number of edges); 16 in 3D,
/// where a cell has 27 vertices on average: the mesh's store of a cell of
/// more than 65,535 faces adds their high halves aside
/// (front::CellsCompositor::Batch::wide), not 6 bytes to every vertex.
template <int D>
using Corners = std::array<std::conditional_t<D == 2, std::uint32_t, std::uint16_t>, static_cast<std::size_t>(D)>;

/// Scratch of for_each_face_loop, reused across cells (one per thread).
struct FaceLoopScratch {
  std::vector<std::uint32_t> edge;   // 3D: [a * nfaces + b] = the corner 3t + k holding the directed edge a -> b
  std::vector<std::uint32_t> first;  // per face: 3D its first corner, 2D the vertex its edge leaves
  std::vector<std::uint32_t> last;   // 2D, per face: the vertex its edge arrives at
  std::vector<std::uint32_t> next;   // 3D, per corner 3t + k: the corner after it around its face
  std::vector<std::uint32_t> loop;
  // 3D, a huge cell (face_successors_bucketed): the corners bucketed by face,
  // and per face b the stamp and corner of the edge (a -> b) of the face a
  // being matched.
  std::vector<std::uint32_t> offset, bucket, mark, holder;
  std::uint32_t mark_epoch = 0;
};

/// Above this many faces a 3D cell's face pairs are bucketed instead of
/// tabled: the table's nfaces^2 entries took 1.6 GB for one point inside a
/// shell of 20,000 points.
inline constexpr std::size_t dense_face_pairs = 1024;

inline constexpr std::uint32_t no_corner = std::numeric_limits<std::uint32_t>::max();

/// for_each_face_loop's first and next for a cell of more than
/// dense_face_pairs faces, in time linear in its corners, where the table
/// would hold nfaces^2 entries: the directed edges are bucketed by their
/// first face (a counting sort), and each face's successors are matched
/// within its bucket through a per-face mark (stamped, so never cleared).
/// Until stop 56 the edges were sorted and each found by binary search: a
/// third of the mesh's time where every cell has ~2,000 faces (a circle of
/// points and its axis).
template <class Corner>
void face_successors_bucketed(std::size_t nv, std::size_t nfaces, Corner& corner, FaceLoopScratch& w) {
  w.offset.assign(nfaces + 1, 0);
  std::uint32_t* const offset = w.offset.data();
  for (std::size_t t = 0; t < nv; ++t)
    for (int k = 0; k < 3; ++k) ++offset[corner(t, k) + 1];
  for (std::size_t a = 0; a < nfaces; ++a) offset[a + 1] += offset[a];
  // Backwards, so that each face's first corner is written last (as the
  // dense table's are).
  if (w.bucket.size() < 3 * nv) w.bucket.resize(3 * nv);
  std::uint32_t* const bucket = w.bucket.data();
  std::uint32_t* const first = w.first.data();
  for (std::size_t t = nv; t-- > 0;)
    for (int k = 3; k-- > 0;) {
      const std::size_t a = corner(t, k);
      const std::uint32_t at = static_cast<std::uint32_t>(3 * t + static_cast<std::size_t>(k));
      bucket[--offset[a + 1]] = at;
      first[a] = at;
    }
  // offset[a + 1] counted down from bucket a's end to its start: bucket a
  // is [offset[a + 1], offset[a + 2]), the last one ending at 3 nv.
  if (w.mark.size() < nfaces) w.mark.resize(nfaces);  // new marks are 0, no face's stamp
  if (w.holder.size() < nfaces) w.holder.resize(nfaces);
  std::uint32_t* const mark = w.mark.data();
  std::uint32_t* const holder = w.holder.data();
  std::uint32_t* const next = w.next.data();
  for (std::size_t a = 0; a < nfaces; ++a) {
    const std::uint32_t b0 = offset[a + 1], b1 = a + 2 <= nfaces ? offset[a + 2] : static_cast<std::uint32_t>(3 * nv);
    if (b0 == b1) continue;
    if (++w.mark_epoch == 0) {  // wrapped: stale marks could read as this face's
      std::fill(w.mark.begin(), w.mark.end(), 0);
      w.mark_epoch = 1;
    }
    const std::uint32_t stamp = w.mark_epoch;
    // Face a's edges a -> b, b the corner after a in its triangle.
    for (std::uint32_t e = b0; e < b1; ++e) {
      const std::uint32_t at = bucket[e];
      const std::size_t b = corner(at / 3, static_cast<int>((at % 3 + 1) % 3));
      mark[b] = stamp;
      holder[b] = at;
    }
    // Around face a, the corner after `at` holds the edge a -> c, c the
    // corner before a in at's triangle.
    for (std::uint32_t e = b0; e < b1; ++e) {
      const std::uint32_t at = bucket[e];
      const std::size_t c = corner(at / 3, static_cast<int>((at % 3 + 2) % 3));
      // In a closed surface the edge is there; otherwise the walk's step bound ends the loop.
      next[at] = mark[c] == stamp ? holder[c] : at;
    }
  }
}

/// Visit the faces of a closed 3D cell of nv vertices in face order, as
/// f(face, vertex indices, count): each face's vertices counter-clockwise
/// seen from outside, starting from its first vertex. corner(t, k) is vertex
/// t's k-th face (below nfaces), counter-clockwise from outside. Faces that
/// no vertex names are skipped.
///
/// Around face p, the vertex after t (p its corner k) is the one holding the
/// directed edge p -> (t's corner before k): in a closed oriented surface
/// every directed edge's twin lies in the neighbouring triangle. The edges
/// are tabled per pair of faces, nfaces^2 entries, as the Hull tables its
/// own; only entries written for this cell are read, so the table is never
/// cleared. Every corner's successor is looked up first (independent loads),
/// so that each step of a walk is a single load.
template <class Corner, class F>
void for_each_face_loop(std::size_t nv, std::size_t nfaces, Corner&& corner, FaceLoopScratch& w, F&& f) {
  w.first.assign(nfaces, no_corner);
  if (w.next.size() < 3 * nv) w.next.resize(3 * nv);
  if (w.loop.size() < nv + 1) w.loop.resize(nv + 1);
  std::uint32_t* const first = w.first.data();
  std::uint32_t* const next = w.next.data();
  std::uint32_t* const loop = w.loop.data();
  if (nfaces > dense_face_pairs) [[unlikely]] {
    face_successors_bucketed(nv, nfaces, corner, w);
  } else {
    if (w.edge.size() < nfaces * nfaces) w.edge.resize(nfaces * nfaces);
    std::uint32_t* const edge = w.edge.data();
    // Backwards, so that each face's first corner is written last (no branch).
    for (std::size_t t = nv; t-- > 0;)
      for (int k = 3; k-- > 0;) {
        const std::size_t a = corner(t, k);
        const std::uint32_t at = static_cast<std::uint32_t>(3 * t + static_cast<std::size_t>(k));
        edge[a * nfaces + corner(t, (k + 1) % 3)] = at;
        first[a] = at;
      }
    for (std::size_t t = 0; t < nv; ++t)
      for (int k = 0; k < 3; ++k)
        next[3 * t + static_cast<std::size_t>(k)] = edge[std::size_t{corner(t, k)} * nfaces + corner(t, (k + 2) % 3)];
  }
  for (std::size_t p = 0; p < nfaces; ++p) {
    const std::uint32_t start = first[p];
    if (start == no_corner) continue;
    std::size_t m = 0;
    std::uint32_t at = start;
    do {  // bounded by nv + 1 steps should the surface not be closed
      loop[m++] = at / 3;
      at = next[at];
    } while (at != start && m <= nv);
    f(p, static_cast<const std::uint32_t*>(loop), m);
  }
}

/// The same for a cell stored as Corners.
template <class F>
void for_each_face_loop(std::span<const Corners<3>> corners, std::size_t nfaces, FaceLoopScratch& w, F&& f) {
  const Corners<3>* const c = corners.data();
  for_each_face_loop(
      corners.size(), nfaces, [c](std::size_t t, int k) { return c[t][static_cast<std::size_t>(k)]; }, w,
      std::forward<F>(f));
}

/// 2D: face p is the edge from the vertex that leaves by it to the vertex
/// that arrives by it; faces in face order, as f(face, {from, to}, 2).
template <class F>
void for_each_face_loop(std::span<const Corners<2>> corners, std::size_t nfaces, FaceLoopScratch& w, F&& f) {
  w.first.assign(nfaces, no_corner);
  w.last.assign(nfaces, no_corner);
  for (std::size_t t = 0; t < corners.size(); ++t) {
    w.last[corners[t][0]] = static_cast<std::uint32_t>(t);
    w.first[corners[t][1]] = static_cast<std::uint32_t>(t);
  }
  for (std::size_t p = 0; p < nfaces; ++p) {
    if (w.first[p] == no_corner) continue;
    const std::uint32_t e[2] = {w.first[p], w.last[p]};
    f(p, static_cast<const std::uint32_t*>(e), std::size_t{2});
  }
}

}  // namespace tessera::kernels
