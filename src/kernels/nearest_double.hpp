// Exact numbers rounded to the nearest double, as the exact cell measure
// gives its volumes and centroids (exact_vertices.cpp). Internal to
// src/kernels; declared here so that tests can hold them to an oracle.
#pragma once

#include <gmp.h>

namespace tessera::kernels {

/// The double nearest to sign (m + f) 2^-k, ties to even, where m >= 0 is an
/// integer of at least 54 bits and f is 0 (sticky false) or lies strictly
/// between 0 and 1 (sticky true: a quotient's nonzero remainder). Rounded
/// once, into the subnormals below DBL_MIN too; an infinity from 2^1024 on,
/// as IEEE rounding gives; a zero of the sign below half the smallest
/// subnormal. `q`, `r` are scratch integers (not m).
double nearest_double(mpz_srcptr m, bool sticky, long k, int sign, mpz_ptr q, mpz_ptr r);

/// q rounded to the nearest double, as nearest_double. Modifies q.
double rational_to_double(mpq_ptr q);

}  // namespace tessera::kernels
