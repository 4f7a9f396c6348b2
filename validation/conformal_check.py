#!/usr/bin/python3
"""An independent check of a hexfem MSH mesh's conformity (issue 15), with meshio and numpy only.

Reads the file with meshio and derives everything from the cells (Gmsh node order):
  - faces shared by more than two cells;
  - interior quads: a quad face of two cells; an NC quad: a quad face of one cell with a triangle
    of another cell on three of its corners; every other quad or triangle of one cell must be a
    boundary element of the file (a 2D element outside the "nonconformal" group), and every
    boundary element such a face ("boundary faces match");
  - a shared face must be seen in opposite orders by its two cells (consistent orientation);
  - open boundary edges (an edge of the boundary faces not in exactly two of them);
  - inverted cells: a corner whose edge triple has a determinant <= 0;
  - the volume: the sum of the cells' volumes, each by the divergence theorem over its own
    faces (bilinear quads by 2x2 Gauss, exact), and the volume enclosed by the outer faces
    alone (the faces of one cell, less the NC quads and the triangles on their corners);
  - the boundary quads' half slivers: sum of |tet(a, b, c, d)| / 2 over the boundary quads, the
    most their bilinear faces can differ from the two triangles each was made of.
Prints one JSON object; "conformal" is true when there is no NC quad, no face of 3+ cells, no
unmatched interior triangle or quad, no orientation clash, no open edge and nothing inverted.
Usage: conformal_check.py MESH.msh"""
import itertools
import json
import sys

import meshio
import numpy as np

# Outward faces for a positive cell (hexfem's element_topology.hpp = Gmsh's convention).
FACES = {"tetra": [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)],
         "pyramid": [(0, 3, 2, 1), (0, 1, 4), (1, 2, 4), (2, 3, 4), (3, 0, 4)],
         "wedge": [(0, 2, 1), (3, 4, 5), (0, 1, 4, 3), (0, 3, 5, 2), (1, 2, 5, 4)],
         "hexahedron": [(0, 3, 2, 1), (0, 1, 5, 4), (0, 4, 7, 3), (1, 2, 6, 5), (2, 3, 7, 6),
                        (4, 5, 6, 7)]}
# Each corner and its three edge ends, right-handed for a positive cell.
CORNERS = {"tetra": [(0, 1, 2, 3), (1, 2, 0, 3), (2, 0, 1, 3), (3, 0, 2, 1)],
           "pyramid": [(0, 1, 3, 4), (1, 2, 0, 4), (2, 3, 1, 4), (3, 0, 2, 4)],
           "wedge": [(0, 1, 2, 3), (1, 2, 0, 4), (2, 0, 1, 5), (3, 5, 4, 0), (4, 3, 5, 1),
                     (5, 4, 3, 2)],
           "hexahedron": [(0, 1, 3, 4), (1, 2, 0, 5), (2, 3, 1, 6), (3, 0, 2, 7), (4, 7, 5, 0),
                          (5, 4, 6, 1), (6, 5, 7, 2), (7, 6, 4, 3)]}
G = 1 / np.sqrt(3)


def cone_volume(x, faces):
    """Sum over the faces (n, k, 3 arrays, k = 3 or 4, outward) of the cones from the origin."""
    if faces.shape[1] == 3:
        return np.einsum("ij,ij->i", faces[:, 0], np.cross(faces[:, 1], faces[:, 2])) / 6
    a, b, c, d = (faces[:, i] for i in range(4))
    v = np.zeros(len(faces))
    for u, w in itertools.product((-G, G), repeat=2):
        n = [(1 - u) * (1 - w) / 4, (1 + u) * (1 - w) / 4, (1 + u) * (1 + w) / 4,
             (1 - u) * (1 + w) / 4]
        p = n[0] * a + n[1] * b + n[2] * c + n[3] * d
        xu = ((1 - w) * (b - a) + (1 + w) * (c - d)) / 4
        xw = ((1 - u) * (d - a) + (1 + u) * (c - b)) / 4
        v += np.einsum("ij,ij->i", p, np.cross(xu, xw)) / 3
    return v


