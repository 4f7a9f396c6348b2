#!/usr/bin/python3
"""Writes the first-order mesh of a second-order MSH: each cell's corners only (the first 4, 5, 6
or 8 of its nodes in meshio's order, which are the corners in Gmsh's order too), MSH 2.2, all
points kept. An independent path to the mesh `hexfem modal --order 1` solves on a second-order
file. Usage: order2_corners.py IN.msh OUT.msh"""
import sys

import meshio

# Debian's meshio 5.0.0 knows the wedge15 and pyramid13 types but not their dimension.
for t in ("wedge15", "pyramid13"):
    meshio._mesh.topological_dimension.setdefault(t, 3)
KEEP = {"hexahedron20": ("hexahedron", 8), "wedge15": ("wedge", 6), "pyramid13": ("pyramid", 5),
        "tetra10": ("tetra", 4)}
m = meshio.read(sys.argv[1])
cells = [(KEEP[c.type][0], c.data[:, :KEEP[c.type][1]]) for c in m.cells if c.type in KEEP]
meshio.write_points_cells(sys.argv[2], m.points, cells, file_format="gmsh22", binary=False)
