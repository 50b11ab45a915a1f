// Positions of copies of one vertex in a periodic face set (VertexCopies,
// include/tessera/faces.hpp): lattice translations in the net's frame.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>

namespace tessera::front {

/// The lattice translation by `shift` (dim integers): sum of shift[a] times
/// lattice vector a, the vectors scaled by 2^k (the net's frame).
inline void lattice_translation(const std::array<std::array<double, 3>, 3>& lattice, int dim, const std::int32_t* shift,
                                int k, double* out) {
  for (int a = 0; a < dim; ++a) {
    double x = 0;
    for (int b = 0; b < dim; ++b) x += shift[b] * std::ldexp(lattice[static_cast<std::size_t>(b)][static_cast<std::size_t>(a)], k);
    out[a] = x;
  }
}

}  // namespace tessera::front
