// Periodic boxes: the input's wrapping and rounding, the images, and the
// cells mapped back (see periodic.hpp).
#include "periodic.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "tessera/engine/classifier.hpp"
#include "tessera/engine/thread_arena.hpp"
#include "tessera/finite_points.hpp"

namespace tessera::front {
namespace {

const char* axis_name(int a) { return a == 0 ? "x" : (a == 1 ? "y" : "z"); }

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

/// x rounded to the nearest multiple of g (a power of two), ties to even.
double snap(double x, double g) { return std::nearbyint(x / g) * g; }

}  // namespace

PeriodicInput periodic_input(std::span<const double> points, int dim, std::span<const std::int32_t> labels,
                             const VoronoiOptions& options) {
  if (dim != 2 && dim != 3) throw InputError("dimension must be 2 or 3, got " + std::to_string(dim));
  const auto du = static_cast<std::size_t>(dim);
  if (points.empty()) throw InputError("no input points");
  if (points.size() % du != 0)
    throw InputError("point array length " + std::to_string(points.size()) + " is not a multiple of dimension " +
                     std::to_string(dim));
  PeriodicInput in;
  in.dim = dim;
  in.n = points.size() / du;
  if (in.n > static_cast<std::size_t>(INT32_MAX - 1)) throw InputError("too many points (ids are 32-bit)");
  if (!labels.empty() && labels.size() != in.n)
    throw InputError("labels: " + std::to_string(labels.size()) + " values for " + std::to_string(in.n) + " points");
  for (int a = dim; a < 3; ++a)
    if (options.periodic[static_cast<std::size_t>(a)])
      throw InputError(std::string("periodic axis ") + axis_name(a) + " of " + std::to_string(dim) + "D points");
  if (!options.bounds) throw InputError("a periodic box needs its bounds (the box that repeats)");
  in.periodic = options.periodic;
  in.box = *options.bounds;
  for (int a = 0; a < dim; ++a) {
    const auto au = static_cast<std::size_t>(a);
    if (!std::isfinite(in.box.lo[au]) || !std::isfinite(in.box.hi[au]) || !(in.box.lo[au] < in.box.hi[au]))
      throw InputError(std::string("bounds along ") + axis_name(a) + " must be finite with lo < hi, not [" +
                       num(in.box.lo[au]) + ", " + num(in.box.hi[au]) + "]");
    in.length[au] = in.box.hi[au] - in.box.lo[au];
    if (!std::isfinite(in.length[au])) throw InputError("the periodic box's extent overflows double");
  }
  // A cell lies within its point's images one box length away along each
  // periodic axis (the box about the point) and within the walls along the
  // others: its security sphere (twice its farthest vertex) reaches at most
  // `cap` from the point.
  double r2 = 0;
  for (int a = 0; a < dim; ++a) {
    const auto au = static_cast<std::size_t>(a);
    const double half = in.periodic[au] ? 0.5 * in.length[au] : in.length[au];
    r2 += half * half;
  }
  const double cap = 2 * std::sqrt(r2) * (1 + 0x1p-20);
  for (int a = 0; a < dim; ++a) {
    const auto au = static_cast<std::size_t>(a);
    if (!in.periodic[au]) continue;
    // Shifts are int8 (Cells::neighbor_shifts). A box whose walls are more
    // than ~60 periods long may ask for more than 127 only where its cells
    // are that long (a few points): the driver then reports it.
    const double k = std::min(std::ceil(cap / in.length[au]), double{max_periodic_shift});
    in.max_shift[au] = static_cast<int>(k);
    in.reach_cap[au] = std::min(cap, k * in.length[au]);
    in.reach_clamped[au] = in.reach_cap[au] < cap;
    // The grid: multiples of g below 2^(e+1) are doubles, and every image
    // x + k L (|k| <= max_shift, x in the box) stays below that; the margin
    // covers the box's own rounding to the grid (g / 2 of m's 2^-52). Also
    // the wrap's steps by a period (x within a period of the box).
    const double lo = in.box.lo[au], hi = in.box.hi[au];
    const double m = (std::max(std::fabs(lo), std::fabs(hi)) + k * in.length[au]) * (1 + 0x1p-40);
    if (!std::isfinite(m)) throw InputError("the periodic box's images overflow double; scale the input down");
    const double g = std::ldexp(1.0, std::max(std::ilogb(m) - 52, -1074));
    in.box.lo[au] = snap(lo, g);
    in.box.hi[au] = snap(hi, g);
    if (!(in.box.lo[au] < in.box.hi[au])) throw InputError("the periodic box is too thin for its coordinates");
    in.length[au] = in.box.hi[au] - in.box.lo[au];  // exact: both on the grid
    in.grid[au] = g;
  }

  in.points.assign(points.begin(), points.end());
  in.takes_part.assign(in.n, 1);
  for (std::size_t i = 0; i < in.n; ++i) {
    double* p = in.points.data() + i * du;
    if (!finite_point(in.points, i, dim)) {
      if (!options.ignore_outside_points)
        throw InputError("point " + std::to_string(i) +
                         " has a NaN or infinite coordinate (ignore_outside sets such points aside)");
      in.takes_part[i] = 0;
      in.ignored.push_back(static_cast<std::int32_t>(i));
      continue;
    }
    for (std::size_t a = 0; a < du && in.takes_part[i]; ++a) {
      const double lo = in.box.lo[a], hi = in.box.hi[a], len = in.length[a];
      if (!in.periodic[a]) {
        if (p[a] < lo || p[a] > hi) {
          if (!options.ignore_outside_points)
            throw InputError("point " + std::to_string(i) + " lies outside the bounds along " +
                             axis_name(static_cast<int>(a)) +
                             ", which is not periodic (use --ignore-outside to drop such points)");
          in.takes_part[i] = 0;
          in.ignored.push_back(static_cast<std::int32_t>(i));
        }
        continue;
      }
      // Wrapped into [lo, hi): nearly, in floating point, where it lies a
      // period or more out; then rounded to the grid, where the last steps
      // of a box length are exact.
      double x = p[a];
      if (x < lo - len || x >= hi + len) {
        // fmod is exact: the error is only that of x - lo, the point's own
        // imprecision at that distance.
        const double off = x - lo;
        if (!std::isfinite(off))
          throw InputError("point " + std::to_string(i) + " lies too far from the periodic box to be wrapped into it");
        double r = std::fmod(off, len);
        if (r < 0) r += len;
        x = lo + r;
      }
      x = snap(x, in.grid[a]);
      while (x >= hi) x -= len;
      while (x < lo) x += len;
      p[a] = x;
    }
  }
  if (in.ignored.size() == in.n) throw InputError("all points lie outside the bounds");
  std::sort(in.ignored.begin(), in.ignored.end());
  in.ignored.erase(std::unique(in.ignored.begin(), in.ignored.end()), in.ignored.end());
  return in;
}

PeriodicImages periodic_images(const PeriodicInput& in, std::span<const std::int32_t> labels,
                               const std::array<double, 3>& width, int threads) {
  const int dim = in.dim;
  const auto du = static_cast<std::size_t>(dim);
  PeriodicImages im;
  im.domain = in.box;
  std::array<int, 3> k{0, 0, 0};  // the largest shift per axis
  for (std::size_t a = 0; a < du; ++a) {
    if (!in.periodic[a]) continue;
    const double w = std::min(width[a], in.reach_cap[a]);
    im.domain.lo[a] = in.box.lo[a] - w;
    im.domain.hi[a] = in.box.hi[a] + w;
    k[a] = std::min(in.max_shift[a], static_cast<int>(std::ceil(w / in.length[a])));
  }
  // Shifts in lexicographic order (x, then y, then z), shift 0 among them
  // (periodic.hpp: the perturbation's order).
  std::vector<std::array<int, 3>> shifts;
  for (int s0 = -k[0]; s0 <= k[0]; ++s0)
    for (int s1 = -k[1]; s1 <= k[1]; ++s1)
      for (int s2 = -k[2]; s2 <= k[2]; ++s2) shifts.push_back({s0, s1, s2});
  // Point i's images in the layer, in shift order: f(shift, image).
  auto for_each_image = [&](std::size_t i, auto&& f) {
    if (!in.takes_part[i]) return;
    const double* p = in.points.data() + i * du;
    for (const auto& s : shifts) {
      double y[3] = {0, 0, 0};
      bool inside = true;
      for (std::size_t a = 0; a < du && inside; ++a) {
        y[a] = p[a] + s[a] * in.length[a];  // exact (PeriodicInput's grid)
        inside = y[a] >= im.domain.lo[a] && y[a] <= im.domain.hi[a];
      }
      if (inside) f(s, y);
    }
  };
  // Counted, then written at their offsets, one block of points per task:
  // the same array for any thread count.
  std::vector<std::size_t> first(in.n + 1, 0);
  engine::ThreadArena arena(threads);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, in.n, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i)
        for_each_image(i, [&](const std::array<int, 3>&, const double*) { ++first[i + 1]; });
    });
  });
  std::partial_sum(first.begin(), first.end(), first.begin());
  const std::size_t m = first.back();
  if (m > static_cast<std::size_t>(INT32_MAX - 1))
    throw InputError("too many points with their periodic images (ids are 32-bit)");
  im.original.assign(in.n, -1);
  im.base.resize(m);
  im.points.resize(m * du);
  im.shift.resize(m * du);
  im.labels.resize(m);
  im.images = m - (in.n - in.ignored.size());
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, in.n, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i) {
        std::size_t at = first[i];
        for_each_image(i, [&](const std::array<int, 3>& s, const double* y) {
          const bool zero = s[0] == 0 && s[1] == 0 && s[2] == 0;
          if (zero) im.original[i] = static_cast<std::int32_t>(at);
          im.base[at] = static_cast<std::int32_t>(i);
          for (std::size_t a = 0; a < du; ++a) {
            im.points[at * du + a] = y[a];
            im.shift[at * du + a] = static_cast<std::int8_t>(s[a]);
          }
          im.labels[at] = zero ? (labels.empty() ? 0 : labels[i]) : -1;
          ++at;
        });
      }
    });
  });
  return im;
}

