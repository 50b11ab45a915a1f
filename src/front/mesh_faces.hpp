// Private helpers for the products read off the merged mesh of Cells (the
// adjacency graph, face sets, flowers): the mesh precondition, face measures
// and the parallel loop over cells.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "../progress_chunks.hpp"
#include "tessera/cells.hpp"
#include "tessera/engine/thread_arena.hpp"
#include "tessera/kernels/filter.hpp"

namespace tessera::front {

/// The mesh arrays exist and have consistent sizes. A Cells without a mesh is
/// a programming error of the caller (std::invalid_argument), not bad input.
/// Periodic cells only where `periodic_too` (their faces meet images: the
/// product must carry Cells::face_shift).
inline void require_mesh(const Cells& c, const char* who, bool periodic_too = false) {
  const std::size_t nc = c.n_cells();
  auto fail = [who](const char* what) { throw std::invalid_argument(std::string(who) + ": " + what); };
  if (c.dim != 2 && c.dim != 3) fail("dim must be 2 or 3");
  if (c.is_periodic() && !periodic_too)
    throw InputError(std::string(who) + ": not available for cells in a periodic box");
  if (c.cell_face_offsets.size() != nc + 1)
    fail("cells have no mesh (compute them with VoronoiOptions::build_mesh = true)");
  const std::size_t nf = static_cast<std::size_t>(c.cell_face_offsets.back());
  if (c.face_vertex_offsets.size() != nf + 1 || c.face_neighbor.size() != nf || c.face_class.size() != nf ||
      static_cast<std::size_t>(c.face_vertex_offsets.back()) != c.face_vertices.size())
    fail("face arrays have inconsistent sizes");
  if (c.generator.size() != nc || c.region.size() != nc || c.volume.size() != nc ||
      c.cell_of.size() != c.n_points)
    fail("per-cell arrays have inconsistent sizes");
  if (c.vertices.size() != c.n_vertices() * static_cast<std::size_t>(c.dim)) fail("bad vertex array");
  if (c.is_periodic() && c.face_shift.size() != nf * static_cast<std::size_t>(c.dim)) fail("periodic cells without face shifts");
}

/// Cells that are some only (Cells::partial: VoronoiOptions::only or
/// only_with_faces) are no whole tessellation: what needs every cell (the
/// adjacency graph, validate) refuses them, as a caller's mistake.
inline void refuse_partial(const Cells& c, const char* who) {
  if (c.partial)
    throw std::invalid_argument(std::string(who) +
                                ": these cells are some only (Cells::partial: VoronoiOptions::only or "
                                "only_with_faces), not a whole tessellation");
}

/// Area of a 3D face (a planar convex polygon, via the fan from its first
/// vertex) or length of a 2D face (an edge).
inline double face_measure(const Cells& c, std::int64_t f) {
  const std::size_t b = static_cast<std::size_t>(c.face_vertex_offsets[static_cast<std::size_t>(f)]);
  const std::size_t e = static_cast<std::size_t>(c.face_vertex_offsets[static_cast<std::size_t>(f) + 1]);
  auto at = [&](std::size_t k) { return &c.vertices[static_cast<std::size_t>(c.face_vertices[k]) * c.dim]; };
  if (c.dim == 2) {
    const double* p = at(b);
    const double* q = at(b + 1);
    return std::hypot(q[0] - p[0], q[1] - p[1]);
  }
  // The fan's cross products are of coordinates relative to the first vertex,
  // scaled by a power of two that brings the largest near 1 where they are
  // beyond 2^±200: their products, and the squares of the sum, would over- or
  // underflow (faces past ~1e77 were inf, below ~1e-77 zero). A power of two
  // changes no rounding, and within that range nothing is scaled.
  const double* o = at(b);
  double m = 0;
  for (std::size_t k = b + 1; k < e; ++k)
    for (int d = 0; d < 3; ++d) m = std::max(m, std::fabs(at(k)[d] - o[d]));
  std::int32_t x = 0;
  if (m > 0 && m <= std::numeric_limits<double>::max() && !(m >= 0x1p-200 && m <= 0x1p200))
    x = kernels::filter::binary_exponent(m);
  const double sc = kernels::filter::pow2(-x);
  double s[3] = {0, 0, 0};
  for (std::size_t k = b + 1; k + 1 < e; ++k) {
    const double* p = at(k);
    const double* q = at(k + 1);
    const double u[3] = {(p[0] - o[0]) * sc, (p[1] - o[1]) * sc, (p[2] - o[2]) * sc};
    const double v[3] = {(q[0] - o[0]) * sc, (q[1] - o[1]) * sc, (q[2] - o[2]) * sc};
    s[0] += u[1] * v[2] - u[2] * v[1];
    s[1] += u[2] * v[0] - u[0] * v[2];
    s[2] += u[0] * v[1] - u[1] * v[0];
  }
  return std::ldexp(0.5 * std::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]), 2 * x);
}

/// body(cell index) for every cell, on the thread count the cells were
/// computed with. Bodies write only per-cell slots, so results never depend
/// on the schedule. `progress` (may be empty) is called between chunks of
/// cells (detail::in_progress_chunks): Ctrl-C from Python.
template <class Body>
void for_each_cell(const Cells& c, Body&& body, const std::function<void(double)>& progress = {}) {
  // (threads_used 0, never computed: one thread)
  detail::parallel_in_progress_chunks(
      c.threads_used, c.n_cells(), 256, progress,
      [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t k = r.begin(); k != r.end(); ++k) body(k);
      },
      std::size_t{1} << 15);
}

}  // namespace tessera::front
