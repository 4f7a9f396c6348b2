#!/usr/bin/python3
"""Reads hexfem's order-2 exports with meshio and checks every cell: each mid-edge node within
0.25 edge lengths of its edge's midpoint under the format's own (VTK/Abaqus) node order, which a
wrong permutation breaks (~0.5). Prints `type count worst_offset` per cell type.
Usage: order2_readers.py MESH.{msh,vtu,inp}"""
import sys

import meshio
import numpy as np

# VTK quadratic cells (meshio's order for every format) and Abaqus C3D10/C3D15/C3D20: edges of
# the mid-edge nodes, in node order after the corners.
EDGES = {
    "tetra10": [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)],
    "pyramid13": [(0, 1), (1, 2), (2, 3), (3, 0), (0, 4), (1, 4), (2, 4), (3, 4)],
    "wedge15": [(0, 1), (1, 2), (2, 0), (3, 4), (4, 5), (5, 3), (0, 3), (1, 4), (2, 5)],
    "hexahedron20": [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4),
                     (0, 4), (1, 5), (2, 6), (3, 7)],
    "triangle6": [(0, 1), (1, 2), (2, 0)],
    "quad8": [(0, 1), (1, 2), (2, 3), (3, 0)],
}
CORNERS = {"tetra10": 4, "pyramid13": 5, "wedge15": 6, "hexahedron20": 8, "triangle6": 3,
           "quad8": 4}

# Debian's meshio 5.0.0 knows the wedge15 and pyramid13 types but not their dimension (a
# KeyError on any read of them).
for t in ("wedge15", "pyramid13"):
    meshio._mesh.topological_dimension.setdefault(t, 3)
m = meshio.read(sys.argv[1])
x = np.asarray(m.points)
for block in m.cells:
    if block.type not in EDGES:
        print(block.type, len(block.data), "nan")
        continue
    c = np.asarray(block.data)
    nc = CORNERS[block.type]
    worst = 0.0
    for k, (a, b) in enumerate(EDGES[block.type]):
        pa, pb, pm = x[c[:, a]], x[c[:, b]], x[c[:, nc + k]]
        length = np.linalg.norm(pb - pa, axis=1)
        off = np.linalg.norm(pm - (pa + pb) / 2, axis=1)
        ok = length > 0  # a collapsed C3D20 (pyramid) has zero-length top edges at the apex
        if ok.any():
            worst = max(worst, float((off[ok] / length[ok]).max()))
        if (~ok).any():
            worst = max(worst, float(off[~ok].max()))
    print(block.type, len(c), "%.4f" % worst)
