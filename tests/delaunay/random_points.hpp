// Uniform random points for the Delaunay tests: n points of dim coordinates
// in [lo, hi), fixed by the seed.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

inline std::vector<double> uniform_points(std::size_t n, int dim, std::uint64_t seed, double lo = 0, double hi = 1) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(lo, hi);
  std::vector<double> p(n * static_cast<std::size_t>(dim));
  for (double& x : p) x = u(rng);
  return p;
}
