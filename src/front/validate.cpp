// tessera::validate: the invariants a correct tessellation satisfies.
//
// The checks over every cell and every merged vertex run in parallel, in an
// arena of the thread count the cells were computed with: read serially, the
// neighbour lists and vertices of cells numbered by generator id (input
// order, no spatial order) missed the cache at nearly every access, and
// validating 1M 3D cells took longer than computing them. Every result is a
// count, a maximum or a sum taken in a fixed order, so the report does not
// depend on the thread count.
#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <limits>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "tessera/cells.hpp"
#include "tessera/engine/thread_arena.hpp"
#include "mesh_faces.hpp"
#include "validate_measures.hpp"
#include "walls.hpp"

namespace tessera {
namespace {

// A cell's distinct merged vertices among its face corners (each vertex is a
// corner of several faces): a small open-addressing set, reused from cell to
// cell by stamping its slots with the cell's number instead of clearing it.
class CornerSet {
 public:
  /// Starts a cell of at most `corners` corners.
  void start(std::size_t corners) {
    const std::size_t size = std::bit_ceil(std::max<std::size_t>(64, 2 * corners));
    if (slots_.size() < size || ++stamp_ == 0) {
      slots_.assign(std::max(size, slots_.size()), Slot{});
      stamp_ = 1;
    }
    mask_ = size - 1;
    shift_ = 64 - std::countr_zero(size);
  }
  /// True the first time v is met in this cell.
  bool insert(std::int32_t v) {
    // Fibonacci hashing: the product's top bits.
    for (std::size_t s = (std::uint64_t{static_cast<std::uint32_t>(v)} * 0x9E3779B97F4A7C15ull) >> shift_;;
         s = (s + 1) & mask_) {
      Slot& e = slots_[s];
      if (e.stamp != stamp_) {
        e = {v, stamp_};
        return true;
      }
      if (e.vertex == v) return false;
    }
  }

 private:
  struct Slot {
    std::int32_t vertex = 0;
    std::uint32_t stamp = 0;
  };
  std::vector<Slot> slots_;
  std::size_t mask_ = 0;
  int shift_ = 64;
  std::uint32_t stamp_ = 0;
};

// What the per-cell pass over the mesh counts.
struct MeshCounts {
  std::size_t bad_euler = 0;
  std::size_t unresolved = 0;  // corners naming no merged vertex
};

/// Entries (i, j, s) of a periodic box's neighbour lists without as many
/// entries (j, i, -s) in j's list (both cells; an outside point's list is
/// one-sided by design).
std::size_t asymmetric_periodic_spokes(const Cells& c) {
  const auto du = static_cast<std::size_t>(c.dim);
  auto count_in = [&](std::size_t cell, std::int32_t id, const std::int8_t* shift, bool negate) {
    std::size_t k = 0;
    for (auto e = c.neighbor_offsets[cell]; e < c.neighbor_offsets[cell + 1]; ++e) {
      const auto eu = static_cast<std::size_t>(e);
      if (c.neighbors[eu] != id) continue;
      bool same = true;
      for (std::size_t a = 0; a < du; ++a)
        same = same && c.neighbor_shifts[eu * du + a] == (negate ? -shift[a] : shift[a]);
      k += same;
    }
    return k;
  };
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, c.n_cells()), std::size_t{0},
      [&](const tbb::blocked_range<std::size_t>& range, std::size_t n) {
        for (std::size_t k = range.begin(); k != range.end(); ++k) {
          const std::int32_t g = c.generator[k];
          for (auto e = c.neighbor_offsets[k]; e < c.neighbor_offsets[k + 1]; ++e) {
            const auto eu = static_cast<std::size_t>(e);
            const std::int32_t cj = c.cell_of[static_cast<std::size_t>(c.neighbors[eu])];
            if (cj < 0) continue;
            const std::int8_t* s = c.neighbor_shifts.data() + eu * du;
            n += count_in(static_cast<std::size_t>(cj), g, s, true) != count_in(k, c.neighbors[eu], s, false);
          }
        }
        return n;
      },
      [](std::size_t a, std::size_t b) { return a + b; });
}

