// The shared set-up of a cells pass; see pass.hpp.
#include "pass.hpp"
#include "walls.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "tessera/engine/thread_arena.hpp"
#include "tessera/finite_points.hpp"
#include "../message_text.hpp"

namespace tessera::front {
namespace {
}  // namespace

void check_shape(std::span<const double> points, int dim, std::span<const std::int32_t> labels) {
  if (dim != 2 && dim != 3) throw InputError("dimension must be 2 or 3, got " + std::to_string(dim));
  if (points.empty()) throw InputError("no input points");
  if (points.size() % static_cast<std::size_t>(dim) != 0)
    throw InputError("point array length " + std::to_string(points.size()) + " is not a multiple of dimension " +
                     std::to_string(dim));
  const std::size_t n = points.size() / static_cast<std::size_t>(dim);
  if (n > static_cast<std::size_t>(INT32_MAX - 1)) throw InputError("too many points (ids are 32-bit)");
  if (!labels.empty() && labels.size() != n)
    throw InputError("labels: " + std::to_string(labels.size()) + " values for " + std::to_string(n) + " points");
}

void check_input(std::span<const double> points, int dim, std::span<const std::int32_t> labels) {
  check_shape(points, dim, labels);
  for (std::size_t k = 0; k < points.size(); ++k)
    if (!std::isfinite(points[k]))
      throw InputError("point " + std::to_string(k / static_cast<std::size_t>(dim)) +
                       " has a NaN or infinite coordinate (ignore_outside sets such points aside)");
  if (!labels.empty() && std::none_of(labels.begin(), labels.end(), [](std::int32_t l) { return l >= 0; }))
    throw InputError("labels: every point is outside (label < 0); nothing to tessellate");
}

void set_aside_non_finite(std::span<const double>& points, int dim, VoronoiOptions& options,
                          std::vector<double>& cleaned) {
  if (!options.ignore_outside_points || (dim != 2 && dim != 3) || points.size() % static_cast<std::size_t>(dim) != 0)
    return;  // (check_input names what is wrong)
  const auto d = static_cast<std::size_t>(dim);
  const std::size_t n = points.size() / d;
  auto finite = [&](std::size_t i) { return finite_point(points, i, dim); };
  std::size_t kept = 0;
  for (std::size_t i = 0; i < n; ++i) kept += finite(i);
  if (kept == n) return;
  if (kept == 0) throw InputError("every point has a NaN or infinite coordinate");
  if (!options.bounds) {
    std::vector<double> good;
    good.reserve(kept * d);
    for (std::size_t i = 0; i < n; ++i)
      if (finite(i)) good.insert(good.end(), points.begin() + static_cast<std::ptrdiff_t>(i * d),
                                 points.begin() + static_cast<std::ptrdiff_t>((i + 1) * d));
    options.bounds = make_domain(good, dim, options);
  }
  const Bounds& b = *options.bounds;
  // One ulp beyond a face of the box (the first whose neighbour is finite):
  // as far outside as anything can be while keeping the magnitudes, and so
  // the frame, of the box.
  std::array<double, 3> away{};
  bool placed = false;
  for (std::size_t a = 0; a < d && !placed; ++a) {
    for (std::size_t c = 0; c < d; ++c) away[c] = b.lo[c];
    for (const double x : {std::nextafter(b.lo[a], -INFINITY), std::nextafter(b.hi[a], INFINITY)})
      if (std::isfinite(x)) {
        away[a] = x;
        placed = true;
        break;
      }
  }
  if (!placed) throw InputError("points with a NaN or infinite coordinate: the domain leaves no room outside it");
  cleaned.assign(points.begin(), points.end());
  for (std::size_t i = 0; i < n; ++i)
    if (!finite(i))
      for (std::size_t a = 0; a < d; ++a) cleaned[i * d + a] = away[a];
  points = cleaned;
}

Bounds bounding_box(std::span<const double> points, int dim, std::span<const std::int32_t> labels) {
  const std::size_t d = static_cast<std::size_t>(dim), n = points.size() / d;
  Bounds b;
  for (std::size_t a = 0; a < d; ++a) {
    b.lo[a] = INFINITY;
    b.hi[a] = -INFINITY;
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!labels.empty() && labels[i] < 0) continue;
    for (std::size_t a = 0; a < d; ++a) {
      const double x = points[i * d + a];
      b.lo[a] = std::min(b.lo[a], x);
      b.hi[a] = std::max(b.hi[a], x);
    }
  }
  return b;
}

