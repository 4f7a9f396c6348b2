#!/usr/bin/python3
"""Serendipity hex20 against Lagrange hex27 on hexes that are not parallelepipeds (issue 12).

The model problem: the first Dirichlet eigenvalue of -Laplace on the cube [0, pi]^3, exactly 3
(u = sin x sin y sin z). An n x n x n grid of hexes whose interior vertices are moved by
+-delta h in a checkerboard pattern (dx ~ (-1)^(J+K), dy ~ (-1)^(I+K), dz ~ (-1)^(I+J)), so that
each hex is twisted and tapered by about delta of its size at every n, as the hexes of a remeshed
round part are (validation/hex_shape.py measures the same ratio: 0.06-0.10 median on the
cylinder and the sphere). Geometry is trilinear in both (the mid-edge, face and cell nodes sit
where the hex's trilinear map puts them); 4x4x4 Gauss points; free DOF = nodes off the boundary.
Lowest eigenvalue by inverse iteration on dense matrices (numpy only).

    /usr/bin/python3 validation/serendipity_vs_lagrange.py [--n 2,3,4,5,6] [--delta 0,0.1]
"""
import argparse
import itertools

import numpy as np

CORNERS = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
                    [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], float)


def lagrange_1d(t):
    """Values and derivatives of the quadratic Lagrange basis at nodes -1, 0, 1."""
    v = np.array([t * (t - 1) / 2, 1 - t * t, t * (t + 1) / 2])
    d = np.array([t - 0.5, -2 * t, t + 0.5])
    return v, d


def lagrange27(x):
    """Shape functions and gradients of the 27-node hex at reference point x; nodes are the
    offsets (a, b, c) in {-1, 0, 1}^3 in itertools.product order."""
    vx, dx = lagrange_1d(x[0])
    vy, dy = lagrange_1d(x[1])
    vz, dz = lagrange_1d(x[2])
    n, g = [], []
    for i, j, k in itertools.product(range(3), repeat=3):
        n.append(vx[i] * vy[j] * vz[k])
        g.append([dx[i] * vy[j] * vz[k], vx[i] * dy[j] * vz[k], vx[i] * vy[j] * dz[k]])
    return np.array(n), np.array(g)


def serendipity20_nodes():
    """Reference offsets of the 20 nodes: those of the 27 with at most one zero coordinate."""
    return [o for o in itertools.product((-1, 0, 1), repeat=3) if sum(c == 0 for c in o) <= 1]


def serendipity20(x, nodes):
    n, g = [], []
    for o in nodes:
        o = np.array(o, float)
        if not (o == 0).any():  # corner
            a = [(1 + x[d] * o[d]) for d in range(3)]
            n.append(a[0] * a[1] * a[2] * (x @ o - 2) / 8)
            gr = []
            for d in range(3):
                others = np.prod([a[e] for e in range(3) if e != d])
                gr.append(o[d] * others * (x @ o - 2) / 8 + a[0] * a[1] * a[2] * o[d] / 8)
            g.append(gr)
        else:  # mid-edge: coordinate m is zero
            m = int(np.where(o == 0)[0][0])
            rest = [d for d in range(3) if d != m]
            b = {d: 1 + x[d] * o[d] for d in rest}
            n.append((1 - x[m] ** 2) * b[rest[0]] * b[rest[1]] / 4)
            gr = [0.0] * 3
            gr[m] = -2 * x[m] * b[rest[0]] * b[rest[1]] / 4
            gr[rest[0]] = (1 - x[m] ** 2) * o[rest[0]] * b[rest[1]] / 4
            gr[rest[1]] = (1 - x[m] ** 2) * b[rest[0]] * o[rest[1]] / 4
            g.append(gr)
    return np.array(n), np.array(g)


def trilinear(x):
    n = np.array([np.prod(1 + x * c) / 8 for c in CORNERS])
    g = np.array([[c[d] * np.prod([1 + x[e] * c[e] for e in range(3) if e != d]) / 8
                   for d in range(3)] for c in CORNERS])
    return n, g


