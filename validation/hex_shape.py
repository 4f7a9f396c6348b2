#!/usr/bin/python3
"""How far each hexahedron of a mesh is from a parallelepiped: the trilinear map
x(xi, eta, zeta) = a0 + a1 xi + a2 eta + a3 zeta + a4 xi eta + a5 eta zeta + a6 xi zeta
+ a7 xi eta zeta, and the ratio (|a4| + |a5| + |a6| + |a7|) / (|a1| + |a2| + |a3|): 0 for a
parallelepiped (an affine map, where a serendipity hex20 is complete quadratic), growing with
twist and taper. Corners only (an order-2 file's mid-edge nodes are ignored).

    /usr/bin/python3 validation/hex_shape.py mesh.msh [more.msh ...]
"""
import sys

import meshio
import numpy as np

# Gmsh's hex corner order as reference coordinates (xi, eta, zeta) in {-1, 1}.
CORNERS = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
                    [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], float)
BASIS = np.column_stack([np.ones(8), CORNERS[:, 0], CORNERS[:, 1], CORNERS[:, 2],
                         CORNERS[:, 0] * CORNERS[:, 1], CORNERS[:, 1] * CORNERS[:, 2],
                         CORNERS[:, 0] * CORNERS[:, 2], CORNERS.prod(axis=1)])


def non_affine_ratios(path):
    m = meshio.read(path)
    hexes = [c.data[:, :8] for c in m.cells if c.type in ("hexahedron", "hexahedron20")]
    if not hexes:
        return np.zeros(0)
    x = m.points[np.vstack(hexes)]                       # (n, 8, 3) corners
    a = np.einsum("ij,njk->nik", np.linalg.inv(BASIS), x)  # map coefficients (n, 8, 3)
    affine = np.linalg.norm(a[:, 1:4, :], axis=2).sum(axis=1)
    rest = np.linalg.norm(a[:, 4:8, :], axis=2).sum(axis=1)
    return rest / affine


def main():
    for path in sys.argv[1:]:
        r = non_affine_ratios(path)
        if r.size == 0:
            print(f"{path}: no hexahedra")
            continue
        print(f"{path}: {r.size} hexes, non-affine / affine median {np.median(r):.3f}, "
              f"mean {r.mean():.3f}, 90th percentile {np.percentile(r, 90):.3f}, "
              f"share above 0.1 {100 * (r > 0.1).mean():.0f} %")


if __name__ == "__main__":
    main()
