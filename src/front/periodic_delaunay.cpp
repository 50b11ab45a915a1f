// The Delaunay triangulation of a periodic box (delaunay() with every axis
// periodic), and its validation.
//
// The points' cells among their images (front/periodic.hpp, the same layer
// of images as the periodic cells) find the simplices: the cells pass's
// Delaunay compositor emits each vertex of a cell from its lowest id's cell
// (delaunay_of_images). Every simplex of the periodic triangulation,
// translated so that its least (id, shift) entry is at shift 0, is such a
// vertex of that point's cell, and it is its lowest augmented id (the
// augmented input lists each point's images by shift): each simplex comes
// exactly once, in that canonical translate, oriented by the cell's exact
// topology (a flat simplex cannot arise: its bisectors would not meet).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "periodic.hpp"
#include "tessera/delaunay.hpp"
#include "tessera/kernels/delaunay_predicates.hpp"
#include "tessera/kernels/filter.hpp"

namespace tessera::front {
namespace {

/// One vertex of a simplex: a point and its image's shift.
struct Entry {
  std::int32_t id;
  std::array<int, 3> shift;
  auto operator<=>(const Entry&) const = default;
};

// The hidden points (wrapped into the box) that no translate of a simplex
// holds, or that one holding them is in conflict with (`conflicts`, as the
// facets' test). In the lattice's fractional coordinates an entry with
// shift s lies in [s, s + 1) along each axis, so a translate by t meets the
// box [0, 1) only for -max s <= t <= -min s over the simplex's entries
// (-1..1 as a rule; weights far above the box's size give simplices that
// span several box lengths). Those translates whose bounding box meets the
// hidden points' are tested, through a grid of the hidden points.
// Containment is exact (`orient` of the simplex with one vertex replaced by
// the point).
template <class Conflicts, class Orient>
std::size_t hidden_in_conflict(const Delaunay& dt, std::span<const std::int32_t> hidden, const Conflicts& conflicts,
                               const Orient& orient) {
  const int D = dt.dim;
  const auto du = static_cast<std::size_t>(D);
  const std::size_t w = du + 1;
  const auto lattice = periodic_lattice(dt.bounds, dt.tilt);
  auto at = [&](std::int32_t id) { return &dt.periodic_points[static_cast<std::size_t>(id) * du]; };
  // The grid: about one hidden point per bin.
  double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0}, size[3] = {1, 1, 1};
  std::int64_t bins[3] = {1, 1, 1};
  for (std::size_t a = 0; a < du; ++a) {
    lo[a] = INFINITY, hi[a] = -INFINITY;
    for (const std::int32_t h : hidden) lo[a] = std::min(lo[a], at(h)[a]), hi[a] = std::max(hi[a], at(h)[a]);
    bins[a] = std::max<std::int64_t>(1, static_cast<std::int64_t>(std::pow(static_cast<double>(hidden.size()), 1.0 / D)));
    size[a] = std::max(hi[a] - lo[a], 1e-300) / static_cast<double>(bins[a]);
  }
  auto bin_of = [&](std::size_t a, double x) {
    return std::clamp(static_cast<std::int64_t>(std::floor((x - lo[a]) / size[a])), std::int64_t{0}, bins[a] - 1);
  };
  const auto n_bins = static_cast<std::size_t>(bins[0] * bins[1] * bins[2]);
  std::vector<std::size_t> start(n_bins + 1, 0);
  std::vector<std::size_t> key(hidden.size());
  for (std::size_t i = 0; i < hidden.size(); ++i) {
    std::size_t k = 0;
    for (std::size_t a = du; a-- > 0;) k = k * static_cast<std::size_t>(bins[a]) + static_cast<std::size_t>(bin_of(a, at(hidden[i])[a]));
    ++start[(key[i] = k) + 1];
  }
  for (std::size_t k = 0; k < n_bins; ++k) start[k + 1] += start[k];
  std::vector<std::size_t> slot(hidden.size()), fill(start.begin(), start.end() - 1);
  for (std::size_t i = 0; i < hidden.size(); ++i) slot[fill[key[i]]++] = i;

