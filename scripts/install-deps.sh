#!/usr/bin/env bash
# Installs the Debian 12 packages Tessera needs, idempotently: packages already
# installed are skipped, and apt-get runs only when something is missing.
#   scripts/install-deps.sh          build + test dependencies
#   scripts/install-deps.sh --bench  also the peers' libraries (Voro++, CGAL, VTK, Qhull)
set -euo pipefail

pkgs=(build-essential cmake ninja-build ccache pkg-config
      libtbb-dev libcli11-dev libgtest-dev libgmock-dev libbenchmark-dev libgmp-dev zlib1g-dev liblzf-dev
      voro++-dev libvoro++1
      python3 python3-numpy python3-vtk9 qhull-bin
      # test oracles (CGAL's Delaunay, scipy) and the Python module (pybind11, pytest, meshio, matplotlib)
      libcgal-dev libmpfr-dev libboost-dev python3-scipy
      python3-dev pybind11-dev python3-pybind11 python3-pytest python3-meshio python3-matplotlib
      python3-setuptools python3-pip python3-venv)
if [[ "${1:-}" == "--bench" ]]; then
  pkgs+=(libeigen3-dev voro++ libqhull-dev libvtk9-dev libgmsh-dev gmsh)
fi

missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "install-deps: installing ${missing[*]}" >&2
  SUDO=""; [[ $(id -u) -ne 0 ]] && SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
