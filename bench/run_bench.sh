#!/usr/bin/env bash
# Tessera vs the Voronoi and Delaunay peers, in one run; writes docs/performance.md.
#
# usage: bench/run_bench.sh            (from anywhere; see bench/README.md)
#
#   1. builds the peers harness ($SHARED/peers) into bench/build-peers (voro_cells, cgal_delaunay2;
#      with OPS delaunay also cgal_delaunay3, gmsh_delaunay)
#   2. generates the inputs into bench/data/ (fixed seed; existing files are reused)
#   3. per input, for each op in OPS:
#      voronoi:  `tessera bench voronoi` at each thread count, then the peers
#                (3D: Voro++; 2D: CGAL Delaunay_triangulation_2 and scipy.spatial.Voronoi)
#      delaunay: `tessera bench delaunay` at each thread count, then the peers
#                (3D: CGAL Delaunay_triangulation_3 and Gmsh HXT at each PEER_THREADS count;
#                 2D: CGAL Delaunay_triangulation_2, shared with voronoi when both run)
#      each WARMUP untimed runs then REPS timed ones; JSON lines into $OUT/<input>.jsonl
#   4. bench/report.py $OUT -> docs/performance.md (REPORT=0 skips it)
#
# env knobs (defaults in brackets):
#   OPS      tessera ops to measure, with their peers ["voronoi delaunay"]
#   DELAUNAY_INPUTS  restrict the delaunay op to these inputs (names as in $OUT, e.g. uniform3_1e6,
#            or KIND:ARG as in INPUTS; "all") [with INPUTS: all of them; without: the default inputs but
#            clustered3_1e6 and uniform3_1e7 (Tessera's Delaunay of clustered input is the cells pass,
#            ~10x CGAL's time: long, and says nothing the 1e5 run does not)]
#   PEER_THREADS  thread counts of the parallel Delaunay peers (CGAL 3D, Gmsh HXT) ["1 2"]
#   SIZES    size classes to run ["1e4 1e5 1e6", plus 1e7 with FULL=1]; lattice3 K=50 is class 1e5, K=100 is 1e6
#   FULL     1: add the 1e7 class (uniform3 1e7) [0]
#   REPS     timed runs per configuration [3]        WARMUP  untimed runs before them [1]
#   THREADS  tessera thread counts ["1 2"]           MESH    1: also time tessera with --mesh [0]
#   TESSERA  tessera binary [build/tessera, build-cli/tessera, else built in bench/build-tessera];
#            "none": peers only
#   SHARED   folder holding peers/ [the repository's parent folder's shared/]
#   INPUTS   replace the input list, e.g. "uniform3:2e5 lattice3:30 jlattice3:20:1e-9" (KIND:ARG[:ARG], gen_points.py)
#   OUT      results folder [bench/results/raw/<date-time>]
#   DOC      report file [docs/performance.md]     REPORT  0: do not write it [1]
#   JOBS     build parallelism [2]                 TIMEOUT seconds per run [900]
set -euo pipefail

bench=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(dirname "$bench")
py=/usr/bin/python3   # Debian's, with numpy/scipy (not a pyenv python3)

# The exact command, with the knobs that were set, for the report.
quote() {
  if [[ $1 =~ ^[A-Za-z0-9_./:=+-]+$ ]]; then printf '%s' "$1"
  elif [[ $1 != *"'"* ]]; then printf "'%s'" "$1"
  else printf '%q' "$1"; fi
}
cmd=""
for v in OPS FULL SIZES REPS WARMUP THREADS PEER_THREADS MESH INPUTS DELAUNAY_INPUTS TESSERA SHARED OUT DOC; do
  [[ -n ${!v+x} ]] && cmd+="$v=$(quote "${!v}") "
done
cmd+="bench/run_bench.sh"