def gauss(npts):
    t, w = np.polynomial.legendre.leggauss(npts)
    return [(np.array(p), np.prod(ws)) for p, ws in
            zip(itertools.product(t, repeat=3), itertools.product(w, repeat=3))]


def lowest_eigenvalue(n, delta, kind, quad):
    h = np.pi / n
    # Corner grid, interior vertices moved in a checkerboard pattern.
    X = np.zeros((n + 1, n + 1, n + 1, 3))
    for I, J, K in itertools.product(range(n + 1), repeat=3):
        p = np.array([I, J, K], float) * h
        if 0 < I < n and 0 < J < n and 0 < K < n:
            p += delta * h * np.array([(-1) ** (J + K), (-1) ** (I + K), (-1) ** (I + J)])
        X[I, J, K] = p
    offsets = (serendipity20_nodes() if kind == "hex20"
               else list(itertools.product((-1, 0, 1), repeat=3)))
    # Global nodes on the (2n+1)^3 half-step grid.
    index = {}
    def node(key):
        if key not in index:
            index[key] = len(index)
        return index[key]
    elems = []
    for I, J, K in itertools.product(range(n), repeat=3):
        ids = [node((2 * I + 1 + o[0], 2 * J + 1 + o[1], 2 * K + 1 + o[2])) for o in offsets]
        corners = np.array([X[I + (c[0] > 0), J + (c[1] > 0), K + (c[2] > 0)] for c in CORNERS])
        elems.append((ids, corners))
    N = len(index)
    boundary = np.zeros(N, bool)
    for key, i in index.items():
        boundary[i] = any(k == 0 or k == 2 * n for k in key)
    Kg = np.zeros((N, N))
    Mg = np.zeros((N, N))
    ref = [(x, w, *(serendipity20(x, offsets) if kind == "hex20" else lagrange27(x)), trilinear(x)[1])
           for x, w in quad]
    for ids, corners in elems:
        Ke = np.zeros((len(ids), len(ids)))
        Me = np.zeros_like(Ke)
        for x, w, Nv, G, Gg in ref:
            J = corners.T @ Gg  # dX/dxi (3x3)
            detJ = np.linalg.det(J)
            B = G @ np.linalg.inv(J)  # dN/dX
            Ke += w * detJ * B @ B.T
            Me += w * detJ * np.outer(Nv, Nv)
        ix = np.array(ids)
        Kg[np.ix_(ix, ix)] += Ke
        Mg[np.ix_(ix, ix)] += Me
    free = ~boundary
    K, M = Kg[np.ix_(free, free)], Mg[np.ix_(free, free)]
    L = np.linalg.cholesky(K)
    v = np.ones(K.shape[0])
    lam = 0
    for _ in range(200):
        w = np.linalg.solve(L.T, np.linalg.solve(L, M @ v))
        new = (w @ K @ w) / (w @ M @ w)
        v = w / np.sqrt(w @ M @ w)
        if abs(new - lam) < 1e-14 * new:
            break
        lam = new
    return int(free.sum()), new


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", default="2,3,4,5,6")
    ap.add_argument("--delta", default="0,0.1")
    a = ap.parse_args()
    quad = gauss(4)
    for delta in [float(d) for d in a.delta.split(",")]:
        print(f"delta = {delta}")
        print("| n | hex20 DOF | hex20 error | hex27 DOF | hex27 error |")
        print("|---:|---:|---:|---:|---:|")
        for n in [int(x) for x in a.n.split(",")]:
            d20, l20 = lowest_eigenvalue(n, delta, "hex20", quad)
            d27, l27 = lowest_eigenvalue(n, delta, "hex27", quad)
            print(f"| {n} | {d20} | {(l20 - 3) / 3:.3e} | {d27} | {(l27 - 3) / 3:.3e} |", flush=True)


if __name__ == "__main__":
    main()
