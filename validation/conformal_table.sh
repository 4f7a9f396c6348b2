#!/bin/bash
# conformal table: every shared model at diag/30 and /60 with --conformal, checked by
# `hexfem stats` and by the independent validation/conformal_check.py (meshio + numpy).
# Usage: conformal_table.sh [HEXFEM] [OUTDIR] [MODELS]; then conformal_table_md.py OUTDIR/table.tsv
H=${1:-build/app/hexfem}
OUT=${2:-/tmp/conformal_table}; mkdir -p $OUT
out=$OUT/table.tsv; : > $out
MODELS=${3:-../shared/models}
CHECK=$(dirname "$0")/conformal_check.py
for f in "$MODELS"/*.*; do
  case "$f" in *.md) continue;; esac
  n=$(basename "$f")
  diag=$($H info "$f" --json 2>/dev/null | /usr/bin/python3 -c "import json,sys,math; b=json.load(sys.stdin)['bbox']; print(math.dist(b[:3],b[3:]) if isinstance(b,list) else math.dist(b['min'],b['max']))" 2>/dev/null)
  if [ -z "$diag" ]; then echo -e "$n\t-\tinfo refused: $($H info "$f" 2>&1 | head -1)" >> $out; continue; fi
  for d in 30 60; do
    h=$(/usr/bin/python3 -c "print(f'{$diag/$d:.6g}')")
    s=$(date +%s.%N)
    timeout 600 $H mesh "$f" --h $h -o ${OUT}/m.msh --conformal > ${OUT}/r.txt 2>&1; rc=$?
    t=$(/usr/bin/python3 -c "print(f'{$(date +%s.%N)-$s:.1f}')")
    if [ $rc -ne 0 ]; then echo -e "$n\t$d\t$h\trc=$rc\t$t\t$(grep error ${OUT}/r.txt | head -1)" >> $out; continue; fi
    conf=$(grep -E "^conformal" ${OUT}/r.txt | sed 's/conformal *//')
    st=$($H stats ${OUT}/m.msh --json | /usr/bin/python3 -c "import json,sys; j=json.load(sys.stdin); print(j['nonconformal_quads'], j['inverted'], j['degenerate'], j['watertight'], round(j['H_vol'],2), j['nodes'], sep='\t')")
    tets=$(grep -E "^volume  " ${OUT}/r.txt | sed -E 's/^volume +tets ([0-9.e+-]+),.*/\1/')
    gap=$(grep -E "^volume  " ${OUT}/r.txt | grep -o "gap [0-9.e+-]*" | cut -d' ' -f2)
    chk=$(/usr/bin/python3 "$CHECK" ${OUT}/m.msh 2>${OUT}/check_err.txt | /usr/bin/python3 -c "
import json,sys; j=json.load(sys.stdin); t=float('$tets')
bad=[k for k in ('nc_quads','faces_of_3_or_more_cells','orientation_clashes','unmatched_faces','boundary_elements_not_a_face','open_boundary_edges','inverted') if j[k]]
print('ok' if j['conformal'] else 'FAIL '+' '.join(f'{k}={j[k]}' for k in bad), f\"{(j['enclosed_volume']-t)/t:.3e}\", f\"{j['boundary_quad_half_slivers']/t:.3e}\", sep='\t')")
    echo -e "$n\t$d\t$h\tok\t$t\t$st\t$gap\t$chk\t$conf" >> $out
  done
done
echo finished >> $out