Bounds make_domain(std::span<const double> pts, int dim, const VoronoiOptions& opt) {
  const std::size_t n = pts.size() / static_cast<std::size_t>(dim);
  if (opt.bounds) {
    Bounds b = *opt.bounds;
    for (int d = 0; d < dim; ++d) {
      auto du = static_cast<std::size_t>(d);
      if (!std::isfinite(b.lo[du]) || !std::isfinite(b.hi[du]) || !(b.lo[du] < b.hi[du])) {
        std::ostringstream m;
        m << "bounds: " << detail::axis_name(d) << " range [" << b.lo[du] << ", " << b.hi[du] << "] is empty or not finite";
        throw InputError(m.str());
      }
    }
    return b;
  }
  if (!(opt.padding >= 0) || !std::isfinite(opt.padding))
    throw InputError("padding must be a finite number >= 0");
  Bounds b = bounding_box(pts, dim);
  if (n == 1)
    throw InputError("a single point has no extent to make a domain from; give the domain with --bounds");
  // Half the largest extent: points spanning most of double's range have an
  // extent that overflows, and their domain is still representable.
  double half = 0;
  for (int d = 0; d < dim; ++d) {
    auto du = static_cast<std::size_t>(d);
    // (Decided on hi > lo: an extent of one subnormal ulp halves to 0.)
    double e = 0.5 * b.hi[du] - 0.5 * b.lo[du];
    if (!(b.hi[du] > b.lo[du])) {
      std::ostringstream m;
      m << "all points have the same " << detail::axis_name(d) << " coordinate (" << b.lo[du]
        << "): the bounding box has zero extent";
      if (dim == 3) m << "; for planar input use --dim 2, or give --bounds";
      else m << "; give --bounds";
      throw InputError(m.str());
    }
    half = std::max({half, e, std::numeric_limits<double>::denorm_min()});
  }
  // Pad, then round outward to a multiple of a power of two near ext/64: the
  // box constants become short binary fractions (integer grids get the
  // half-integer box), so exact predicates on box vertices stay in the fast
  // 128-bit path. The margin is never smaller than asked.
  int e;
  std::frexp(half, &e);
  // ext / 64 < step <= ext / 32 (no smaller than the least subnormal, which divides every double)
  const double step = std::max(std::ldexp(1.0, e - 6), std::numeric_limits<double>::denorm_min());
  const double pad = 2.0 * opt.padding * half;
  for (int d = 0; d < dim; ++d) {
    auto du = static_cast<std::size_t>(d);
    b.lo[du] = std::floor((b.lo[du] - pad) / step) * step;
    b.hi[du] = std::ceil((b.hi[du] + pad) / step) * step;
    if (!std::isfinite(b.lo[du]) || !std::isfinite(b.hi[du])) {
      std::ostringstream m;
      m << "the padded domain's " << detail::axis_name(d) << " range overflows double (padding " << opt.padding
        << " of the points' extent); give a smaller --padding, or --bounds";
      throw InputError(m.str());
    }
  }
  return b;
}

// The float filters bound rounding relative to the magnitudes involved. A
// product that lands below DBL_MIN errs in absolute terms instead (up to
// 2^-1075), which no relative bound covers: a vertex's Cramer numerator whose
// terms all underflow computes as 0 where the true value is 1e-85, and its
// error bound is a thousand times smaller than that (found by fuzzing, with
// coordinates near 1e-65 a few ulps apart). So the computation's frame keeps
// products of coordinate differences normal:
//  * A nonzero difference of two doubles is at least an ulp of the smaller
//    nonzero one in magnitude (or the other one itself when one is zero): at
//    least mu 2^-53, mu the smallest nonzero |coordinate|.
//  * The kernels' float terms are products of at most four such differences
//    (a 3D numerator: half a squared length times a cross product's entry),
//    or a cancelled difference of two products (an ulp of them, 2^-53) times
//    two more. With every difference at least 2^-200, each lies above
//    2^-853: normal, with room to spare. Hence mu >= 2^-147.
//  * At the top, coordinates below 2^200 keep the in-sphere filter's degree-5
//    terms finite.
// Scaling by 2^k is exact, so any k keeping every nonzero coordinate normal
// and finite computes the same cells. Input within both limits is computed as
// given (k = 0); otherwise k is the nearest shift that brings it within them.
// When none does (the nonzero coordinates span more than ~2^347: subnormals
// beside ordinary values, or 1e-160 beside 1e200), the kernels add an
// absolute underflow term to their vertex error bounds
// (ExactContext::may_underflow): still exact, only more often on the exact
// path. The frame then keeps the largest coordinates near 2^200 (the smallest
// as large as the top allows), or, where even that would turn a nonzero
// coordinate subnormal (bits lost), as close to it as normality allows.
constexpr int kSmallestSafeExp = -147, kLargestSafeExp = 200;

