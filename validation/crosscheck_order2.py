#!/usr/bin/python3
"""Order-2 cross-check of hexfem against CalculiX 2.20 on the SAME nodes and cells (issue 12).

  validation/crosscheck_order2.py [--out validation/out/crosscheck_order2] [--hexfem BIN]
      [--modes 10] [--json FILE] [--part-h 2] [--skip-part]

hexfem reads an order-1 .msh with `--order 2` (straight mid-edge nodes at the edge midpoints);
this script writes ccx's decks itself, with the same mid-edge nodes (edge midpoints computed
here, in Abaqus node order), so any difference comes from the element formulations.
1. 100 x 10 x 10 mm cantilever clamped at x = 0, 40 x 4 x 4 hex20 (and the same grid with every
   node moved by up to 0.15 spacing: non-affine hex20 with straight edges) against C3D20
   (3x3x3 Gauss, as hexfem); C3D20R (2x2x2) shown for information: hexfem has no reduced hex20.
2. One-kind boxes (20 x 2 x 2 grid): tet10 (Kuhn), wedge15, pyramid13 against C3D10, C3D15 and
   the C3D20 collapsed onto the apex that `hexfem mesh --order 2 -o .inp` writes for a pyramid.
   A dense numpy assembly, independent of both codes, computes each box with the exact rule and
   with ccx's rule, which says where each difference comes from.
3. The steel part at h = --part-h: `hexfem mesh --order 2 -o part.inp` read by ccx (curved
   mid-edge nodes, every kind), against `hexfem modal part.step --order 2` on the same mesh.
Units: mm, N, tonne -> Hz. Exit status 1 if hex20 vs C3D20 or tet10 vs numpy/ccx-rule misses 1e-6.
"""
import argparse
import json
import math
import os
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import crosscheck_ccx as xc  # noqa: E402  (box grids, MSH 2.2 writer, ccx runner and parser)

ROOT = xc.ROOT
TOL = 1e-6

# Abaqus/CalculiX mid-edge nodes of each kind, as pairs of corners (0-based, Gmsh = Abaqus corners).
C3D10_EDGES = [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)]
C3D15_EDGES = [(0, 1), (1, 2), (2, 0), (3, 4), (4, 5), (5, 3), (0, 3), (1, 4), (2, 5)]
C3D20_EDGES = [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4), (1, 5),
               (2, 6), (3, 7)]
# A pyramid as the C3D20 that hexfem's INP writes: corners 1 2 3 4 5 5 5 5, top mid-edges = apex.
PYR_AS_C3D20 = [0, 1, 2, 3, 4, 4, 4, 4]
PYR_C3D20_EDGES = [(0, 1), (1, 2), (2, 3), (3, 0), None, None, None, None, (0, 4), (1, 4),
                   (2, 4), (3, 4)]


def quadratic_cells(kind, xyz, conn):
    """Adds the edge midpoints; returns (xyz, rows of Abaqus node indices (0-based), ccx type)."""
    mids, new = {}, []

    def mid(a, b):
        key = (min(a, b), max(a, b))
        if key not in mids:
            mids[key] = len(xyz) + len(new)
            new.append((xyz[a] + xyz[b]) / 2)
        return mids[key]

    rows = []
    for c in conn.tolist():
        if kind == "tet10":
            rows.append(c + [mid(c[a], c[b]) for a, b in C3D10_EDGES])
        elif kind == "wedge15":
            rows.append(c + [mid(c[a], c[b]) for a, b in C3D15_EDGES])
        elif kind == "hex20":
            rows.append(c + [mid(c[a], c[b]) for a, b in C3D20_EDGES])
        else:  # pyramid13 as a collapsed C3D20
            rows.append([c[i] for i in PYR_AS_C3D20] +
                        [c[4] if e is None else mid(c[e[0]], c[e[1]]) for e in PYR_C3D20_EDGES])
    typ = {"tet10": "C3D10", "wedge15": "C3D15", "hex20": "C3D20", "pyramid13": "C3D20"}[kind]
    return np.vstack([xyz] + new) if new else xyz, np.array(rows), typ


