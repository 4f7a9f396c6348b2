#!/usr/bin/python3
"""Why hexfem's tet4 and CalculiX's C3D4 differ (validation/solver.md, section 3).

A 2 x 1 x 1 box of 12 Kuhn tets, clamped at x = 0 (E = 1000, nu = 0.3, rho = 1): the first four
frequencies from a numpy model with the exact consistent tet mass rho*V*(1+delta_ij)/20 and with a
one-point mass rho*V/16 (every entry), next to ccx's C3D4 on the same deck. hexfem's tet4 gives
1.73111668 1.97287828 4.25887331 5.16000827 Hz on this mesh (make_box_mesh({2,1,1},2,1,1,Tet4),
--fix face:1), the consistent values. Run: /usr/bin/python3 validation/ccx_c3d4_mass.py
"""
import itertools
import os
import subprocess
import tempfile

import numpy as np

E, NU, RHO = 1000.0, 0.3, 1.0
LAM = E * NU / ((1 + NU) * (1 - 2 * NU))
MU = E / (2 * (1 + NU))

nodes = [(i, j, k) for k in range(2) for j in range(2) for i in range(3)]
index = {n: i for i, n in enumerate(nodes)}
X = np.array(nodes, float)
tets = []
for c in range(2):
    for perm in itertools.permutations(range(3)):
        o = [c, 0, 0]
        path = [tuple(o)]
        for a in perm:
            o[a] += 1
            path.append(tuple(o))
        t = [index[q] for q in path]
        J = np.array([X[t[1]] - X[t[0]], X[t[2]] - X[t[0]], X[t[3]] - X[t[0]]]).T
        if np.linalg.det(J) < 0:
            t[1], t[2] = t[2], t[1]
        tets.append(t)


def frequencies(one_point_mass):
    n = 3 * len(nodes)
    K, M = np.zeros((n, n)), np.zeros((n, n))
    for t in tets:
        J = np.array([X[t[1]] - X[t[0]], X[t[2]] - X[t[0]], X[t[3]] - X[t[0]]]).T
        V = np.linalg.det(J) / 6
        g = np.array([[-1, -1, -1], [1, 0, 0], [0, 1, 0], [0, 0, 1]]) @ np.linalg.inv(J)
        for a in range(4):
            for b in range(4):
                k = V * (LAM * np.outer(g[a], g[b]) + MU * np.outer(g[b], g[a]) +
                         MU * g[a] @ g[b] * np.eye(3))
                m = RHO * V / 16 if one_point_mass else RHO * V * (2 if a == b else 1) / 20
                K[3 * t[a]:3 * t[a] + 3, 3 * t[b]:3 * t[b] + 3] += k
                M[3 * t[a]:3 * t[a] + 3, 3 * t[b]:3 * t[b] + 3] += m * np.eye(3)
    free = [3 * i + a for i, nd in enumerate(nodes) if nd[0] > 0 for a in range(3)]
    w = np.linalg.eigvals(np.linalg.solve(M[np.ix_(free, free)], K[np.ix_(free, free)]))
    return np.sqrt(np.sort(w.real)[:4]) / (2 * np.pi)


def ccx_frequencies():
    with tempfile.TemporaryDirectory() as d:
        with open(os.path.join(d, "box.inp"), "w") as f:
            f.write("*NODE, NSET=NALL\n")
            for i, nd in enumerate(nodes):
                f.write(f"{i + 1}, {nd[0]}, {nd[1]}, {nd[2]}\n")
            f.write("*ELEMENT, TYPE=C3D4, ELSET=EALL\n")
            for e, t in enumerate(tets):
                f.write(f"{e + 1}, " + ", ".join(str(v + 1) for v in t) + "\n")
            f.write("*BOUNDARY\n")
            for i, nd in enumerate(nodes):
                if nd[0] == 0:
                    f.write(f"{i + 1}, 1, 3\n")
            f.write("*MATERIAL, NAME=MAT\n*ELASTIC\n1000, 0.3\n*DENSITY\n1\n"
                    "*SOLID SECTION, ELSET=EALL, MATERIAL=MAT\n*STEP\n*FREQUENCY\n4\n*END STEP\n")
        subprocess.run(["ccx", "box"], cwd=d, capture_output=True, check=True)
        out, block = [], False
        for line in open(os.path.join(d, "box.dat")):
            if "E I G E N V A L U E" in line:
                block = True
            elif block and "P A R T I C I P" in line:
                break
            elif block:
                parts = line.split()
                if len(parts) == 5 and parts[0].isdigit():
                    out.append(float(parts[3]))
        return np.array(out)


np.set_printoptions(precision=7)
print("consistent mass (hexfem):", frequencies(False))
print("one-point mass          :", frequencies(True))
print("ccx C3D4                :", ccx_frequencies())
