// tessera::SimplexLocator: a walk from seeded simplices, or a grid of
// simplices, queried with exact orientation tests (see locate.hpp).
#include "tessera/locate.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numeric>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "../progress_chunks.hpp"
#include "point_buckets.hpp"
#include "tessera/engine/thread_arena.hpp"
#include "tessera/kernels/delaunay_predicates.hpp"

namespace tessera {
namespace {

void check_points(const Delaunay& dt, std::span<const double> points, const char* what) {
  if (points.size() != dt.n_points * static_cast<std::size_t>(dt.dim))
    throw InputError(std::string(what) + ": " + std::to_string(points.size()) + " coordinates for a triangulation of " +
                     std::to_string(dt.n_points) + " points in " + std::to_string(dt.dim) + "D");
}

/// The grid aims at this many simplices per bin (a uniform 3D simplex then
/// meets about three or four bins, so a query tests a few dozen at most), and
/// the index at most `max_entries_per_simplex` entries per simplex: long thin
/// simplices (points on a circle or sphere) would otherwise meet whole rows
/// of bins, and the grid is made coarser until they do not.
constexpr double simplices_per_bin = 8;
constexpr std::uint64_t max_entries_per_simplex = 16;

}  // namespace

std::size_t SimplexLocator::bin_index(std::int64_t x, std::int64_t y, std::int64_t z) const {
  return static_cast<std::size_t>((z * bins_[1] + y) * bins_[0] + x);
}

std::int64_t SimplexLocator::bin_of(int d, double x) const {
  const double t = (x - lo_[d]) * scale_[d];
  if (!(t > 0)) return 0;
  const double top = static_cast<double>(bins_[d]);
  return t < top ? static_cast<std::int64_t>(t) : bins_[d] - 1;
}

SimplexLocator::SimplexLocator(const Delaunay& dt, std::span<const double> points, int threads, LocateMethod method,
                               Adjacency neighbors)
    : dim_(dt.dim), n_simplices_(dt.n_simplices()), n_points_(dt.n_points), neighbors_(std::move(neighbors)) {
  front::refuse_periodic(dt, "locate");
  check_points(dt, points, "locate");
  if (method == LocateMethod::walk && !dt.hull_completed)
    throw InputError("locate: a walk needs a triangulation of the whole convex hull (no labels, hull completion on)");
  method_ = method == LocateMethod::grid || !dt.hull_completed ? LocateMethod::grid : LocateMethod::walk;
  if (method_ == LocateMethod::grid) neighbors_.reset();
  if (neighbors_) {
    // Trusted to be simplex_neighbors(dt) once it could not send the walk
    // out of bounds: the right size, every entry a simplex or -1.
    const std::size_t w = static_cast<std::size_t>(dt.dim + 1);
    const std::int64_t m = static_cast<std::int64_t>(n_simplices_);
    if (neighbors_->size() != n_simplices_ * w)
      throw InputError("locate: the simplex adjacency has " + std::to_string(neighbors_->size()) + " entries for " +
                       std::to_string(n_simplices_) + " simplices of " + std::to_string(w) + " facets");
    if (!std::all_of(neighbors_->begin(), neighbors_->end(), [m](std::int32_t t) { return t >= -1 && t < m; }))
      throw InputError("locate: the simplex adjacency names a simplex that does not exist");
  }
  const int D = dim_;
  offsets_.assign(2, 0);
  if (n_simplices_ == 0) return;

  // The box of every simplex vertex: both methods bin it.
  engine::ThreadArena arena(resolve_threads(threads));
  struct Box {
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  };
  const Box box = arena.execute([&] {
    return tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, dt.simplices.size(), 16384), Box{},
        [&](const tbb::blocked_range<std::size_t>& r, Box b) {
          for (std::size_t e = r.begin(); e != r.end(); ++e) {
            const double* x = points.data() + static_cast<std::size_t>(dt.simplices[e]) * static_cast<std::size_t>(D);
            for (int d = 0; d < D; ++d) {
              b.lo[d] = std::min(b.lo[d], x[d]);
              b.hi[d] = std::max(b.hi[d], x[d]);
            }
          }
          return b;
        },
        [&](Box a, const Box& b) {
          for (int d = 0; d < D; ++d) {
            a.lo[d] = std::min(a.lo[d], b.lo[d]);
            a.hi[d] = std::max(a.hi[d], b.hi[d]);
          }
          return a;
        });
  });
  for (int d = 0; d < D; ++d) {
    lo_[d] = box.lo[d];
    hi_[d] = box.hi[d];
  }
  if (method_ == LocateMethod::walk) build_walk(dt, points, threads);
  else build_grid(dt, points, threads);
}