def write_mesh_inp(path, xyz, rows, typ):
    out = ["*NODE, NSET=NALL"] + [f"{i + 1},{p[0]!r},{p[1]!r},{p[2]!r}"
                                  for i, p in enumerate(xyz.tolist())]
    out.append(f"*ELEMENT, TYPE={typ}, ELSET=EALL")
    for e, r in enumerate(rows.tolist(), start=1):
        ids = [e] + [v + 1 for v in r]
        out.append(",".join(map(str, ids[:16])) + ("," if len(ids) > 16 else ""))
        if len(ids) > 16:
            out.append(",".join(map(str, ids[16:])))
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


# ---------------------------------------------------------------- independent dense numpy FE


def gauss01(n):
    x, w = np.polynomial.legendre.leggauss(n)
    return (x + 1) / 2, w / 2


def rule_exact(kind, n=4):
    """Gauss-Legendre product rules (Duffy-collapsed for the simplex parts), exact to degree
    2n-1 per collapsed variable: enough for the mass and stiffness of affine order-2 cells."""
    g, w = gauss01(n)
    pts, wts = [], []
    if kind == "tet10":
        for a, wa in zip(g, w):
            for b, wb in zip(g, w):
                for c, wc in zip(g, w):
                    pts.append((a * (1 - b) * (1 - c), b * (1 - c), c))
                    wts.append(wa * wb * wc * (1 - b) * (1 - c) ** 2)
    elif kind == "wedge15":
        for a, wa in zip(g, w):
            for b, wb in zip(g, w):
                for c, wc in zip(g, w):
                    pts.append((a * (1 - b), b, 2 * c - 1))
                    wts.append(2 * wa * wb * wc * (1 - b))
    else:  # hex20 and the collapsed C3D20: Gauss on [-1, 1]^3
        x, wx = np.polynomial.legendre.leggauss(n)
        for a, wa in zip(x, wx):
            for b, wb in zip(x, wx):
                for c, wc in zip(x, wx):
                    pts.append((a, b, c))
                    wts.append(wa * wb * wc)
    return np.array(pts), np.array(wts)


def rule_ccx(kind):
    """CalculiX's points for each type (ccx 2.20, e_c3d.f / gauss.f): C3D10 4 points
    (a = 0.1381966, the degree-2 rule), C3D15 3-point triangle x 3-point Gauss, C3D20 3x3x3."""
    if kind == "tet10":
        a, b = (5 - math.sqrt(5)) / 20, (5 + 3 * math.sqrt(5)) / 20
        return np.array([(a, a, a), (b, a, a), (a, b, a), (a, a, b)]), np.full(4, 1 / 24)
    if kind == "wedge15":
        x, wx = np.polynomial.legendre.leggauss(3)
        tri = [(1 / 6, 1 / 6), (2 / 3, 1 / 6), (1 / 6, 2 / 3)]
        pts = [(s, t, z) for z in x for s, t in tri]
        return np.array(pts), np.array([wz / 6 for wz in wx for _ in tri])
    return rule_exact(kind, 3)


