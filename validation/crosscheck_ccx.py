#!/usr/bin/python3
"""Cross-check of hexfem's modal solver against CalculiX 2.20 on the SAME mesh (issue 6, item 5).

  validation/crosscheck_ccx.py [--h 1.0] [--out validation/out/crosscheck] [--hexfem BIN]
                               [--modes 10] [--compare 6] [--json FILE] [--skip-part]

1. Steel part (models/steel_part.step, clamped on CAD face 8, x = 0): `hexfem mesh` -> .msh,
   `hexfem convert` -> .inp (also `hexfem mesh -o .inp` to check that meshing is repeatable).
   Variants of that mesh, each written as MSH 2.2 and exported by `hexfem convert`, so both codes
   read exactly the same nodes and cells:
     mixed     the mesh as made (hex8, wedge6, pyramid5, tet4)
     pyr-tet   each pyramid split into 2 tets (base diagonal through its smallest node id)
     all-tet   pyramids -> 2 tets and wedges -> 3 tets (Dompierre et al. 1999 rule, conforming
               between split cells); hex8 + tet4 only, where both codes use the same elements
   hexfem: `hexfem modal V.msh --fix face:8 --units mm --json`.
   ccx, two decks per variant that has wedges:
     native    the exported .inp: wedges C3D6 (1 x 2 points, under-integrated), pyramids C3D8
               with the apex repeated (2x2x2 Gauss-Legendre: exact stiffness, inexact mass)
     w-c3d8    wedges rewritten as C3D8 with nodes 1 2 3 3 4 5 6 6 (same linear field, 2x2x2
               Gauss: exact on a right prism, like hexfem's 3 x 2 rule)
   Attribution: mixed/w-c3d8 differs from hexfem by the pyramids only; pyr-tet/native by the
   C3D6 wedges only; all-tet must agree to the solvers' precision.
2. Pure hex: a structured 100 x 10 x 10 mm cantilever 40 x 4 x 4 (affine cells) and the same
   grid with every node moved at random (trilinear cells), clamped at x = 0: C3D8 = hexfem hex8.

Units: mm, N, tonne: E = 210000 MPa, rho = 7.85e-9 t/mm^3 -> Hz; hexfem gets the same as
steel (SI) with --units mm. ccx eigenvalues are read at full precision from the binary .eig file
(*FREQUENCY, STORAGE=YES) and checked against the 7 digits of the .dat.
Only stdlib + numpy. Run with /usr/bin/python3.
"""
import argparse
import json
import math
import os
import struct
import subprocess
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
E_MPA, NU, RHO_T_MM3 = 210000.0, 0.3, 7.85e-9
TOL_MIXED, TOL_HEX = 5e-3, 1e-6  # acceptance of issue 6

# MSH element types and node counts; hexfem kinds by name.
TRI, QUAD, TET, HEX, WEDGE, PYR = 2, 3, 4, 5, 6, 7
NNODES = {TRI: 3, QUAD: 4, TET: 4, HEX: 8, WEDGE: 6, PYR: 5, 1: 2, 15: 1}
KIND = {HEX: "hex8", WEDGE: "wedge6", PYR: "pyramid5", TET: "tet4"}


# ---------------------------------------------------------------- processes


def run(cmd, cwd, log, env=None):
    """Runs cmd in cwd, output to log; returns (stdout, seconds); exits with the log's tail."""
    t0 = time.time()
    with open(log, "w") as f:
        p = subprocess.run(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=f, text=True, env=env)
    with open(log, "a") as f:
        f.write(p.stdout)
    if p.returncode != 0:
        tail = open(log).read()[-2000:]
        sys.exit(f"crosscheck: `{' '.join(cmd)}` failed ({p.returncode}) in {cwd}:\n{tail}")
    return p.stdout, time.time() - t0