Scaling choose_scaling(std::span<const double> points, const Bounds& b, int dim) {
  double m = 0, m_min = INFINITY;
  auto see = [&](double x) {
    x = std::fabs(x);
    m = std::max(m, x);
    if (x != 0) m_min = std::min(m_min, x);
  };
  // The points that take part only: those outside the box (or not finite)
  // are set aside (--ignore-outside) or refused, and one at 1e200 beside
  // the box's points made radii refuse the whole input ("need coordinates
  // within ~1e-150..1e150"; a fuzz of the Python module).
  const auto du = static_cast<std::size_t>(dim);
  for (std::size_t i = 0; i + du <= points.size(); i += du) {
    bool inside = true;
    for (std::size_t a = 0; a < du && inside; ++a)
      inside = points[i + a] >= b.lo[a] && points[i + a] <= b.hi[a];  // false on NaN
    if (inside)
      for (std::size_t a = 0; a < du; ++a) see(points[i + a]);
  }
  for (int d = 0; d < dim; ++d) {
    see(b.lo[static_cast<std::size_t>(d)]);
    see(b.hi[static_cast<std::size_t>(d)]);
  }
  Scaling s;
  if (m == 0) return s;
  int e_max, e_min;  // m in [2^(e_max-1), 2^e_max), m_min in [2^(e_min-1), 2^e_min)
  std::frexp(m, &e_max);
  std::frexp(m_min, &e_min);
  // Safe: m_min 2^k >= 2^-147 and m 2^k < 2^200.
  const int lo = kSmallestSafeExp + 1 - e_min, hi = kLargestSafeExp - e_max;
  if (lo <= hi) {
    s.k = std::clamp(0, lo, hi);
    return s;
  }
  s.may_underflow = true;
  // Normal iff e_min + k >= -1021; finite iff e_max + k <= 1024 (1000: room).
  const int keep_normal = -1021 - e_min, keep_finite = 1000 - e_max;
  s.k = keep_normal <= keep_finite ? std::clamp(hi, keep_normal, keep_finite) : 0;
  return s;
}