std::array<double, 3> initial_image_reach(const PeriodicInput& in) {
  double volume = 1;
  for (int a = 0; a < in.dim; ++a) volume *= in.length[static_cast<std::size_t>(a)];
  const double taking = static_cast<double>(in.n - in.ignored.size());
  const double spacing = std::pow(volume / taking, 1.0 / in.dim);
  // Four spacings: uniform points (20k, 200k and 1M, 2D and 3D) needed no
  // wider layer; at 3.5 one 2D cell of 20k asked for 4.0.
  const double w = 4.0 * spacing;
  std::array<double, 3> width{0, 0, 0};
  for (std::size_t a = 0; a < 3; ++a)
    if (in.periodic[a]) width[a] = std::isfinite(w) ? std::min(w, in.reach_cap[a]) : in.reach_cap[a];
  return width;
}

std::array<double, 3> needed_image_reach(const PeriodicInput& in, const PeriodicImages& im, const Cells& cells,
                                         std::span<const double> reach) {
  const auto du = static_cast<std::size_t>(in.dim);
  std::array<double, 3> need{0, 0, 0};
  for (std::size_t c = 0; c < cells.n_cells(); ++c) {
    const auto g = static_cast<std::size_t>(cells.generator[c]);
    const double r = reach[g];
    const double* p = im.points.data() + g * du;
    for (std::size_t a = 0; a < du; ++a) {
      if (!in.periodic[a]) continue;
      const double beyond = std::max(in.box.lo[a] - (p[a] - r), (p[a] + r) - in.box.hi[a]);
      need[a] = beyond <= need[a] ? need[a] : beyond;  // NaN too: unbounded, below
    }
  }
  for (double& n : need) n = n >= 0 ? n : std::numeric_limits<double>::infinity();  // NaN: unbounded
  return need;
}