def shell_line(cmd):
    return " ".join(c if c and all(ch.isalnum() or ch in "-_./:=,@" for ch in c) else repr(c)
                    for c in cmd)


# ---------------------------------------------------------------- MSH


def read_msh41(path):
    """ASCII MSH 4.1: (node tags, coords (n,3)), [(dim, entity, type, conn (m,k) of node tags)]."""
    with open(path) as f:
        tok = f.read().split("\n")
    i = 0
    tags, xyz, blocks = [], [], []
    while i < len(tok):
        line = tok[i].strip()
        if line == "$MeshFormat":
            v = tok[i + 1].split()
            if not v[0].startswith("4.1") or v[1] != "0":
                sys.exit(f"{path}: need ASCII MSH 4.1, got {v}")
        elif line == "$Nodes":
            nblocks = int(tok[i + 1].split()[0])
            i += 2
            for _ in range(nblocks):
                n = int(tok[i].split()[3])
                tags += [int(t) for t in tok[i + 1:i + 1 + n]]
                xyz += [[float(c) for c in t.split()[:3]] for t in tok[i + 1 + n:i + 1 + 2 * n]]
                i += 1 + 2 * n
            continue
        elif line == "$Elements":
            nblocks = int(tok[i + 1].split()[0])
            i += 2
            for _ in range(nblocks):
                dim, ent, typ, n = (int(t) for t in tok[i].split())
                rows = np.array([[int(t) for t in r.split()] for r in tok[i + 1:i + 1 + n]],
                                dtype=np.int64).reshape(n, -1)
                blocks.append((dim, ent, typ, rows[:, 1:1 + NNODES[typ]]))
                i += 1 + n
            continue
        i += 1
    return np.array(tags, dtype=np.int64), np.array(xyz, dtype=float), blocks


def write_msh22(path, tags, xyz, cells, bfaces):
    """cells: [(type, conn)], bfaces: [(type, cad face id, conn)]; conn in node tags.
    Boundary faces carry their CAD face as elementary tag (what `--fix face:ID` selects)."""
    out = ["$MeshFormat", "2.2 0 8", "$EndMeshFormat", "$Nodes", str(len(tags))]
    out += [f"{t} {x!r} {y!r} {z!r}" for t, (x, y, z) in zip(tags.tolist(), xyz.tolist())]
    out.append("$EndNodes")
    rows = []
    for typ, face, conn in bfaces:
        rows += [f"{typ} 2 0 {face} " + " ".join(map(str, r)) for r in conn.tolist()]
    for typ, conn in cells:
        rows += [f"{typ} 2 0 1 " + " ".join(map(str, r)) for r in conn.tolist()]
    out += ["$Elements", str(len(rows))] + [f"{k + 1} {r}" for k, r in enumerate(rows)]
    out.append("$EndElements")
    with open(path + ".part", "w") as f:
        f.write("\n".join(out) + "\n")
    os.replace(path + ".part", path)


# ---------------------------------------------------------------- splitting into tets


def orient(tets, pos):
    """Swaps two nodes of every tet with a negative volume (Gmsh/CalculiX want positive)."""
    p = [pos[tets[:, k]] for k in range(4)]
    vol = np.einsum("ij,ij->i", np.cross(p[1] - p[0], p[2] - p[0]), p[3] - p[0])
    tets = tets.copy()
    neg = vol < 0
    tets[neg, 1], tets[neg, 2] = tets[neg, 2].copy(), tets[neg, 1].copy()
    return tets, np.abs(vol) / 6


def split_quad(q):
    """Two triangles of a quad (cyclic a b c d) along the diagonal through its smallest id: the
    rule every split cell follows, so neighbours split a shared quad the same way."""
    k = int(np.argmin(q))
    a, b, c, d = (q[(k + j) % 4] for j in range(4))
    return (a, b, c), (a, c, d)


