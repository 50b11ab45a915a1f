// FacetTable, hull completion's facet counts: counts per key against a
// std::map, through many rehashes (the table starts small on purpose).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <map>
#include <random>
#include <vector>

#include <tbb/task_arena.h>

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

// bump_all: the counts after a batch equal the map's after the same bumps
// one by one, on top of earlier single bumps, on one thread and on two
// (shards are filled in parallel), through the shards' growth.
TEST(FacetTable, BumpAllMatchesSingleBumps) {
  for (const int threads : {1, 2}) {
    tessera::front::FacetTable<3> table(4);
    std::map<std::array<std::int32_t, 3>, int> want;
    std::mt19937 rng(11);
    std::uniform_int_distribution<std::int32_t> id(0, 60);
    auto facet = [&] {
      std::array<std::int32_t, 3> f{id(rng), id(rng), id(rng)};
      std::sort(f.begin(), f.end());
      return f;
    };
    for (int k = 0; k < 500; ++k) {
      const auto f = facet();
      EXPECT_EQ(table.bump(f), ++want[f]);
    }
    for (int round = 0; round < 3; ++round) {
      std::vector<std::array<std::int32_t, 3>> batch(30000);
      for (auto& f : batch) {
        f = facet();
        ++want[f];
      }
      std::vector<std::uint8_t> counts;
      tbb::task_arena(threads).execute(
          [&] { table.bump_all(batch.size(), [&](std::size_t i) { return batch[i]; }, counts); });
      ASSERT_EQ(counts.size(), batch.size());
      for (std::size_t i = 0; i < batch.size(); ++i) EXPECT_EQ(counts[i], std::min(255, want[batch[i]])) << i;
    }
    for (const auto& [f, c] : want) EXPECT_EQ(table.count(f), c);
  }
}
