#!/usr/bin/env bash
# The README's main job: 1M uniform random points in the unit cube -> every
# Voronoi cell as out/cells.vtu (ParaView) + out/cells.csv, with a summary.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh
"${BUILD_DIR:-build}/tessera" run-default -o "${OUT_DIR:-out}" "$@"
