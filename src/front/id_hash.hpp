// A point's hash in [0, 2^64): splitmix64's finaliser over its id. The
// pseudo-random choices of the Delaunay front end (the pilot's sample, the
// skipped cells, insertion's BRIO rounds) all draw from it, so they depend on
// the ids only, never on the thread count or the run.
#pragma once

#include <cstdint>

namespace tessera::front {

inline std::uint64_t id_hash(std::int32_t id) {
  std::uint64_t z = static_cast<std::uint64_t>(id) + 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

}  // namespace tessera::front
