#!/bin/bash
# Cells in a convex domain (tessera --wall) against Voro++'s plane walls
# (wall_plane) on the same points, box and walls, in one run; Tessera's cells
# of the same points in the box alone beside them, for what the walls cost.
# Writes JSON lines and a Markdown table (summarize.py).
#
# usage: bench/walls/run.sh [BUILD_DIR] [N...]
#   env: KINDS (default "halfcube ball"; also hull, sphere: gen_walls.py), REPEAT (default 3),
#        DATA (default bench/data, git-ignored), OUT (default bench/walls/results/walls.jsonl)
# Needs Debian's voro++-dev (the driver voro_walls.cpp is compiled here).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
build=${1:-build}
shift || true
sizes=${*:-"1e5 1e6"}
kinds=${KINDS:-"halfcube ball"}
repeat=${REPEAT:-3}
data=${DATA:-$here/../data}
py=/usr/bin/python3
mkdir -p "$data" "$here/results"
out=${OUT:-$here/results/walls.jsonl}
: > "$out"
note() { echo "walls: $*" >&2; }
[[ -x $build/tessera ]] || { note "error: no $build/tessera (build it first)"; exit 1; }
voro=$build/voro_walls
g++ -O2 -std=c++20 -o "$voro" "$here/voro_walls.cpp" -lvoro++
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
    p=$data/walls_${kind}_$n.npy w=$data/walls_${kind}_${n}_walls.npy
    [[ -f $p && -f $w ]] || PYTHONPATH=$build/python $py "$here/gen_walls.py" "$kind" "$n" "$p" "$w"
    for t in 1 2; do
      note "$kind $n: tessera, $t thread(s)"
      run "$kind $n" tessera-walls "$build/tessera" bench voronoi "$p" --bounds 0 1 0 1 0 1 --walls "$w" \
        --threads $t --repeat 1
      run "$kind $n" tessera-box "$build/tessera" bench voronoi "$p" --bounds 0 1 0 1 0 1 --threads $t --repeat 1
    done
    note "$kind $n: voro++ with plane walls"
    run "$kind $n" voro++-walls "$voro" "$p" 0 1 0 1 0 1 "$w"
  done
done
$py "$here/summarize.py" "$out"
