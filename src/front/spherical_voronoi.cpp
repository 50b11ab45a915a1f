// Spherical Voronoi cells; see spherical_voronoi.hpp.
//
// Two passes over the cells, each parallel over fixed blocks of the
// locator's slots (spatial order: a cell's neighbours and their rings lie
// close by in memory, whatever order the ids come in), independent of the
// thread count:
//  1. cells: every point's cell clipped by its neighbours nearest first
//     (kernels::SphereTile); each ring rotated to start at its lowest id, so
//     the result is a function of the points alone.
//  2. vertices: a vertex (hull facet) belongs to the cell of its lowest
//     generator; owners number theirs in id order, and the other two cells
//     find the number in the owner's ring (the facet (p, a, b) is (a, b, p)
//     in a's ring and (b, p, a) in b's; one that is not there is a
//     logic_error: the rings disagree). Each cell computes its vertices'
//     directions from the facet's lowest id, so the three copies agree to
//     the bit, and from them its area, as a fan of Van Oosterom-Strackee
//     solid angles (A. van Oosterom and J. Strackee, "The solid angle of a
//     plane triangle", IEEE Trans. Biomed. Eng. 30(2), 1983), and its
//     centroid, from the vector area int x dA = 1/2 sum_edges theta_e n_e
//     (Stokes on the unit sphere: an arc of angle theta in the plane of
//     unit normal n contributes theta n).
#include "tessera/spherical_voronoi.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "compensated_sum.hpp"
#include "tessera/finite_points.hpp"
#include "../progress_chunks.hpp"
#include "tessera/cells.hpp"
#include "tessera/engine/thread_arena.hpp"
#include "tessera/kernels/locator.hpp"
#include "tessera/kernels/sphere_tile.hpp"

