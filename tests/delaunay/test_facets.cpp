// Facet matching (simplex_facets.hpp) through its two users: simplex_neighbors
// against a brute-force map of every facet, and the validator on triangulations
// corrupted on purpose (a simplex removed, repeated, inverted, or two flipped
// into three non-Delaunay ones), each of which it must report.
#include <gtest/gtest.h>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <algorithm>
#include <array>
#include <map>
#include <random>
#include <vector>

#include "random_points.hpp"
#include "tessera/delaunay.hpp"

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;

std::vector<double> random_points(std::size_t n, int dim, std::uint64_t seed) { return uniform_points(n, dim, seed); }

tessera::Delaunay triangulate(const std::vector<double>& p, int dim, int threads = 2) {
  tessera::DelaunayOptions o;
  o.dim = dim;
  o.threads = threads;
  return tessera::delaunay(p, dim, {}, o);
}

// The oracle: every facet (sorted ids) with its (simplex, slot) records in
// ascending simplex order; consecutive records pair up, as documented.
std::vector<std::int32_t> brute_force_neighbors(const tessera::Delaunay& dt) {
  const std::size_t w = static_cast<std::size_t>(dt.dim + 1);
  std::map<std::vector<std::int32_t>, std::vector<std::pair<std::int32_t, std::size_t>>> facets;
  for (std::size_t s = 0; s < dt.n_simplices(); ++s)
    for (std::size_t k = 0; k < w; ++k) {
      std::vector<std::int32_t> f;
      for (std::size_t j = 0; j < w; ++j)
        if (j != k) f.push_back(dt.simplices[s * w + j]);
      std::sort(f.begin(), f.end());
      facets[f].emplace_back(static_cast<std::int32_t>(s), k);
    }
  std::vector<std::int32_t> nb(dt.n_simplices() * w, -1);
  for (const auto& [f, recs] : facets)
    for (std::size_t i = 0; i + 1 < recs.size(); i += 2) {
      nb[static_cast<std::size_t>(recs[i].first) * w + recs[i].second] = recs[i + 1].first;
      nb[static_cast<std::size_t>(recs[i + 1].first) * w + recs[i + 1].second] = recs[i].first;
    }
  return nb;
}

// Copies of dt's rows with `rows` appended and row `drop` (if any) left out.
tessera::Delaunay with_rows(const tessera::Delaunay& dt, const std::vector<std::int32_t>& rows, std::ptrdiff_t drop = -1,
                            std::ptrdiff_t drop2 = -1) {
  tessera::Delaunay out;
  out.dim = dt.dim;
  out.n_points = dt.n_points;
  out.bounds = dt.bounds;
  out.threads_used = dt.threads_used;
  out.hull_completed = dt.hull_completed;  // validate checks the hull of hull-complete results only
  const std::size_t w = static_cast<std::size_t>(dt.dim + 1);
  std::vector<std::int32_t> all;
  for (std::size_t s = 0; s < dt.n_simplices(); ++s)
    if (static_cast<std::ptrdiff_t>(s) != drop && static_cast<std::ptrdiff_t>(s) != drop2)
      all.insert(all.end(), dt.simplices.begin() + static_cast<std::ptrdiff_t>(s * w),
                 dt.simplices.begin() + static_cast<std::ptrdiff_t>((s + 1) * w));
  all.insert(all.end(), rows.begin(), rows.end());
  out.simplices.resize(all.size());
  std::copy(all.begin(), all.end(), out.simplices.begin());
  return out;
}

K::Point_3 point3(const std::vector<double>& p, std::int32_t id) {
  const std::size_t i = static_cast<std::size_t>(id) * 3;
  return {p[i], p[i + 1], p[i + 2]};
}

TEST(SimplexNeighbors, EqualBruteForceIn2DAnd3D) {
  for (int dim : {2, 3}) {
    const auto p = random_points(dim == 2 ? 3000 : 1500, dim, 7 + static_cast<std::uint64_t>(dim));
    const tessera::Delaunay dt = triangulate(p, dim);
    EXPECT_EQ(tessera::simplex_neighbors(dt), brute_force_neighbors(dt)) << dim << "D";
    EXPECT_EQ(tessera::simplex_neighbors(triangulate(p, dim, 1)), tessera::simplex_neighbors(dt)) << "1 vs 2 threads";
  }
}

TEST(SimplexNeighbors, NonConformingRowsPairAsDocumented) {
  // Repeated simplices (three or four records on one facet) and rows out of
  // the usual order: the grouping must not rely on the rows' layout.
  const auto p = random_points(400, 3, 3);
  const tessera::Delaunay dt = triangulate(p, 3);
  std::vector<std::int32_t> extra;
  for (std::size_t s : {5u, 17u, 17u, 200u}) extra.insert(extra.end(), dt.simplices.begin() + s * 4, dt.simplices.begin() + s * 4 + 4);
  const std::size_t last = dt.n_simplices() - 1;
  extra.insert(extra.end(), dt.simplices.begin() + last * 4, dt.simplices.begin() + last * 4 + 4);
  const tessera::Delaunay bad = with_rows(dt, extra, 0);
  EXPECT_EQ(tessera::simplex_neighbors(bad), brute_force_neighbors(bad));
}