void SimplexLocator::size_bins(double items_per_bin, double items) {
  const int D = dim_;
  double volume = 1;
  for (int d = 0; d < D; ++d) volume *= hi_[d] - lo_[d];  // > 0: the simplices are not flat
  const double target = std::max(1.0, items / items_per_bin);
  const double side = std::pow(volume / target, 1.0 / D);
  for (int d = 0; d < D; ++d) {
    const double g = std::ceil((hi_[d] - lo_[d]) / side);
    bins_[d] = g >= 1 ? static_cast<std::int64_t>(std::min(g, 1048576.0)) : 1;  // also NaN, infinite
  }
  // A slab (one thin axis) would get very many bins across the wide ones.
  while (static_cast<double>(bins_[0] * bins_[1] * bins_[2]) > 4 * target + 64) {
    std::int64_t* widest = std::max_element(bins_, bins_ + D);
    *widest = (*widest + 1) / 2;
  }
  for (int d = 0; d < D; ++d) scale_[d] = static_cast<double>(bins_[d]) / (hi_[d] - lo_[d]);
}

void SimplexLocator::build_grid(const Delaunay& dt, std::span<const double> points, int threads) {
  const int D = dim_;
  const std::size_t w = static_cast<std::size_t>(D + 1);
  const std::size_t m = n_simplices_;
  engine::ThreadArena arena(resolve_threads(threads));
  // Bins near cubes of the volume that holds simplices_per_bin simplices each.
  size_bins(simplices_per_bin, static_cast<double>(m));
  auto total_bins = [&] { return bins_[0] * bins_[1] * bins_[2]; };
  auto bin_range = [&](std::size_t s, std::int64_t* b0, std::int64_t* b1) {
    const std::int32_t* row = dt.simplices.data() + s * w;
    for (int d = 0; d < D; ++d) {
      double a = INFINITY, b = -INFINITY;
      for (std::size_t k = 0; k < w; ++k) {
        const double x = points[static_cast<std::size_t>(row[k]) * static_cast<std::size_t>(D) + static_cast<std::size_t>(d)];
        a = std::min(a, x);
        b = std::max(b, x);
      }
      b0[d] = bin_of(d, a);
      b1[d] = bin_of(d, b);
    }
    for (int d = D; d < 3; ++d) b0[d] = b1[d] = 0;
  };
  auto for_each_entry = [&](auto&& body) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, m, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
      std::int64_t b0[3], b1[3];
      for (std::size_t s = r.begin(); s != r.end(); ++s) {
        bin_range(s, b0, b1);
        for (std::int64_t z = b0[2]; z <= b1[2]; ++z)
          for (std::int64_t y = b0[1]; y <= b1[1]; ++y)
            for (std::int64_t x = b0[0]; x <= b1[0]; ++x) body(bin_index(x, y, z), s);
      }
    });
  };
  arena.execute([&] {
    // Coarsen until the index fits its budget (see max_entries_per_simplex),
    // counting its entries from each simplex's bin ranges (a product, not a
    // walk over the bins: over budget, that walk could be quadratic).
    for (;;) {
      for (int d = 0; d < D; ++d) scale_[d] = static_cast<double>(bins_[d]) / (hi_[d] - lo_[d]);
      const std::uint64_t entries = tbb::parallel_reduce(
          tbb::blocked_range<std::size_t>(0, m, 4096), std::uint64_t{0},
          [&](const tbb::blocked_range<std::size_t>& r, std::uint64_t sum) {
            std::int64_t b0[3], b1[3];
            for (std::size_t s = r.begin(); s != r.end(); ++s) {
              bin_range(s, b0, b1);
              sum += static_cast<std::uint64_t>((b1[0] - b0[0] + 1) * (b1[1] - b0[1] + 1) * (b1[2] - b0[2] + 1));
            }
            return sum;
          },
          std::plus<>());
      if (entries <= max_entries_per_simplex * m + 4096 || total_bins() == 1) break;
      for (int d = 0; d < D; ++d) bins_[d] = (bins_[d] + 1) / 2;
    }
    // Counts per bin, then the slots; then each bin's list sorted, so the
    // index does not depend on the order the threads filled it in.
    offsets_.assign(static_cast<std::size_t>(total_bins()) + 1, 0);
    for_each_entry([&](std::size_t b, std::size_t) {
      std::atomic_ref<std::uint64_t>(offsets_[b + 1]).fetch_add(1, std::memory_order_relaxed);
    });
    std::partial_sum(offsets_.begin(), offsets_.end(), offsets_.begin());
    ids_.resize(offsets_.back());
    std::vector<std::uint64_t> cursor(offsets_.begin(), offsets_.end() - 1);
    for_each_entry([&](std::size_t b, std::size_t s) {
      const std::uint64_t at = std::atomic_ref<std::uint64_t>(cursor[b]).fetch_add(1, std::memory_order_relaxed);
      ids_[at] = static_cast<std::int32_t>(s);
    });
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, offsets_.size() - 1, 1024), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t b = r.begin(); b != r.end(); ++b)
        std::sort(ids_.begin() + static_cast<std::ptrdiff_t>(offsets_[b]), ids_.begin() + static_cast<std::ptrdiff_t>(offsets_[b + 1]));
    });
  });
}

