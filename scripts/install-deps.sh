#!/usr/bin/env bash
# Installs exactly the Debian 12 packages hexfem needs that are not installed yet.
# Idempotent: when everything is present it prints one line and does nothing.
set -euo pipefail

PACKAGES=(
  cmake g++ make pkg-config
  libeigen3-dev libspectra-dev libtet1.5-dev libcgal-dev libgmp-dev libmpfr-dev
  libocct-foundation-dev libocct-modeling-data-dev libocct-modeling-algorithms-dev
  libocct-data-exchange-dev libtbb-dev
  libsuitesparse-dev libopenblas0-pthread libboost-dev libcli11-dev nlohmann-json3-dev
  petsc-dev libslepc-real-dev libopenmpi-dev openmpi-bin
  libgtest-dev libgmock-dev libbenchmark-dev
  calculix-ccx python3-meshio gmsh gnuplot-nox xvfb xauth
)

# libopenblas0-pthread: an optimized BLAS behind libblas.so.3 (Debian's alternatives); CHOLMOD's
# supernodal factorization is BLAS-3 and runs 5-7x faster than on the reference BLAS.
# petsc-dev, libslepc-real-dev (and OpenMPI): the iterative eigensolver, on one process or under
# mpirun (fem/iterative_solver.hpp).

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