def main(path):
    mesh = meshio.read(path, file_format="gmsh")
    x = mesh.points - mesh.points.mean(axis=0)  # cones from the centre: less cancellation
    nc_tag = mesh.field_data.get("nonconformal", [None])[0]
    phys = mesh.cell_data.get("gmsh:physical", [None] * len(mesh.cells))
    # Every cell face: sorted key, the cell, the face's cyclic order.
    keys, owner, ordered = {3: [], 4: []}, {3: [], 4: []}, {3: [], 4: []}
    cells, inverted, volume = 0, 0, 0.0
    kinds = {}
    boundary = {3: set(), 4: set()}
    for block, tags in zip(mesh.cells, phys):
        if block.type in ("triangle", "quad"):
            data = block.data if tags is None or nc_tag is None else block.data[tags != nc_tag]
            boundary[data.shape[1]] |= {tuple(sorted(map(int, f))) for f in data}
            continue
        if block.type not in FACES:
            continue
        data = block.data.astype(np.int64)
        ids = np.arange(cells, cells + len(data))
        cells += len(data)
        kinds[block.type] = kinds.get(block.type, 0) + len(data)
        for c0, c1, c2, c3 in CORNERS[block.type]:
            e1, e2, e3 = (x[data[:, k]] - x[data[:, c0]] for k in (c1, c2, c3))
            det = np.einsum("ij,ij->i", e1, np.cross(e2, e3))
            if c0 == 0:
                bad = det <= 0
            else:
                bad |= det <= 0
        inverted += int(bad.sum())
        for f in FACES[block.type]:
            fn = data[:, f]
            volume += cone_volume(x, x[fn]).sum()
            keys[len(f)].append(np.sort(fn, axis=1))
            owner[len(f)].append(ids)
            ordered[len(f)].append(fn)
    out = {"file": path, "nodes": len(mesh.points), "cells": cells, "kinds": kinds}
    once = {}
    clashes, over_two = 0, 0
    for k in (3, 4):
        if not keys[k]:
            once[k] = np.zeros((0, k), dtype=np.int64), np.zeros((0, k), dtype=np.int64)
            continue
        K, O = np.concatenate(keys[k]), np.concatenate(ordered[k])
        uniq, inv, count = np.unique(K, axis=0, return_inverse=True, return_counts=True)
        inv = inv.ravel()
        over_two += int((count > 2).sum())
        # Orientation: a face of two cells, seen in opposite cyclic orders.
        two = np.nonzero(count[inv] == 2)[0]
        order = two[np.argsort(inv[two], kind="stable")]
        first, second = O[order[0::2]], O[order[1::2]]
        for r in range(len(first)):
            f, g = list(first[r]), list(second[r])
            i = g.index(f[0])
            g = g[i:] + g[:i]
            if [g[0]] + g[1:][::-1] != f:
                clashes += 1
        single = count[inv] == 1
        once[k] = K[single], O[single]
        out[f"interior_{'triangles' if k == 3 else 'quads'}"] = int((count == 2).sum())
    tri_once = {tuple(t) for t in once[3][0]}
    nc, bfaces, enclosed_faces = set(), {3: [], 4: []}, {3: [], 4: []}
    on_nc = set()
    for q, qo in zip(*once[4]):
        halves = [t for t in itertools.combinations(q, 3) if t in tri_once]
        if halves:
            nc.add(tuple(q))
            on_nc |= set(halves)
        else:
            bfaces[4].append(tuple(q))
            enclosed_faces[4].append(qo)
    for t, to in zip(*once[3]):
        if tuple(t) not in on_nc:
            bfaces[3].append(tuple(t))
            enclosed_faces[3].append(to)
    unmatched = {k: len(set(bfaces[k]) - boundary[k]) for k in (3, 4)}
    missing = {k: len(boundary[k] - set(bfaces[k])) for k in (3, 4)}
    edges = {}
    for k in (3, 4):
        for f in enclosed_faces[k]:
            for i in range(k):
                e = tuple(sorted((int(f[i]), int(f[(i + 1) % k]))))
                edges[e] = edges.get(e, 0) + 1
    open_edges = sum(1 for n in edges.values() if n != 2)
    enclosed = sum(cone_volume(x, x[np.array(enclosed_faces[k])]).sum()
                   for k in (3, 4) if enclosed_faces[k])
    half_slivers = 0.0
    if enclosed_faces[4]:
        q = x[np.array(enclosed_faces[4])]
        half_slivers = float(np.abs(np.einsum("ij,ij->i", q[:, 1] - q[:, 0], np.cross(
            q[:, 2] - q[:, 0], q[:, 3] - q[:, 0]))).sum() / 12)
    out.update({"nc_quads": len(nc), "faces_of_3_or_more_cells": over_two,
                "orientation_clashes": clashes,
                "unmatched_faces": unmatched[3] + unmatched[4],
                "boundary_elements_not_a_face": missing[3] + missing[4],
                "boundary_faces": len(bfaces[3]) + len(bfaces[4]),
                "boundary_quads": len(bfaces[4]), "open_boundary_edges": open_edges,
                "inverted": inverted, "volume": float(volume), "enclosed_volume": float(enclosed),
                "boundary_quad_half_slivers": half_slivers})
    out["conformal"] = (not nc and not over_two and not clashes and not open_edges and
                        not inverted and out["unmatched_faces"] == 0 and
                        out["boundary_elements_not_a_face"] == 0)
    print(json.dumps(out))
    return 0 if out["conformal"] else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