ValidationReport validate_in_arena(const Cells& c, std::span<const std::int32_t> labels,
                                   std::span<const double> points, std::span<const double> radii) {
  ValidationReport r;
  const std::size_t nc = c.n_cells();
  const int D = c.dim;
  const auto Du = static_cast<std::size_t>(D);

  // Volumes: with every point inside, the cells tile the domain exactly.
  // Checked only where the volumes are normal doubles (volumes_representable):
  // outside that the input's scale, not the tessellation, decides what a
  // double can hold. Summed serially: the sum's rounding must not depend on
  // the thread count.
  for (double v : c.volume) r.volume_sum += v;
  r.domain_volume = front::domain_volume(c.bounds, c.walls, D, c.threads_used);  // the box inside the walls
  r.volume_rel_error = std::fabs(r.volume_sum - r.domain_volume) / r.domain_volume;
  r.volumes_checked = volumes_representable(r.domain_volume, nc);
  const bool all_inside = c.ignored_outside_bounds.empty() &&
                          std::none_of(labels.begin(), labels.end(), [](std::int32_t l) { return l < 0; });
  if (r.volumes_checked && all_inside && r.volume_rel_error > 1e-9) {
    std::ostringstream m;
    m << "cell volumes sum to " << r.volume_sum << ", domain volume " << r.domain_volume
      << " (relative error " << r.volume_rel_error << ")";
    r.messages.push_back(m.str());
    r.ok = false;
  }
  // A cell's volume is exact where its float sum cancels (front/cell_geometry.hpp),
  // so it is never negative, and zero only when the exact volume is below
  // the smallest double (points within ~1e-160 of each other): counted, not
  // a failure.
  for (std::size_t k = 0; r.volumes_checked && k < nc; ++k) {
    if (c.volume[k] == 0) {
      ++r.underflowed_volumes;
    } else if (!(c.volume[k] > 0)) {
      r.messages.push_back("cell of point " + std::to_string(c.generator[k]) + " has negative volume");
      r.ok = false;
      break;
    }
  }

  // Symmetric spokes between cells; in a periodic box between images: i
  // meets j moved by s as often as j meets i moved by -s.
  if (c.is_periodic()) r.asymmetric_spokes = asymmetric_periodic_spokes(c);
  else r.asymmetric_spokes = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, nc), std::size_t{0},
      [&](const tbb::blocked_range<std::size_t>& range, std::size_t n) {
        for (std::size_t k = range.begin(); k != range.end(); ++k) {
          const std::int32_t g = c.generator[k];
          for (auto e = c.neighbor_offsets[k]; e < c.neighbor_offsets[k + 1]; ++e) {
            const std::int32_t j = c.neighbors[static_cast<std::size_t>(e)];
            const std::int32_t cj = c.cell_of[static_cast<std::size_t>(j)];
            if (cj < 0) continue;  // outside point: one-sided by design
            auto b = c.neighbors.begin() + c.neighbor_offsets[static_cast<std::size_t>(cj)];
            auto en = c.neighbors.begin() + c.neighbor_offsets[static_cast<std::size_t>(cj) + 1];
            n += !std::binary_search(b, en, g);
          }
        }
        return n;
      },
      [](std::size_t a, std::size_t b) { return a + b; });
  if (r.asymmetric_spokes) {
    r.messages.push_back(std::to_string(r.asymmetric_spokes) + " one-sided spokes (i lists j, j does not list i)");
    r.ok = false;
  }

  if (c.vertex_keys.empty()) return r;
  // Each merged vertex is used by exactly the cells of its key's generators.
  // With the points, each cell's radius (its farthest vertex from its
  // generator, squared) is taken too, for the exact check's sample. A vertex
  // lies equally far from every generator of its key, so its distance is
  // measured once, from the first generator in its key.
  const std::size_t nv = c.n_vertices();
  const bool measuring = !points.empty() && r.volumes_checked;
  // A periodic box's cells lie where they took their points: wrapped into it.
  const bool periodic = c.is_periodic();
  if (periodic && measuring) points = c.periodic_points;
  const auto lattice = periodic ? c.lattice() : std::array<std::array<double, 3>, 3>{};
  std::vector<std::int32_t> users(nv, 0);
  // Power cells: a vertex has equal powers, not distances, to its key's
  // points. dist2 holds its squared distance s from the key's first point
  // g, so its squared distance from the cell's generator k is s + r_k^2 -
  // r_g^2, taken as (r_k - r_g)(r_k + r_g): a radius past ~1e154 has no
  // finite square, and s - r_g^2 + r_k^2 gave NaN there (until stop 79 the
  // cell's radius then read 0, and its corners' offsets infinite relative
  // to it).
  const bool power = !radii.empty();
  auto radius_of = [&](std::int32_t g) { return power ? radii[static_cast<std::size_t>(g)] : 0.0; };
  std::vector<double> dist2(measuring ? nv : 0, 0.0), radius2(measuring ? nc : 0, 0.0);
  std::vector<double> key_radius(measuring && power ? nv : 0, 0.0);  // r_g of each vertex's g
  if (measuring)
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nv), [&](const tbb::blocked_range<std::size_t>& range) {
      for (std::size_t v = range.begin(); v != range.end(); ++v) {
        const std::int32_t* key = c.vertex_keys.data() + v * (Du + 1);
        const std::int32_t* g = std::find_if(key, key + Du + 1, [](std::int32_t id) { return id >= 0; });
        if (g == key + Du + 1) continue;  // no generator: the degree check below fails it
        const double* p = points.data() + static_cast<std::size_t>(*g) * Du;
        double image[3];
        if (periodic && c.vertex_key_shifts.size() == c.vertex_keys.size() * Du) {  // the entry's image
          const auto e = v * (Du + 1) + static_cast<std::size_t>(g - key);
          periodic_image(lattice, c.dim, &c.periodic_points[static_cast<std::size_t>(*g) * Du],
                         &c.vertex_key_shifts[e * Du], image);
          p = image;
        }
        double s = 0;
        for (std::size_t d = 0; d < Du; ++d) {
          const double x = c.vertices[v * Du + d] - p[d];
          s += x * x;
        }
        dist2[v] = s;
        if (power) key_radius[v] = radius_of(*g);
      }
    });
  tbb::enumerable_thread_specific<CornerSet> sets;
  const MeshCounts counts = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, nc), MeshCounts{},
      [&](const tbb::blocked_range<std::size_t>& range, MeshCounts m) {
        CornerSet& seen = sets.local();
        for (std::size_t k = range.begin(); k != range.end(); ++k) {
          const std::int64_t f0 = c.cell_face_offsets[k], f1 = c.cell_face_offsets[k + 1];
          const auto q_begin = c.face_vertex_offsets[static_cast<std::size_t>(f0)];
          const auto q_end = c.face_vertex_offsets[static_cast<std::size_t>(f1)];
          seen.start(static_cast<std::size_t>(q_end - q_begin));
          std::int64_t corners = 0, distinct = 0;
          double r2 = 0.0;
          const double rk = radius_of(c.generator[k]);
          for (auto q = q_begin; q < q_end; ++q) {
            const std::int32_t v = c.face_vertices[static_cast<std::size_t>(q)];
            if (v < 0 || static_cast<std::size_t>(v) >= nv) {
              ++m.unresolved;
              continue;
            }
            ++corners;
            if (!seen.insert(v)) continue;
            ++distinct;
            std::atomic_ref<std::int32_t>(users[static_cast<std::size_t>(v)]).fetch_add(1, std::memory_order_relaxed);
            if (measuring) {
              const auto vu = static_cast<std::size_t>(v);
              const double rg = power ? key_radius[vu] : 0.0;
              r2 = std::max(r2, dist2[vu] + (rk - rg) * (rk + rg));
            }
          }
          if (measuring) radius2[k] = r2;
          if (D == 3) {
            // Every corner starts an edge of its face's loop, and every edge
            // is in two faces.
            const std::int64_t F = f1 - f0, E = corners / 2, V = distinct;
            m.bad_euler += V - E + F != 2;
          }
        }
        return m;
      },
      [](MeshCounts a, const MeshCounts& b) {
        a.bad_euler += b.bad_euler;
        a.unresolved += b.unresolved;
        return a;
      });
  // In a periodic box a merged vertex is used by the cells of its key's
  // points at shift 0 (Cells::vertex_key_shifts; the entries at other shifts
  // are images, whose copies of the vertex are other merged vertices).
  const bool shifted = c.is_periodic();
  const bool degrees = !shifted || c.vertex_key_shifts.size() == c.vertex_keys.size() * Du;
  if (degrees) r.bad_vertex_degree = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, nv), std::size_t{0},
      [&](const tbb::blocked_range<std::size_t>& range, std::size_t n) {
        for (std::size_t v = range.begin(); v != range.end(); ++v) {
          std::int32_t expect = 0;
          for (std::size_t d = 0; d <= Du; ++d) {
            const std::size_t e = v * (Du + 1) + d;
            const std::int32_t id = c.vertex_keys[e];
            bool here = id >= 0 && c.cell_of[static_cast<std::size_t>(id)] >= 0;
            if (shifted)
              for (std::size_t a = 0; a < Du; ++a) here &= c.vertex_key_shifts[e * Du + a] == 0;
            expect += here;
          }
          n += users[v] != expect;
        }
        return n;
      },
      [](std::size_t a, std::size_t b) { return a + b; });
  r.bad_euler = counts.bad_euler;
  if (r.bad_vertex_degree) {
    r.messages.push_back(std::to_string(r.bad_vertex_degree) +
                         " merged vertices not shared by exactly the cells of their generators");
    r.ok = false;
  }
  if (counts.bad_euler) {
    r.messages.push_back(std::to_string(counts.bad_euler) + " cells with Euler characteristic != 2");
    r.ok = false;
  }
  if (counts.unresolved) {
    r.messages.push_back(std::to_string(counts.unresolved) + " face corners refer to no merged vertex");
    r.ok = false;
  }
  // Every vertex used by exactly the cells of its key (so the distance
  // measured from its key's first generator is each of its cells' own) and
  // every corner resolved: the mesh can be measured exactly.
  // (A periodic box's cells are measured among their keys' images, which
  // needs every key's shifts.)
  if (measuring && r.bad_vertex_degree == 0 && counts.unresolved == 0 &&
      (!periodic || c.vertex_key_shifts.size() == c.vertex_keys.size() * Du))
    front::check_measures(c, points, radii, radius2, r);
  return r;
}

}  // namespace

