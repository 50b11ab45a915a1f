// tessera::validate for a Delaunay triangulation: orientation, conformity,
// closed and convex boundary, every point used, local Delaunay, volumes.
//
// Local Delaunay on every interior facet of a conforming triangulation implies
// the triangulation is Delaunay (Delaunay's lemma); with a closed, locally
// convex boundary and every point a vertex, it is the triangulation of the
// convex hull. All decisions use the exact predicates, in the same symbolic
// perturbation the computation used.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <tbb/parallel_for.h>

#include "tessera/delaunay.hpp"
#include "tessera/locate.hpp"
#include "pass.hpp"
#include "simplex_facets.hpp"
#include "periodic.hpp"
#include "point_buckets.hpp"
#include "tessera/kernels/delaunay_predicates.hpp"

namespace tessera {
namespace {

using front::FacetRecord;

// Determinant of D rows and its permanent (|terms| summed), which bounds the
// rounding error of the float determinant.
double det_rows(const double (*r)[3], int D, double& perm) {
  if (D == 2) {
    perm = std::fabs(r[0][0] * r[1][1]) + std::fabs(r[0][1] * r[1][0]);
    return r[0][0] * r[1][1] - r[0][1] * r[1][0];
  }
  double m0 = r[1][1] * r[2][2] - r[1][2] * r[2][1], m1 = r[1][0] * r[2][2] - r[1][2] * r[2][0],
         m2 = r[1][0] * r[2][1] - r[1][1] * r[2][0];
  perm = std::fabs(r[0][0]) * (std::fabs(r[1][1] * r[2][2]) + std::fabs(r[1][2] * r[2][1])) +
         std::fabs(r[0][1]) * (std::fabs(r[1][0] * r[2][2]) + std::fabs(r[1][2] * r[2][0])) +
         std::fabs(r[0][2]) * (std::fabs(r[1][0] * r[2][1]) + std::fabs(r[1][1] * r[2][0]));
  return r[0][0] * m0 - r[0][1] * m1 + r[0][2] * m2;
}

/// True when the points that take part (not hidden ones either) span less
/// than D dimensions (exactly).
bool is_flat(const kernels::ExactContext& ctx, const Delaunay& dt) {
  std::vector<std::uint8_t> skip(dt.n_points, 0);
  for (auto [dup, owner] : dt.duplicates) skip[static_cast<std::size_t>(dup)] = 1;
  for (std::int32_t id : dt.ignored_outside_bounds) skip[static_cast<std::size_t>(id)] = 1;
  for (std::int32_t id : dt.hidden) skip[static_cast<std::size_t>(id)] = 1;
  // Grow an affinely independent set greedily; the input is flat iff it stops short of D+1.
  std::array<std::int32_t, 4> basis{};
  int size = 0;
  const int D = dt.dim;
  for (std::size_t i = 0; i < dt.n_points && size <= D; ++i) {
    if (skip[i]) continue;
    const auto id = static_cast<std::int32_t>(i);
    if (size == 0) { basis[0] = id; size = 1; continue; }
    // Is the point affinely independent of the basis (exactly)?
    bool independent = false;
    if (size == 1) {
      for (int d = 0; d < D; ++d)
        independent |= ctx.points[i * static_cast<std::size_t>(D) + static_cast<std::size_t>(d)] !=
                       ctx.points[static_cast<std::size_t>(basis[0]) * static_cast<std::size_t>(D) + static_cast<std::size_t>(d)];
    } else if (size == D) {
      basis[static_cast<std::size_t>(size)] = id;
      independent = kernels::orientation(ctx, basis.data()) != 0;
    } else {
      // 3D, size 2: the candidate is independent iff it is not on the line of
      // basis[0], basis[1]: some coordinate-plane projection is non-collinear.
      const double* a = ctx.points + static_cast<std::size_t>(basis[0]) * 3;
      const double* b = ctx.points + static_cast<std::size_t>(basis[1]) * 3;
      const double* c = ctx.points + i * 3;
      for (int u = 0; u < 3 && !independent; ++u) {
        int x = u, y = (u + 1) % 3;
        kernels::ExactContext plane;
        double pts[6] = {a[x], a[y], b[x], b[y], c[x], c[y]};
        plane.points = pts;
        plane.dim = 2;
        std::int32_t ids[3] = {0, 1, 2};
        independent = kernels::orientation(plane, ids) != 0;
      }
    }
    if (independent) basis[static_cast<std::size_t>(size++)] = id;
  }
  return size <= D;
}

}  // namespace

DelaunayReport validate(const Delaunay& dt, std::span<const double> points, std::span<const std::int32_t> labels,
                        std::span<const double> radii) {
  front::check_simplex_ids(dt);
  if (dt.power && radii.size() != dt.n_points)
    throw InputError("validate: a regular triangulation of " + std::to_string(dt.n_points) + " points needs their " +
                     std::to_string(dt.n_points) + " radii, got " + std::to_string(radii.size()));
  if (!dt.power && !radii.empty())
    throw InputError("validate: radii given for a triangulation computed without them");
  if (!radii.empty()) front::check_radii(radii, dt.n_points);
  if (dt.is_periodic()) return front::validate_periodic(dt, radii);  // its own points (wrapped)
  if (points.size() != dt.n_points * static_cast<std::size_t>(dt.dim))
    throw InputError("validate: " + std::to_string(points.size()) + " coordinates for a triangulation of " +
                     std::to_string(dt.n_points) + " points in " + std::to_string(dt.dim) + "D");
  if (!labels.empty() && labels.size() != dt.n_points)
    throw InputError("validate: " + std::to_string(labels.size()) + " labels for " + std::to_string(dt.n_points) + " points");
  DelaunayReport rep;
  const int D = dt.dim;
  const std::size_t w = static_cast<std::size_t>(D + 1);
  const std::size_t m = dt.n_simplices();
  rep.simplices = m;
  kernels::ExactContext ctx;
  ctx.points = points.data();
  ctx.dim = D;
  if (dt.power) {  // the power test: in_sphere and the regular triangulation's perturbation
    ctx.radii = radii.data();
    ctx.max_radius = *std::max_element(radii.begin(), radii.end());
  }
  auto pt = [&](std::int32_t id) { return points.data() + static_cast<std::size_t>(id) * static_cast<std::size_t>(D); };
  const double fact = D == 2 ? 2.0 : 6.0;
  // Volumes are computed in units of a power of two per axis, near the
  // points' extent along it (exact scalings of the coordinate differences,
  // which scale every volume by their product), so points near 1e-150 or
  // 1e150 neither under- nor overflow them, and an axis a few subnormal ulps
  // thick keeps its bits (a triangle 4e-321 high, flat input that hull
  // completion triangulates: in one unit for all axes its area lost most
  // of them and the sums disagreed; stop 23's fuzz). The report gives the
  // volumes back in the input's units, where they may not be representable.
  // Half extents where the extent overflows (a domain spanning most of
  // double's range), and a coordinate difference that does too (diff).
  double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0}, o[3] = {0, 0, 0}, unit[3] = {1, 1, 1};
  int unit_exp_sum = 0;
  for (int d = 0; d < D; ++d) {
    const auto du = static_cast<std::size_t>(d);
    lo[d] = dt.bounds.lo[du];
    hi[d] = dt.bounds.hi[du];
    // Over the finite points (those with a NaN or infinite coordinate were
    // set aside: VoronoiOptions::ignore_outside_points).
    double l = INFINITY, h = -INFINITY;
    for (std::size_t i = 0; i < dt.n_points; ++i) {
      const double x = points[i * static_cast<std::size_t>(D) + du];
      if (!std::isfinite(x)) continue;
      l = std::min(l, x);
      h = std::max(h, x);
    }
    if (l <= h) {
      lo[d] = l;
      hi[d] = h;
    }
    double extent = hi[d] - lo[d];
    if (!std::isfinite(extent)) extent = 0.5 * hi[d] - 0.5 * lo[d];
    const int e = extent > 0 && std::isfinite(extent) ? std::clamp(std::ilogb(extent), -1000, 1000) : 0;
    unit[d] = std::ldexp(1.0, -e);
    unit_exp_sum += e;
    o[d] = 0.5 * lo[d] + 0.5 * hi[d];  // the enclosed volume's origin
  }
  auto diff = [&unit](double a, double b, int d) {
    const double x = a - b;
    return std::isfinite(x) ? x * unit[d] : a * unit[d] - b * unit[d];
  };
  double volume_sum = 0, enclosed_volume = 0;  // in those units