Cells periodic_cells(Cells&& aug, const PeriodicInput& in, const PeriodicImages& im,
                     std::span<const std::int32_t> labels, int threads) {
  const int dim = in.dim;
  const auto du = static_cast<std::size_t>(dim);
  Cells out;
  out.dim = dim;
  out.n_points = in.n;
  out.bounds = in.box;
  out.periodic = in.periodic;
  out.periodic_images = im.images;
  for (std::size_t a = 0; a < du; ++a)
    if (in.periodic[a]) out.image_reach[a] = std::min(in.box.lo[a] - im.domain.lo[a], im.domain.hi[a] - in.box.hi[a]);
  auto base = [&](std::int32_t id) { return id < 0 ? id : im.base[static_cast<std::size_t>(id)]; };
  const std::size_t nc = aug.n_cells();
  // Element-wise maps over the outputs, in blocks on the caller's threads.
  engine::ThreadArena arena(threads);
  auto each = [&](std::size_t n, auto&& f) {
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 16384), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t k = r.begin(); k != r.end(); ++k) f(k);
      });
    });
  };

  // Per cell: every cell is a point's own (images own none), in the order
  // of the points, as the augmented ids keep it.
  out.generator = std::move(aug.generator);
  each(nc, [&](std::size_t c) { out.generator[c] = base(out.generator[c]); });
  out.region = std::move(aug.region);
  out.volume = std::move(aug.volume);
  out.centroid = std::move(aug.centroid);
  out.num_faces = std::move(aug.num_faces);
  out.cell_of.assign(in.n, -1);
  for (std::size_t c = 0; c < nc; ++c) out.cell_of[static_cast<std::size_t>(out.generator[c])] = static_cast<std::int32_t>(c);

  // Neighbours: (point, shift), ascending.
  out.neighbor_offsets = std::move(aug.neighbor_offsets);
  out.neighbors = std::move(aug.neighbors);
  out.neighbor_shifts.resize(out.neighbors.size() * du);
  // Augmented ids list each point's images together, by shift, so their
  // ascending order is (point, shift): the order the entries keep.
  each(out.neighbors.size(), [&](std::size_t e) {
    const auto j = static_cast<std::size_t>(out.neighbors[e]);
    out.neighbors[e] = im.base[j];
    for (std::size_t a = 0; a < du; ++a) out.neighbor_shifts[e * du + a] = im.shift[j * du + a];
  });

  // The mesh: keys and faces by the points' ids; classes by their labels.
  if (!aug.vertex_keys.empty() || !aug.cell_face_offsets.empty()) {
    out.vertices = std::move(aug.vertices);
    out.vertex_keys = std::move(aug.vertex_keys);
    each(out.vertex_keys.size() / (du + 1), [&](std::size_t v) {
      std::int32_t* key = out.vertex_keys.data() + v * (du + 1);
      for (std::size_t d = 0; d <= du; ++d) key[d] = base(key[d]);
      std::sort(key, key + du + 1);
    });
    out.cell_face_offsets = std::move(aug.cell_face_offsets);
    out.face_vertex_offsets = std::move(aug.face_vertex_offsets);
    out.face_vertices = std::move(aug.face_vertices);
    out.face_neighbor = std::move(aug.face_neighbor);
    out.face_class = std::move(aug.face_class);
    const engine::RegionClassifier classify(labels);
    each(nc, [&](std::size_t c) {
      for (auto f = out.cell_face_offsets[c]; f < out.cell_face_offsets[c + 1]; ++f) {
        const auto fu = static_cast<std::size_t>(f);
        out.face_neighbor[fu] = base(out.face_neighbor[fu]);
        out.face_class[fu] = classify(out.generator[c], out.face_neighbor[fu]);
      }
    });
  }

  // Duplicates among the points (the pass reports generators only, so not
  // their images' copies; an owner is the lowest id of its group, at shift 0).
  for (const auto& [d, o] : aug.duplicates) out.duplicates.emplace_back(base(d), base(o));
  std::sort(out.duplicates.begin(), out.duplicates.end());
  out.ignored_outside_bounds = in.ignored;
  out.exact_predicate_calls = aug.exact_predicate_calls;
  out.far_points = aug.far_points;
  out.threads_used = aug.threads_used;
  out.from_insertion = aug.from_insertion;
  out.assembled_from_stars = aug.assembled_from_stars;
  out.cells_from_pilot = aug.cells_from_pilot;
  return out;
}

}  // namespace tessera::front