def split_pyramids(pyr):
    tets = []
    for p in pyr.tolist():
        (t1, t2) = split_quad(p[:4])
        tets += [t1 + (p[4],), t2 + (p[4],)]
    return np.array(tets, dtype=np.int64).reshape(-1, 4)


# Dompierre, Labbé, Vallet, Camarero 1999, "How to subdivide pyramids, prisms and hexahedra into
# tetrahedra": the prism's symmetries bring the smallest node to position 0; two choices remain.
_PRISM_PERM = [[0, 1, 2, 3, 4, 5], [1, 2, 0, 4, 5, 3], [2, 0, 1, 5, 3, 4],
               [3, 5, 4, 0, 2, 1], [4, 3, 5, 1, 0, 2], [5, 4, 3, 2, 1, 0]]


def split_wedges(wed):
    tets = []
    for w in wed.tolist():
        v = [w[j] for j in _PRISM_PERM[int(np.argmin(w))]]
        if min(v[1], v[5]) < min(v[2], v[4]):
            tets += [(v[0], v[1], v[2], v[5]), (v[0], v[1], v[5], v[4]), (v[0], v[4], v[5], v[3])]
        else:
            tets += [(v[0], v[1], v[2], v[4]), (v[0], v[4], v[2], v[5]), (v[0], v[4], v[5], v[3])]
    return np.array(tets, dtype=np.int64).reshape(-1, 4)


def tet_faces(tets):
    return {tuple(sorted(f)) for t in tets.tolist()
            for f in ((t[0], t[1], t[2]), (t[0], t[1], t[3]), (t[0], t[2], t[3]), (t[1], t[2], t[3]))}


def make_variant(tags, xyz, blocks, split_pyr, split_wed):
    """Cells and boundary faces of a variant; every split quad face (boundary or not) is split
    by split_quad, and split boundary quads become the two triangles of the cells they bound."""
    pos = np.zeros((tags.max() + 1, 3))
    pos[tags] = xyz
    by_type = {}
    for dim, _, typ, conn in blocks:
        if dim == 3:
            by_type.setdefault(typ, []).append(conn)
    by_type = {t: np.vstack(c) for t, c in by_type.items()}
    cells, new_tets = [], []
    for typ, conn in sorted(by_type.items()):
        if typ == PYR and split_pyr:
            new_tets.append(split_pyramids(conn))
        elif typ == WEDGE and split_wed:
            new_tets.append(split_wedges(conn))
        else:
            cells.append((typ, conn))
    if new_tets:
        tets, vol = orient(np.vstack(new_tets), pos)
        if vol.min() <= 0:
            sys.exit("crosscheck: a split produced a flat tet")
        cells.append((TET, np.vstack([by_type[TET], tets]) if TET in by_type else tets))
        split_faces = tet_faces(tets)
    else:
        split_faces = set()
    bfaces = []
    for dim, ent, typ, conn in blocks:
        if dim != 2:
            continue
        if typ == QUAD and split_faces:
            keep, tris = [], []
            for q in conn.tolist():
                t1, t2 = split_quad(q)
                if tuple(sorted(t1)) in split_faces:
                    tris += [t1, t2]
                else:
                    keep.append(q)
            if keep:
                bfaces.append((QUAD, ent, np.array(keep, dtype=np.int64)))
            if tris:
                bfaces.append((TRI, ent, np.array(tris, dtype=np.int64)))
        else:
            bfaces.append((typ, ent, conn))
    return cells, bfaces


def counts_of(cells):
    c = {k: 0 for k in KIND.values()}
    for typ, conn in cells:
        c[KIND[typ]] += len(conn)
    return c


# ---------------------------------------------------------------- structured hex grids


