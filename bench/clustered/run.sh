#!/bin/bash
# Strongly clustered inputs and surface samples (gen_clustered.py: blobs,
# sheet, hier; terrain, ellipsoid, torus): Tessera's cells and Delaunay
# against Voro++, CGAL and Gmsh HXT on the same files, in one run. These are
# the inputs on which the meshless method is weakest (see docs/design.md,
# known limits); this script keeps that visible.
#
# usage: bench/clustered/run.sh [BUILD_DIR] [N]
#   env: KINDS (default "blobs sheet hier"; the surfaces: "terrain ellipsoid torus"; near-degenerate: "latrot latjit sphere"; ties off a small grid: "lat01 voxels"; 2D: "circle2 curves2 blobs2"), REPEAT (default 3), THREADS (default 2),
#        VORO=0 skips Voro++ (single-threaded; minutes per input at 1e6), CELLS=0 skips Tessera's cells,
#        SEARCH=1 also times the cells with --method search (tool "tessera-search"; the default is auto),
#        TIMEOUT per command in seconds (default 900), DATA (default bench/data, git-ignored),
#        OUT (default bench/clustered/results/clustered_N.jsonl)
# Needs the peer drivers in bench/build-peers: bench/run_bench.sh builds them
# (OPS=delaunay for CGAL and HXT; OPS=voronoi for Voro++).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
build=${1:-build}
n=${2:-1e6}
kinds=${KINDS:-"blobs sheet hier"}
repeat=${REPEAT:-3}
threads=${THREADS:-2}
timeout=${TIMEOUT:-900}
voro=${VORO:-1}
cells=${CELLS:-1}
search=${SEARCH:-0}
data=${DATA:-$here/../data}
peers=$here/../build-peers
# The shared harness's Python drivers (scipy), for the 2D kinds.
shared_peers=${SHARED:-$(cd "$here/../../.." && pwd)/shared}/peers
[[ -f $shared_peers/scipy_bench.py ]] || shared_peers=""
py=/usr/bin/python3
mkdir -p "$data" "$here/results"
out=${OUT:-$here/results/clustered_$n.jsonl}
: > "$out"
note() { echo "clustered: $*" >&2; }
[[ -x $build/tessera ]] || { note "error: no $build/tessera (build it first)"; exit 1; }
echo "# $(date -u +%FT%TZ) $(uname -m) $(nproc) cores; tessera $(git -C "$here" rev-parse --short HEAD 2>/dev/null || echo '?')" >&2
# run LABEL CMD...: REPEAT runs, each JSON line tagged with the input's label
# (and its tool renamed to $tool_tag when set).
run() {
  local label=$1 i; shift
  for ((i = 0; i < repeat; i++)); do
    timeout "$timeout" "$@" 2>/dev/null | grep '^{' |
      sed "s/^{/{\"input\":\"$label\",/; s/\"tool\":\"tessera\"/\"tool\":\"${tool_tag:-tessera}\"/" >>"$out" ||
      { note "FAILED or timed out: $*"; return 0; }
  done
}
for kind in $kinds; do
  f=$data/clustered_${kind}_$n.npy
  [[ -f $f ]] || $py "$here/gen_clustered.py" "$kind" "$n" "$f"
  note "$kind: tessera"
  [[ $cells == 1 ]] && run "$kind" "$build/tessera" bench voronoi "$f" --threads "$threads" --repeat 1
  [[ $cells == 1 && $search == 1 ]] &&
    tool_tag=tessera-search run "$kind" "$build/tessera" bench voronoi "$f" --method search --threads "$threads" --repeat 1
  run "$kind" "$build/tessera" bench delaunay "$f" --threads "$threads" --repeat 1
  if [[ $kind == *2 ]]; then  # 2D: CGAL's Delaunay_triangulation_2 and scipy (Qhull, one thread) are the peers
    if [[ -x $peers/cgal_delaunay2 ]]; then
      note "$kind: CGAL"
      run "$kind" "$peers/cgal_delaunay2" "$f"
    else note "skip: no $peers/cgal_delaunay2"; fi
    if [[ -n $shared_peers ]]; then
      note "$kind: scipy (Qhull)"
      run "$kind" $py "$shared_peers/scipy_bench.py" "$f" --op delaunay
      run "$kind" $py "$shared_peers/scipy_bench.py" "$f" --op voronoi
    fi
    continue
  fi
  if [[ -x $peers/cgal_delaunay3 ]]; then
    note "$kind: CGAL"
    run "$kind" "$peers/cgal_delaunay3" "$f" --threads "$threads"
  else note "skip: no $peers/cgal_delaunay3"; fi
  if [[ -x $peers/gmsh_delaunay ]]; then
    note "$kind: HXT"
    run "$kind" "$peers/gmsh_delaunay" "$f" --algo hxt --threads "$threads"
  else note "skip: no $peers/gmsh_delaunay"; fi
  if [[ $voro == 1 && -x $peers/voro_cells ]]; then
    note "$kind: Voro++ (one run)"
    repeat=1 run "$kind" "$peers/voro_cells" "$f"
  fi
done
$py "$here/summarize.py" "$out"
