#!/usr/bin/env bash
# End-to-end studies of validation/README.md (issue 6), regenerated in one go:
#   1. the steel part's Table-2 study (h = 2, 1, 0.5) against the independent reference, at
#      order 1 as the paper: the incompatible-mode hex and the fully integrated hex (= C3D8);
#      (order 2, the default for CAD parts since session 14, is validation/order2.md section 3);
#   2. ANC101 clamped on its bottom face: the same study without a reference (convergence only);
#   3. hexfem versus CalculiX on the same exported meshes (validation/crosscheck_ccx.py);
#   4. a cut-away picture of the steel part's mesh (validation/render_cutaway.py).
# usage: validation/run_end_to_end.sh [BUILD_DIR]   (default: build; outputs in validation/out/)
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${1:-build}
HEXFEM=$BUILD/app/hexfem
OUT=validation/out
mkdir -p "$OUT"
[ -x "$HEXFEM" ] || { echo "run_end_to_end: $HEXFEM not built (make build)"; exit 1; }

step() { echo; echo "=== $*"; }

step "1. steel part, Table 2 (order 1, incompatible hex8)"
/usr/bin/time -f "wall %e s, peak %M kB" "$HEXFEM" converge models/steel_part.step --h 2,1,0.5 \
  --order 1 --fix face:8 --modes 6 --reference validation/reference/steel_part.json -o "$OUT/steel_table"
cp "$OUT/steel_table.png" validation/steel_convergence.png
step "1b. steel part, Table 2 (order 1, full hex8 = C3D8)"
"$HEXFEM" converge models/steel_part.step --h 2,1,0.5 --order 1 --fix face:8 --modes 6 --hex8 full \
  --reference validation/reference/steel_part.json -o "$OUT/steel_table_full"

step "2. ANC101 clamped on face 8 (z = 0), convergence only"
/usr/bin/time -f "wall %e s, peak %M kB" "$HEXFEM" converge tests/data/ANC101.stp \
  --h 12,8,5.6,4 --order 1 --fix face:8 --modes 6 -o "$OUT/anc101_table"

step "3. hexfem vs CalculiX on the same meshes"
HEXFEM=$HEXFEM /usr/bin/python3 validation/crosscheck_ccx.py --h 1 --out "$OUT/crosscheck" \
  --json "$OUT/crosscheck.json"

step "4. cut-away picture"
"$HEXFEM" mesh models/steel_part.step --h 1 -o "$OUT/steel_h1.msh" >/dev/null
/usr/bin/python3 validation/render_cutaway.py "$OUT/steel_h1.msh" validation/steel_cutaway.png \
  --axis y --at 0.5