shared=${SHARED:-$(dirname "$repo")/shared}
peers=$shared/peers
full=${FULL:-0}
default_sizes="1e4 1e5 1e6"; [[ $full == 1 ]] && default_sizes+=" 1e7"
sizes=${SIZES:-$default_sizes}
reps=${REPS:-3}
warmup=${WARMUP:-1}
threads=${THREADS:-"1 2"}
peer_threads=${PEER_THREADS:-"1 2"}
ops=${OPS:-"voronoi delaunay"}
jobs=${JOBS:-2}
timeout=${TIMEOUT:-900}
out=${OUT:-$bench/results/raw/$(date +%Y%m%d-%H%M%S)}
doc=${DOC:-$repo/docs/performance.md}

note() { echo "run_bench: $*" >&2; }
die() { note "error: $*"; exit 1; }
[[ -f $peers/run_peers.sh && -f $peers/gen_points.py ]] || die "no peers harness in $peers (set SHARED=/path/to/shared)"
$py -c 'import numpy, scipy' 2>/dev/null || die "$py lacks numpy/scipy (apt-get install python3-numpy python3-scipy)"
for op in $ops; do
  [[ $op == voronoi || $op == delaunay ]] || die "OPS entries are voronoi or delaunay, got '$op'"
done
has_op() { [[ " $ops " == *" $1 "* ]]; }
has_op voronoi || has_op delaunay || die "OPS is empty"

# ---- 1. peers -------------------------------------------------------------------------------
# The peers' libraries (Voro++, CGAL, VTK, Qhull, Gmsh; idempotent). Without them a peer
# is skipped with a note, and its columns stay empty.
"$repo/scripts/install-deps.sh" --bench || die "installing the peers' packages failed (scripts/install-deps.sh --bench)"
peer_build=$bench/build-peers
peer_log=$peer_build/run_bench.log
mkdir -p "$peer_build"
note "building peer drivers in $peer_build"
cmake -S "$peers" -B "$peer_build" -DCMAKE_BUILD_TYPE=Release >"$peer_log" 2>&1 \
  || die "configuring the peers failed, see $peer_log"
peer_targets=(cgal_delaunay2)
has_op voronoi && peer_targets+=(voro_cells)
has_op delaunay && peer_targets+=(cgal_delaunay3 gmsh_delaunay)
for t in "${peer_targets[@]}"; do
  # A target CMake dropped (library missing) is skipped by run_peers.sh with a note.
  if grep -q "^$t:" "$peer_build/Makefile" 2>/dev/null || grep -q "build $t:" "$peer_build/build.ninja" 2>/dev/null; then
    cmake --build "$peer_build" -j"$jobs" --target "$t" >>"$peer_log" 2>&1 || die "building $t failed, see $peer_log"
  else
    note "warning: $t not configured (library missing?), see $peer_log"
  fi
done

# ---- tessera ----------------------------------------------------------------------------------
if [[ -z ${TESSERA:-} ]]; then
  for c in "$repo/build/tessera" "$repo/build-cli/tessera"; do
    [[ -x $c ]] && { TESSERA=$c; break; }
  done
fi
if [[ -z ${TESSERA:-} ]]; then
  tb=$bench/build-tessera
  note "no tessera binary found: building a Release one in $tb"
  mkdir -p "$tb"
  { cmake -S "$repo" -B "$tb" -DCMAKE_BUILD_TYPE=Release \
          -DTESSERA_BUILD_TESTS=OFF -DTESSERA_BUILD_BENCH=OFF >"$tb/run_bench.log" 2>&1 &&
    cmake --build "$tb" -j"$jobs" --target tessera_cli >>"$tb/run_bench.log" 2>&1; } \
    || die "building tessera failed, see $tb/run_bench.log"
  TESSERA=$tb/tessera
fi
build_type=
if [[ $TESSERA == none ]]; then
  note "TESSERA=none: peers only"
