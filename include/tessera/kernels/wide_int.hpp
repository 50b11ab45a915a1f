// Fixed-width signed integers of N 64-bit limbs, for the exact predicate's
// middle stage (WidePredicate in exact_predicates.hpp).
//
// Values are two's complement. Products are exact (multiply: A + B limbs
// from A and B). Sums and differences are modulo 2^(64N), so exact whenever
// the true result fits in N limbs as a signed value: the caller proves that
// by a bound on its operands (the predicate's comments carry them); nothing
// here checks for overflow.
//
// Written here rather than taken from GMP: the predicate's operands have a
// known, small size, and GMP's general integers cost their dispatch, their
// size bookkeeping and the conversion of each double (mpz_set_d) on every
// call, which was most of a call's ~1 µs on exactly cospherical points with
// full mantissas (a lattice of spacing 0.1).
#pragma once

#include <cstdint>

namespace tessera::kernels {

template <int N>
struct WideInt {
  static_assert(N >= 1);
  std::uint64_t limb[N];  // least significant first

  static WideInt from(__int128 x) {
    static_assert(N >= 2);
    WideInt r;
    r.limb[0] = static_cast<std::uint64_t>(x);
    r.limb[1] = static_cast<std::uint64_t>(static_cast<unsigned __int128>(x) >> 64);
    const std::uint64_t ext = x < 0 ? ~std::uint64_t{0} : 0;
    for (int k = 2; k < N; ++k) r.limb[k] = ext;
    return r;
  }

  static WideInt from_int64(std::int64_t x) {
    WideInt r;
    r.limb[0] = static_cast<std::uint64_t>(x);
    for (int k = 1; k < N; ++k) r.limb[k] = x < 0 ? ~std::uint64_t{0} : 0;
    return r;
  }

  int sign() const {
    if (static_cast<std::int64_t>(limb[N - 1]) < 0) return -1;
    for (int k = 0; k < N; ++k)
      if (limb[k] != 0) return 1;
    return 0;
  }

  friend WideInt operator+(const WideInt& a, const WideInt& b) {
    WideInt r;
    unsigned carry = 0;
    for (int k = 0; k < N; ++k) {
      const unsigned __int128 s = static_cast<unsigned __int128>(a.limb[k]) + b.limb[k] + carry;
      r.limb[k] = static_cast<std::uint64_t>(s);
      carry = static_cast<unsigned>(s >> 64);
    }
    return r;
  }

  friend WideInt operator-(const WideInt& a, const WideInt& b) {
    WideInt r;
    unsigned borrow = 0;
    for (int k = 0; k < N; ++k) {
      const std::uint64_t d = a.limb[k] - b.limb[k];
      r.limb[k] = d - borrow;
      borrow = static_cast<unsigned>(a.limb[k] < b.limb[k]) | static_cast<unsigned>(d < borrow);
    }
    return r;
  }

  bool negative() const { return static_cast<std::int64_t>(limb[N - 1]) < 0; }

  /// The same value in M <= N limbs: its low limbs, exact when the value
  /// fits M limbs as a signed value (the caller's bound).
  template <int M>
  WideInt<M> narrow() const {
    static_assert(M <= N);
    WideInt<M> r;
    for (int k = 0; k < M; ++k) r.limb[k] = limb[k];
    return r;
  }

  /// The same value in M >= N limbs (sign-extended).
  template <int M>
  WideInt<M> widen() const {
    static_assert(M >= N);
    WideInt<M> r;
    for (int k = 0; k < N; ++k) r.limb[k] = limb[k];
    for (int k = N; k < M; ++k) r.limb[k] = negative() ? ~std::uint64_t{0} : 0;
    return r;
  }
};

/// a * b exactly, in A + B limbs (always fits): A * B word products (the
/// predicate's mixed sizes, a 1-limb times a 2-limb and a 2-limb times a
/// 3-limb, need 2 and 6). The limbs are multiplied as unsigned; a negative
/// operand then stands for itself plus 2^(64 size), so the other operand
/// shifted by that much is subtracted. Branch-free: the predicate's signs are
/// random, and a branch on them was mispredicted half the time.
template <int A, int B>
[[gnu::always_inline]] inline WideInt<A + B> multiply(const WideInt<A>& a, const WideInt<B>& b) {
  WideInt<A + B> r;
  for (int k = 0; k < A + B; ++k) r.limb[k] = 0;
  for (int x = 0; x < A; ++x) {
    std::uint64_t carry = 0;
    for (int y = 0; y < B; ++y) {
      const unsigned __int128 t = static_cast<unsigned __int128>(a.limb[x]) * b.limb[y] + r.limb[x + y] + carry;
      r.limb[x + y] = static_cast<std::uint64_t>(t);
      carry = static_cast<std::uint64_t>(t >> 64);
    }
    r.limb[x + B] = carry;
  }
  // r -= (a < 0 ? b : 0) << 64A, and (b < 0 ? a : 0) << 64B, modulo 2^(64(A+B)).
  const std::uint64_t ma = a.negative() ? ~std::uint64_t{0} : 0, mb = b.negative() ? ~std::uint64_t{0} : 0;
  auto subtract_at = [&r](int at, const std::uint64_t* v, int n, std::uint64_t mask) {
    unsigned borrow = 0;
    for (int k = 0; at + k < A + B; ++k) {
      const std::uint64_t s = k < n ? v[k] & mask : 0;
      const std::uint64_t d = r.limb[at + k] - s;
      const unsigned out = static_cast<unsigned>(r.limb[at + k] < s) | static_cast<unsigned>(d < borrow);
      r.limb[at + k] = d - borrow;
      borrow = out;
    }
  };
  subtract_at(A, b.limb, B, ma);
  subtract_at(B, a.limb, A, mb);
  return r;
}

}  // namespace tessera::kernels
