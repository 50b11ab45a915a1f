#!/usr/bin/env bash
# Install the built project into a scratch prefix, then configure, build and run
# a consumer that uses find_package(tessera).  Args: BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1 src=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cmake --install "$build" --prefix "$work/prefix" >/dev/null
cmake -S "$src/tests/package" -B "$work/consumer" -DCMAKE_PREFIX_PATH="$work/prefix" >/dev/null
cmake --build "$work/consumer" >/dev/null
"$work/consumer/consumer"
# Without gmp.pc the package is not found, quietly (it was a configure error).
PKG_CONFIG_LIBDIR=/nonexistent PKG_CONFIG_PATH= cmake -S "$src/tests/package/quiet" -B "$work/quiet" \
  -DCMAKE_PREFIX_PATH="$work/prefix" >/dev/null
