// Fixed-width signed integers of N 64-bit limbs, for the exact predicate's
// middle stage (WidePredicate in exact_predicates.hpp).
//
// Arithmetic is modulo 2^(64N) in two's complement: sums, differences and
// truncated products of sign-extended operands are the true results modulo
// 2^(64N), so they are exact whenever the true result fits in N limbs as a
// signed value. The caller proves that by a bound on its operands (the
// predicate's comments carry them); nothing here checks for overflow.
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
  static_assert(N >= 2);
  std::uint64_t limb[N];  // least significant first

  static WideInt from(__int128 x) {
    WideInt r;
    r.limb[0] = static_cast<std::uint64_t>(x);
    r.limb[1] = static_cast<std::uint64_t>(static_cast<unsigned __int128>(x) >> 64);
    const std::uint64_t ext = x < 0 ? ~std::uint64_t{0} : 0;
    for (int k = 2; k < N; ++k) r.limb[k] = ext;
    return r;
  }

  /// The same value in M >= N limbs (sign-extended).
  template <int M>
  WideInt<M> widen() const {
    static_assert(M >= N);
    WideInt<M> r;
    for (int k = 0; k < N; ++k) r.limb[k] = limb[k];
    const std::uint64_t ext = static_cast<std::int64_t>(limb[N - 1]) < 0 ? ~std::uint64_t{0} : 0;
    for (int k = N; k < M; ++k) r.limb[k] = ext;
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

  /// The product modulo 2^(64N) (schoolbook, the limbs above N dropped).
  friend WideInt operator*(const WideInt& a, const WideInt& b) {
    WideInt r;
    for (int k = 0; k < N; ++k) r.limb[k] = 0;
    for (int x = 0; x < N; ++x) {
      std::uint64_t carry = 0;
      for (int y = 0; x + y < N; ++y) {
        const unsigned __int128 t =
            static_cast<unsigned __int128>(a.limb[x]) * b.limb[y] + r.limb[x + y] + carry;
        r.limb[x + y] = static_cast<std::uint64_t>(t);
        carry = static_cast<std::uint64_t>(t >> 64);
      }
    }
    return r;
  }
};

}  // namespace tessera::kernels
