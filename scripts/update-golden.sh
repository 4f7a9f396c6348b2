#!/usr/bin/env bash
# Regenerates tests/volume/golden_meshes.json from the current build. Only for a change meant to
# move the meshes: commit the new file on its own, saying why they move.
set -euo pipefail
build=${1:-build}
cd "$(dirname "$0")/.."
cmake --build "$build" --target test_volume -j "$(nproc)"
HEXFEM_GOLDEN_WRITE=1 "$build/tests/test_volume" --gtest_filter='Golden.*'
git --no-pager diff --stat tests/volume/golden_meshes.json