  // Orientation and volume of every simplex.
  std::vector<std::uint8_t> bad(m, 0);
  std::vector<double> vol(m, 0), vol_err(m, 0);
  tbb::parallel_for(std::size_t(0), m, [&](std::size_t s) {
    const std::int32_t* row = dt.simplices.data() + s * w;
    bad[s] = kernels::orientation(ctx, row) != 1;
    double r[3][3] = {};
    for (int k = 0; k < D; ++k)
      for (int d = 0; d < D; ++d) r[k][d] = diff(pt(row[k + 1])[d], pt(row[0])[d], d);
    double perm;
    vol[s] = det_rows(r, D, perm) / fact;
    vol_err[s] = 32 * std::numeric_limits<double>::epsilon() * perm / fact;
  });
  rep.flat_or_inverted = static_cast<std::size_t>(std::count(bad.begin(), bad.end(), 1));
  double volume_err = 0;
  for (std::size_t s = 0; s < m; ++s) {
    volume_sum += vol[s];
    volume_err += vol_err[s];
  }

  // Facets, sorted so the simplices sharing one sit together.
  const std::vector<FacetRecord> recs = front::sorted_facets(dt);

  // A facet of simplex s (opposite slot k) with the apex, as D+1 ids in the
  // simplex's own order: the facet's orientation seen from its simplex.
  auto side_of = [&](const FacetRecord& f, std::int32_t q) {
    std::array<std::int32_t, 4> ids;
    const std::int32_t* row = dt.simplices.data() + static_cast<std::size_t>(f.simplex) * w;
    for (std::size_t j = 0; j < w; ++j) ids[j] = row[j];
    ids[static_cast<std::size_t>(f.k)] = q;
    return kernels::orientation(ctx, ids.data());
  };
  auto apex = [&](const FacetRecord& f) {
    return dt.simplices[static_cast<std::size_t>(f.simplex) * w + static_cast<std::size_t>(f.k)];
  };