ValidationReport validate(const Cells& c, std::span<const std::int32_t> labels, std::span<const double> points,
                          std::span<const double> radii) {
  // Some cells only: their volumes do not tile the domain, and their
  // vertices miss cells.
  front::refuse_partial(c, "validate");
  if (!labels.empty() && labels.size() != c.n_points)
    throw std::invalid_argument("validate: " + std::to_string(labels.size()) + " labels given for " +
                                std::to_string(c.n_points) + " points");
  if (!points.empty() && points.size() != c.n_points * static_cast<std::size_t>(c.dim))
    throw std::invalid_argument("validate: " + std::to_string(points.size()) + " coordinates given for " +
                                std::to_string(c.n_points) + " points in " + std::to_string(c.dim) + "D");
  if (!points.empty() && c.power && radii.size() != c.n_points)
    throw std::invalid_argument("validate: power cells need their radii with the points (" +
                                std::to_string(radii.size()) + " given for " + std::to_string(c.n_points) + ")");
  if (!c.power) radii = {};  // equal radii gave the ordinary cells
  // The points and radii are the caller's (Python keeps them without a
  // copy): changed since the cells to NaN or inf, the exact measures got
  // them, and GMP's conversion of a non-finite double aborted the process.
  // Points set aside as outside or not finite are not read.
  if (!points.empty()) {
    std::vector<std::uint8_t> aside(c.n_points, 0);
    for (const std::int32_t i : c.ignored_outside_bounds) aside[static_cast<std::size_t>(i)] = 1;
    const auto du = static_cast<std::size_t>(c.dim);
    for (std::size_t i = 0; i < c.n_points; ++i) {
      if (aside[i]) continue;
      for (std::size_t a = 0; a < du; ++a)
        if (!std::isfinite(points[i * du + a]))
          throw InputError("validate: point " + std::to_string(i) +
                           " has a non-finite coordinate, which its cells were not computed from (were the points "
                           "changed since?)");
      if (!radii.empty() && !(std::isfinite(radii[i]) && radii[i] >= 0))
        throw InputError("validate: the radius of point " + std::to_string(i) +
                         " is not finite and >= 0, which its cells were not computed from (were the radii changed "
                         "since?)");
    }
  }
  engine::ThreadArena arena(c.threads_used);
  return arena.execute([&] { return validate_in_arena(c, labels, points, radii); });
}

}  // namespace tessera
