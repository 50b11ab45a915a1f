// Strict checks on the words given to numeric options.
//
// CLI11 converts an option's word itself, and on its own it reads an empty
// word as 0, wraps "-1" into an unsigned seed, accepts a seed past 2^64 as
// some other number, and its NonNegativeNumber check prints DBL_MAX in full
// when it fails. These validators run before CLI11's conversion and reject
// such words with one short line: "--threads: expected a finite number >= 0,
// got '-2'".
#pragma once

#include <CLI/CLI.hpp>

namespace tessera::cli {

/// A finite number >= 0 (the range check; the word's syntax for the option's
/// type is checked by require_number_syntax).
extern const CLI::Validator NonNegative;
/// A finite number > 0.
extern const CLI::Validator Positive;

/// Give every option of `app` and its subcommands whose value is a number
/// (CLI11 type INT, UINT or FLOAT) a syntax check: FLOAT one whole number
/// (whole_number; "inf" and "nan" are left to the range checks and the
/// library), INT an optional sign and digits, UINT digits without a minus,
/// both within 64 bits. Call once, after every option is declared.
void require_number_syntax(CLI::App& app);

}  // namespace tessera::cli
