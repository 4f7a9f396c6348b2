#!/usr/bin/python3
"""Second check of the cantilever figure, with no mesher at all: structured C3D20 meshes of the
100 x 10 x 10 mm steel cantilever (clamped at x = 0) written here, solved by ccx at three
densities (n x n/10 x n/10 for n = 20, 40, 80), and the observed order and extrapolated f1.

usage: validation/reference/cantilever_c3d20.py WORKDIR OUT.json
"""
import json
import os
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from reference_chain import (E_MPA, NU, RHO_T_PER_MM3, observed_order,  # noqa: E402
                             read_frequencies, richardson, tool_versions)

LENGTH, WIDTH, HEIGHT = 100.0, 10.0, 10.0
# C3D20 edge nodes 9..20 (0-based 8..19) sit on these corner pairs (Abaqus/CalculiX order).
EDGES = [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4),
         (0, 4), (1, 5), (2, 6), (3, 7)]


def write_deck(path, nx, ny, nz, nmodes=6):
    """Nodes live on a lattice of half elements: corner (2i, 2j, 2k), mid-edge one odd index."""
    ids = {}

    def nid(p):
        return ids.setdefault(p, len(ids) + 1)

    elements = []
    for a in range(nx):
        for b in range(ny):
            for c in range(nz):
                i, j, k = 2 * a, 2 * b, 2 * c
                corners = [(i, j, k), (i + 2, j, k), (i + 2, j + 2, k), (i, j + 2, k),
                           (i, j, k + 2), (i + 2, j, k + 2), (i + 2, j + 2, k + 2),
                           (i, j + 2, k + 2)]
                mids = [tuple((u + v) // 2 for u, v in zip(corners[p], corners[q]))
                        for p, q in EDGES]
                elements.append([nid(p) for p in corners + mids])
    fixed = [n for (i, _, _), n in ids.items() if i == 0]
    with open(path, "w") as f:
        f.write("*NODE, NSET=NALL\n")
        for (i, j, k), n in sorted(ids.items(), key=lambda t: t[1]):
            f.write("%d, %.12g, %.12g, %.12g\n" % (n, i * LENGTH / (2 * nx), j * WIDTH / (2 * ny),
                                                   k * HEIGHT / (2 * nz)))
        f.write("*ELEMENT, TYPE=C3D20, ELSET=EALL\n")
        for e, conn in enumerate(elements, start=1):  # 15 entries at most per line
            f.write("%d, %s,\n%s\n" % (e, ", ".join(map(str, conn[:14])),
                                       ", ".join(map(str, conn[14:]))))
        f.write("*NSET, NSET=FIX\n")
        for s in range(0, len(fixed), 10):
            f.write(", ".join(map(str, fixed[s:s + 10])) + ",\n")
        f.write("*BOUNDARY\nFIX, 1, 3\n")
        f.write("*MATERIAL, NAME=STEEL\n*ELASTIC\n%g, %g\n*DENSITY\n%g\n" % (E_MPA, NU, RHO_T_PER_MM3))
        f.write("*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL\n")
        f.write("*STEP\n*FREQUENCY\n%d\n*END STEP\n" % nmodes)
    return len(elements), 3 * (len(ids) - len(fixed))


def main(argv):
    if len(argv) != 2:
        sys.exit(__doc__)
    workdir, out = argv
    os.makedirs(workdir, exist_ok=True)
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    runs = []
    for n in (20, 40, 80):
        job = "cantilever_c3d20_n%d" % n
        elements, dofs = write_deck(os.path.join(workdir, job + ".inp"), n, n // 10, n // 10)
        t0 = time.time()
        with open(os.path.join(workdir, job + ".log"), "w") as log:
            subprocess.run(["ccx", "-i", job], check=True, cwd=workdir, stdout=log,
                           stderr=subprocess.STDOUT)
        freqs = read_frequencies(os.path.join(workdir, job + ".dat"))
        runs.append({"divisions": [n, n // 10, n // 10], "h": LENGTH / n, "elements": elements,
                     "dofs": dofs, "frequencies_hz": freqs, "seconds_ccx": round(time.time() - t0, 2)})
        print("C3D20 %d x %d x %d: %d dofs, f1..f4 = %s Hz" % (
            n, n // 10, n // 10, dofs, ", ".join("%.3f" % f for f in freqs[:4])), flush=True)
    h = [r["h"] for r in runs]
    f1 = [r["frequencies_hz"][0] for r in runs]
    p = observed_order(h, f1)
    ref = richardson(f1[1], f1[2], h[1] / h[2], p) if p else None
    doc = {"what": "100x10x10 mm steel cantilever clamped at x = 0, structured C3D20 (27-point)",
           "command": "validation/reference/cantilever_c3d20.py WORKDIR " + out,
           "versions": tool_versions(), "runs": runs, "f1_observed_order": p,
           "f1_extrapolated_hz": ref}
    with open(out, "w") as f:
        json.dump(doc, f, indent=2)
        f.write("\n")
    print("f1 observed order %s, extrapolated f1 %s Hz" % (
        "-" if p is None else "%.2f" % p, "-" if ref is None else "%.3f" % ref))


if __name__ == "__main__":
    main(sys.argv[1:])