namespace tessera {
namespace {

using Locator = kernels::BinLocator<3>;

std::string num(double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.10g", x);
  return buf;
}

// |v|: by the sum of squares where that cannot overflow or underflow, else
// by hypot (several times slower; the cells' sums hit it only for points
// beyond 1e145 or within 1e-145 of each other).
double norm3(const double* v) {
  const double s = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
  return s > 0x1p-960 && s < 0x1p960 ? std::sqrt(s) : std::hypot(v[0], v[1], v[2]);
}

// What one pass over the points gives: the largest distance from the centre
// and the points' bounding box.
struct Extent {
  double r_max = 0;
  std::array<double, 3> lo{}, hi{};
};

// The sphere's radius and how far the points stray from it, in one pass
// (the deviation is the larger of the nearest's and the farthest's);
// InputError for what the header names.
Extent fit_sphere(std::span<const double> pts, const SphericalVoronoiOptions& o, SphericalVoronoi& out) {
  const std::size_t n = pts.size() / 3;
  const auto& c = o.center;
  for (int d = 0; d < 3; ++d)
    if (!std::isfinite(c[d])) throw InputError("spherical voronoi: the centre has a non-finite coordinate");
  if (!(o.tolerance >= 0)) throw InputError("spherical voronoi: the tolerance must be >= 0, not " + num(o.tolerance));
  if (!(o.radius >= 0) || !std::isfinite(o.radius))
    throw InputError("spherical voronoi: the radius must be positive and finite, not " + num(o.radius));
  Extent e;
  e.lo = e.hi = {pts[0], pts[1], pts[2]};
  double r_min = std::numeric_limits<double>::infinity();
  std::size_t nearest = 0, farthest = 0;
  front::CompensatedSum sum;
  for (std::size_t i = 0; i < n; ++i) {
    if (!finite_point(pts, i, 3))
      throw InputError("spherical voronoi: point " + std::to_string(i) + " has a non-finite coordinate");
    const double* p = &pts[3 * i];
    const double pc[3] = {p[0] - c[0], p[1] - c[1], p[2] - c[2]};
    const double r = norm3(pc);
    if (!(r > 0)) throw InputError("spherical voronoi: point " + std::to_string(i) + " lies at the centre");
    sum.add(r);
    if (r < r_min) r_min = r, nearest = i;
    if (r > e.r_max) e.r_max = r, farthest = i;
    for (int d = 0; d < 3; ++d) {
      e.lo[d] = std::min(e.lo[d], p[d]);
      e.hi[d] = std::max(e.hi[d], p[d]);
    }
  }
  out.radius = o.radius > 0 ? o.radius : sum.value() / static_cast<double>(n);
  if (!(out.radius > 0) || !std::isfinite(out.radius))
    throw InputError("spherical voronoi: the points' mean distance from the centre is not a usable radius");
  const double below = (out.radius - r_min) / out.radius, above = (e.r_max - out.radius) / out.radius;
  out.max_deviation = std::max({below, above, 0.0});
  const std::size_t worst = above >= below ? farthest : nearest;
  if (out.max_deviation > o.tolerance)
    throw InputError("spherical voronoi: point " + std::to_string(worst) + " lies " +
                     num(out.max_deviation * out.radius) + " off the sphere of radius " + num(out.radius) +
                     " (relative " + num(out.max_deviation) + ", tolerance " + num(o.tolerance) +
                     "); give the sphere's centre and radius, or a larger tolerance");
  return e;
}

// Bins for points on a surface: a volume's default (a few points per bin)
// would make (N / 4 pi)^1.5 bins around a sphere, mostly empty. Aim for bins
// two spacings wide, at most 10N of them up to 1M points (~6 points in each
// bin the sphere crosses; 4N took 25% longer at 1M, 20N 3% less) and 4N
// beyond (at 10M, 10N bins cost 250 MB more for no gain: 26.4 s against
// 25.0 s on two threads).
double surface_bin_points(std::size_t n) {
  const double dn = static_cast<double>(n);
  const double divs = std::sqrt(dn / (4 * std::numbers::pi));
  const double bins = std::clamp(divs * divs * divs, 1.0, std::max(4 * dn, std::min(10 * dn, 1e7)));
  return dn / bins;
}

// The unit outward normal of facet (x, y, z), given from its lowest id
// (every cell holding the facet asks the same question and gets the same
// bits). A facet of (nearly) collinear points, decided by the perturbation,
// has no computable normal: the points' mean direction from the centre
// stands in (its topology is exact, its geometry a tie's). Returns whether
// the normal is known to 1e-6 (a cell with one that is not is measured
// without its vertices: Gauss-Bonnet).
bool unit_normal(const double* x, const double* y, const double* z, const double* c, double* un) {
  double u[3];
  const double err = kernels::widest_corner_normal(x, y, z, u);
  double len = norm3(u);
  const bool known = len > 1e6 * err && std::isfinite(len);
  if (!(len > 0) || !std::isfinite(len)) {
    for (int d = 0; d < 3; ++d) u[d] = x[d] + y[d] + z[d] - 3 * c[d];
    len = std::hypot(u[0], u[1], u[2]);
    if (!(len > 0)) u[0] = 1, u[1] = u[2] = 0, len = 1;
  }
  for (int d = 0; d < 3; ++d) un[d] = u[d] / len;
  return known;
}

// A polygon cell's solid angle, and in `dir` its vector area (the
// centroid's direction): cell of the point at x, ring `rg` of slots (point()
// gives their coordinates), vertex k's unit direction at unit + 3k.
//  * The vector area int x dA = 1/2 sum_edges theta_e n_e (Stokes on the unit
//    sphere): edge k runs from vertex k to k+1 on the plane of rg[k], whose
//    unit normal into the cell is (x - q) / |x - q|.
//  * The solid angle as a fan of Van Oosterom-Strackee triangles from x's
//    direction (accurate to rounding on small cells) where x lies inside its
//    cell, no edge is long and every vertex is known (`all_known`); else by
//    Gauss-Bonnet, 2 pi less the turns between the edges' planes, which needs
//    no vertex (a lune's edges are half circles, a flat hull's cells reach
//    from pole to pole, a facet of collinear points has no normal).
template <class Point>
double polygon_measure(const double* x, const double* c, std::span<const std::int32_t> rg, const double* unit,
                       bool all_known, Point&& point, double* dir) {
  constexpr double pi = std::numbers::pi;
  const std::size_t m = rg.size();
  auto U = [&](std::size_t k) { return unit + 3 * (k % m); };
  auto dot = [](const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
  auto cross = [](const double* a, const double* b, double* out) {
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
  };
  for (int d = 0; d < 3; ++d) dir[d] = 0;
  for (std::size_t k = 0; k < m; ++k) {
    double cr[3];
    cross(U(k), U(k + 1), cr);
    const double theta = std::atan2(std::sqrt(dot(cr, cr)), dot(U(k), U(k + 1)));
    const double* q = point(rg[k]);
    const double nq[3] = {x[0] - q[0], x[1] - q[1], x[2] - q[2]};
    const double ln = norm3(nq);
    for (int d = 0; d < 3; ++d) dir[d] += 0.5 * theta * nq[d] / ln;
  }
  const double xc[3] = {x[0] - c[0], x[1] - c[1], x[2] - c[2]};
  const double pl = norm3(xc);
  const double apex[3] = {xc[0] / pl, xc[1] / pl, xc[2] / pl};
  bool fan = m >= 3 && all_known;
  for (std::size_t k = 0; k < m && fan; ++k) {
    const double* q = point(rg[k]);
    const double nq[3] = {x[0] - q[0], x[1] - q[1], x[2] - q[2]};
    fan = dot(U(k), U(k + 1)) > -0.5 && dot(apex, nq) > 0;
  }
  double omega = 0;
  if (fan) {
    for (std::size_t k = 0; k < m; ++k) {
      double cr[3];
      cross(U(k), U(k + 1), cr);
      omega += 2 * std::atan2(dot(apex, cr), 1 + dot(apex, U(k)) + dot(U(k), U(k + 1)) + dot(U(k + 1), apex));
    }
    return omega;
  }
  omega = 2 * pi;
  for (std::size_t k = 0; k < m; ++k) {
    const double* q0 = point(rg[k]);
    const double* q1 = point(rg[(k + 1) % m]);
    const double n0[3] = {x[0] - q0[0], x[1] - q0[1], x[2] - q0[2]};
    const double n1[3] = {x[0] - q1[0], x[1] - q1[1], x[2] - q1[2]};
    double cr[3];
    cross(n0, n1, cr);
    omega -= std::atan2(std::hypot(cr[0], cr[1], cr[2]), dot(n0, n1));
  }
  return omega;
}

struct Workspace {
  kernels::SphereTile tile;
  struct Candidate {
    double d2;
    std::int32_t id;
    std::uint32_t slot;
  };
  std::vector<Candidate> cands;
  std::size_t exact_tests = 0;
};

// One block of the locator's slots: the cells' rings, back to back.
struct Block {
  std::vector<std::int32_t> ring;
  std::vector<std::uint32_t> start;  // per slot of the block, into ring (one past the end last)
  std::vector<std::uint8_t> state;   // per slot: SphereTile::State
};

constexpr std::size_t block_slots = 2048;

}  // namespace

std::vector<double> lonlat_to_points(std::span<const double> lonlat, double radius, const std::array<double, 3>& center) {
  if (lonlat.size() % 2 != 0) throw InputError("lon/lat: the values do not pair up");
  if (!(radius > 0) || !std::isfinite(radius)) throw InputError("lon/lat: the radius must be positive and finite");
  const std::size_t n = lonlat.size() / 2;
  std::vector<double> out(3 * n);
  constexpr double deg = std::numbers::pi / 180;
  for (std::size_t i = 0; i < n; ++i) {
    const double lon = lonlat[2 * i], lat = lonlat[2 * i + 1];
    if (!std::isfinite(lon) || !std::isfinite(lat))
      throw InputError("lon/lat: point " + std::to_string(i) + " has a non-finite longitude or latitude");
    if (lat < -90 || lat > 90)
      throw InputError("lon/lat: point " + std::to_string(i) + " has latitude " + num(lat) + ", beyond [-90, 90]");
    const double cl = std::cos(lat * deg);
    out[3 * i + 0] = center[0] + radius * cl * std::cos(lon * deg);
    out[3 * i + 1] = center[1] + radius * cl * std::sin(lon * deg);
    out[3 * i + 2] = center[2] + radius * std::sin(lat * deg);
  }
  return out;
}

SphericalVoronoi spherical_voronoi(std::span<const double> pts, const SphericalVoronoiOptions& o) {
  if (pts.size() % 3 != 0) throw InputError("spherical voronoi: the coordinates do not make whole 3D points");
  const std::size_t n = pts.size() / 3;
  if (n == 0) throw InputError("spherical voronoi: no points");
  if (n > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max() / 4))
    throw InputError("spherical voronoi: too many points (" + std::to_string(n) + ")");
  SphericalVoronoi out;
  out.center = o.center;
  out.n_points = n;
  const Extent extent = fit_sphere(pts, o, out);
  const auto& c = o.center;
  double r_max = extent.r_max;
  std::array<double, 3> lo = extent.lo, hi = extent.hi;
  r_max *= 1 + 1e-12;
  // The grid needs a box of some extent along every axis (one point, a ring
  // in a coordinate plane); the padding is nothing beside the sphere.
  for (int d = 0; d < 3; ++d) {
    const double pad = 1e-6 * r_max + 1e-6 * std::max(std::fabs(lo[d]), std::fabs(hi[d]));
    lo[d] -= pad;
    hi[d] += pad;
  }