template <int D>
Pass<D>::Pass(std::span<const double> input, std::span<const std::int32_t> labels, const VoronoiOptions& opt) {
  const std::size_t n = input.size() / D;
  user_bounds = make_domain(input, D, opt);
  bounds = user_bounds;
  // Extreme magnitudes: compute on an exactly rescaled copy.
  const Scaling scaling = choose_scaling(input, user_bounds, D);
  k = scaling.k;
  points = input;
  if (k != 0) {
    scaled.resize(input.size());
    for (std::size_t i = 0; i < input.size(); ++i) scaled[i] = std::ldexp(input[i], k);
    for (int d = 0; d < D; ++d) {
      bounds.lo[static_cast<std::size_t>(d)] = std::ldexp(bounds.lo[static_cast<std::size_t>(d)], k);
      bounds.hi[static_cast<std::size_t>(d)] = std::ldexp(bounds.hi[static_cast<std::size_t>(d)], k);
    }
    points = scaled;
  }
  set_radii(opt.radii, n, scaling);
  walls = kernel_walls(opt.walls, D, k);

  // Which points take part (inside the box and the walls) and which get
  // cells (also label >= 0). Each point's first wall it lies outside of
  // (-1: none), in parallel: 1M points against 64 walls cost 0.5 s alone.
  std::vector<std::int32_t> outside(walls.empty() ? 0 : n);
  if (!walls.empty()) {
    engine::ThreadArena(resolve_threads(opt.threads)).execute([&] {
      wall_index = make_wall_index(walls, D, bounds);
      const WallTest test(walls, D, largest_magnitude(points), wall_index.get());
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) outside[i] = test.outside(points.data() + i * D);
      });
    });
  }
  in_box.assign(n, 1);
  std::size_t n_in = n;
  for (std::size_t i = 0; i < n; ++i) {
    int out_along = -1;
    for (int d = 0; d < D; ++d) {
      double x = points[i * D + static_cast<std::size_t>(d)];
      if (x < bounds.lo[static_cast<std::size_t>(d)] || x > bounds.hi[static_cast<std::size_t>(d)]) {
        in_box[i] = 0;
        out_along = d;
        break;
      }
    }
    if (!in_box[i]) {
      if (!opt.ignore_outside_points) {
        // The user's numbers (not the rescaled copy's), each in its shortest
        // exact text: a point an ulp outside a box read from a file shows it.
        const auto du = static_cast<std::size_t>(out_along);
        throw InputError("point " + std::to_string(i) + " lies outside the bounds: " + detail::axis_name(out_along) +
                         " = " + detail::number_text(input[i * D + du]) + " is not in [" +
                         detail::number_text(user_bounds.lo[du]) + ", " + detail::number_text(user_bounds.hi[du]) +
                         "] (use --ignore-outside to drop such points)");
      }
      ignored_outside.push_back(static_cast<std::int32_t>(i));
      --n_in;
      continue;
    }
    if (walls.empty()) continue;
    if (const int w = outside[i]; w >= 0) {
      if (!opt.ignore_outside_points)
        throw InputError("point " + std::to_string(i) + " lies outside wall " + std::to_string(w) +
                         " (use --ignore-outside to drop such points)");
      in_box[i] = 0;
      ignored_outside.push_back(static_cast<std::int32_t>(i));
      --n_in;
    }
  }
  if (n_in == 0) throw InputError(walls.empty() ? "all points lie outside the bounds" : "all points lie outside the domain (the bounds and the walls)");

  std::array<double, D> lo, hi;
  for (int d = 0; d < D; ++d) {
    lo[static_cast<std::size_t>(d)] = bounds.lo[static_cast<std::size_t>(d)];
    hi[static_cast<std::size_t>(d)] = bounds.hi[static_cast<std::size_t>(d)];
  }
  const double ppb = opt.points_per_bin > 0 ? opt.points_per_bin : 2.0;
  engine_options.threads = resolve_threads(opt.threads);
  engine::ThreadArena(engine_options.threads).execute([&] {
    locator.emplace(points, n_in == n ? std::span<const std::uint8_t>() : std::span<const std::uint8_t>(in_box), lo,
                    hi, ppb);
    // Exact duplicates leave the locator (a few ms on 1M distinct points;
    // where some exist, the locator is built again without them). Kept,
    // every cell near a pile of k copies met all k of them, each a tie
    // the exact predicates settled, and each copy's own cell scanned the
    // pile to find its lowest id: 60,000 copies of one point took 97 s.
    if (!locator->has_coincident()) return;
    const std::vector<std::int32_t> lowest = locator->lowest_coincident();
    std::vector<std::uint8_t> use = in_box;
    if (radii.empty()) {
      for (std::size_t s = 0; s < lowest.size(); ++s)
        if (lowest[s] >= 0) {
          duplicates.emplace_back(locator->id(s), lowest[s]);
          use[static_cast<std::size_t>(locator->id(s))] = 0;
        }
    } else {
      // Power cells: the largest radius of each group owns it (its power
      // is the least everywhere), ties to the lowest id.
      std::unordered_map<std::int32_t, std::int32_t> owner;  // group (its lowest id) -> owner
      auto better = [&](std::int32_t a, std::int32_t b) {
        const double ra = radii[static_cast<std::size_t>(a)], rb = radii[static_cast<std::size_t>(b)];
        return ra > rb || (ra == rb && a < b);
      };
      for (std::size_t s = 0; s < lowest.size(); ++s)
        if (lowest[s] >= 0) {
          auto [it, fresh] = owner.try_emplace(lowest[s], lowest[s]);
          if (better(locator->id(s), it->second)) it->second = locator->id(s);
        }
      for (std::size_t s = 0; s < lowest.size(); ++s) {
        const std::int32_t id = locator->id(s);
        const auto it = owner.find(lowest[s] >= 0 ? lowest[s] : id);
        if (it != owner.end() && it->second != id) {
          duplicates.emplace_back(id, it->second);
          use[static_cast<std::size_t>(id)] = 0;
        }
      }
    }
    std::sort(duplicates.begin(), duplicates.end());
    locator.emplace(points, use, lo, hi, ppb);
  });

  // A bin far fuller than the grid was sized for (a cluster much smaller
  // than a bin), or points beyond the grid's box (outliers: BinLocator's
  // grid_box): their cells search a k-d tree of all the located points,
  // built now. Otherwise the tree is built only if a long cell asks.
  // Long cells (CellBuilder::certify_by_petals) search it too, where most
  // bins are empty (points sampled on a surface) or outliers made it anyway
  // (the bulk's hull cells reach out towards them). On volume-filling input
  // (about 14% of the bins empty when uniform) a few cells at the domain's
  // corners would ask for a tree the rest never use: the shell walk serves them.
  std::uint32_t fullest = 0;
  std::size_t empty = 0;
  for (std::size_t k = 0; k < locator->num_bins(); ++k) {
    const std::uint32_t count = locator->offsets()[k + 1] - locator->offsets()[k];
    fullest = std::max(fullest, count);
    empty += count == 0;
  }
  const kernels::BinLocator<D>& loc = *locator;
  const bool outliers = loc.outside_core() != 0;
  // In the arena: an eager tree's build runs parallel loops (its slabs),
  // which honour --threads there.
  engine::ThreadArena(engine_options.threads).execute([&] {
    tree.emplace(
        points,
        [&loc] {
          std::vector<std::int32_t> ids(loc.size());
          for (std::size_t s = 0; s < ids.size(); ++s) ids[s] = loc.id(s);
          return ids;
        },
        fullest > kernels::overfull_bin || outliers, 2 * empty > locator->num_bins() || outliers);
  });

  // Generators with cells, in bin order (neighbouring cells run together).
  order.reserve(locator->size());
  slots.reserve(locator->size());
  for (std::size_t s = 0; s < locator->size(); ++s) {
    std::int32_t id = locator->id(s);
    if (labels.empty() || labels[static_cast<std::size_t>(id)] >= 0) {
      order.push_back(id);
      slots.push_back(static_cast<std::uint32_t>(s));
    }
  }

  exact.points = points.data();
  exact.dim = D;
  exact.may_underflow = scaling.may_underflow;
  if (!radii.empty()) {
    exact.radii = radii.data();
    exact.max_radius = *std::max_element(radii.begin(), radii.end());
  }
  for (int d = 0; d < 3; ++d) {
    exact.lo[static_cast<std::size_t>(d)] = bounds.lo[static_cast<std::size_t>(d)];
    exact.hi[static_cast<std::size_t>(d)] = bounds.hi[static_cast<std::size_t>(d)];
  }
  if (!walls.empty()) {
    exact.walls = walls.data();
    exact.num_walls = static_cast<int>(walls.size());
    exact.wall_index = wall_index.get();
  }
  kernels::make_grid(exact, n, grid);  // lattices and voxel grids: integer exact predicates
  gens.coords = points.data();
  gens.locator = &*locator;
  gens.lo = lo;
  gens.hi = hi;
  gens.order = order;
  gens.slots = slots;
  gens.exact = &exact;
  gens.tree = &*tree;

  engine_options.progress = opt.progress;
}

