// Uniform random points for the Delaunay tests: n points of dim coordinates
// in [lo, hi), fixed by the seed.
#pragma once

#include <cmath>
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

/// n points of the height field z = 0.1 sin(6x) cos(5y) over the unit square
/// (x, y uniform): surface samples, whose Voronoi cells are needles.
inline std::vector<double> height_field(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u;
  std::vector<double> p;
  p.reserve(3 * n);
  for (std::size_t i = 0; i < n; ++i) {
    const double x = u(rng), y = u(rng);
    p.insert(p.end(), {x, y, 0.1 * std::sin(6 * x) * std::cos(5 * y)});
  }
  return p;
}

/// The unit cube's 8 corners, per_face random points on each of its six
/// faces (hull facets with many co-planar points) and `inside` random
/// interior points.
inline std::vector<double> cube_face_points(int per_face, int inside, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u;
  std::vector<double> p;
  for (int c = 0; c < 8; ++c) p.insert(p.end(), {double(c & 1), double((c >> 1) & 1), double((c >> 2) & 1)});
  for (int face = 0; face < 6; ++face)
    for (int i = 0; i < per_face; ++i) {
      double x[3] = {u(rng), u(rng), u(rng)};
      x[face / 2] = face % 2;
      p.insert(p.end(), {x[0], x[1], x[2]});
    }
  for (int i = 0; i < inside; ++i) p.insert(p.end(), {u(rng), u(rng), u(rng)});
  return p;
}