TEST(ValidateDelaunay, ReportsEachKindOfCorruption) {
  const auto p = random_points(2000, 3, 11);
  const tessera::Delaunay dt = triangulate(p, 3);
  const tessera::DelaunayReport good = tessera::validate(dt, p, {});
  ASSERT_TRUE(good.ok);
  const auto nb = tessera::simplex_neighbors(dt);
  auto row = [&](std::size_t s) { return std::vector<std::int32_t>(dt.simplices.begin() + static_cast<std::ptrdiff_t>(s * 4),
                                                                   dt.simplices.begin() + static_cast<std::ptrdiff_t>(s * 4 + 4)); };
  // An interior simplex (no hull facet).
  std::size_t inner = 0;
  while (std::count(nb.begin() + static_cast<std::ptrdiff_t>(inner * 4), nb.begin() + static_cast<std::ptrdiff_t>(inner * 4 + 4), -1) != 0) ++inner;

  {  // Removed: a cavity, whose four facets are boundary with reflex ridges.
    const auto r = tessera::validate(with_rows(dt, {}, static_cast<std::ptrdiff_t>(inner)), p, {});
    EXPECT_FALSE(r.ok);
    EXPECT_EQ(r.boundary_facets, good.boundary_facets + 4);
    EXPECT_GT(r.nonconvex_boundary, 0u);
    EXPECT_EQ(r.nonmanifold_facets, 0u);
  }
  {  // Listed twice: each of its facets in three simplices, or twice on one side.
    const auto r = tessera::validate(with_rows(dt, row(inner)), p, {});
    EXPECT_FALSE(r.ok);
    EXPECT_GE(r.nonmanifold_facets, 4u);
  }
  {  // Inverted.
    auto flipped = row(inner);
    std::swap(flipped[2], flipped[3]);
    const auto r = tessera::validate(with_rows(dt, flipped, static_cast<std::ptrdiff_t>(inner)), p, {});
    EXPECT_FALSE(r.ok);
    EXPECT_EQ(r.flat_or_inverted, 1u);
  }
  {  // A 2-3 flip of an interior facet whose union is convex: still a
     // conforming triangulation of the hull, but not Delaunay.
    bool flipped = false;
    for (std::size_t s = 0; s < dt.n_simplices() && !flipped; ++s)
      for (std::size_t k = 0; k < 4 && !flipped; ++k) {
        const std::int32_t t = nb[s * 4 + k];
        if (t < 0) continue;
        const auto a = row(s), b = row(static_cast<std::size_t>(t));
        const std::int32_t d = a[k];
        const std::int32_t e = *std::find_if(b.begin(), b.end(), [&](std::int32_t id) { return std::find(a.begin(), a.end(), id) == a.end(); });
        std::vector<std::int32_t> f;
        for (std::size_t j = 0; j < 4; ++j)
          if (j != k) f.push_back(a[j]);
        // de crosses the triangle f: the three tetrahedra (d, e, f_i, f_i+1) agree in orientation.
        std::array<CGAL::Orientation, 3> o;
        for (std::size_t i = 0; i < 3; ++i)
          o[i] = CGAL::orientation(point3(p, d), point3(p, e), point3(p, f[i]), point3(p, f[(i + 1) % 3]));
        if (o[0] == CGAL::COPLANAR || o[0] != o[1] || o[1] != o[2]) continue;
        std::vector<std::int32_t> three;
        for (std::size_t i = 0; i < 3; ++i) {
          std::array<std::int32_t, 4> r{d, e, f[i], f[(i + 1) % 3]};
          if (o[i] == CGAL::NEGATIVE) std::swap(r[2], r[3]);
          three.insert(three.end(), r.begin(), r.end());
        }
        const auto r = tessera::validate(with_rows(dt, three, static_cast<std::ptrdiff_t>(s), t), p, {});
        EXPECT_FALSE(r.ok);
        EXPECT_GT(r.local_delaunay_violations, 0u);
        EXPECT_EQ(r.nonmanifold_facets, 0u);
        EXPECT_EQ(r.flat_or_inverted, 0u);
        EXPECT_EQ(r.boundary_facets, good.boundary_facets);
        flipped = true;
      }
    EXPECT_TRUE(flipped) << "no flippable facet found";
  }
  {  // A point id past the input: an error, not a read out of bounds.
    auto wrong = row(inner);
    wrong[1] = static_cast<std::int32_t>(dt.n_points);
    const tessera::Delaunay bad = with_rows(dt, wrong);
    EXPECT_THROW(tessera::simplex_neighbors(bad), tessera::InputError);
    EXPECT_THROW(tessera::validate(bad, p, {}), tessera::InputError);
    // Coordinates or labels that do not match the triangulation's points.
    const std::vector<double> fewer(p.begin(), p.end() - 3);
    EXPECT_THROW(tessera::validate(dt, fewer, {}), tessera::InputError);
    const std::vector<std::int32_t> labels(dt.n_points - 1, 0);
    EXPECT_THROW(tessera::validate(dt, p, labels), tessera::InputError);
  }
}

}  // namespace
