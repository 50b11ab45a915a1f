// Points with a NaN or infinite coordinate (an organized point cloud's
// missing returns) under ignore_outside_points: set aside like points
// outside the bounds, their ids kept; the cells and the triangulation are
// those of the finite points alone, with the same domain.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "cells/helpers.hpp"
#include "tessera/cells.hpp"
#include "tessera/delaunay.hpp"

namespace {

using namespace cells_test;

constexpr double nan_ = std::numeric_limits<double>::quiet_NaN();
constexpr double inf_ = std::numeric_limits<double>::infinity();

struct Split {
  std::vector<double> all;            // with the non-finite points
  std::vector<double> finite;         // without them
  std::vector<std::int32_t> id_of;    // finite index -> index in all
  std::vector<std::int32_t> dropped;  // indices in all
};

Split with_missing(std::size_t n, int dim, std::uint64_t seed) {
  Split s;
  s.all = random_points(n, dim, seed);
  const auto d = static_cast<std::size_t>(dim);
  for (std::size_t i = 0; i < n; ++i) {
    const bool miss = i % 7 == 3 || i == 0 || i + 1 == n;
    if (miss) {
      s.all[i * d + i % d] = (i % 2) ? nan_ : -inf_;  // one coordinate is enough
      s.dropped.push_back(static_cast<std::int32_t>(i));
    } else {
      s.finite.insert(s.finite.end(), s.all.begin() + static_cast<std::ptrdiff_t>(i * d),
                      s.all.begin() + static_cast<std::ptrdiff_t>((i + 1) * d));
      s.id_of.push_back(static_cast<std::int32_t>(i));
    }
  }
  return s;
}

void expect_same_as_finite(const Split& s, int dim, std::optional<tessera::Bounds> bounds) {
  // By the search, whose clips meet the candidates in the same order either
  // way (bins, then ids, whose order the set-aside keeps): the same doubles.
  // (The insertion's order follows the ids themselves, so there the
  // measures may differ in their last bits; the topology cannot.)
  tessera::VoronoiOptions o = options(dim, bounds);
  o.cell_method = tessera::CellMethod::search;
  tessera::VoronoiOptions of = o;
  o.ignore_outside_points = true;
  const tessera::Cells a = tessera::voronoi(std::span<const double>(s.all), dim, {}, o);
  const tessera::Cells f = tessera::voronoi(std::span<const double>(s.finite), dim, {}, of);
  EXPECT_EQ(a.ignored_outside_bounds, s.dropped);
  ASSERT_EQ(a.n_cells(), f.n_cells());
  for (int k = 0; k < dim; ++k) {
    EXPECT_EQ(a.bounds.lo[k], f.bounds.lo[k]);
    EXPECT_EQ(a.bounds.hi[k], f.bounds.hi[k]);
  }
  for (std::size_t c = 0; c < f.n_cells(); ++c) {
    EXPECT_EQ(a.generator[c], s.id_of[static_cast<std::size_t>(f.generator[c])]) << "cell " << c;
    EXPECT_EQ(a.volume[c], f.volume[c]) << "cell " << c;
    std::vector<std::int32_t> mapped;
    for (const std::int32_t j : neighbours_of(f, c)) mapped.push_back(s.id_of[static_cast<std::size_t>(j)]);
    EXPECT_EQ(neighbours_of(a, c), mapped) << "cell " << c;
  }
  for (const std::int32_t i : s.dropped) EXPECT_LT(a.cell_of[static_cast<std::size_t>(i)], 0);

  tessera::DelaunayOptions dop;
  static_cast<tessera::VoronoiOptions&>(dop) = o;
  const tessera::Delaunay da = tessera::delaunay(std::span<const double>(s.all), dim, {}, dop);
  tessera::DelaunayOptions fop;
  static_cast<tessera::VoronoiOptions&>(fop) = of;
  const tessera::Delaunay df = tessera::delaunay(std::span<const double>(s.finite), dim, {}, fop);
  ASSERT_EQ(da.simplices.size(), df.simplices.size());
  std::vector<std::int32_t> mapped(df.simplices.begin(), df.simplices.end());
  for (auto& v : mapped) v = s.id_of[static_cast<std::size_t>(v)];
  EXPECT_TRUE(std::equal(mapped.begin(), mapped.end(), da.simplices.begin()));
  const tessera::DelaunayReport r = tessera::validate(da, s.all, {});
  EXPECT_TRUE(r.ok);
  for (const auto& m : r.messages) ADD_FAILURE() << m;
}

TEST(NonFinite, SetAsideByIgnoreOutside) {
  for (const int dim : {2, 3}) {
    SCOPED_TRACE(dim);
    const Split s = with_missing(500, dim, 73 + static_cast<std::uint64_t>(dim));
    expect_same_as_finite(s, dim, std::nullopt);  // the default domain, of the finite points
    expect_same_as_finite(s, dim, make_bounds({-1, -1, -1}, {2, 2, 2}));
  }
}

TEST(NonFinite, RefusedOtherwise) {
  const Split s = with_missing(50, 3, 5);
  try {
    run(s.all, 3);
    ADD_FAILURE() << "no error";
  } catch (const tessera::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("point 0 has a NaN or infinite coordinate"), std::string::npos) << e.what();
  }
  tessera::VoronoiOptions o = options(3);
  o.ignore_outside_points = true;
  std::vector<double> none(30, nan_);
  EXPECT_THROW(tessera::voronoi(std::span<const double>(none), 3, {}, o), tessera::InputError);
}

}  // namespace