void SimplexLocator::build_walk(const Delaunay& dt, std::span<const double> points, int threads) {
  const int D = dim_;
  // The vertices in use (those of some simplex) size the bins.
  std::vector<std::uint8_t> in_use(n_points_, 0);
  for (const std::int32_t v : dt.simplices) in_use[static_cast<std::size_t>(v)] = 1;
  const auto used = static_cast<std::size_t>(std::count(in_use.begin(), in_use.end(), std::uint8_t{1}));
  // Seeds: bins of about two vertices, each holding the lowest simplex
  // whose centroid lies in it; empty bins take the seed of a nearest filled
  // bin (breadth-first over the grid), so a walk starts a few simplices
  // away. (A simplex of the bin's lowest vertex, the seed until stop 84, may
  // lie across that vertex's star: a fan's centre has all N triangles, and
  // each query near it walked O(N) of them, quadratic over N queries.)
  size_bins(2, static_cast<double>(used));
  seed_.assign(static_cast<std::size_t>(bins_[0] * bins_[1] * bins_[2]), -1);
  const std::size_t w = static_cast<std::size_t>(D + 1);
  for (std::size_t s = n_simplices_; s-- > 0;) {
    const std::int32_t* row = dt.simplices.data() + s * w;
    std::int64_t b[3] = {0, 0, 0};
    for (int d = 0; d < D; ++d) {
      double c = 0;
      for (std::size_t k = 0; k < w; ++k) c += points[static_cast<std::size_t>(row[k]) * static_cast<std::size_t>(D) + static_cast<std::size_t>(d)];
      b[d] = bin_of(d, c / static_cast<double>(w));
    }
    seed_[bin_index(b[0], b[1], b[2])] = static_cast<std::int32_t>(s);
  }
  std::vector<std::size_t> queue;
  for (std::size_t b = 0; b < seed_.size(); ++b)
    if (seed_[b] >= 0) queue.push_back(b);
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const std::size_t b = queue[head];
    std::int64_t c[3] = {static_cast<std::int64_t>(b) % bins_[0], static_cast<std::int64_t>(b) / bins_[0] % bins_[1],
                         static_cast<std::int64_t>(b) / (bins_[0] * bins_[1])};
    for (int d = 0; d < D; ++d)
      for (std::int64_t step : {-1, 1}) {
        c[d] += step;
        if (c[d] >= 0 && c[d] < bins_[d]) {
          const std::size_t nb = bin_index(c[0], c[1], c[2]);
          if (seed_[nb] < 0) {
            seed_[nb] = seed_[b];
            queue.push_back(nb);
          }
        }
        c[d] -= step;
      }
  }
  (void)threads;  // the seeds are a sequential pass; the neighbours run on dt.threads_used
  if (!neighbors_) neighbors_ = std::make_shared<const std::vector<std::int32_t>>(simplex_neighbors(dt));
}