  std::vector<std::uint8_t> held(hidden.size(), 0), bad(hidden.size(), 0);
  const std::size_t m = dt.n_simplices();
  for (std::size_t s = 0; s < m; ++s) {
    std::array<Entry, 4> row{};
    double blo[3] = {INFINITY, INFINITY, INFINITY}, bhi[3] = {-INFINITY, -INFINITY, -INFINITY};
    std::array<int, 3> smin{0, 0, 0}, smax{0, 0, 0};
    for (std::size_t k = 0; k < w; ++k) {
      row[k].id = dt.simplices[s * w + k];
      for (std::size_t a = 0; a < du; ++a) {
        row[k].shift[a] = dt.simplex_shifts[(s * w + k) * du + a];
        smin[a] = k == 0 ? row[k].shift[a] : std::min(smin[a], row[k].shift[a]);
        smax[a] = k == 0 ? row[k].shift[a] : std::max(smax[a], row[k].shift[a]);
      }
      double x[3];
      periodic_image(lattice, D, at(row[k].id), row[k].shift, x);
      for (std::size_t a = 0; a < du; ++a) blo[a] = std::min(blo[a], x[a]), bhi[a] = std::max(bhi[a], x[a]);
    }
    // The translates -smax..-smin per axis, x fastest.
    int span[3] = {1, 1, 1}, translates = 1;
    for (std::size_t a = 0; a < du; ++a) translates *= span[a] = smax[a] - smin[a] + 1;
    for (int t = 0; t < translates; ++t) {
      std::array<int, 3> by{0, 0, 0};
      for (std::size_t a = 0, r = static_cast<std::size_t>(t); a < du; ++a) {
        by[a] = -smax[a] + static_cast<int>(r % static_cast<std::size_t>(span[a]));
        r /= static_cast<std::size_t>(span[a]);
      }
      // The translate's box, widened by a relative 1e-9 for the rounding of the float move.
      double tlo[3], thi[3];
      bool meets = true;
      for (std::size_t a = 0; a < du; ++a) {
        double move = 0;
        for (std::size_t b = a; b < du; ++b) move += by[b] * lattice[b][a];
        const double slack = 1e-9 * (std::fabs(bhi[a]) + std::fabs(blo[a]) + std::fabs(move) + (hi[a] - lo[a]));
        tlo[a] = blo[a] + move - slack;
        thi[a] = bhi[a] + move + slack;
        meets &= tlo[a] <= hi[a] && thi[a] >= lo[a];
      }
      if (!meets) continue;
      std::array<Entry, 4> moved = row;
      for (std::size_t k = 0; k < w; ++k)
        for (std::size_t a = 0; a < du; ++a) moved[k].shift[a] += by[a];
      std::int64_t b0[3] = {0, 0, 0}, b1[3] = {0, 0, 0};
      for (std::size_t a = 0; a < du; ++a) b0[a] = bin_of(a, tlo[a]), b1[a] = bin_of(a, thi[a]);
      for (std::int64_t z = b0[2]; z <= b1[2]; ++z)
        for (std::int64_t y = b0[1]; y <= b1[1]; ++y)
          for (std::int64_t x = b0[0]; x <= b1[0]; ++x) {
            const auto k = static_cast<std::size_t>((z * bins[1] + y) * bins[0] + x);
            for (std::size_t e = start[k]; e < start[k + 1]; ++e) {
              const std::size_t i = slot[e];
              const Entry q{hidden[i], {0, 0, 0}};
              bool inside = true;
              for (std::size_t k2 = 0; k2 < w && inside; ++k2) {
                std::array<Entry, 4> swapped = moved;
                swapped[k2] = q;
                inside = orient(swapped) >= 0;
              }
              if (!inside) continue;
              held[i] = 1;
              bad[i] |= static_cast<std::uint8_t>(conflicts(moved, q));
            }
          }
    }
  }
  std::size_t count = 0;
  for (std::size_t i = 0; i < hidden.size(); ++i) count += !held[i] || bad[i];
  return count;
}

}  // namespace