def shapes(kind, p):
    """N (q, n) and dN/dxi (q, n, 3) in Abaqus node order at reference points p (q, 3)."""
    x, y, z = p[:, 0], p[:, 1], p[:, 2]
    q = len(p)
    if kind == "tet10":
        L = np.stack([1 - x - y - z, x, y, z], axis=1)
        dL = np.array([[-1, -1, -1], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
        N = np.zeros((q, 10))
        dN = np.zeros((q, 10, 3))
        for i in range(4):
            N[:, i] = L[:, i] * (2 * L[:, i] - 1)
            dN[:, i] = (4 * L[:, i] - 1)[:, None] * dL[i]
        for k, (a, b) in enumerate(C3D10_EDGES):
            N[:, 4 + k] = 4 * L[:, a] * L[:, b]
            dN[:, 4 + k] = 4 * (L[:, b][:, None] * dL[a] + L[:, a][:, None] * dL[b])
        return N, dN
    if kind == "wedge15":
        L = np.stack([1 - x - y, x, y], axis=1)
        dL = np.array([[-1, -1], [1, 0], [0, 1]], float)
        N = np.zeros((q, 15))
        dN = np.zeros((q, 15, 3))
        for i in range(6):
            a, s = i % 3, (-1.0 if i < 3 else 1.0)
            h, r = 1 + s * z, 2 * L[:, a] + s * z - 2
            N[:, i] = L[:, a] * h * r / 2
            dN[:, i, :2] = (h * (r + 2 * L[:, a]) / 2)[:, None] * dL[a]
            dN[:, i, 2] = L[:, a] * s * (r + h) / 2
        for k, (i, j) in enumerate(C3D15_EDGES):
            if i % 3 == j % 3:  # vertical
                a = i % 3
                N[:, 6 + k] = L[:, a] * (1 - z * z)
                dN[:, 6 + k, :2] = (1 - z * z)[:, None] * dL[a]
                dN[:, 6 + k, 2] = -2 * z * L[:, a]
            else:
                a, b, s = i % 3, j % 3, (-1.0 if i < 3 else 1.0)
                h = 1 + s * z
                N[:, 6 + k] = 2 * L[:, a] * L[:, b] * h
                dN[:, 6 + k, :2] = (2 * h)[:, None] * (L[:, b][:, None] * dL[a] +
                                                        L[:, a][:, None] * dL[b])
                dN[:, 6 + k, 2] = 2 * L[:, a] * L[:, b] * s
        return N, dN
    # hex20 serendipity (also the collapsed pyramid: same functions, repeated nodes)
    corner = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1], [-1, -1, 1],
                       [1, -1, 1], [1, 1, 1], [-1, 1, 1]], float)
    N = np.zeros((q, 20))
    dN = np.zeros((q, 20, 3))
    for i, c in enumerate(corner):
        f = 1 + c[None, :] * p
        s = p @ c - 2
        prod = f.prod(axis=1)
        N[:, i] = prod * s / 8
        for d in range(3):
            dN[:, i, d] = (c[d] * prod / f[:, d] * s + prod * c[d]) / 8
    for k, (a, b) in enumerate(C3D20_EDGES):
        c = (corner[a] + corner[b]) / 2
        t = int(np.nonzero(c == 0)[0][0])
        u, v = (t + 1) % 3, (t + 2) % 3
        bt, fu, fv = 1 - p[:, t] ** 2, 1 + c[u] * p[:, u], 1 + c[v] * p[:, v]
        N[:, 8 + k] = bt * fu * fv / 4
        dN[:, 8 + k, t] = -2 * p[:, t] * fu * fv / 4
        dN[:, 8 + k, u] = bt * c[u] * fv / 4
        dN[:, 8 + k, v] = bt * fu * c[v] / 4
    return N, dN