else
  [[ -x $TESSERA ]] || die "TESSERA=$TESSERA is not an executable"
  for op in $ops; do
    "$TESSERA" bench "$op" --help >/dev/null 2>&1 || die "$TESSERA has no 'bench $op' subcommand"
  done
  build_type=$(sed -n 's/^CMAKE_BUILD_TYPE:STRING=//p' "$(dirname "$TESSERA")/CMakeCache.txt" 2>/dev/null || true)
  [[ -z $build_type || $build_type == Release ]] || note "warning: $TESSERA is a '$build_type' build, not Release"
fi

# ---- 2. inputs ----------------------------------------------------------------------------------
# name kind arg size-class
default_inputs="
uniform3_1e4 uniform3 1e4 1e4
uniform3_1e5 uniform3 1e5 1e5
uniform3_1e6 uniform3 1e6 1e6
uniform3_1e7 uniform3 1e7 1e7
clustered3_1e5 clustered3 1e5 1e5
clustered3_1e6 clustered3 1e6 1e6
lattice3_K50 lattice3 50 1e5
lattice3_K100 lattice3 100 1e6
uniform2_1e6 uniform2 1e6 1e6"
inputs=()
if [[ -n ${INPUTS:-} ]]; then
  for s in $INPUTS; do
    [[ $s == *:* ]] || die "INPUTS entries are KIND:ARG[:ARG], got '$s'"
    inputs+=("${s//:/_} ${s%%:*} ${s#*:} any")
  done
else
  while read -r name kind arg class; do
    [[ -n $name && " $sizes " == *" $class "* ]] && inputs+=("$name $kind $arg $class")
  done <<<"$default_inputs"
