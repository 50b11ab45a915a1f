// Each cell's distinct merged vertices, listed from its faces: what VTK's
// VTK_POLYHEDRON needs beside the face stream (its point list), written by the
// .vtu writer (src/io/vtk_xml.cpp, `connectivity`) and by Python's
// Voronoi.to_vtk() (python/src/bind_voronoi.cpp, Cells._polyhedron_arrays).
//
// Contract. The list of cell c is the vertex ids of its faces,
//   face_vertices[face_vertex_offsets[cell_face_offsets[c]] ..
//                 face_vertex_offsets[cell_face_offsets[c + 1]]),
// each id once, in the order of its first appearance there (the faces in
// order, each face's vertices in order). It depends on nothing else: not on
// the thread, nor on which cells were listed before, nor on how often.
// for_each, count and offsets may be called from any threads at once.
//
// How: a stamp per merged vertex (the number of the call that last saw it),
// one array per thread (4 bytes per vertex per thread that lists, allocated
// on its first call), so a cell's list costs one pass over its face stream
// and nothing is cleared between cells. The Cells must hold the merged mesh
// (VoronoiOptions::build_mesh) with face vertex ids below its number of
// vertices (vertices.size() / dim), and must outlive this object.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "tessera/cells.hpp"

namespace tessera {

class CellVertexLists {
 public:
  explicit CellVertexLists(const Cells& cells)
      : cfo_(cells.cell_face_offsets.data()),
        fvo_(cells.face_vertex_offsets.data()),
        fv_(cells.face_vertices.data()),
        n_cells_(cells.n_cells()),
        stamps_([n = cells.vertices.size() / static_cast<std::size_t>(cells.dim)] {
          return Stamps{std::vector<std::uint32_t>(n, 0), 0};
        }) {}

  std::size_t n_cells() const { return n_cells_; }

  /// Calls emit(v) (v a std::int32_t vertex id) for each distinct vertex of
  /// `cell`, in order of first appearance in its faces.
  template <class Emit>
  void for_each(std::size_t cell, Emit&& emit) const {
    Stamps& s = stamps_.local();
    if (++s.epoch == 0) {  // 2^32 calls on this thread: stamps restart
      std::fill(s.last.begin(), s.last.end(), 0u);
      s.epoch = 1;
    }
    const std::uint32_t epoch = s.epoch;
    std::uint32_t* last = s.last.data();
    const std::int64_t end = fvo_[cfo_[cell + 1]];
    for (std::int64_t k = fvo_[cfo_[cell]]; k < end; ++k) {
      const std::int32_t v = fv_[k];
      if (last[v] != epoch) {
        last[v] = epoch;
        emit(v);
      }
    }
  }

  /// The length of `cell`'s list.
  std::int64_t count(std::size_t cell) const {
    std::int64_t m = 0;
    for_each(cell, [&m](std::int32_t) { ++m; });
    return m;
  }

  /// Where each cell's list starts in the concatenation of all lists (CSR:
  /// n_cells + 1 values from 0, the last the total). Counted in parallel, in
  /// the calling task arena.
  std::vector<std::int64_t> offsets() const {
    std::vector<std::int64_t> off(n_cells_ + 1, 0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n_cells_), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t c = r.begin(); c != r.end(); ++c) off[c + 1] = count(c);
    });
    for (std::size_t c = 0; c < n_cells_; ++c) off[c + 1] += off[c];
    return off;
  }

 private:
  struct Stamps {
    std::vector<std::uint32_t> last;  // per vertex: the epoch of the call that last listed it
    std::uint32_t epoch = 0;          // this thread's calls so far
  };
  const std::int64_t* cfo_;
  const std::int64_t* fvo_;
  const std::int32_t* fv_;
  std::size_t n_cells_;
  mutable tbb::enumerable_thread_specific<Stamps> stamps_;
};

}  // namespace tessera
