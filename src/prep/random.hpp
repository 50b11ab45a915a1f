// Private: a counter-based random generator for the point-preparation tools
// (joggle, fill, the image sampler). Not installed.
//
// Every random draw is a pure function of (seed, key, counter): a stream is
// opened for one item (a point id, a bin, a voxel) and yields the same
// numbers whichever thread asks and in whatever order the items are visited,
// so results never depend on the thread count or on which items are
// processed. The generator is SplitMix64 (Steele, Lea & Flood, "Fast
// splittable pseudorandom number generators", OOPSLA 2014) run from a state
// derived by hashing (seed, key, stream) with the same finaliser; it passes
// BigCrush per stream and is more than enough for jitter and sampling.
#pragma once

#include <cstdint>

namespace tessera::detail {

/// SplitMix64's output function: a bijective 64-bit mixer.
constexpr std::uint64_t mix64(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

/// A stream of random numbers owned by one item.
///   RandomStream r(seed, point_id);        // the point's stream
///   RandomStream r(seed, voxel, kSampler); // another purpose, independent
/// `stream` separates uses of the same (seed, key) by different tools.
class RandomStream {
 public:
  static constexpr std::uint64_t kGamma = 0x9e3779b97f4a7c15ULL;  ///< golden-ratio increment

  constexpr RandomStream(std::uint64_t seed, std::uint64_t key, std::uint64_t stream = 0)
      : state_(mix64(mix64(seed ^ 0x6a09e667f3bcc909ULL) ^ (key * kGamma) ^ mix64(stream + 0x3c6ef372fe94f82bULL))) {}

  /// Next 64 random bits.
  constexpr std::uint64_t next() {
    state_ += kGamma;
    return mix64(state_);
  }

  /// Uniform double in [0, 1), 53 random bits (every value a multiple of 2^-53).
  constexpr double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }

  /// Uniform double in [-1, 1) (multiples of 2^-52).
  constexpr double symmetric() { return static_cast<double>(next() >> 11) * 0x1.0p-52 - 1.0; }

  /// Uniform in the unit `dim`-ball (dim 1..3) by rejection from the cube
  /// [-1,1)^dim; writes dim values with x·x < 1. Expected tries: 1 (dim 1),
  /// 1.27 (2), 1.91 (3).
  void in_unit_ball(int dim, double* out) {
    for (;;) {
      double r2 = 0;
      for (int d = 0; d < dim; ++d) {
        out[d] = symmetric();
        r2 += out[d] * out[d];
      }
      if (r2 < 1.0) return;
    }
  }

 private:
  std::uint64_t state_;
};

/// Purpose tags for RandomStream's `stream` argument, so that the tools never
/// share draws when given the same seed and key.
enum : std::uint64_t {
  kStreamJoggle = 1,
  kStreamFillJoggle = 2,
  kStreamSamplerKeep = 3,
  kStreamSamplerJoggle = 4,
};

}  // namespace tessera::detail
