#!/bin/bash
# Surface nets on a labelled volume: Tessera's whole pipeline (sample -> cells
# -> surface net -> smoothing -> triangles) against VTK 9.1's
# vtkDiscreteFlyingEdges3D and vtkDiscreteMarchingCubes on the same volume, in
# one run. See README.md next to this script.
#
# usage: bench/surface_nets/run.sh [BUILD_DIR] [SIZE] [LABELS]
#   env: REPEAT (default 3), THREADS (default 2), DATA (default bench/data, git-ignored),
#        OUT (default bench/surface_nets/results/surface_nets_SIZE.jsonl)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
build=${1:-build}
size=${2:-256}
labels=${3:-12}
repeat=${REPEAT:-3}
threads=${THREADS:-2}
data=${DATA:-$here/../data}  # bench/data/ is git-ignored
mkdir -p "$data" "$here/results"
vol=$data/labels_${size}_${labels}.npy
out=${OUT:-$here/results/surface_nets_${size}.jsonl}
[ -f "$vol" ] || /usr/bin/python3 "$here/gen_volume.py" "$vol" --size "$size" --labels "$labels"
sel=$(seq -s, 1 "$labels")
: > "$out"
echo "# $(date -u +%FT%TZ) $(uname -m) $(nproc) cores; volume $vol" >&2
# Tessera: labels 1..L selected, background 0 unselected, capped -> every label closed.
"$build/tessera" bench surface-nets "$vol" --image --select "$sel" --capping --triangles \
  --threads "$threads" --repeat "$repeat" | sed 's/"op":"surface-nets"/"op":"surface-nets:smoothed"/' >> "$out"
"$build/tessera" bench surface-nets "$vol" --image --select "$sel" --capping --triangles --smooth 0 \
  --threads "$threads" --repeat "$repeat" | sed 's/"op":"surface-nets"/"op":"surface-nets:raw (--smooth 0)"/' >> "$out"
# VTK: DFE, DMC, DFE + windowed sinc (20 iterations).
/usr/bin/python3 "$here/vtk_discrete.py" "$vol" --repeat "$repeat" --smooth 20 >> "$out"
/usr/bin/python3 "$here/summarize.py" "$out"