  engine::ThreadArena arena(resolve_threads(o.threads));
  arena.execute([&] {
    const Locator loc(pts, {}, lo, hi, o.bin_points > 0 ? o.bin_points : surface_bin_points(n));
    const std::vector<std::int32_t> lowest = loc.lowest_coincident();  // per slot
    out.duplicate_of.assign(n, -1);
    for (std::size_t slot = 0; slot < n; ++slot)
      if (lowest[slot] >= 0) out.duplicate_of[static_cast<std::size_t>(loc.id(slot))] = lowest[slot];

    // ---- pass 1: the cells ----
    // The first box's half-width: 1.5 mean spacings of points spread over
    // the sphere, about the radius a cell's search needs (a larger box
    // follows where it does not).
    const double w0 = 1.5 * out.radius * std::sqrt(4 * std::numbers::pi / static_cast<double>(n));
    const std::size_t n_blocks = (n + block_slots - 1) / block_slots;
    std::vector<Block> blocks(n_blocks);
    const double* const slot0 = loc.point(0).data();  // slot k's point is slot0 + 3k
    tbb::enumerable_thread_specific<Workspace> spaces;
    // Progress: the cells are ~60% of a run, the second pass the rest;
    // chunks of 32 blocks (65,536 cells) between the callbacks.
    std::function<void(double)> progress1, progress2;
    if (o.progress) {
      progress1 = [&](double f) { o.progress(0.6 * f); };
      progress2 = [&](double f) { o.progress(0.6 + 0.4 * f); };
    }
    detail::in_progress_chunks(n_blocks, progress1, [&](std::size_t b0, std::size_t b1) {
      tbb::parallel_for(b0, b1, [&](std::size_t bk) {
        Workspace& ws = spaces.local();
        Block& block = blocks[bk];
        const std::size_t first = bk * block_slots, last = std::min(n, first + block_slots);
        for (std::size_t slot = first; slot < last; ++slot) {
          block.start.push_back(static_cast<std::uint32_t>(block.ring.size()));
          if (lowest[slot] >= 0) {
            block.state.push_back(static_cast<std::uint8_t>(kernels::SphereTile::State::empty));
            continue;
          }
          const double* x = loc.point(slot).data();
          const std::int32_t id = loc.id(slot);
          auto& tile = ws.tile;
          tile.reset(id, x, c.data(), r_max);
          int clips = 0;
          // Candidates by boxes of growing half-width w: each round offers the
          // points whose largest coordinate difference from x (computed the
          // same way every round) lies in (the last w, w], once each (a cell
          // clipped twice by one plane would tie with itself). The bins of the
          // box [x - w, x + w], widened by a few ulps for its rounded corners,
          // hold them all. The search ends once the cell's radius is within w
          // (less a rounding margin: a point that near has a difference within
          // w) or the box holds the whole grid.
          double covered = -1;
          for (double w = w0;; w *= 2) {
            if (tile.state() == kernels::SphereTile::State::empty) break;
            const double wb = w + 4 * std::numeric_limits<double>::epsilon() *
                                      (w + std::max({std::fabs(x[0]), std::fabs(x[1]), std::fabs(x[2])}));
            const double blo[3] = {x[0] - wb, x[1] - wb, x[2] - wb}, bhi[3] = {x[0] + wb, x[1] + wb, x[2] + wb};
            std::array<std::int32_t, 3> bf, bl;
            loc.bin_range(blo, bhi, bf, bl);
            bool whole = true;
            for (int d = 0; d < 3; ++d) whole = whole && bf[d] == 0 && bl[d] == loc.divisions()[d] - 1;
            ws.cands.clear();
            const double r2 = tile.security2();
            loc.for_each_row_run(bf, bl, [&](std::uint32_t f, std::uint32_t e) {
              for (std::uint32_t k = f; k < e; ++k) {
                if (k == slot || lowest[k] >= 0) continue;
                const auto& q = loc.point(k);
                const double dx = q[0] - x[0], dy = q[1] - x[1], dz = q[2] - x[2];
                const double cheb = std::max({std::fabs(dx), std::fabs(dy), std::fabs(dz)});
                if (cheb <= covered || cheb > w) continue;  // an earlier round's, or a later one's
                const double d2 = dx * dx + dy * dy + dz * dz;
                if (d2 <= r2) ws.cands.push_back({d2, loc.id(k), k});
              }
            });
            // Nearest first, a dozen at a time: once a cell has its nearest
            // neighbours its security radius passes most of the rest unsorted.
            auto nearer = [](const auto& a, const auto& b2) { return a.d2 != b2.d2 ? a.d2 < b2.d2 : a.id < b2.id; };
            // The first few clips of a cell go ahead without asking its
            // radius (a clip that changes nothing is merely a wasted test).
            auto first = ws.cands.begin(), last = ws.cands.end();
            while (first != last) {
              const auto stop = last - first > 12 ? first + 12 : last;
              if (stop != last) std::nth_element(first, stop - 1, last, nearer);
              std::sort(first, stop, nearer);
              bool done = false;
              for (; first != stop; ++first) {
                if (tile.state() == kernels::SphereTile::State::empty ||
                    (++clips > 6 && first->d2 > tile.security2())) {
                  done = true;
                  break;
                }
                tile.clip(first->id, loc.point(first->slot).data());
              }
              if (done) break;
              // Drop what the radius now passes before sorting again.
              const double r2now = tile.security2();
              last = std::partition(first, last, [&](const auto& cd) { return cd.d2 <= r2now; });
            }
            covered = w;
            const double sure = w * (1 - 1e-12);
            if (tile.security2() <= sure * sure) break;
            if (whole) {
              // The last round: what lay beyond w in the box's bins.
              if (covered == std::numeric_limits<double>::infinity()) break;
              w = std::numeric_limits<double>::infinity() / 2;
            }
          }
          ws.exact_tests += tile.exact_tests();
          block.state.push_back(static_cast<std::uint8_t>(tile.state()));
          // The ring by the neighbours' slots (the passes below read their
          // points and rings there), rotated to start at the lowest id.
          const auto ring = tile.edges();
          const auto ring_pts = tile.edge_points();
          const std::size_t rot = static_cast<std::size_t>(std::min_element(ring.begin(), ring.end()) - ring.begin());
          for (std::size_t k = 0; k < ring.size(); ++k)
            block.ring.push_back(static_cast<std::int32_t>((ring_pts[(rot + k) % ring.size()] - slot0) / 3));
        }
        block.start.push_back(static_cast<std::uint32_t>(block.ring.size()));
      });
    }, 32);
    for (const auto& ws : spaces) out.exact_tests += ws.exact_tests;

    // Rings in slot order (the blocks back to back), of slots: the pass
    // below walks the cells in the locator's order, where a cell's
    // neighbours' rings and points lie close by in memory, whatever order
    // the ids come in.
    Buffer<std::int64_t> ring_at(n + 1, 0);  // per slot
    std::vector<std::uint8_t> slot_state(n);
    for (std::size_t bk = 0; bk < n_blocks; ++bk)
      for (std::size_t k = 0; k + 1 < blocks[bk].start.size(); ++k) {
        ring_at[bk * block_slots + k + 1] = blocks[bk].start[k + 1] - blocks[bk].start[k];
        slot_state[bk * block_slots + k] = blocks[bk].state[k];
      }
    for (std::size_t s = 0; s < n; ++s) ring_at[s + 1] += ring_at[s];
    Buffer<std::int32_t> rings(static_cast<std::size_t>(ring_at[n]));
    tbb::parallel_for(std::size_t{0}, n_blocks, [&](std::size_t bk) {
      std::copy(blocks[bk].ring.begin(), blocks[bk].ring.end(), rings.begin() + ring_at[bk * block_slots]);
    });
    blocks.clear();
    blocks.shrink_to_fit();
    Buffer<std::uint32_t> slot_of(n);
    for (std::size_t s = 0; s < n; ++s) slot_of[static_cast<std::size_t>(loc.id(s))] = static_cast<std::uint32_t>(s);
    auto ring = [&](std::size_t slot) {
      return std::span<const std::int32_t>(rings.data() + ring_at[slot], static_cast<std::size_t>(ring_at[slot + 1] - ring_at[slot]));
    };
    auto point = [&](std::int32_t slot) { return loc.point(static_cast<std::size_t>(slot)).data(); };
    auto id_at = [&](std::int32_t slot) { return loc.id(static_cast<std::size_t>(slot)); };

    using State = kernels::SphereTile::State;
    out.status.assign(n, SphereCellStatus::cell);
    out.neighbor_offsets.assign(n + 1, 0);
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t s = slot_of[i];
      out.neighbor_offsets[i + 1] = out.neighbor_offsets[i] + (ring_at[s + 1] - ring_at[s]);
      if (out.duplicate_of[i] >= 0) {
        out.status[i] = SphereCellStatus::duplicate;
        ++out.duplicates;
      } else if (static_cast<State>(slot_state[s]) == State::empty) {
        out.status[i] = SphereCellStatus::hidden;
        ++out.hidden;
      }
    }
    out.neighbors.resize(rings.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i) {
        const auto rg = ring(slot_of[i]);
        std::transform(rg.begin(), rg.end(), out.neighbors.begin() + out.neighbor_offsets[i], id_at);
      }
    });