fi
((${#inputs[@]})) || die "no inputs selected (SIZES='$sizes')"

mkdir -p "$bench/data" "$out"
for e in "${inputs[@]}"; do
  read -r name kind arg _ <<<"$e"
  f=$bench/data/$name.npy
  # shellcheck disable=SC2086  # ARG:ARG -> separate arguments
  [[ -s $f ]] || $py "$peers/gen_points.py" "$kind" ${arg//:/ } "$f" || die "generating $f failed"
done

$py "$bench/report.py" --write-meta "$out" --command "$cmd" --tessera "$TESSERA" \
    --build-type "${build_type:-unknown}" --reps "$reps" --warmup "$warmup" --threads "$threads" \
    --peers "$peers" --inputs "$(for e in "${inputs[@]}"; do echo "${e%% *}"; done)" \
    --ops "$ops" --peer-threads "$peer_threads"

# Time one binary throughout, even if the build folder is rebuilt during the sweep.
if [[ $TESSERA != none ]]; then
  cp -p "$TESSERA" "$out/tessera"
  bin=$out/tessera
fi

# ---- 3. runs --------------------------------------------------------------------------------------
# repeat CMD...: WARMUP untimed runs (output dropped), then REPS timed runs, stdout -> JSON lines.
repeat() {
  local i rc
  for ((i = 0; i < warmup + reps; i++)); do
    if ((i < warmup)); then timeout "$timeout" "$@" >/dev/null; else timeout "$timeout" "$bench/maxrss.py" "$@"; fi
    rc=$?
    ((rc == 0)) || { note "FAILED (rc=$rc): $*"; return 0; }
  done
}

# tessera_runs OP EXTRA-ARGS...: for each T in THREADS, WARMUP untimed processes, then one
# process timing REPS repeats (--repeat); JSON lines -> $jl.
tessera_runs() {
  local op=$1 t i rc; shift
  [[ $TESSERA != none ]] || return 0
  for t in $threads; do
    local args=(bench "$op" "$f" --dim "$dim" --threads "$t" "$@")
    (
      set +e
      for ((i = 0; i < warmup; i++)); do timeout "$timeout" "$bin" "${args[@]}" --repeat 1 >/dev/null; done
      timeout "$timeout" "$bin" "${args[@]}" --repeat "$reps"
      rc=$?; ((rc == 0)) || note "FAILED (rc=$rc): tessera ${args[*]}"
    ) | grep '^{' >>"$jl" || true
  done
}
# peer EXE ARGS...: one peer driver from $peer_build, WARMUP untimed + REPS timed runs, each timed
# run under maxrss.py (its own peak RSS); skipped with a note when the driver was not built.
peer() {
  local exe=$peer_build/$1; shift
  if [[ ! -x $exe ]]; then note "skip: $(basename "$exe") not built (see $peer_log)"; return 0; fi
  (set +e; repeat "$exe" "$@") | grep '^{' >>"$jl" || true
}

# DELAUNAY_INPUTS: names (KIND_ARG) or KIND:ARG specs; "all" = every input.
default_delaunay_inputs="uniform3_1e4 uniform3_1e5 uniform3_1e6 clustered3_1e5 lattice3_K50 lattice3_K100 uniform2_1e6"
delaunay_sel=${DELAUNAY_INPUTS:-}
[[ -n $delaunay_sel || -n ${INPUTS:-} ]] || delaunay_sel=$default_delaunay_inputs
[[ -n $delaunay_sel ]] || delaunay_sel=all
delaunay_inputs=" "
for s in $delaunay_sel; do delaunay_inputs+="${s//:/_} "; done
if [[ -n ${DELAUNAY_INPUTS:-} && $delaunay_sel != all ]]; then
  for s in $delaunay_inputs; do
    found=0
    for e in "${inputs[@]}"; do [[ ${e%% *} == "$s" ]] && found=1; done
    ((found)) || note "warning: DELAUNAY_INPUTS names '$s', which is not among the inputs"
  done
fi

variants=("")  # tessera voronoi runs: plain, and with --mesh when MESH=1
[[ ${MESH:-0} != 1 ]] || variants+=(--mesh)
for e in "${inputs[@]}"; do
  read -r name _ _ _ <<<"$e"
  f=$bench/data/$name.npy
  dim=$($py -c 'import sys, numpy; print(numpy.load(sys.argv[1], mmap_mode="r").shape[1])' "$f")
  jl=$out/$name.jsonl
  : >"$jl"
  do_delaunay=0
  if has_op delaunay && [[ $delaunay_sel == all || $delaunay_inputs == *" $name "* ]]; then do_delaunay=1; fi
  note "$name ($(cut -d' ' -f1-3 /proc/loadavg) load)"
  if has_op voronoi; then
    for mesh in "${variants[@]}"; do
      tessera_runs voronoi ${mesh:+"$mesh"}
    done
    if [[ $dim == 3 ]]; then
      BUILD=$peer_build ONLY=voro WARMUP=$warmup TIMEOUT=$timeout \
        $py "$bench/maxrss.py" "$peers/run_peers.sh" "$f" 3 "$reps" | grep '^{' >>"$jl" || true
    else
      BUILD=$peer_build ONLY=cgal WARMUP=$warmup TIMEOUT=$timeout \
        $py "$bench/maxrss.py" "$peers/run_peers.sh" "$f" 2 "$reps" | grep '^{' >>"$jl" || true
      (set +e; repeat $py "$peers/scipy_bench.py" "$f" --op voronoi) | grep '^{' >>"$jl" || true
    fi
  fi
  if ((do_delaunay)); then
    note "$name: delaunay"
    tessera_runs delaunay
    if [[ $dim == 3 ]]; then
      for t in $peer_threads; do peer cgal_delaunay3 "$f" --threads "$t"; done
      for t in $peer_threads; do peer gmsh_delaunay "$f" --algo hxt --threads "$t"; done
    elif ! has_op voronoi; then
      peer cgal_delaunay2 "$f"   # otherwise already timed above, for the voronoi comparison
    fi
  fi
done

# ---- 4. report --------------------------------------------------------------------------------------
$py "$bench/report.py" --finish-meta "$out"
if [[ ${REPORT:-1} == 1 ]]; then
  $py "$bench/report.py" "$out" -o "$doc"
  note "wrote $doc from $out"
else
  $py "$bench/report.py" "$out"
fi