  std::vector<const FacetRecord*> boundary;
  std::vector<std::pair<const FacetRecord*, const FacetRecord*>> interior;
  for (std::size_t i = 0; i < recs.size();) {
    std::size_t j = i + 1;
    while (j < recs.size() && recs[j].same_facet(recs[i])) ++j;
    if (j - i == 1) boundary.push_back(&recs[i]);
    else if (j - i == 2) interior.emplace_back(&recs[i], &recs[i + 1]);
    else rep.nonmanifold_facets += j - i - 2;
    i = j;
  }
  rep.boundary_facets = boundary.size();

  // Interior facets: the two apexes on opposite sides; neither in the other's sphere.
  std::vector<std::uint8_t> twice(interior.size(), 0), nonlocal(interior.size(), 0);
  tbb::parallel_for(std::size_t(0), interior.size(), [&](std::size_t i) {
    auto [a, b] = interior[i];
    // Replacing a's apex by b's apex must flip a's orientation (+1 -> -1).
    if (side_of(*a, apex(*b)) != -1) { twice[i] = 1; return; }
    const std::int32_t* row = dt.simplices.data() + static_cast<std::size_t>(a->simplex) * w;
    if (kernels::in_sphere(ctx, row[0], row + 1, apex(*b))) nonlocal[i] = 1;
  });
  rep.nonmanifold_facets += static_cast<std::size_t>(std::count(twice.begin(), twice.end(), 1));
  rep.local_delaunay_violations = static_cast<std::size_t>(std::count(nonlocal.begin(), nonlocal.end(), 1));

  // Boundary: the volume it encloses (facets in the simplex's induced
  // orientation, sign (-1)^k), and its ridges, each in exactly two boundary facets.
  struct RidgeRec {
    std::array<std::int32_t, 2> ridge;
    std::int32_t facet;   // index into boundary
    std::int32_t other;   // the facet's vertex not on the ridge
    bool operator<(const RidgeRec& r) const { return ridge != r.ridge ? ridge < r.ridge : facet < r.facet; }
  };
  std::vector<RidgeRec> ridges;
  for (std::size_t b = 0; b < boundary.size(); ++b) {
    const FacetRecord& f = *boundary[b];
    const std::int32_t* row = dt.simplices.data() + static_cast<std::size_t>(f.simplex) * w;
    double r[3][3] = {};
    for (std::size_t j = 0, c = 0; j < w; ++j) {
      if (static_cast<std::int32_t>(j) == f.k) continue;
      for (int d = 0; d < D; ++d) r[c][d] = diff(pt(row[j])[d], o[d], d);
      ++c;
    }
    double perm;
    enclosed_volume += ((f.k % 2) ? -1.0 : 1.0) * det_rows(r, D, perm) / fact;
    volume_err += 32 * std::numeric_limits<double>::epsilon() * perm / fact;
    for (int drop = 0; drop < D; ++drop) {
      RidgeRec rr{{-1, -1}, static_cast<std::int32_t>(b), f.facet[static_cast<std::size_t>(drop)]};
      for (int j = 0, c = 0; j < D; ++j)
        if (j != drop) rr.ridge[static_cast<std::size_t>(c++)] = f.facet[static_cast<std::size_t>(j)];
      ridges.push_back(rr);
    }
  }
  std::sort(ridges.begin(), ridges.end());
  for (std::size_t i = 0; i < ridges.size();) {
    std::size_t j = i + 1;
    while (j < ridges.size() && ridges[j].ridge == ridges[i].ridge) ++j;
    if (!labels.empty() || !dt.hull_completed) {
      // Labelled results, and those without hull completion (the simplices
      // whose circumcentre lies in the box), may be concave and pinched:
      // nothing to check here.
    } else if (j - i != 2) {
      ++rep.open_boundary_ridges;
    } else {
      // Convex: each facet's far vertex is not strictly beyond the other facet.
      for (int t = 0; t < 2; ++t) {
        const RidgeRec& a = ridges[i + static_cast<std::size_t>(t)];
        const RidgeRec& b = ridges[i + static_cast<std::size_t>(1 - t)];
        if (side_of(*boundary[static_cast<std::size_t>(a.facet)], b.other) == -1) {
          ++rep.nonconvex_boundary;
          break;
        }
      }
    }
    i = j;
  }