def box_grid(n=(40, 4, 4), size=(100.0, 10.0, 10.0), jitter=0.0, seed=6):
    """Structured hex grid; jitter moves every node by up to jitter * spacing per axis (nodes on
    x = 0 keep x = 0, so the clamp stays a plane): trilinear, non-affine cells."""
    nx, ny, nz = n
    g = np.stack(np.meshgrid(*(np.linspace(0, s, k + 1) for s, k in zip(size, n)), indexing="ij"),
                 axis=-1)
    if jitter:
        h = np.array(size) / np.array(n)
        d = np.random.default_rng(seed).uniform(-jitter, jitter, g.shape) * h
        d[0, :, :, 0] = 0
        g = g + d
    xyz = g.transpose(2, 1, 0, 3).reshape(-1, 3)  # x fastest
    tags = np.arange(1, len(xyz) + 1)

    def tag(i, j, k):
        return 1 + i + (nx + 1) * (j + (ny + 1) * k)

    i, j, k = (a.ravel() for a in np.meshgrid(np.arange(nx), np.arange(ny), np.arange(nz),
                                              indexing="ij"))
    hexes = np.stack([tag(i, j, k), tag(i + 1, j, k), tag(i + 1, j + 1, k), tag(i, j + 1, k),
                      tag(i, j, k + 1), tag(i + 1, j, k + 1), tag(i + 1, j + 1, k + 1),
                      tag(i, j + 1, k + 1)], axis=1)
    return tags, xyz, [(HEX, hexes)]


# ---------------------------------------------------------------- ccx


def inp_nodes(path):
    """Node id -> (x, y, z) from the *NODE block of an .inp."""
    nodes, on = {}, False
    for line in open(path):
        if line.startswith("*"):
            on = line.upper().startswith("*NODE")
            continue
        if on and line.strip():
            p = line.split(",")
            nodes[int(p[0])] = tuple(float(v) for v in p[1:4])
    return nodes


def inp_wedges_as_c3d8(src, dst):
    """Copy of an exported .inp with each C3D6 written as a C3D8 with nodes 1 2 3 3 4 5 6 6."""
    out, wedge = [], False
    for line in open(src):
        if line.startswith("*"):
            wedge = line.upper().replace(" ", "").startswith("*ELEMENT,TYPE=C3D6")
            if wedge:
                line = line.replace("C3D6", "C3D8")
        elif wedge and line.strip():
            p = [v.strip() for v in line.split(",")]
            line = ",".join([p[0], p[1], p[2], p[3], p[3], p[4], p[5], p[6], p[6]]) + "\n"
        out.append(line)
    with open(dst, "w") as f:
        f.writelines(out)


def write_deck(path, mesh_inp, fixed_nset, modes, extra_nset=None):
    lines = [f"** hexfem cross-check: {os.path.basename(mesh_inp)} clamped on {fixed_nset}",
             f"*INCLUDE, INPUT={os.path.basename(mesh_inp)}"]
    if extra_nset:
        name, ids = extra_nset
        lines.append(f"*NSET, NSET={name}")
        lines += [",".join(map(str, ids[k:k + 16])) for k in range(0, len(ids), 16)]
    lines += ["*BOUNDARY", f"{fixed_nset}, 1, 3",
              "*MATERIAL, NAME=STEEL", "*ELASTIC", f"{E_MPA}, {NU}", "*DENSITY", f"{RHO_T_MM3}",
              "*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL",
              "*STEP", "*FREQUENCY, STORAGE=YES", str(modes), "*END STEP"]
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def parse_dat(path):
    """Eigenvalues (omega^2) of the E I G E N V A L U E   O U T P U T block of a ccx .dat."""
    lines = open(path).read().split("\n")
    for i, line in enumerate(lines):
        if "E I G E N V A L U E   O U T P U T" in line:
            vals = []
            for row in lines[i + 1:]:
                p = row.split()
                if vals and not p:
                    break
                if len(p) == 5 and p[0].isdigit():
                    vals.append(float(p[1]))
            return vals
    sys.exit(f"crosscheck: no eigenvalue block in {path}")