void check_radii(std::span<const double> radii, std::size_t n) {
  if (radii.empty()) return;
  if (radii.size() != n)
    throw InputError("radii: " + std::to_string(radii.size()) + " values for " + std::to_string(n) + " points");
  for (std::size_t i = 0; i < n; ++i)
    if (!(radii[i] >= 0 && radii[i] <= std::numeric_limits<double>::max())) {
      std::ostringstream m;
      m.precision(17);
      m << "radius of point " << i << " is ";
      if (std::isnan(radii[i])) m << "NaN";
      else m << radii[i];
      m << ": radii must be finite and non-negative";
      throw InputError(m.str());
    }
}

template <int D>
void Pass<D>::set_radii(std::span<const double> given, std::size_t n, const Scaling& scaling) {
  if (given.empty()) return;
  // voronoi() checked them (check_radii, by the input's ids); a periodic
  // pass's are its points' radii, copied to their images.
  if (given.size() != n) throw std::logic_error("tessera: radii do not match the pass's points");
  // Equal radii add one constant to every power: the ordinary cells, by
  // the ordinary (faster, prepared) predicates.
  if (std::all_of(given.begin(), given.end(), [&](double r) { return r == given[0]; })) return;
  if (scaling.may_underflow)
    throw InputError("radii (power cells) need coordinates within ~1e-150..1e150 of each other; this input spans more");
  if (k == 0) {
    radii = given;
    return;
  }
  scaled_radii.resize(n);  // in the computation's frame, exactly (as the coordinates)
  for (std::size_t i = 0; i < n; ++i) scaled_radii[i] = std::ldexp(given[i], k);
  radii = scaled_radii;
}

template struct Pass<2>;
template struct Pass<3>;

}  // namespace tessera::front
