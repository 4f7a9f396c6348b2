#!/usr/bin/python3
"""The Markdown table of conformal_table.sh's table.tsv (see validation/conformal.md).
Usage: conformal_table_md.py TABLE.tsv"""
import sys

print("| model | /d | h | result | s | NC left | inverted | degenerate | watertight | H_vol % "
      "| nodes | gap vs tets | independent check | enclosed vs tets | boundary-quad half slivers |")
print("|---|---:|---:|---|---:|---:|---:|---:|---|---:|---:|---:|---|---:|---:|")
for line in open(sys.argv[1]):
    f = line.rstrip("\n").split("\t")
    if f[0] == "finished":
        continue
    if len(f) < 4 or f[3] != "ok":
        why = f[-1] if len(f) > 3 else f[2]
        h = f[2] if len(f) > 4 else ""
        s = f[4] if len(f) > 4 else ""
        print(f"| {f[0]} | {f[1] if f[1] != '-' else ''} | {h} | refused: {why[:160]} | {s} "
              "| | | | | | | | | | |")
        continue
    name, d, h, _, s, nc, inv, deg, wt, hvol, nodes, gap, chk, enc, half = f[:15]
    print(f"| {name} | {d} | {h} | meshed | {s} | {nc} | {inv} | {deg} | "
          f"{'yes' if wt == 'True' else 'NO'} | {hvol} | {nodes} | {gap} | {chk} | {enc} | {half} |")
