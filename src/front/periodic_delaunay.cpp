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
#include <stdexcept>
#include <string>
#include <vector>

#include "periodic.hpp"
#include "tessera/delaunay.hpp"
#include "tessera/kernels/delaunay_predicates.hpp"

namespace tessera::front {
namespace {

/// One vertex of a simplex: a point and its image's shift.
struct Entry {
  std::int32_t id;
  std::array<int, 3> shift;
  auto operator<=>(const Entry&) const = default;
};

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
  auto [aug, im] = run_in_final_layer(in, labels, threads, [&](const PeriodicImages& images, std::vector<double>& reach) {
    o.bounds = images.domain;
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
  return dt;
}

DelaunayReport validate_periodic(const Delaunay& dt) {
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
  // the box: Lx Ly Lz, the lattice's determinant).
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
      for (std::size_t a = 0; a < du; ++a) r[k - 1][a] = xyz[k][a] - xyz[0][a];
    const double det = D == 2 ? r[0][0] * r[1][1] - r[0][1] * r[1][0]
                              : r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1]) -
                                    r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0]) +
                                    r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0]);
    volume += det / fact;
    perm_sum += std::fabs(det) / fact;
  }

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
        // The five points in (id, shift) order as local ids: the
        // perturbation's order, as in the augmented input.
        std::array<Entry, 5> all{};
        for (std::size_t k = 0; k < w; ++k) all[k] = row[k];
        all[w] = apex;
        std::array<std::size_t, 5> order{0, 1, 2, 3, 4};
        std::sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(w) + 1,
                  [&](std::size_t x, std::size_t y) { return all[x] < all[y]; });
        std::array<std::int32_t, 5> local{};
        double xyz[5][3] = {};
        for (std::size_t r = 0; r <= w; ++r) {
          local[order[r]] = static_cast<std::int32_t>(r);
          place(all[order[r]], xyz[r]);
        }
        kernels::ExactContext ctx;
        ctx.points = &xyz[0][0];
        ctx.dim = D;
        if (D == 2) {  // in_sphere reads dim doubles per point
          double packed[10];
          for (std::size_t r = 0; r <= w; ++r) {
            packed[2 * r] = xyz[r][0];
            packed[2 * r + 1] = xyz[r][1];
          }
          ctx.points = packed;
          const std::array<std::int32_t, 2> planes{local[1], local[2]};
          rep.local_delaunay_violations += kernels::in_sphere(ctx, local[0], planes.data(), local[w]);
        } else {
          const std::array<std::int32_t, 3> planes{local[1], local[2], local[3]};
          rep.local_delaunay_violations += kernels::in_sphere(ctx, local[0], planes.data(), local[w]);
        }
      }
    }
    i = j;
  }

  // Every point that takes part is a vertex.
  std::vector<std::uint8_t> seen(dt.n_points, 0);
  for (std::int32_t id : dt.simplices) seen[static_cast<std::size_t>(id)] = 1;
  for (auto [dup, owner] : dt.duplicates) seen[static_cast<std::size_t>(dup)] = 1;
  for (std::int32_t id : dt.ignored_outside_bounds) seen[static_cast<std::size_t>(id)] = 1;
  rep.missing_points = static_cast<std::size_t>(std::count(seen.begin(), seen.end(), 0));

  auto fail = [&](std::size_t count, const std::string& what) {
    if (count == 0) return;
    rep.ok = false;
    rep.messages.push_back(std::to_string(count) + " " + what);
  };
  fail(rep.flat_or_inverted, "simplices are flat or inverted");
  fail(rep.nonmanifold_facets, "facets are shared by more than two simplices or overlap");
  fail(rep.boundary_facets, "facets are in one simplex only (a periodic triangulation has no boundary)");
  fail(rep.missing_points, "points are in no simplex");
  fail(rep.local_delaunay_violations, "facets are not locally Delaunay");
  rep.volume_sum = volume;
  rep.enclosed_volume = dt.bounds.volume(D);
  rep.volume_tolerance = 1e-9 * rep.enclosed_volume + 32 * std::numeric_limits<double>::epsilon() * perm_sum;
  if (!(std::fabs(rep.volume_sum - rep.enclosed_volume) <= rep.volume_tolerance)) {
    rep.ok = false;
    char buf[160];
    std::snprintf(buf, sizeof buf, "simplex volumes sum to %.17g but the periodic box holds %.17g", rep.volume_sum,
                  rep.enclosed_volume);
    rep.messages.push_back(buf);
  }
  return rep;
}

}  // namespace tessera::front
