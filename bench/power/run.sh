#!/bin/bash
# Power cells (the radical tessellation of spheres: tessera voronoi --radii)
# against Voro++'s container_poly on the same points, radii and box, in one
# run; Tessera's ordinary cells of the same points beside them, for what the
# radii cost. Then their dual, the regular triangulation (tessera delaunay
# --radii), against CGAL's Regular_triangulation_3, and Tessera's ordinary
# Delaunay triangulation of the same points; and the periodic one (the unit
# cube, --periodic xyz) against CGAL's Periodic_3_regular_triangulation_3.
# Writes JSON lines and Markdown tables (summarize.py).
#
# usage: bench/power/run.sh [BUILD_DIR] [N...]
#   env: KINDS (default "uniform bimodal"; gen_power.py), REPEAT (default 3),
#        PARTS (default "cells regular periodic"), DATA (default bench/data,
#        git-ignored), OUT (default bench/power/results/power.jsonl)
# Needs Debian's voro++-dev and libcgal-dev (the drivers voro_poly.cpp,
# cgal_regular.cpp and cgal_periodic_regular.cpp are compiled here).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
build=${1:-build}
shift || true
sizes=${*:-"1e5 1e6"}
kinds=${KINDS:-"uniform bimodal"}
repeat=${REPEAT:-3}
data=${DATA:-$here/../data}
py=/usr/bin/python3
mkdir -p "$data" "$here/results"
out=${OUT:-$here/results/power.jsonl}
: > "$out"
note() { echo "power: $*" >&2; }
[[ -x $build/tessera ]] || { note "error: no $build/tessera (build it first)"; exit 1; }
parts=${PARTS:-"cells regular periodic"}
voro=$build/voro_poly cgal=$build/cgal_regular cgal_per=$build/cgal_periodic_regular
[[ $parts != *cells* ]] || g++ -O2 -std=c++20 -o "$voro" "$here/voro_poly.cpp" -lvoro++
[[ $parts != *regular* ]] ||
  g++ -O2 -DNDEBUG -DCGAL_LINKED_WITH_TBB -std=c++20 -o "$cgal" "$here/cgal_regular.cpp" -ltbb -ltbbmalloc -lgmp -lmpfr
[[ $parts != *periodic* ]] ||
  g++ -O2 -DNDEBUG -std=c++20 -o "$cgal_per" "$here/cgal_periodic_regular.cpp" -lgmp -lmpfr
echo "# $(date -u +%FT%TZ) $(uname -m) $(nproc) cores; tessera $(git -C "$here" rev-parse --short HEAD 2>/dev/null || echo '?')" >&2
# run LABEL TOOL_TAG CMD...: REPEAT runs, each JSON line tagged with the input and the tool.
run() {
  local label=$1 tag=$2 i; shift 2
  for ((i = 0; i < repeat; i++)); do
    "$@" 2>/dev/null | grep '^{' | sed "s/^{/{\"input\":\"$label\",/; s/\"tool\":\"[^\"]*\"/\"tool\":\"$tag\"/" >>"$out" ||
      { note "FAILED: $*"; return 0; }
  done
}
for n in $sizes; do
  for kind in $kinds; do
    p=$data/power_${kind}_$n.npy r=$data/power_${kind}_${n}_radii.npy
    [[ -f $p && -f $r ]] || $py "$here/gen_power.py" "$kind" "$n" "$p" "$r"
    if [[ $parts == *cells* ]]; then
      for t in 1 2; do
        note "$kind $n: tessera, $t thread(s)"
        run "$kind" tessera-power "$build/tessera" bench voronoi "$p" --radii "$r" --bounds 0 1 0 1 0 1 --threads $t --repeat 1
        run "$kind" tessera "$build/tessera" bench voronoi "$p" --bounds 0 1 0 1 0 1 --threads $t --repeat 1
      done
      note "$kind $n: voro++ container_poly"
      run "$kind" voro++-poly "$voro" "$p" "$r" 0 1 0 1 0 1
    fi
    if [[ $parts == *regular* ]]; then
      for t in 1 2; do
        note "$kind $n: regular triangulations, $t thread(s)"
        run "$kind" tessera-regular "$build/tessera" bench delaunay "$p" --radii "$r" --threads $t --repeat 1
        run "$kind" tessera-delaunay "$build/tessera" bench delaunay "$p" --threads $t --repeat 1
        run "$kind" cgal-regular "$cgal" "$p" "$r" $t
      done
    fi
    if [[ $parts == *periodic* ]]; then
      for t in 1 2; do
        note "$kind $n: periodic regular triangulations, $t thread(s)"
        run "$kind" tessera-periodic-regular "$build/tessera" bench delaunay "$p" --radii "$r" --periodic xyz \
          --bounds 0 1 0 1 0 1 --threads $t --repeat 1
      done
      note "$kind $n: CGAL's periodic regular triangulation"
      run "$kind" cgal-periodic-regular "$cgal_per" "$p" "$r" 0 1
    fi
  done
done
$py "$here/summarize.py" "$out"