namespace {

// Orientation of simplex row with vertex k replaced by x: its sign says on
// which side of the facet opposite k the query lies (> 0: the simplex's).
int side(const Delaunay& dt, std::span<const double> points, std::size_t s, std::size_t k, const double* x) {
  const std::size_t du = static_cast<std::size_t>(dt.dim);
  const std::int32_t* row = dt.simplices.data() + s * (du + 1);
  const double* v[4];
  for (std::size_t j = 0; j <= du; ++j) v[j] = points.data() + static_cast<std::size_t>(row[j]) * du;
  v[k] = x;
  return kernels::orientation(dt.dim, v);
}

// A closed, positively oriented simplex holds x iff putting x in place of
// each vertex in turn never makes it negative (its barycentric signs).
bool holds(const Delaunay& dt, std::span<const double> points, std::size_t s, const double* x) {
  for (std::size_t k = 0; k <= static_cast<std::size_t>(dt.dim); ++k)
    if (side(dt, points, s, k, x) < 0) return false;
  return true;
}

}  // namespace

std::int32_t SimplexLocator::scan_bin(const Delaunay& dt, std::span<const double> points, const double* x) const {
  std::int64_t b[3] = {0, 0, 0};
  for (int d = 0; d < dim_; ++d) b[d] = bin_of(d, x[d]);
  const std::size_t bin = bin_index(b[0], b[1], b[2]);
  for (std::uint64_t e = offsets_[bin]; e != offsets_[bin + 1]; ++e)
    if (holds(dt, points, static_cast<std::size_t>(ids_[e]), x)) return ids_[e];
  return -1;
}

