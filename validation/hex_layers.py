#!/usr/bin/python3
"""Where a mesh's non-hex volume sits (issue 16): each cell is counted in the layer of its vertex
nearest the CAD surface, in steps of one element (layer 0 touches the surface; the surface is the
boundary faces of the .msh, without the physical group "nonconformal", whose quads are inside).
Prints, per layer, the share of the volume, H_vol and the non-hex volume as a share of the part.

    hexfem mesh ../shared/models/ANC101.stp --h 4.5 -o anc.msh
    /usr/bin/python3 validation/hex_layers.py anc.msh [--last 6]
"""
import argparse
from collections import defaultdict, deque

import meshio
import numpy as np

# Cells split into tets from their centroid, by faces (corner indices, Gmsh/meshio order).
FACES = {
    "tetra": [(0, 1, 2), (0, 3, 1), (1, 3, 2), (0, 2, 3)],
    "pyramid": [(0, 1, 2), (0, 2, 3), (0, 1, 4), (1, 2, 4), (2, 3, 4), (3, 0, 4)],
    "wedge": [(0, 1, 2), (3, 4, 5), (0, 1, 4), (0, 4, 3), (1, 2, 5), (1, 5, 4), (2, 0, 3),
              (2, 3, 5)],
    "hexahedron": [(0, 1, 2), (0, 2, 3), (4, 5, 6), (4, 6, 7), (0, 1, 5), (0, 5, 4), (1, 2, 6),
                   (1, 6, 5), (2, 3, 7), (2, 7, 6), (3, 0, 4), (3, 4, 7)],
}


def volume(points, kind, cell):
    x = points[cell]
    g = x.mean(axis=0)
    return sum(abs(np.dot(x[a] - g, np.cross(x[b] - g, x[c] - g))) / 6
               for a, b, c in FACES[kind])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("msh")
    ap.add_argument("--last", type=int, default=6, help="layers from this one on are summed")
    a = ap.parse_args()
    m = meshio.read(a.msh)
    nc_tag = m.field_data.get("nonconformal", [None])[0]
    surface = set()
    for block, phys in zip(m.cells, m.cell_data["gmsh:physical"]):
        if block.type in ("quad", "triangle") and phys[0] != nc_tag:
            surface.update(block.data.ravel().tolist())
    cells = [(b.type, c) for b in m.cells if b.type in FACES for c in b.data]
    adjacent = defaultdict(set)
    for _, c in cells:
        for v in c:
            adjacent[v].update(c.tolist())
    layer = np.full(len(m.points), -1)
    queue = deque(surface)
    for v in surface:
        layer[v] = 0
    while queue:
        v = queue.popleft()
        for w in adjacent[v]:
            if layer[w] < 0:
                layer[w] = layer[v] + 1
                queue.append(w)
    vol = defaultdict(lambda: [0.0, 0.0])  # layer -> [all, hex]
    for kind, c in cells:
        k = min(int(layer[c].min()), a.last)
        v = volume(m.points, kind, c)
        vol[k][0] += v
        vol[k][1] += v if kind == "hexahedron" else 0
    total = sum(v[0] for v in vol.values())
    print("| layer | share of the volume | H_vol | non-hex volume, % of the part |")
    print("|---:|---:|---:|---:|")
    for k in sorted(vol):
        v, h = vol[k]
        name = f"{k}+" if k == a.last else str(k)
        print(f"| {name} | {100 * v / total:.1f} % | {100 * h / v:.1f} % | "
              f"{100 * (v - h) / total:.2f} |")


if __name__ == "__main__":
    main()