def parse_eig(path, dat):
    """Full-precision eigenvalues from the .eig of *FREQUENCY, STORAGE=YES: int cyclic flag (0),
    int Hermitian flag (1), nev and nev doubles (omega^2), then the matrices. ccx 2.20 writes one
    more int before nev than older versions: both layouts are tried, and the values must match
    the .dat's 7 digits. None if neither does."""
    if not os.path.exists(path):
        return None
    n = len(dat)
    with open(path, "rb") as f:
        head = f.read(16 + 8 * n)
    for nint in (3, 4):
        ints = struct.unpack(f"<{nint}i", head[:4 * nint])
        if ints[0] != 0 or ints[1] != 1 or ints[-1] < n:
            continue
        vals = struct.unpack(f"<{n}d", head[4 * nint:4 * nint + 8 * n])
        if all(abs(a - b) <= 1e-6 * abs(b) for a, b in zip(vals, dat)):
            return list(vals)
    return None


def run_ccx(workdir, job, modes):
    env = dict(os.environ, OMP_NUM_THREADS="1", CCX_NPROC_EQUATION_SOLVER="1")
    _, secs = run(["ccx", job], workdir, os.path.join(workdir, job + ".log"), env)
    dat = parse_dat(os.path.join(workdir, job + ".dat"))
    eig = parse_eig(os.path.join(workdir, job + ".eig"), dat)
    if os.path.exists(os.path.join(workdir, job + ".eig")):
        os.remove(os.path.join(workdir, job + ".eig"))  # the matrices make it large
    lam = eig if eig is not None else dat
    return {"freq": [math.sqrt(max(v, 0.0)) / (2 * math.pi) for v in lam],
            "seconds": secs, "full_precision": eig is not None,
            "command": f"cd {workdir} && OMP_NUM_THREADS=1 ccx {job}"}


# ---------------------------------------------------------------- hexfem


def hexfem_modal(hexfem, workdir, msh, fix, modes, log):
    cmd = [hexfem, "modal", msh, "--fix", fix, "--units", "mm", "--modes", str(modes), "--json"]
    out, secs = run(cmd, workdir, log)
    d = json.loads(out)
    return {"freq": [m["frequency_hz"] for m in d["modes"]], "seconds": secs,
            "command": f"cd {workdir} && {shell_line(cmd)}", "mesh": d.get("mesh", {})}


def rel(a, b):
    return (a - b) / b


def table(title, rows, ncmp, tol):
    """Markdown table mode / hexfem / ccx / relative difference; returns (text, worst)."""
    out = [f"#### {title}", "", "| mode | hexfem [Hz] | ccx [Hz] | (hexfem - ccx) / ccx |",
           "|---:|---:|---:|---:|"]
    worst = 0.0
    for m in range(ncmp):
        a, b = rows["hexfem"][m], rows["ccx"][m]
        worst = max(worst, abs(rel(a, b)))
        out.append(f"| {m + 1} | {a:.7g} | {b:.7g} | {rel(a, b):+.3e} |")
    verdict = "PASS" if worst <= tol else "FAIL"
    out += ["", f"max |rel| = {worst:.3e} (tolerance {tol:g}): **{verdict}**", ""]
    return "\n".join(out), worst


# ---------------------------------------------------------------- cases


def ccx_decks(args, out, name, mesh_inp, nset, extra=None):
    """ccx on the exported mesh as is (native) and, if it has wedges, with wedges as C3D8."""
    res = {}
    write_deck(os.path.join(out, f"{name}_native.inp"), mesh_inp, nset, args.modes, extra)
    res["native"] = run_ccx(out, f"{name}_native", args.modes)
    if "C3D6" in open(mesh_inp).read():
        w8 = os.path.join(out, f"mesh_{name}_w8.inp")
        inp_wedges_as_c3d8(mesh_inp, w8)
        write_deck(os.path.join(out, f"{name}_w8.inp"), w8, nset, args.modes, extra)
        res["w8"] = run_ccx(out, f"{name}_w8", args.modes)
    return res