    // ---- pass 2: vertices, numbered by their owners; areas, centroids ----
    // Vertex k of a polygon cell is where edge k-1 ends: facet (p, ring[k-1], ring[k]).
    Buffer<std::int64_t> owned(n + 1, 0);  // by id
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t s = r.begin(); s != r.end(); ++s) {
        const auto rg = ring(s);
        if (rg.size() < 2) continue;
        const std::int32_t p = loc.id(s);
        std::int64_t k = 0;
        for (std::size_t e = 0; e < rg.size(); ++e) k += p < id_at(rg[(e + rg.size() - 1) % rg.size()]) && p < id_at(rg[e]);
        owned[static_cast<std::size_t>(p) + 1] = k;
      }
    });
    for (std::size_t i = 0; i < n; ++i) owned[i + 1] += owned[i];
    const std::size_t n_vertices = static_cast<std::size_t>(owned[n]);
    if (n_vertices > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
      throw InputError("spherical voronoi: too many vertices");
    out.region_offsets.assign(n + 1, 0);
    for (std::size_t i = 0; i < n; ++i) {
      const std::int64_t m = out.neighbor_offsets[i + 1] - out.neighbor_offsets[i];
      out.region_offsets[i + 1] = out.region_offsets[i] + (m >= 2 ? m : 0);
    }
    out.region_vertices.resize(static_cast<std::size_t>(out.region_offsets[n]));
    out.triangles.resize(3 * n_vertices);
    out.vertices.resize(3 * n_vertices);
    out.areas.resize(n);
    out.centroids.resize(3 * n);
    const double R = out.radius, R2 = R * R;
    constexpr double pi = std::numbers::pi;
    tbb::enumerable_thread_specific<std::vector<double>> unit_space;
    detail::in_progress_chunks(n, progress2, [&](std::size_t s0, std::size_t s1) {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(s0, s1, 2048), [&](const tbb::blocked_range<std::size_t>& r) {
        std::vector<double>& unit = unit_space.local();
        for (std::size_t s = r.begin(); s != r.end(); ++s) {
          const std::int32_t p = loc.id(s);
          const std::size_t i = static_cast<std::size_t>(p);
          const double* x = loc.point(s).data();
          const auto rg = ring(s);
          const std::size_t m = rg.size();
          unit.resize(3 * m);
          bool all_known = true;  // every vertex's normal (unit_normal)
          if (m >= 2) {
            std::int64_t next_owned = owned[i];
            for (std::size_t e = 0; e < m; ++e) {
              const std::int32_t as = rg[(e + m - 1) % m], bs = rg[e], ps = static_cast<std::int32_t>(s);
              const std::int32_t a = id_at(as), b = id_at(bs);
              // The facet from its lowest generator, so that every cell
              // holding it computes the same normal (unit_normal).
              const std::int32_t lowest = std::min({p, a, b});
              const std::int32_t f0 = lowest == p ? ps : (lowest == a ? as : bs);
              const std::int32_t f1 = lowest == p ? as : (lowest == a ? bs : ps);
              const std::int32_t f2 = lowest == p ? bs : (lowest == a ? ps : as);
              double* un = &unit[3 * e];
              all_known = unit_normal(point(f0), point(f1), point(f2), c.data(), un) && all_known;
              std::int64_t v;
              if (lowest == p) {
                v = next_owned++;
                std::int32_t* t = &out.triangles[3 * static_cast<std::size_t>(v)];
                t[0] = p, t[1] = a, t[2] = b;
                double* pos = &out.vertices[3 * static_cast<std::size_t>(v)];
                for (int d = 0; d < 3; ++d) pos[d] = c[d] + R * un[d];
              } else {
                // The owner q = lowest: the facet is (a, b, p) in a's ring, (b, p, a) in b's.
                const std::int32_t q = lowest;
                const std::int32_t in = q == a ? bs : ps, outgoing = q == a ? ps : as;  // slots
                const auto oring = ring(static_cast<std::size_t>(q == a ? as : bs));
                const std::size_t om = oring.size();
                v = -1;
                std::int64_t num = owned[static_cast<std::size_t>(q)];
                for (std::size_t f = 0; f < om; ++f) {
                  const std::int32_t oa = oring[(f + om - 1) % om], ob = oring[f];
                  if (oa == in && ob == outgoing) {
                    v = num;
                    break;
                  }
                  num += q < id_at(oa) && q < id_at(ob);
                }
                if (v < 0)
                  throw std::logic_error("spherical voronoi: cell " + std::to_string(p) + "'s vertex with " + std::to_string(a) +
                                         ", " + std::to_string(b) + " is not in cell " + std::to_string(q));
              }
              out.region_vertices[static_cast<std::size_t>(out.region_offsets[i]) + e] = static_cast<std::int32_t>(v);
            }
          }
          // Areas and centroids.
          double dir[3] = {x[0] - c[0], x[1] - c[1], x[2] - c[2]};  // the centroid's direction
          double omega = 0;
          if (out.status[i] != SphereCellStatus::cell) {
            omega = 0;
          } else if (m == 0) {
            omega = 4 * pi;
          } else if (m == 1) {
            const double* q = point(rg[0]);
            for (int d = 0; d < 3; ++d) dir[d] = x[d] - q[d];
            omega = 2 * pi;
          } else {
            omega = polygon_measure(x, c.data(), rg, unit.data(), all_known, point, dir);
          }
          out.areas[i] = R2 * omega;
          double ld = norm3(dir);
          if (!(ld > 0)) dir[0] = x[0] - c[0], dir[1] = x[1] - c[1], dir[2] = x[2] - c[2], ld = norm3(dir);
          for (int d = 0; d < 3; ++d) out.centroids[3 * i + d] = c[d] + R * dir[d] / ld;
        }
      });
    });
    front::CompensatedSum total;
    for (double a : out.areas) total.add(a);
    out.area_sum = total.value();
  });
  return out;
}

}  // namespace tessera