Delaunay periodic_delaunay(std::span<const double> input, int dim, std::span<const std::int32_t> labels,
                           const DelaunayOptions& options) {
  for (int a = 0; a < dim && a < 3; ++a)
    if (!options.periodic[static_cast<std::size_t>(a)])
      throw InputError(std::string("a periodic Delaunay triangulation needs every axis periodic (") + "xyz"[a] +
                       " is a wall: the triangulation would need its hull there)");
  for (const std::int32_t l : labels)
    if (l < 0) throw InputError("a periodic Delaunay triangulation takes no outside points (labels < 0)");
  const PeriodicInput in = periodic_input(input, dim, labels, options);
  const int threads = resolve_threads(options.threads);
  VoronoiOptions o = options;
  o.periodic = {false, false, false};
  o.tilt = {0, 0, 0};
  o.ignore_outside_points = false;  // set aside already; every image lies in the layer
  std::vector<double> radii;  // regular triangulations: each image has its point's radius
  auto [aug, im] = run_in_final_layer(in, labels, threads, [&](const PeriodicImages& images, std::vector<double>& reach) {
    o.bounds = images.domain;
    if (!options.radii.empty()) {
      radii.resize(images.base.size());
      for (std::size_t k = 0; k < radii.size(); ++k) radii[k] = options.radii[static_cast<std::size_t>(images.base[k])];
      o.radii = radii;
    }
    return delaunay_of_images(images.points, dim, images.labels, o, reach);
  });

  // Rows in augmented ids, each from its lowest id's cell: a point at shift
  // 0, the least (id, shift) entry (augmented ids ascend by (point, shift)),
  // so each simplex comes once, as its canonical translate, ascending but
  // for the orientation's swap. Mapped to (point, shift) in place.
  const auto du = static_cast<std::size_t>(dim);
  Delaunay dt;
  describe_box(in, dt);
  dt.from_cells = aug.n_simplices();
  dt.exact_predicate_calls = aug.exact_predicate_calls;
  dt.threads_used = aug.threads_used;
  dt.duplicates = duplicates_as_points(im, aug.duplicates);
  dt.simplices = std::move(aug.simplices);
  dt.simplex_shifts.resize(dt.simplices.size() * du);
  to_points(im, dim, dt.simplices, dt.simplex_shifts, threads);
  dt.power = aug.power;
  list_hidden(dt);
  return dt;
}