def numpy_modes(kind, xyz, rows, clamp, nmodes, rule):
    """Dense K, M (E, nu, rho of crosscheck_ccx) with the given rule; clamped nodes removed;
    the lowest nmodes frequencies in Hz."""
    lam = xc.E_MPA * xc.NU / ((1 + xc.NU) * (1 - 2 * xc.NU))
    mu = xc.E_MPA / (2 * (1 + xc.NU))
    pts, wts = rule
    N, dN = shapes(kind, pts)
    X = xyz[rows]  # (e, n, 3)
    J = np.einsum("eni,qnj->eqij", X, dN)
    det = np.linalg.det(J)
    if det.min() <= 0:
        sys.exit(f"numpy {kind}: non-positive Jacobian")
    G = np.einsum("qnj,eqji->eqni", dN, np.linalg.inv(J))  # physical gradients
    wd = det * wts[None, :]
    GG = np.einsum("eqak,eqbk->eqab", G, G)
    n = rows.shape[1]
    Ke = (lam * np.einsum("eq,eqai,eqbj->eaibj", wd, G, G) +
          mu * np.einsum("eq,eqaj,eqbi->eaibj", wd, G, G) +
          mu * np.einsum("eq,eqab,ij->eaibj", wd, GG, np.eye(3)))
    me = xc.RHO_T_MM3 * np.einsum("eq,qa,qb->eab", wd, N, N)
    ndof = 3 * len(xyz)
    K, M = np.zeros((ndof, ndof)), np.zeros((ndof, ndof))
    dof = (3 * rows[:, :, None] + np.arange(3)[None, None, :]).reshape(len(rows), 3 * n)
    np.add.at(K, (dof[:, :, None], dof[:, None, :]), Ke.reshape(len(rows), 3 * n, 3 * n))
    Me = np.einsum("eab,ij->eaibj", me, np.eye(3)).reshape(len(rows), 3 * n, 3 * n)
    np.add.at(M, (dof[:, :, None], dof[:, None, :]), Me)
    used = np.zeros(len(xyz), bool)
    used[rows.ravel()] = True
    free = np.array([d for d in range(ndof) if used[d // 3] and not clamp(xyz[d // 3])])
    Linv = np.linalg.inv(np.linalg.cholesky(K[np.ix_(free, free)]))
    m_ = np.linalg.eigvalsh(Linv @ M[np.ix_(free, free)] @ Linv.T)[::-1][:nmodes]
    return [math.sqrt(1 / v) / (2 * math.pi) for v in m_]


# ---------------------------------------------------------------- cases


def hexfem_modal(args, workdir, msh, fix, log, extra=()):
    cmd = [args.hexfem, "modal", msh, "--fix", fix, "--units", "mm", "--modes", str(args.modes),
           "--json"] + list(extra)
    out, secs = xc.run(cmd, workdir, log)
    d = json.loads(out)
    return {"freq": [m["frequency_hz"] for m in d["modes"]], "seconds": secs,
            "command": f"cd {workdir} && {xc.shell_line(cmd)}", "dofs": d.get("free_dofs"),
            "order": d.get("order"), "elements": d.get("elements")}


def ccx_case(args, out, key, xyz, rows, typ, fixed, types=None):
    """Runs ccx on the quadratic mesh with each element type in types (default: typ)."""
    res = {}
    for t in types or [typ]:
        inp = os.path.join(out, f"mesh_{key}_{t}.inp")
        write_mesh_inp(inp, xyz, rows, t)
        job = f"{key}_{t}"
        xc.write_deck(os.path.join(out, job + ".inp"), inp, "CLAMP", args.modes,
                      ("CLAMP", [i + 1 for i in fixed]))
        res[t] = xc.run_ccx(out, job)
    return res


def box_case(args, out, key, kind, tags, xyz, cells, numpy_check):
    """hexfem --order 2 on the order-1 box, ccx on the same quadratic mesh, numpy if asked."""
    msh = os.path.join(out, f"mesh_{key}.msh")
    xc.write_msh22(msh, tags, xyz, cells, [])
    typ, conn = cells[0]
    qxyz, rows, ccx_type = quadratic_cells(kind, xyz, conn - 1)
    fixed = [i for i, p in enumerate(qxyz.tolist()) if abs(p[0]) < 1e-9]
    r = {"kind": kind, "cells": len(conn), "nodes": len(qxyz), "fixed_nodes": len(fixed)}
    r["hexfem"] = hexfem_modal(args, out, os.path.basename(msh), "x<1e-6",
                               os.path.join(out, f"hexfem_{key}.log"), ["--order", "2"])
    types = [ccx_type] + (["C3D20R"] if kind == "hex20" else [])
    r["ccx"] = ccx_case(args, out, key, qxyz, rows, ccx_type, fixed, types)
    if numpy_check:
        clamp = lambda p: abs(p[0]) < 1e-9  # noqa: E731
        t0 = time.time()
        r["numpy_exact"] = numpy_modes(kind, qxyz, rows, clamp, args.modes, rule_exact(kind))
        r["numpy_ccx_rule"] = numpy_modes(kind, qxyz, rows, clamp, args.modes, rule_ccx(kind))
        r["numpy_seconds"] = time.time() - t0
    print(f"  {key}: {len(conn)} {kind}, {len(qxyz)} nodes, {len(fixed)} clamped", flush=True)
    return r


def structured(args, out, report):
    rep = report["structured"] = {}
    for key, jitter in (("hex20", 0.0), ("hex20_jitter", 0.15)):
        tags, xyz, cells = xc.box_grid(jitter=jitter)
        rep[key] = box_case(args, out, key, "hex20", tags, xyz, cells, False)
        rep[key]["jitter"] = jitter
    for kind, order1 in (("tet10", "tet4"), ("wedge15", "wedge6"), ("pyramid13", "pyramid5")):
        tags, xyz, cells = xc.split_box(order1)
        rep[kind] = box_case(args, out, kind, kind, tags, xyz, cells, True)


def steel_part(args, out, report):
    """ccx reads the order-2 INP that hexfem writes; hexfem solves the same mesh."""
    step = os.path.join(ROOT, "models", "steel_part.step")
    h = f"{args.part_h:g}"
    inp = os.path.join(out, "part_order2.inp")
    xc.run([args.hexfem, "mesh", step, "--h", h, "--order", "2", "-o", inp], out,
           os.path.join(out, "mesh_part.log"))
    text = open(inp).read()
    counts = {t: text.count(f"TYPE={t}") for t in ("C3D20", "C3D15", "C3D10")}
    pyramids = sum(1 for line in text.split("\n") if line.startswith("*ELEMENT")
                   and "PYRAMID" in line.upper())
    xc.write_deck(os.path.join(out, "part.inp"), inp, "FACE_8", args.modes)
    r = report["part"] = {"h": args.part_h, "element_blocks": counts, "pyramid_blocks": pyramids}
    r["ccx"] = xc.run_ccx(out, "part")
    r["hexfem"] = hexfem_modal(args, out, step, "face:8", os.path.join(out, "hexfem_part.log"),
                               ["--h", h, "--order", "2"])
    print(f"steel part h = {h}: ccx {r['ccx']['seconds']:.1f} s, hexfem "
          f"{r['hexfem']['seconds']:.1f} s", flush=True)


# ---------------------------------------------------------------- report


def maxrel(a, b, n):
    return max(abs(x - y) / abs(y) for x, y in zip(a[:n], b[:n]))


def summarize(args, report):
    n, md, worst = args.modes, [], {}
    st = report["structured"]
    md += ["### Structured boxes: hexfem --order 2 against ccx on the same quadratic mesh", "",
           "| mesh | cells | hexfem vs ccx | hexfem vs numpy, exact rule | ccx vs numpy, ccx's rule "
           "| ccx C3D20R vs C3D20 |", "|---|---|---:|---:|---:|---:|"]
    for key, r in st.items():
        hx, c = r["hexfem"]["freq"], r["ccx"]
        typ = next(iter(c))
        worst[f"{key}/ccx"] = maxrel(hx, c[typ]["freq"], n)
        ne = nc = red = "-"
        if "numpy_exact" in r:
            worst[f"{key}/numpy_exact"] = maxrel(hx, r["numpy_exact"], n)
            worst[f"{key}/ccx_numpy_rule"] = maxrel(c[typ]["freq"], r["numpy_ccx_rule"], n)
            ne = f"{worst[f'{key}/numpy_exact']:.1e}"
            nc = f"{worst[f'{key}/ccx_numpy_rule']:.1e}"
        if "C3D20R" in c:
            red = f"{maxrel(c['C3D20R']['freq'], c[typ]['freq'], n):.1e}"
        md.append(f"| {key} | {r['cells']} {r['kind']} ({typ}) | {worst[f'{key}/ccx']:.1e} | "
                  f"{ne} | {nc} | {red} |")
    md.append("")
    for key, r in st.items():
        hx, c = r["hexfem"]["freq"], r["ccx"]
        typ = next(iter(c))
        cols = [("hexfem", hx), (f"ccx {typ}", c[typ]["freq"])]
        if "numpy_exact" in r:
            cols += [("numpy exact", r["numpy_exact"]), ("numpy ccx rule", r["numpy_ccx_rule"])]
        if "C3D20R" in c:
            cols.append(("ccx C3D20R", c["C3D20R"]["freq"]))
        md += [f"#### {key} [Hz]", "", "| mode | " + " | ".join(h for h, _ in cols) +
               " | (hexfem - ccx)/ccx |", "|---:" * (len(cols) + 2) + "|"]
        for m in range(n):
            md.append(f"| {m + 1} | " + " | ".join(f"{v[m]:.10g}" for _, v in cols) +
                      f" | {(hx[m] - c[typ]['freq'][m]) / c[typ]['freq'][m]:+.2e} |")
        md.append("")
    p = report.get("part")
    if p:
        hx, cx = p["hexfem"]["freq"], p["ccx"]["freq"]
        worst["part/ccx"] = maxrel(hx, cx, n)
        md += [f"### Steel part, h = {p['h']:g}, order 2: hexfem against ccx reading hexfem's INP",
               "", "| mode | hexfem [Hz] | ccx [Hz] | (hexfem - ccx)/ccx |", "|---:|---:|---:|---:|"]
        md += [f"| {m + 1} | {hx[m]:.7g} | {cx[m]:.7g} | {(hx[m] - cx[m]) / cx[m]:+.2e} |"
               for m in range(n)]
        md.append("")
    return "\n".join(md), worst


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=os.path.join(ROOT, "validation", "out", "crosscheck_order2"))
    ap.add_argument("--hexfem", default=os.environ.get(
        "HEXFEM", os.path.join(ROOT, "build", "app", "hexfem")))
    ap.add_argument("--modes", type=int, default=10)
    ap.add_argument("--json", help="write every figure to this JSON file")
    ap.add_argument("--part-h", type=float, default=2.0)
    ap.add_argument("--skip-part", action="store_true")
    args = ap.parse_args()
    args.hexfem = os.path.abspath(args.hexfem)
    out = os.path.abspath(args.out)
    os.makedirs(out, exist_ok=True)
    git = subprocess.run(["git", "-C", ROOT, "describe", "--always", "--dirty"],
                         stdout=subprocess.PIPE, text=True).stdout.strip()
    report = {"hexfem": args.hexfem, "source": git, "argv": sys.argv[1:]}
    t0 = time.time()
    structured(args, out, report)
    if not args.skip_part:
        steel_part(args, out, report)
    md, worst = summarize(args, report)
    report["max_rel"], report["seconds"] = worst, time.time() - t0
    print("\n" + md)
    with open(os.path.join(out, "tables.md"), "w") as f:
        f.write(md + "\n")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(report, f, indent=1)
    checks = [("hex20 vs ccx C3D20", max(worst["hex20/ccx"], worst["hex20_jitter/ccx"])),
              ("tet10 vs numpy exact rule", worst["tet10/numpy_exact"]),
              ("ccx C3D10 vs numpy with ccx's 4-point rule", worst["tet10/ccx_numpy_rule"])]
    ok = True
    for what, v in checks:
        ok = ok and v <= TOL
        print(f"acceptance: {what}: max |rel| {v:.2e} (<= {TOL:g}): {'PASS' if v <= TOL else 'FAIL'}")
    print(f"({report['seconds']:.0f} s)")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
