#!/bin/bash
# Alpha shapes (tessera bench delaunay --alpha R: the triangulation, then the
# kept simplices, boundary, singular facets and pieces) against CGAL's
# (Fixed_alpha_shape_3 / Alpha_shape_2 on its Delaunay triangulation, with
# the INTERIOR / REGULAR / SINGULAR extraction), on the same points and
# alpha, in one run. Writes JSON lines and a Markdown table (summarize.py).
#
# usage: bench/alpha/run.sh [BUILD_DIR] [N...]
#   env: KINDS (default "cube torus square annulus"; gen_alpha.py), REPEAT
#        (default 3), DATA (default bench/data, git-ignored), OUT (default
#        bench/alpha/results/alpha.jsonl)
# Needs Debian's libcgal-dev (the driver cgal_alpha.cpp is compiled here).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
build=${1:-build}
shift || true
sizes=${*:-"1e5 1e6"}
kinds=${KINDS:-"cube torus square annulus"}
repeat=${REPEAT:-3}
data=${DATA:-$here/../data}
py=/usr/bin/python3
mkdir -p "$data" "$here/results"
out=${OUT:-$here/results/alpha.jsonl}
: > "$out"
note() { echo "alpha: $*" >&2; }
[[ -x $build/tessera ]] || { note "error: no $build/tessera (build it first)"; exit 1; }
cgal=$build/cgal_alpha
g++ -O2 -DNDEBUG -DCGAL_LINKED_WITH_TBB -std=c++20 -o "$cgal" "$here/cgal_alpha.cpp" -ltbb -ltbbmalloc -lgmp -lmpfr
echo "# $(date -u +%FT%TZ) $(uname -m) $(nproc) cores; tessera $(git -C "$here" rev-parse --short HEAD 2>/dev/null || echo '?')" >&2
# run LABEL CMD...: REPEAT runs, each JSON line tagged with the input.
run() {
  local label=$1 i; shift
  for ((i = 0; i < repeat; i++)); do
    "$@" 2>/dev/null | grep '^{' | sed "s/^{/{\"input\":\"$label\",/" >>"$out" || { note "FAILED: $*"; return 0; }
  done
}
for n in $sizes; do
  for kind in $kinds; do
    p=$data/alpha_${kind}_$n.npy a=$data/alpha_${kind}_$n.txt
    [[ -f $p && -f $a ]] || $py "$here/gen_alpha.py" "$kind" "$n" "$p" "$a"
    alpha=$(cat "$a")
    for t in 1 2; do
      note "$kind $n (alpha $alpha): tessera, $t thread(s)"
      run "$kind" "$build/tessera" bench delaunay "$p" --alpha "$alpha" --threads $t --repeat 1
      # CGAL's 2D triangulation and alpha shapes are sequential: one thread only.
      if [[ $kind == cube || $kind == torus || $t == 1 ]]; then
        note "$kind $n: CGAL, $t thread(s)"
        run "$kind" "$cgal" "$p" "$alpha" $t
      fi
    done
  done
done
$py "$here/summarize.py" "$out"