DelaunayReport validate_periodic(const Delaunay& dt, std::span<const double> radii) {
  const int D = dt.dim;
  const auto du = static_cast<std::size_t>(D);
  const std::size_t w = du + 1, m = dt.n_simplices();
  if (dt.simplex_shifts.size() != m * w * du || dt.periodic_points.size() != dt.n_points * du)
    throw std::invalid_argument("validate: a periodic triangulation without its shifts or points");
  DelaunayReport rep;
  rep.simplices = m;
  const auto lattice = periodic_lattice(dt.bounds, dt.tilt);
  auto entry = [&](std::size_t s, std::size_t k) {
    Entry e{dt.simplices[s * w + k], {0, 0, 0}};
    for (std::size_t a = 0; a < du; ++a) e.shift[a] = dt.simplex_shifts[(s * w + k) * du + a];
    return e;
  };
  auto place = [&](const Entry& e, double* out) {
    periodic_image(lattice, D, &dt.periodic_points[static_cast<std::size_t>(e.id) * du], e.shift, out);
  };
  // Exact orientation of D+1 entries (images placed exactly: the grid).
  auto orient = [&](const std::array<Entry, 4>& e) {
    double xyz[4][3];
    const double* pts[4];
    for (std::size_t k = 0; k < w; ++k) {
      place(e[k], xyz[k]);
      pts[k] = xyz[k];
    }
    return kernels::orientation(D, pts);
  };

  // Orientation and volume (the volumes of a periodic triangulation tile
  // the box: Lx Ly Lz, the lattice's determinant). The volumes are summed
  // in units of 2^ve per length, ve the exponent of the box's largest
  // length: a box 2^665 wide holds 2^1995 (infinite in doubles) and one
  // 2^-615 wide 2^-1845 (zero), where its triangulation is the unit box's.
  double largest = 0;
  for (int a = 0; a < D; ++a)
    largest = std::max(largest, dt.bounds.hi[static_cast<std::size_t>(a)] - dt.bounds.lo[static_cast<std::size_t>(a)]);
  const int ve = kernels::filter::binary_exponent(largest);
  const double unit = std::ldexp(1.0, -ve);
  const double fact = D == 2 ? 2.0 : 6.0;
  double volume = 0, perm_sum = 0;
  std::vector<Entry> used;
  for (std::size_t s = 0; s < m; ++s) {
    std::array<Entry, 4> e{};
    for (std::size_t k = 0; k < w; ++k) e[k] = entry(s, k);
    rep.flat_or_inverted += orient(e) != 1;
    double xyz[4][3];
    for (std::size_t k = 0; k < w; ++k) place(e[k], xyz[k]);
    double r[3][3] = {};
    for (std::size_t k = 1; k < w; ++k)
      for (std::size_t a = 0; a < du; ++a) r[k - 1][a] = (xyz[k][a] - xyz[0][a]) * unit;
    const double det = D == 2 ? r[0][0] * r[1][1] - r[0][1] * r[1][0]
                              : r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1]) -
                                    r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0]) +
                                    r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0]);
    volume += det / fact;
    perm_sum += std::fabs(det) / fact;
  }

  // Is `q` in conflict with the (power) sphere of `row` (D+1 entries), in
  // the perturbation of the cells: the D+2 points in (id, shift) order as
  // local ids, the order of the augmented input.
  auto conflicts = [&](const std::array<Entry, 4>& row, const Entry& q) {
    std::array<Entry, 5> all{};
    for (std::size_t k = 0; k < w; ++k) all[k] = row[k];
    all[w] = q;
    std::array<std::size_t, 5> order{0, 1, 2, 3, 4};
    // Insertion sort of the w + 1 <= 5 entries (std::sort's introsort here
    // drew GCC 12's -Warray-bounds, a false positive of its inlining).
    for (std::size_t r = 1; r <= w; ++r)
      for (std::size_t t = r; t > 0 && all[order[t]] < all[order[t - 1]]; --t) std::swap(order[t], order[t - 1]);
    std::array<std::int32_t, 5> local{};
    double xyz[5][3] = {}, packed[15] = {}, rho[5] = {};
    for (std::size_t r = 0; r <= w; ++r) {
      local[order[r]] = static_cast<std::int32_t>(r);
      place(all[order[r]], xyz[r]);
      for (std::size_t a = 0; a < du; ++a) packed[r * du + a] = xyz[r][a];  // in_sphere reads dim doubles per point
      if (dt.power) rho[r] = radii[static_cast<std::size_t>(all[order[r]].id)];
    }
    kernels::ExactContext ctx;
    ctx.points = packed;
    ctx.dim = D;
    if (dt.power) {
      ctx.radii = rho;
      ctx.max_radius = *std::max_element(rho, rho + w + 1);
    }
    std::array<std::int32_t, 3> planes{};
    for (std::size_t k = 0; k < du; ++k) planes[k] = local[k + 1];
    return kernels::in_sphere(ctx, local[0], planes.data(), local[w]) ? 1 : 0;
  };

  // Facets: each, translated canonically (its least (id, shift) entry at
  // shift 0), in exactly two simplices, whose apexes lie on opposite
  // sides and neither in the other's circumsphere (perturbed as the cells
  // were: by (id, shift) order).
  struct Facet {
    std::array<Entry, 3> key;       // canonical, ascending
    std::array<int, 3> translation;  // subtracted from the simplex's shifts
    std::size_t simplex, k;          // the simplex and the slot of its apex
    bool operator<(const Facet& o) const {
      return key != o.key ? key < o.key : (simplex != o.simplex ? simplex < o.simplex : k < o.k);
    }
  };
  std::vector<Facet> facets;
  facets.reserve(m * w);
  for (std::size_t s = 0; s < m; ++s)
    for (std::size_t k = 0; k < w; ++k) {
      std::array<Entry, 3> f{};
      for (std::size_t j = 0, c = 0; j < w; ++j)
        if (j != k) f[c++] = entry(s, j);
      for (std::size_t x = 1; x < du; ++x)  // ascending (insertion: at most 3)
        for (std::size_t y = x; y > 0 && f[y] < f[y - 1]; --y) std::swap(f[y], f[y - 1]);
      Facet g{f, f[0].shift, s, k};
      for (std::size_t c = 0; c < du; ++c)
        for (std::size_t a = 0; a < 3; ++a) g.key[c].shift[a] = f[c].shift[a] - f[0].shift[a];
      facets.push_back(g);
    }
  std::sort(facets.begin(), facets.end());
  for (std::size_t i = 0; i < facets.size();) {
    std::size_t j = i + 1;
    while (j < facets.size() && facets[j].key == facets[i].key) ++j;
    if (j - i == 1) {
      ++rep.boundary_facets;
    } else if (j - i > 2) {
      rep.nonmanifold_facets += j - i - 2;
    } else {
      const Facet& a = facets[i];
      const Facet& b = facets[i + 1];
      // b's apex in a's frame.
      Entry apex = entry(b.simplex, b.k);
      for (std::size_t t = 0; t < 3; ++t) apex.shift[t] += a.translation[t] - b.translation[t];
      std::array<Entry, 4> row{};
      for (std::size_t k = 0; k < w; ++k) row[k] = entry(a.simplex, k);
      std::array<Entry, 4> swapped = row;
      swapped[a.k] = apex;
      if (orient(swapped) != -1) {
        ++rep.nonmanifold_facets;
      } else {
        rep.local_delaunay_violations += conflicts(row, apex);
      }
    }
    i = j;
  }

  // Every point that takes part is a vertex, or (radii) hidden: in some
  // translate of a simplex, not in conflict with it.
  std::vector<std::uint8_t> seen(dt.n_points, 0);
  for (std::int32_t id : dt.simplices) seen[static_cast<std::size_t>(id)] = 1;
  for (auto [dup, owner] : dt.duplicates) seen[static_cast<std::size_t>(dup)] = 1;
  for (std::int32_t id : dt.ignored_outside_bounds) seen[static_cast<std::size_t>(id)] = 1;
  std::vector<std::int32_t> hidden;
  for (std::int32_t id : dt.hidden) {
    if (seen[static_cast<std::size_t>(id)]) ++rep.hidden_not_hidden;
    else hidden.push_back(id);
    seen[static_cast<std::size_t>(id)] = 1;
  }
  rep.missing_points = static_cast<std::size_t>(std::count(seen.begin(), seen.end(), 0));
  if (!hidden.empty()) rep.hidden_in_conflict = hidden_in_conflict(dt, hidden, conflicts, orient);

  auto fail = [&](std::size_t count, const std::string& what) {
    if (count == 0) return;
    rep.ok = false;
    rep.messages.push_back(std::to_string(count) + " " + what);
  };
  fail(rep.flat_or_inverted, "simplices are flat or inverted");
  fail(rep.nonmanifold_facets, "facets are shared by more than two simplices or overlap");
  fail(rep.boundary_facets, "facets are in one simplex only (a periodic triangulation has no boundary)");
  fail(rep.missing_points, dt.power ? "points are in no simplex and not hidden" : "points are in no simplex");
  fail(rep.hidden_not_hidden, "points listed as hidden are vertices, duplicates or set aside");
  fail(rep.hidden_in_conflict, "hidden points are in conflict with the simplex that holds them (they should be vertices)");
  fail(rep.local_delaunay_violations, dt.power ? "facets are not locally regular" : "facets are not locally Delaunay");
  double enclosed = 1;  // in the units above
  for (int a = 0; a < D; ++a)
    enclosed *= (dt.bounds.hi[static_cast<std::size_t>(a)] - dt.bounds.lo[static_cast<std::size_t>(a)]) * unit;
  const double tolerance = 1e-9 * enclosed + 32 * std::numeric_limits<double>::epsilon() * perm_sum;
  rep.volume_sum = std::ldexp(volume, D * ve);
  rep.enclosed_volume = std::ldexp(enclosed, D * ve);
  rep.volume_tolerance = std::ldexp(tolerance, D * ve);
  if (!(std::fabs(volume - enclosed) <= tolerance)) {
    rep.ok = false;
    char buf[160];
    std::snprintf(buf, sizeof buf, "simplex volumes sum to %.17g but the periodic box holds %.17g", rep.volume_sum,
                  rep.enclosed_volume);
    rep.messages.push_back(buf);
  }
  return rep;
}

}  // namespace tessera::front
