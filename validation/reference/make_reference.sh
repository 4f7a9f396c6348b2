#!/bin/bash
# Independent modal reference for models/steel_part.step (issue 6, item 4): Gmsh 4.8.4 second-order
# tets at several sizes -> CalculiX 2.20 C3D10, clamped at x = 0 -> Richardson extrapolation.
# Shares no code with hexfem. Also runs the chain on the 100 x 10 x 10 mm cantilever as a sanity
# check of the deck (node ordering, units): f1 should approach ~833 Hz.
#
# usage: validation/reference/make_reference.sh [WORKDIR]
#   env SIZES (steel part, mm, default "2,1.4142136,1"), CANTILEVER_SIZES (default "2.5,1.767767,1.25"),
#   SKIP_CANTILEVER=1 to skip the check, CLAMP_CHECK=1 to also run the same sizes with size 0.5
#   within 2 mm of the clamped face (how much the clamped-edge singularity weighs). Writes
#   validation/reference/steel_part.json, cantilever_check.json (and steel_part_clamp_graded.json);
#   meshes, decks and logs stay in WORKDIR.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
work=${1:-$(mktemp -d /tmp/hexfem-reference.XXXXXX)}
mkdir -p "$work"
work=$(cd "$work" && pwd)
for tool in gmsh ccx /usr/bin/python3; do
  command -v "$tool" >/dev/null || { echo "make_reference.sh: $tool not found" >&2; exit 1; }
done
# ccx 2.20 with 2 OpenMP threads on a shared 2-core machine runs 3-9x slower (threads spin).
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
echo "work directory: $work"

sizes=${SIZES:-2,1.4142136,1}
cantilever_sizes=${CANTILEVER_SIZES:-2.5,1.767767,1.25}
export HEXFEM_REFERENCE_COMMAND="SIZES=$sizes CANTILEVER_SIZES=$cantilever_sizes CLAMP_CHECK=${CLAMP_CHECK:-0} validation/reference/make_reference.sh"
cd "$root"  # the json records paths relative to the repository root
/usr/bin/python3 validation/reference/reference_chain.py study steel_part models/steel_part.step \
  validation/reference/steel_part.json "$sizes" "$work" \
  "steel part (models/steel_part.step), steel, clamped on the planar face x = 0 (face id 8)"

if [ "${SKIP_CANTILEVER:-0}" != 1 ]; then
  /usr/bin/python3 validation/reference/reference_chain.py study cantilever \
    validation/reference/cantilever.geo validation/reference/cantilever_check.json \
    "$cantilever_sizes" "$work" \
    "sanity check: 100x10x10 mm steel cantilever clamped at x = 0; expect f1 ~ 833.3 Hz"
fi

if [ "${CLAMP_CHECK:-0}" = 1 ]; then
  /usr/bin/python3 validation/reference/reference_chain.py study steel_part_clamp_graded \
    models/steel_part.step validation/reference/steel_part_clamp_graded.json "$sizes" "$work" \
    "check: steel part with size 0.5 mm within 2 mm of the clamped face x = 0" 0.5
fi
