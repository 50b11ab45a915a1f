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
#        1e6), GRIDS (lon/lat grid steps in degrees, cell centres, default
#        "1 0.25": 64,800 and 1,036,800 points), DATA (default bench/data,
#        git-ignored), OUT (default bench/sphere/results/sphere.jsonl)
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
# bench_all LABEL POINTS N: every tool on one input.
bench_all() {
  local label=$1 p=$2 n=$3 t
  for t in 1 2; do
    note "$label $n: tessera, $t thread(s)"
    run "$label" "$build/tessera" bench sphere "$p" --threads $t --repeat 1
  done
  note "$label $n: CGAL"
  run "$label" "$cgal" "$p"
  if $py -c "import sys; sys.exit(0 if float('$n') <= float('$scipy_max') else 1)"; then
    note "$label $n: scipy"
    run "$label" "$py" "$here/scipy_sphere.py" "$p"
  fi
}
for n in $sizes; do
  p=$data/sphere_uniform_$n.npy
  [[ -f $p ]] || $py -c "
import numpy as np, sys
n = int(float(sys.argv[1])); v = np.random.default_rng(20261202).normal(size=(n, 3))
np.save(sys.argv[2], v / np.linalg.norm(v, axis=1)[:, None])" "$n" "$p"
  bench_all uniform "$p" "$n"
done
# Regular lon/lat grids (cell centres): every four points of two rows are
# cocircular, a row shares its z.
for step in ${GRIDS-1 0.25}; do
  p=$data/sphere_lonlat_$step.npy
  [[ -f $p ]] || $py -c "
import numpy as np, sys
s = float(sys.argv[1]); lat = np.radians(np.arange(-90 + s / 2, 90, s)); lon = np.radians(np.arange(-180, 180, s))
la, lo = np.meshgrid(lat, lon, indexing='ij')
np.save(sys.argv[2], np.column_stack([np.cos(la.ravel()) * np.cos(lo.ravel()), np.cos(la.ravel()) * np.sin(lo.ravel()), np.sin(la.ravel())]))" "$step" "$p"
  bench_all "lonlat_$step" "$p" "$($py -c "import numpy as np; print(len(np.load('$p', mmap_mode='r')))")"
done
$py "$here/summarize.py" "$out"