def steel_part(args, out, report):
    hexfem, h = args.hexfem, args.h
    step = os.path.join(ROOT, "models", "steel_part.step")
    msh = os.path.join(out, "mesh_mixed.msh")
    cmd = [hexfem, "mesh", step, "--h", f"{h:g}", "-o", msh, "--json"]
    stdout, secs = run(cmd, out, os.path.join(out, "mesh.log"))
    info = json.loads(stdout)
    inp = os.path.join(out, "mesh_mixed.inp")
    run([hexfem, "convert", msh, inp], out, os.path.join(out, "convert.log"))
    direct = os.path.join(out, "mesh_direct.inp")
    run([hexfem, "mesh", step, "--h", f"{h:g}", "-o", direct], out, os.path.join(out, "mesh2.log"))
    report["part_mesh"] = {
        "command": shell_line(cmd), "seconds": secs,
        "h_vol_percent": info.get("h_vol_percent"), "h_nbr_percent": info.get("h_nbr_percent"),
        "nc_percent": info.get("nc_percent"), "inverted": info.get("inverted"),
        "mesh_volume": info.get("mesh_volume"), "cad_volume": info.get("cad_volume"),
        "repeatable": open(direct).read() == open(inp).read()}
    print(f"steel part h = {h:g}: {report['part_mesh']}", flush=True)

    tags, xyz, blocks = read_msh41(msh)
    variants = [("mixed", False, False), ("pyr-tet", True, False), ("all-tet", True, True)]
    report["part"] = {}
    for name, spyr, swed in variants:
        cells, bfaces = make_variant(tags, xyz, blocks, spyr, swed)
        key = name.replace("-", "_")
        if name == "mixed":
            vmsh, vinp = msh, inp  # hexfem's own files, untouched
        else:
            vmsh = os.path.join(out, f"mesh_{key}.msh")
            vinp = os.path.join(out, f"mesh_{key}.inp")
            write_msh22(vmsh, tags, xyz, cells, bfaces)
            run([hexfem, "convert", vmsh, vinp], out, os.path.join(out, f"convert_{key}.log"))
        r = {"cells": counts_of(cells)}
        print(f"  {name}: {r['cells']}", flush=True)
        r["hexfem"] = hexfem_modal(hexfem, out, os.path.basename(vmsh), "face:8", args.modes,
                                   os.path.join(out, f"hexfem_{key}.log"))
        r["ccx"] = ccx_decks(args, out, key, vinp, "FACE_8")
        report["part"][name] = r


def pure_hex(args, out, report):
    report["hex"] = {}
    for name, jitter in (("box", 0.0), ("box-jitter", 0.15)):
        key = name.replace("-", "_")
        tags, xyz, cells = box_grid(jitter=jitter)
        vmsh, vinp = (os.path.join(out, f"mesh_{key}.{e}") for e in ("msh", "inp"))
        write_msh22(vmsh, tags, xyz, cells, [])
        run([args.hexfem, "convert", vmsh, vinp], out, os.path.join(out, f"convert_{key}.log"))
        fixed = sorted(i for i, p in inp_nodes(vinp).items() if abs(p[0]) < 1e-9)
        r = {"cells": counts_of(cells), "jitter": jitter, "fixed_nodes": len(fixed)}
        r["hexfem"] = hexfem_modal(args.hexfem, out, os.path.basename(vmsh), "x<1e-6", args.modes,
                                   os.path.join(out, f"hexfem_{key}.log"))
        r["ccx"] = ccx_decks(args, out, key, vinp, "CLAMP", ("CLAMP", fixed))
        report["hex"][name] = r
        print(f"  {name}: {r['cells']}, {len(fixed)} clamped nodes", flush=True)


