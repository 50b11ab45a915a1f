#!/bin/bash
# Spherical Voronoi cells (tessera bench sphere: cells, vertices, areas,
# centroids, neighbours) against CGAL's Delaunay triangulation on the sphere
# (its triangulation and dual vertices: less than tessera computes) and
# scipy's SphericalVoronoi (construction, sorted regions, areas), on the
# same unit vectors, in one run. Writes JSON lines and a Markdown table
# (summarize.py).
#
# usage: bench/sphere/run.sh [BUILD_DIR] [N...]
#   env: REPEAT (default 3), SCIPY_MAX (largest N given to scipy, default
#        1e6), DATA (default bench/data, git-ignored), OUT (default
#        bench/sphere/results/sphere.jsonl)
# Needs Debian's libcgal-dev (cgal_sphere.cpp is compiled here) and python3-scipy.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
build=${1:-build}
shift || true
sizes=${*:-"1e4 1e5 1e6"}
repeat=${REPEAT:-3}
scipy_max=${SCIPY_MAX:-1e6}
data=${DATA:-$here/../data}
py=/usr/bin/python3
mkdir -p "$data" "$here/results"
out=${OUT:-$here/results/sphere.jsonl}
: > "$out"
note() { echo "sphere: $*" >&2; }
[[ -x $build/tessera ]] || { note "error: no $build/tessera (build it first)"; exit 1; }
cgal=$build/cgal_sphere
g++ -O2 -DNDEBUG -std=c++20 -o "$cgal" "$here/cgal_sphere.cpp" -lgmp -lmpfr
echo "# $(date -u +%FT%TZ) $(uname -m) $(nproc) cores; tessera $(git -C "$here" rev-parse --short HEAD 2>/dev/null || echo '?')" >&2
run() {
  local label=$1 i; shift
  for ((i = 0; i < repeat; i++)); do
    "$@" 2>/dev/null | grep '^{' | sed "s/^{/{\"input\":\"$label\",/" >>"$out" || { note "FAILED: $*"; return 0; }
  done
}
for n in $sizes; do
  p=$data/sphere_uniform_$n.npy
  [[ -f $p ]] || $py -c "
import numpy as np, sys
n = int(float(sys.argv[1])); v = np.random.default_rng(20261202).normal(size=(n, 3))
np.save(sys.argv[2], v / np.linalg.norm(v, axis=1)[:, None])" "$n" "$p"
  for t in 1 2; do
    note "$n: tessera, $t thread(s)"
    run uniform "$build/tessera" bench sphere "$p" --threads $t --repeat 1
  done
  note "$n: CGAL"
  run uniform "$cgal" "$p"
  if $py -c "import sys; sys.exit(0 if float('$n') <= float('$scipy_max') else 1)"; then
    note "$n: scipy"
    run uniform "$py" "$here/scipy_sphere.py" "$p"
  fi
done
$py "$here/summarize.py" "$out"