  // Every point that takes part is a vertex, or (radii) hidden: it lies in
  // a simplex whose orthosphere it is not in conflict with. With local
  // regularity everywhere, that makes the simplices the lower hull of the
  // lifted points, every one of them on or above it.
  if (labels.empty() && dt.hull_completed) {
    std::vector<std::uint8_t> used(dt.n_points, 0);
    for (std::int32_t id : dt.simplices) used[static_cast<std::size_t>(id)] = 1;
    for (auto [dup, owner] : dt.duplicates) used[static_cast<std::size_t>(dup)] = 1;
    for (std::int32_t id : dt.ignored_outside_bounds) used[static_cast<std::size_t>(id)] = 1;
    std::vector<std::int32_t> hidden;
    for (std::int32_t id : dt.hidden) {
      if (used[static_cast<std::size_t>(id)]) ++rep.hidden_not_hidden;  // a vertex, duplicate or set aside
      else hidden.push_back(id);
      used[static_cast<std::size_t>(id)] = 1;
    }
    rep.missing_points = static_cast<std::size_t>(std::count(used.begin(), used.end(), 0));
    if (m == 0) {
      // Exactly flat (coplanar / collinear) input has no simplex: nothing
      // is missing; with radii, neither where the points not hidden are.
      if (is_flat(ctx, dt)) rep.missing_points = 0;
    } else if (!hidden.empty()) {
      const std::vector<double> at = [&] {
        std::vector<double> q(hidden.size() * static_cast<std::size_t>(D));
        for (std::size_t i = 0; i < hidden.size(); ++i)
          std::copy_n(pt(hidden[i]), D, q.begin() + static_cast<std::ptrdiff_t>(i * static_cast<std::size_t>(D)));
        return q;
      }();
      const SimplexLocator loc(dt, points, 0, LocateMethod::grid);
      const std::vector<std::int32_t> in = loc.locate(dt, points, at);
      for (std::size_t i = 0; i < hidden.size(); ++i) {
        const std::int32_t* row = in[i] < 0 ? nullptr : dt.simplices.data() + static_cast<std::size_t>(in[i]) * w;
        if (row == nullptr || kernels::in_sphere(ctx, row[0], row + 1, hidden[i])) ++rep.hidden_in_conflict;
      }
    }
  }

  auto fail = [&](std::size_t count, const char* what) {
    if (count == 0) return;
    rep.ok = false;
    std::ostringstream s;
    s << count << " " << what;
    rep.messages.push_back(s.str());
  };
  fail(rep.flat_or_inverted, "simplices are flat or inverted");
  fail(rep.nonmanifold_facets, "facets are shared by more than two simplices or overlap");
  fail(rep.open_boundary_ridges, "boundary ridges are not shared by exactly two boundary facets");
  fail(rep.nonconvex_boundary, "boundary ridges are not convex (the hull is incomplete)");
  fail(rep.missing_points, dt.power ? "points are in no simplex and not hidden" : "points are in no simplex");
  fail(rep.hidden_not_hidden, "points listed as hidden are vertices, duplicates or set aside");
  fail(rep.hidden_in_conflict, "hidden points are in conflict with the simplex that holds them (they should be vertices)");
  fail(rep.local_delaunay_violations,
       dt.power ? "interior facets are not locally regular" : "interior facets are not locally Delaunay");
  // Float volumes: the comparison allows their rounding (a bound from each
  // determinant's permanent, which matters for nearly flat input) plus 1e-9.
  rep.volume_sum = std::ldexp(volume_sum, unit_exp_sum);
  rep.enclosed_volume = std::ldexp(enclosed_volume, unit_exp_sum);
  const double tol = 1e-9 * std::max(std::fabs(volume_sum), std::fabs(enclosed_volume)) + volume_err;
  rep.volume_tolerance = std::ldexp(tol, unit_exp_sum);
  if (!(std::fabs(volume_sum - enclosed_volume) <= tol)) {  // NaN fails too
    rep.ok = false;
    std::ostringstream s;
    s << "simplex volumes sum to " << rep.volume_sum << " but the boundary encloses " << rep.enclosed_volume
      << " (relative difference "
      << std::fabs(volume_sum - enclosed_volume) / std::max(std::fabs(volume_sum), std::fabs(enclosed_volume)) << ")";
    rep.messages.push_back(s.str());
  }
  return rep;
}

}  // namespace tessera
