#!/usr/bin/python3
"""Are hexfem's curved order-2 cells valid, by an independent check? Each part is meshed at order
2 (`hexfem mesh PART --h H --order 2 --curvature 12 -o x.msh`, MSH 4.1: hex20, prism15,
pyramid13, tet10) and Gmsh's AnalyseMeshQuality plugin computes min/max det J of every element
from its own Bezier bounds (Johnen, Remacle, Geuzaine 2013). Prints, per element type, the worst
value and how many elements are below 0 and below 1e-3 (validation/order2.md, "Curved cells
kept curved").

Gmsh's pyramid13 is not hexfem's (a rational basis, Bedrosian 1992): for pyramids the column is
Gmsh's reading of the same 13 nodes, not a check of the element hexfem solves.

    /usr/bin/python3 validation/order2_validity.py [--hexfem build/app/hexfem]
        [PART:H ...]   (default: the parts below at diagonal / 30)
"""
import argparse
import os
import subprocess
import sys
import tempfile
from collections import defaultdict

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARED = os.path.join(os.path.dirname(ROOT), "shared", "models")
DEFAULT = ["cylinder.stp:4", "sphere.stp:2", "ANC101.stp:16.95", "0049_control_arm.step:10.1",
           "0083_nist_ctc_01_asme1_ap242_colored.stp:31", "1385_Laufrad_1000.stp:64.03",
           "40mm_capot.stp:7.322", "917_fusee.stp:14.36", "Block.stp:2.799",
           "SampleCrankshaft4A.stp:10.99", "freecad_hole_puzzle_counterbore.brep:0.8654",
           "gehause_rohteil.stp:1.396", "bottle.brep:3.131", "tie_rod.step:4.265"]
TYPES = {11: "tet10", 17: "hex20", 18: "prism15", 19: "pyramid13"}


def element_types(msh):
    """{element tag: Gmsh type} from an MSH 4.1 file."""
    lines = open(msh).read().split("\n")
    i = lines.index("$Elements")
    blocks = int(lines[i + 1].split()[0])
    k, types = i + 2, {}
    for _ in range(blocks):
        _, _, typ, n = map(int, lines[k].split())
        for line in lines[k + 1:k + 1 + n]:
            types[int(line.split()[0])] = typ
        k += 1 + n
    return types


def element_values(view):
    """{element tag: value} from the $ElementData of a saved view."""
    lines = open(view).read().split("\n")
    j = lines.index("$ElementData") + 1
    j += 1 + int(lines[j])  # string tags
    j += 1 + int(lines[j])  # real tags
    n = int(lines[j + 3])
    j += 1 + int(lines[j])  # integer tags
    return {int(l.split()[0]): float(l.split()[1]) for l in lines[j:j + n]}


def check(hexfem, part, h, work):
    msh, view, geo = (os.path.join(work, n) for n in ("x.msh", "view.msh", "q.geo"))
    p = subprocess.run([hexfem, "mesh", os.path.join(SHARED, part), "--h", str(h), "--order",
                        "2", "--curvature", "12", "-o", msh], capture_output=True, text=True)
    if p.returncode != 0:
        return None, p.stderr.strip().splitlines()[-1]
    with open(geo, "w") as f:
        f.write(f'Merge "{msh}";\nPlugin(AnalyseMeshQuality).JacobianDeterminant = 1;\n'
                "Plugin(AnalyseMeshQuality).CreateView = 1;\nPlugin(AnalyseMeshQuality).Run;\n"
                f'Save View[0] "{view}";\n')
    subprocess.run(["gmsh", "-0", "-v", "1", geo], check=True, capture_output=True)
    types, values = element_types(msh), element_values(view)
    worst, negative, low = defaultdict(lambda: float("inf")), defaultdict(int), defaultdict(int)
    for tag, v in values.items():
        t = TYPES.get(types[tag])
        if t is None:
            continue
        worst[t] = min(worst[t], v)
        negative[t] += v < 0
        low[t] += v < 1e-3
    straightened = next((l for l in p.stdout.splitlines() if l.startswith("order 2:")), "")
    return {t: (worst[t], negative[t], low[t]) for t in worst}, straightened


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--hexfem", default=os.path.join(ROOT, "build", "app", "hexfem"))
    ap.add_argument("parts", nargs="*", default=DEFAULT)
    a = ap.parse_args()
    names = ["hex20", "prism15", "tet10", "pyramid13"]
    print("| part | h | " + " | ".join(f"{n}: worst, < 0, < 1e-3" for n in names) + " |")
    print("|---|---:|" + "---|" * len(names))
    with tempfile.TemporaryDirectory() as work:
        for item in a.parts:
            part, _, h = item.rpartition(":")
            result, note = check(a.hexfem, part, float(h), work)
            if result is None:
                print(f"| {part} | {h} | {note} |")
                continue
            cells = [f"{result[n][0]:.3g}, {result[n][1]}, {result[n][2]}" if n in result else "–"
                     for n in names]
            print(f"| {part} | {h} | " + " | ".join(cells) + " |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
