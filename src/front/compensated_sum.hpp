// Neumaier's compensated sum (an improved Kahan sum): the rounding error of
// each addition, recovered exactly, is carried beside the running sum, so
// adding in a fixed order gives the same, nearly exact, result on any
// thread count (callers sum fixed blocks, then the blocks in order).
#pragma once

#include <cmath>

namespace tessera::front {

struct CompensatedSum {
  double sum = 0, carry = 0;
  void add(double x) {
    const double t = sum + x;
    carry += std::fabs(sum) >= std::fabs(x) ? (sum - t) + x : (x - t) + sum;
    sum = t;
  }
  double value() const { return sum + carry; }
};

}  // namespace tessera::front