// The remembering stochastic walk (Devillers, Pion and Teillaud, "Walking in
// a triangulation", 2002): from the seed, leave by a facet the query lies
// strictly beyond, testing the facets in an order that varies by step and
// never the one just entered by, until a simplex holds the query or a step
// leaves the hull (the triangulation being convex, the query then lies
// outside). On a Delaunay triangulation (ours are, under the symbolic
// perturbation: regular triangulations) every such walk ends, as the
// "in front of" relation between its simplices is acyclic (Edelsbrunner
// 1990); the varying order keeps walks short on degenerate ones. The order
// comes from a hash of the query and the step, so runs repeat. A walk past
// its step budget (a guard no test reaches) falls back to a scan.
std::int32_t SimplexLocator::walk(const Delaunay& dt, std::span<const double> points, const double* x,
                                  std::uint64_t salt) const {
  const int D = dim_;
  const std::size_t w = static_cast<std::size_t>(D + 1);
  std::int64_t b[3] = {0, 0, 0};
  for (int d = 0; d < D; ++d) b[d] = bin_of(d, x[d]);
  std::size_t s = static_cast<std::size_t>(seed_[bin_index(b[0], b[1], b[2])]);
  std::int32_t came_from = -1;
  const std::uint64_t budget = 4 * static_cast<std::uint64_t>(n_simplices_) + 1024;
  for (std::uint64_t step = 0;; ++step) {
    if (step == budget) {
      for (std::size_t t = 0; t < n_simplices_; ++t)
        if (holds(dt, points, t, x)) return static_cast<std::int32_t>(t);
      return -1;
    }
    std::uint64_t h = (salt + step) * 0x9E3779B97F4A7C15ull;
    h ^= h >> 29;
    const std::size_t first = static_cast<std::size_t>(h % w);
    std::int32_t next = -2;  // -2: none found; -1: beyond the hull
    bool on_facet = false;   // x lies on a facet of s (sign 0)
    for (std::size_t i = 0; i < w && next == -2; ++i) {
      const std::size_t k = (first + i) % w;
      const std::int32_t t = (*neighbors_)[s * w + k];
      if (t >= 0 && t == came_from) continue;  // the query lies strictly on this side of it
      const int o = side(dt, points, s, k, x);
      if (o < 0) next = t;
      on_facet |= o == 0;
    }
    if (next == -1) return -1;
    if (next == -2) {
      if (!on_facet) return static_cast<std::int32_t>(s);  // strictly inside: the only simplex holding x
      break;
    }
    came_from = static_cast<std::int32_t>(s);
    s = static_cast<std::size_t>(next);
  }
  // s holds x, on one of its facets (rare, so the allocations below stay off
  // the common path). Every simplex holding x holds the face of s that x lies
  // inside (x's face: its vertices are those whose facet-opposite sign is
  // not 0), and those simplices are joined across facets through that face,
  // on each of which x lies (sign 0): gather them and answer the lowest.
  std::int32_t best = static_cast<std::int32_t>(s);
  std::vector<std::int32_t> seen{best}, stack{best};
  while (!stack.empty()) {
    const std::size_t t = static_cast<std::size_t>(stack.back());
    stack.pop_back();
    for (std::size_t k = 0; k < w; ++k) {
      if (side(dt, points, t, k, x) != 0) continue;
      const std::int32_t u = (*neighbors_)[t * w + k];
      if (u < 0 || std::find(seen.begin(), seen.end(), u) != seen.end()) continue;
      seen.push_back(u);
      stack.push_back(u);
      best = std::min(best, u);
    }
  }
  return best;
}

std::vector<std::int32_t> SimplexLocator::locate(const Delaunay& dt, std::span<const double> points,
                                                 std::span<const double> queries, int threads,
                                                 const std::function<void(double)>& progress) const {
  check_points(dt, points, "locate");
  if (dt.dim != dim_ || dt.n_simplices() != n_simplices_ || dt.n_points != n_points_)
    throw InputError("locate: the triangulation is not the one this locator was built for");
  const int D = dim_;
  const auto du = static_cast<std::size_t>(D);
  if (queries.size() % du != 0)
    throw InputError("locate: query array length " + std::to_string(queries.size()) + " is not a multiple of dimension " +
                     std::to_string(D));
  const std::size_t nq = queries.size() / du;
  std::vector<std::int32_t> found(nq, -1);
  if (n_simplices_ == 0) return found;
  detail::parallel_in_progress_chunks(resolve_threads(threads), nq, 1024, progress,
                                      [&](const tbb::blocked_range<std::size_t>& r) {
                                        for (std::size_t q = r.begin(); q != r.end(); ++q) {
                                          const double* x = queries.data() + q * du;
                                          // in the vertices' box (false on NaN): else outside every simplex
                                          bool inside = true;
                                          for (int d = 0; d < D; ++d) inside &= x[d] >= lo_[d] && x[d] <= hi_[d];
                                          if (!inside) continue;
                                          found[q] = method_ == LocateMethod::walk ? walk(dt, points, x, q)
                                                                                   : scan_bin(dt, points, x);
                                        }
                                      });
  return found;
}

}  // namespace tessera