def summarize(args, report):
    n = args.compare
    md, verdicts = [], {}

    def pair(title, hx, cc, tol, key):
        text, worst = table(title, {"hexfem": hx, "ccx": cc}, n, tol)
        md.append(text)
        verdicts[key] = worst

    for name, r in report.get("hex", {}).items():
        pair(f"{name} ({r['cells']['hex8']} hex8): hexfem hex8 vs ccx C3D8",
             r["hexfem"]["freq"], r["ccx"]["native"]["freq"], TOL_HEX, name)
    part = report.get("part", {})
    for name, r in part.items():
        pair(f"steel part, {name} {r['cells']}: hexfem vs ccx as exported",
             r["hexfem"]["freq"], r["ccx"]["native"]["freq"], TOL_MIXED if name == "mixed" else 1,
             f"{name}/native")
        if "w8" in r["ccx"]:
            pair(f"steel part, {name}: hexfem vs ccx with wedges as C3D8 (1 2 3 3 4 5 6 6)",
                 r["hexfem"]["freq"], r["ccx"]["w8"]["freq"], 1, f"{name}/w8")
    if "mixed" in part:
        m, pt = part["mixed"], part.get("pyr-tet")
        md += ["#### Attribution on the mixed mesh (relative to ccx; sums to the total to first order)",
               "", "| mode | total: hexfem vs ccx | pyramids: hexfem vs ccx(wedges C3D8) "
               "| C3D6 wedges: ccx(wedges C3D8) vs ccx | C3D6 on pyr-tet mesh |",
               "|---:|---:|---:|---:|---:|"]
        for k in range(n):
            hx, cn = m["hexfem"]["freq"][k], m["ccx"]["native"]["freq"][k]
            w8 = m["ccx"]["w8"]["freq"][k] if "w8" in m["ccx"] else float("nan")
            wt = rel(pt["hexfem"]["freq"][k], pt["ccx"]["native"]["freq"][k]) if pt else float("nan")
            md.append(f"| {k + 1} | {rel(hx, cn):+.3e} | {rel(hx, w8):+.3e} | {rel(w8, cn):+.3e} "
                      f"| {wt:+.3e} |")
        md.append("")
    return "\n".join(md), verdicts


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--h", type=float, default=1.0, help="mesh size of the steel part (mm)")
    ap.add_argument("--out", default=os.path.join(ROOT, "validation", "out", "crosscheck"))
    ap.add_argument("--hexfem", default=os.environ.get("HEXFEM", os.path.join(ROOT, "build-xc", "app", "hexfem")))
    ap.add_argument("--modes", type=int, default=10, help="modes asked of both solvers")
    ap.add_argument("--compare", type=int, default=6, help="modes compared")
    ap.add_argument("--json", help="write the figures to this JSON file")
    ap.add_argument("--skip-part", action="store_true", help="only the pure-hex boxes")
    args = ap.parse_args()
    args.hexfem = os.path.abspath(args.hexfem)
    if not os.access(args.hexfem, os.X_OK):
        sys.exit(f"crosscheck: no hexfem binary at {args.hexfem} (--hexfem or $HEXFEM)")
    out = os.path.abspath(args.out)
    os.makedirs(out, exist_ok=True)
    report = {"h": args.h, "hexfem": args.hexfem, "out": out}
    t0 = time.time()
    pure_hex(args, out, report)
    if not args.skip_part:
        steel_part(args, out, report)
    md, verdicts = summarize(args, report)
    report["max_rel"] = verdicts
    report["seconds"] = time.time() - t0
    print("\n" + md)
    with open(os.path.join(out, "tables.md"), "w") as f:
        f.write(md + "\n")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(report, f, indent=1)
    ok = all(v <= TOL_HEX for k, v in verdicts.items() if k.startswith("box"))
    ok = ok and verdicts.get("mixed/native", 0.0) <= TOL_MIXED
    print(f"acceptance: {'PASS' if ok else 'FAIL'} ({report['seconds']:.0f} s)")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
