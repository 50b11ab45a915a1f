// FacetTable, hull completion's facet counts: counts per key against a
// std::map, through many rehashes (the table starts small on purpose).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <map>
#include <random>

#include "front/facet_table.hpp"

TEST(FacetTable, CountsMatchAMapThroughGrowth) {
  tessera::front::FacetTable<3> table(1);
  std::map<std::array<std::int32_t, 3>, int> want;
  std::mt19937 rng(5);
  std::uniform_int_distribution<std::int32_t> id(0, 400);
  for (int k = 0; k < 20000; ++k) {
    std::array<std::int32_t, 3> f{id(rng), id(rng), id(rng)};
    std::sort(f.begin(), f.end());
    EXPECT_EQ(table.bump(f), ++want[f]);
  }
  for (const auto& [f, c] : want) EXPECT_EQ(table.count(f), c);
  EXPECT_EQ(table.count({401, 402, 403}), 0);
  // Keys differing in one id only, and a 2D table.
  tessera::front::FacetTable<2> t2;
  for (std::int32_t a = 0; a < 100; ++a)
    for (std::int32_t b = a + 1; b < 100; ++b) EXPECT_EQ(t2.bump({a, b}), 1);
  EXPECT_EQ(t2.bump({3, 4}), 2);
  EXPECT_EQ(t2.count({4, 5}), 1);
  EXPECT_EQ(t2.count({5, 4}), 0);
}
