// Hostile inputs shared by the cells and Delaunay tests.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

/// n points of small-integer coordinates (multiples of 16 below 464, with
/// many exact ties, as in the fuzz's failing inputs), a fifth of the
/// coordinates replaced by zero and a fifth by +-1..4 times the smallest
/// subnormal: points a subnormal distance off the lines and planes their
/// neighbours span. Fixed by the seed.
inline std::vector<double> subnormal_offset_points(std::size_t n, int dim, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<double> p(n * static_cast<std::size_t>(dim));
  for (double& x : p) {
    const unsigned r = static_cast<unsigned>(rng() % 10);
    if (r < 2) x = 0;
    else if (r < 4) x = (rng() % 2 ? 1.0 : -1.0) * static_cast<double>(1 + rng() % 4) * 0x1p-1074;
    else x = 16.0 * static_cast<double>(rng() % 29);
  }
  return p;
}
