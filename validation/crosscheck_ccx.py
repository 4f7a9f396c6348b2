#!/usr/bin/python3
"""Cross-check of hexfem's modal solver against CalculiX 2.20 on the SAME mesh (issue 6, item 5).

  validation/crosscheck_ccx.py [--h 1.0] [--out validation/out/crosscheck] [--hexfem BIN]
      [--modes 10] [--compare 6] [--json FILE] [--skip-part] [--reuse-ccx] [--timeout S]

Both codes read the same nodes and cells: meshes go to hexfem as .msh and to ccx as the .inp that
`hexfem convert` writes. ccx runs each mesh as exported (C3D8, C3D6, C3D4, pyramids as C3D8 with
the apex repeated) and with kinds rewritten so that ccx integrates hexfem's field exactly (see
inp_with_formulations): the difference per kind is the attribution.
1. Structured 100 x 10 x 10 mm cantilevers clamped at x = 0: 40 x 4 x 4 hex8, the same jittered
   (acceptance 1e-6), and one-kind boxes (tet4, wedge6, pyramid5); the tet box also against a
   dense numpy assembly that shares no code with either.
2. The steel part (models/steel_part.step, CAD face 8 clamped): `hexfem mesh --h H`, then the mesh
   as exported (acceptance 0.5 %) and, if it holds zero-volume cells, the same mesh without them,
   with every formulation.
Units: mm, N, tonne (E = 210000 MPa, rho = 7.85e-9 t/mm^3) -> Hz; hexfem: steel, --units mm,
--hex8 full (= C3D8) and incompatible (vs C3D8I, informative). ccx eigenvalues are read at full
precision from the .eig of *FREQUENCY, STORAGE=YES, checked against the 7 digits of the .dat.
Only stdlib + numpy; run with /usr/bin/python3. Exit status 1 if an acceptance check fails.
"""
import argparse
import hashlib
import itertools
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


TIMEOUT = 900  # seconds a single hexfem or ccx run may take (--timeout)


def run(cmd, cwd, log, env=None):
    """Runs cmd in cwd, output to log; returns (stdout, seconds); exits with the log's tail."""
    t0 = time.time()
    with open(log, "w") as f:
        try:
            p = subprocess.run(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=f, text=True, env=env,
                               timeout=TIMEOUT)
        except subprocess.TimeoutExpired:
            sys.exit(f"crosscheck: `{shell_line(cmd)}` ran over {TIMEOUT} s (--timeout) in {cwd}")
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


# ---------------------------------------------------------------- structured meshes


def box_grid(n=(40, 4, 4), size=(100.0, 10.0, 10.0), jitter=0.0, seed=6):
    """Structured hex grid (node tags, coords, [(HEX, conn)]); jitter moves every node by up to
    jitter * spacing per axis (nodes on x = 0 keep x = 0, so the clamp stays a plane):
    trilinear, non-affine cells."""
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


# Node permutation that mirrors a cell, and the node that is "above" its first three.
_MIRROR = {TET: ([0, 2, 1, 3], 3), WEDGE: ([0, 2, 1, 3, 5, 4], 3), PYR: ([0, 3, 2, 1, 4], 4)}


def positive(typ, conn, xyz):
    """Mirrors the cells whose (n0, n1, n2, top) tet has a negative volume (Gmsh order)."""
    perm, top = _MIRROR[typ]
    p = [xyz[conn[:, k] - 1] for k in (0, 1, 2, top)]
    neg = np.einsum("ij,ij->i", np.cross(p[1] - p[0], p[2] - p[0]), p[3] - p[0]) < 0
    conn = conn.copy()
    conn[neg] = conn[neg][:, perm]
    return conn


def _kuhn_paths():
    corner = {(0, 0, 0): 0, (1, 0, 0): 1, (1, 1, 0): 2, (0, 1, 0): 3, (0, 0, 1): 4, (1, 0, 1): 5,
              (1, 1, 1): 6, (0, 1, 1): 7}
    unit = {v: np.array(k, dtype=float) for k, v in corner.items()}
    paths = []
    for perm in itertools.permutations(range(3)):
        c, path = [0, 0, 0], [0]
        for axis in perm:
            c[axis] = 1
            path.append(corner[tuple(c)])
        p = [unit[i] for i in path]
        if np.dot(np.cross(p[1] - p[0], p[2] - p[0]), p[3] - p[0]) < 0:  # odd permutation
            path[1], path[2] = path[2], path[1]
        paths.append(path)
    return paths


KUHN = _kuhn_paths()  # the 6 tets of a hex along its diagonal 0-6 (Gmsh corner order)
_TETS_OF = {TET: [[0, 1, 2, 3]], HEX: KUHN, PYR: [[0, 1, 2, 4], [0, 2, 3, 4]],
            WEDGE: [[0, 1, 2, 5], [0, 1, 5, 4], [0, 4, 5, 3]]}


def cell_volumes(typ, conn, pos):
    """Signed volumes (sum over a split into tets; exact for tets and affine cells)."""
    v = np.zeros(len(conn))
    for t in _TETS_OF[typ]:
        p = [pos[conn[:, k]] for k in t]
        v += np.einsum("ij,ij->i", np.cross(p[1] - p[0], p[2] - p[0]), p[3] - p[0]) / 6
    return v


def split_box(kind, n=(20, 2, 2)):
    """The box grid cut into one kind of cell, conforming: tet4 by Kuhn's 6 tets along the main
    diagonal, wedge6 by 2 right prisms along z, pyramid5 by 6 pyramids on a centre node.
    Every cell is affine (or a right prism), where both codes' "exact" rules are exact."""
    tags, xyz, [(_, hexes)] = box_grid(n)
    if kind == "tet4":
        conn = np.vstack([hexes[:, path] for path in KUHN])
        typ = TET
    elif kind == "wedge6":
        conn = np.vstack([hexes[:, [0, 1, 2, 4, 5, 6]], hexes[:, [0, 2, 3, 4, 6, 7]]])
        typ = WEDGE
    else:
        centre = np.arange(len(xyz) + 1, len(xyz) + 1 + len(hexes))
        xyz = np.vstack([xyz, xyz[hexes - 1].mean(axis=1)])
        tags = np.arange(1, len(xyz) + 1)
        faces = [(0, 1, 2, 3), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
        conn = np.vstack([np.column_stack([hexes[:, list(f)], centre]) for f in faces])
        typ = PYR
    return tags, xyz, [(typ, positive(typ, conn, xyz))]


def counts_of(cells):
    c = {k: 0 for k in KIND.values()}
    for typ, conn in cells:
        c[KIND[typ]] += len(conn)
    return c


def numpy_tet4_modes(tags, xyz, tets, clamp, nmodes):
    """Independent of both codes: dense linear-tet K and M (exact consistent mass rho V/20 (1 +
    delta_ij), and the centroid-only mass rho V/16) of a small mesh, clamped nodes removed;
    returns {"consistent": f, "centroid": f} in Hz."""
    lam, mu = E_MPA * NU / ((1 + NU) * (1 - 2 * NU)), E_MPA / (2 * (1 + NU))
    D = np.zeros((6, 6))
    D[:3, :3] = lam
    D[range(3), range(3)] += 2 * mu
    D[range(3, 6), range(3, 6)] = mu
    index = {t: i for i, t in enumerate(tags.tolist())}
    ndof = 3 * len(tags)
    K, Mc, M1 = (np.zeros((ndof, ndof)) for _ in range(3))
    for tet in tets.tolist():
        ids = [index[t] for t in tet]
        A = np.hstack([np.ones((4, 1)), xyz[ids]])
        grad = np.linalg.inv(A)[1:, :]  # column i: gradient of N_i
        V = abs(np.linalg.det(A)) / 6
        B = np.zeros((6, 12))
        for i, (gx, gy, gz) in enumerate(grad.T):
            B[:, 3 * i:3 * i + 3] = [[gx, 0, 0], [0, gy, 0], [0, 0, gz], [gy, gx, 0], [0, gz, gy],
                                     [gz, 0, gx]]
        dof = np.array([[3 * n, 3 * n + 1, 3 * n + 2] for n in ids]).ravel()
        K[np.ix_(dof, dof)] += V * B.T @ D @ B
        m = RHO_T_MM3 * V
        Mc[np.ix_(dof, dof)] += np.kron(m / 20 * (np.ones((4, 4)) + np.eye(4)), np.eye(3))
        M1[np.ix_(dof, dof)] += np.kron(m / 16 * np.ones((4, 4)), np.eye(3))
    free = np.array([d for d in range(ndof) if not clamp(xyz[d // 3])])
    Linv = np.linalg.inv(np.linalg.cholesky(K[np.ix_(free, free)]))
    res = {}
    for name, M in (("consistent", Mc), ("centroid", M1)):  # centroid M is singular: invert K
        mu_ = np.linalg.eigvalsh(Linv @ M[np.ix_(free, free)] @ Linv.T)[::-1][:nmodes]
        res[name] = [math.sqrt(1 / m) / (2 * math.pi) for m in mu_]
    return res


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


# How ccx is given each kind of cell. "native" is what `hexfem convert` exports; the others make
# ccx integrate the SAME linear field as hexfem does, exactly:
#   tet4     tied10: C3D10 whose mid-edge nodes are tied to the edge's mean by *EQUATION (the field
#            stays linear; its 4-point rule integrates the consistent mass exactly; C3D4's mass
#            uses the centroid only)
#   wedge6   c3d8: C3D8 with nodes 1 2 3 3 4 5 6 6 (the linear wedge field, 2x2x2 Gauss: exact on a
#            right prism; C3D6 uses 1 x 2 points)
#   pyramid5 tied20: C3D20 collapsed to the apex (corners 1 2 3 4 5 5 5 5, top mid-edges = apex),
#            other mid-edge nodes tied to the edge's mean: the field of the collapsed C3D8, which is
#            the rational pyramid's, integrated with 3x3x3 Gauss, exact for the mass of an affine
#            pyramid (the collapsed C3D8's 2x2x2 rule is not)
#   hex8     c3d8i: C3D8I (incompatible modes), to compare with hexfem --hex8 incompatible
NATIVE = {"hex8": "native", "wedge6": "native", "pyramid5": "native", "tet4": "native"}
_BLOCK_KIND = {"E_HEX8": "hex8", "E_WEDGE6": "wedge6", "E_PYRAMID5": "pyramid5", "E_TET4": "tet4"}
_TET10_EDGES = [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)]  # Abaqus nodes 5..10
_PYR_BASE_EDGES = [(0, 1), (1, 2), (2, 3), (3, 0)]  # C3D20 nodes 9..12; 17..20 are (i, apex)


def ccx_real(v):
    """v in at most 20 characters: ccx 2.20 reads a field of 20 and refuses a longer one
    ("*ERROR reading *NODE"), as hexfem's own writer knows (put_inp_real)."""
    text = repr(v)
    digits = 16
    while len(text) > 20 and digits > 1:
        text = f"{v:.{digits}g}"
        digits -= 1
    return text


def inp_with_formulations(src, dst, form):
    """Copy of an exported .inp with the cells of each kind written as form[kind] says (see
    above). New mid-edge nodes get ids above the largest one and one *EQUATION per component."""
    lines = open(src).read().split("\n")
    # The *NODE block only: a set's data line of four ids is not a node.
    xyz = {i: list(p) for i, p in inp_nodes(src).items()}
    next_id = max(xyz) + 1
    mids = {}  # (a, b) sorted -> mid-edge node id

    def mid(a, b):
        nonlocal next_id
        key = (min(a, b), max(a, b))
        if key not in mids:
            mids[key] = next_id
            xyz[next_id] = [(u + v) / 2 for u, v in zip(xyz[a], xyz[b])]
            next_id += 1
        return mids[key]

    out, kind, nodes_done = [], None, False
    for line in lines:
        if line.startswith("*"):
            kind = None
            up = line.upper().replace(" ", "")
            if up.startswith("*ELEMENT"):
                kind = _BLOCK_KIND[line.split("ELSET=")[1].strip()]
                new_type = {("tet4", "tied10"): "C3D10", ("wedge6", "c3d8"): "C3D8",
                            ("pyramid5", "tied20"): "C3D20", ("hex8", "c3d8i"): "C3D8I"}
                t = new_type.get((kind, form[kind]))
                if t:
                    line = f"*ELEMENT, TYPE={t}, ELSET={line.split('ELSET=')[1].strip()}"
                elif form[kind] != "native":
                    sys.exit(f"crosscheck: no formulation {form[kind]} for {kind}")
            elif up.startswith("*ELSET") and not nodes_done:
                nodes_done = True
                if mids:  # new nodes and their ties, before the sets (model data)
                    out.append("*NODE, NSET=NALL")
                    out += [f"{i}," + ",".join(ccx_real(v) for v in xyz[i])
                            for i in range(min(mids.values()), next_id)]
                    out.append("*EQUATION")
                    for (a, b), m in sorted(mids.items(), key=lambda kv: kv[1]):
                        for c in (1, 2, 3):
                            out += ["3", f"{m},{c},1.,{a},{c},-0.5,{b},{c},-0.5"]
            out.append(line)
            continue
        if kind is None or form[kind] == "native" or not line.strip():
            out.append(line)
            continue
        p = [int(v) for v in line.split(",")]
        e, n = p[0], p[1:]
        if form[kind] == "tied10":
            row = [e] + n + [mid(n[a], n[b]) for a, b in _TET10_EDGES]
        elif form[kind] == "c3d8":
            row = [e, n[0], n[1], n[2], n[2], n[3], n[4], n[5], n[5]]
        elif form[kind] == "tied20":
            apex = n[4]
            row = ([e] + n[:4] + [apex] * 4 + [mid(n[a], n[b]) for a, b in _PYR_BASE_EDGES]
                   + [apex] * 4 + [mid(n[i], apex) for i in range(4)])
        else:  # c3d8i: same nodes
            row = p
        text = ",".join(map(str, row))
        if len(row) > 16:  # data lines hold at most 16 entries
            text = ",".join(map(str, row[:16])) + ",\n" + ",".join(map(str, row[16:]))
        out.append(text)
    with open(dst + ".part", "w") as f:
        f.write("\n".join(out))
    os.replace(dst + ".part", dst)
    return len(mids)


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


def run_ccx(workdir, job, reuse=False):
    """Runs ccx on <job>.inp. With reuse, a result saved by an earlier run of the same deck on
    the same mesh text (sha256 of both) is read back instead (ccx takes most of the time)."""
    deck = open(os.path.join(workdir, job + ".inp")).read()
    digest = hashlib.sha256(deck.encode())
    for line in deck.split("\n"):
        if line.upper().startswith("*INCLUDE"):
            digest.update(open(os.path.join(workdir, line.split("=", 1)[1].strip()), "rb").read())
    saved = os.path.join(workdir, job + ".result.json")
    if reuse and os.path.exists(saved):
        res = json.load(open(saved))
        if res.get("sha256") == digest.hexdigest():
            res["reused"] = True
            return res
    env = dict(os.environ, OMP_NUM_THREADS="1", CCX_NPROC_EQUATION_SOLVER="1")
    _, secs = run(["ccx", job], workdir, os.path.join(workdir, job + ".log"), env)
    dat = parse_dat(os.path.join(workdir, job + ".dat"))
    eig = parse_eig(os.path.join(workdir, job + ".eig"), dat)
    if os.path.exists(os.path.join(workdir, job + ".eig")):
        os.remove(os.path.join(workdir, job + ".eig"))  # the matrices make it large
    lam = eig if eig is not None else dat
    res = {"freq": [math.sqrt(max(v, 0.0)) / (2 * math.pi) for v in lam],
           "seconds": secs, "full_precision": eig is not None,
           "command": f"cd {workdir} && OMP_NUM_THREADS=1 ccx {job}", "sha256": digest.hexdigest()}
    with open(saved, "w") as f:
        json.dump(res, f)
    return res


# ---------------------------------------------------------------- hexfem


def hexfem_modal(args, workdir, msh, fix, log, hex8="full"):
    """hexfem modal --json on msh; hex8 "full" (= C3D8) or "incompatible" (None if this hexfem
    has no --hex8 option, in which case its hexes are the full ones)."""
    cmd = [args.hexfem, "modal", msh, "--fix", fix, "--units", "mm", "--modes", str(args.modes),
           "--json"]
    if args.hex8_option:
        cmd += ["--hex8", hex8]
    elif hex8 != "full":
        return None
    out, secs = run(cmd, workdir, log)
    d = json.loads(out)
    return {"freq": [m["frequency_hz"] for m in d["modes"]], "seconds": secs,
            "command": f"cd {workdir} && {shell_line(cmd)}", "mesh": d.get("mesh", {}),
            "fixed_dofs": d.get("fixed_dofs")}


def rel(a, b):
    return (a - b) / b


# ---------------------------------------------------------------- cases

FORMS = {  # ccx decks: label -> formulation per kind (see inp_with_formulations)
    "native": NATIVE,
    "tets": dict(NATIVE, tet4="tied10"),
    "wedges": dict(NATIVE, wedge6="c3d8"),
    "pyramids": dict(NATIVE, pyramid5="tied20"),
    "tets+wedges": dict(NATIVE, tet4="tied10", wedge6="c3d8"),
    "exact": dict(NATIVE, tet4="tied10", wedge6="c3d8", pyramid5="tied20"),
    "exact+c3d8i": dict(NATIVE, tet4="tied10", wedge6="c3d8", pyramid5="tied20", hex8="c3d8i"),
}


def ccx_forms(args, out, key, mesh_inp, labels, nset, extra=None):
    """Runs ccx on the exported mesh under each formulation label; {label: result}."""
    res = {}
    for label in labels:
        job = f"{key}_{label.replace('+', '_')}"
        inp = mesh_inp
        if FORMS[label] != NATIVE:
            inp = os.path.join(out, f"mesh_{job}.inp")
            inp_with_formulations(mesh_inp, inp, FORMS[label])
        write_deck(os.path.join(out, job + ".inp"), inp, nset, args.modes, extra)
        res[label] = run_ccx(out, job, args.reuse_ccx)
    return res


def structured_case(args, out, key, tags, xyz, cells, labels):
    """A structured mesh clamped at x = 0: hexfem (full hexes, and incompatible if "exact+c3d8i"
    is asked) and ccx under each label."""
    vmsh, vinp = (os.path.join(out, f"mesh_{key}.{e}") for e in ("msh", "inp"))
    write_msh22(vmsh, tags, xyz, cells, [])
    run([args.hexfem, "convert", vmsh, vinp], out, os.path.join(out, f"convert_{key}.log"))
    fixed = sorted(i for i, p in inp_nodes(vinp).items() if abs(p[0]) < 1e-9)
    r = {"cells": counts_of(cells), "nodes": len(tags), "fixed_nodes": len(fixed)}
    r["hexfem"] = hexfem_modal(args, out, os.path.basename(vmsh), "x<1e-6",
                               os.path.join(out, f"hexfem_{key}.log"))
    if "exact+c3d8i" in labels:
        r["hexfem_incompatible"] = hexfem_modal(args, out, os.path.basename(vmsh), "x<1e-6",
                                                os.path.join(out, f"hexfem_{key}_i.log"),
                                                "incompatible")
    r["ccx"] = ccx_forms(args, out, key, vinp, labels, "CLAMP", ("CLAMP", fixed))
    print(f"  {key}: {r['cells']}, {len(fixed)} clamped nodes", flush=True)
    return r


def structured(args, out, report):
    rep = report["structured"] = {}
    for key, jitter in (("hex", 0.0), ("hex_jitter", 0.15)):
        tags, xyz, cells = box_grid(jitter=jitter)
        rep[key] = structured_case(args, out, key, tags, xyz, cells, ["native", "exact+c3d8i"])
        rep[key]["jitter"] = jitter
    for kind, label in (("tet4", "tets"), ("wedge6", "wedges"), ("pyramid5", "pyramids")):
        tags, xyz, cells = split_box(kind)
        rep[kind] = structured_case(args, out, kind, tags, xyz, cells, ["native", label])
        rep[kind]["exact_label"] = label
        if kind == "tet4":
            rep[kind]["numpy"] = numpy_tet4_modes(tags, xyz, cells[0][1],
                                                  lambda p: abs(p[0]) < 1e-9, args.modes)


FLAT = 1e-9  # a cell whose volume is below FLAT x the median cell volume counts as flat


def tet_stiffness_scale(pts):
    """V max_i |grad N_i|^2 of a tet: its largest stiffness entry over E (up to a factor)."""
    A = np.hstack([np.ones((4, 1)), pts])
    vol = abs(np.linalg.det(A)) / 6
    try:
        return vol * float(np.max(np.sum(np.linalg.inv(A)[1:, :] ** 2, axis=0)))
    except np.linalg.LinAlgError:
        return math.inf


def drop_flat_cells(msh, out_msh):
    """Writes the mesh without its flat cells (volume < FLAT x median, when every node stays in
    some other cell) to out_msh; returns ([{kind, volume, nodes, stiffness scale / median tet's}],
    median volume, cell counts left)."""
    tags, xyz, blocks = read_msh41(msh)
    pos = np.zeros((tags.max() + 1, 3))
    pos[tags] = xyz
    vols = [cell_volumes(t, c, pos) if d == 3 else None for d, _, t, c in blocks]
    median = float(np.median(np.concatenate([v for v in vols if v is not None])))
    cells, dropped, bfaces, scales = [], [], [], []
    for (dim, ent, typ, conn), v in zip(blocks, vols):
        if dim == 2:
            bfaces.append((typ, ent, conn))
        if dim != 3:
            continue
        flat = np.abs(v) < FLAT * median
        for c, vol in zip(conn[flat].tolist(), v[flat].tolist()):
            dropped.append({"kind": KIND[typ], "volume_mm3": vol, "nodes": c,
                            "stiffness_scale": tet_stiffness_scale(pos[c]) if typ == TET else None})
        if typ == TET:
            scales += [tet_stiffness_scale(pos[c]) for c in conn[~flat].tolist()]
        cells.append((typ, conn[~flat]))
    if dropped:
        used = set(np.concatenate([c.ravel() for _, c in cells]).tolist())
        if len(used) < len(tags):
            sys.exit("crosscheck: dropping the flat cells would leave nodes in no cell")
        for d in dropped:
            if d["stiffness_scale"] is not None and scales:
                d["stiffness_scale"] /= float(np.median(scales))
        write_msh22(out_msh, tags, xyz, cells, bfaces)
    return dropped, median, counts_of(cells)


def part_case(args, out, key, msh, inp, labels, incompatible):
    r = {"hexfem": hexfem_modal(args, out, os.path.basename(msh), "face:8",
                                os.path.join(out, f"hexfem_{key}.log"))}
    if incompatible:
        r["hexfem_incompatible"] = hexfem_modal(args, out, os.path.basename(msh), "face:8",
                                                os.path.join(out, f"hexfem_{key}_i.log"),
                                                "incompatible")
    r["ccx"] = ccx_forms(args, out, key, inp, labels, "FACE_8")
    r["fixed_nodes_ccx"] = len(",".join(
        open(inp).read().split("*NSET, NSET=FACE_8\n")[1].split("*")[0].split()).split(","))
    return r


def steel_part(args, out, report):
    hexfem, h = args.hexfem, args.h
    step = os.path.join(ROOT, "models", "steel_part.step")
    msh = os.path.join(out, "mesh_part.msh")
    cmd = [hexfem, "mesh", step, "--h", f"{h:g}", "-o", msh, "--json"]
    stdout, secs = run(cmd, out, os.path.join(out, "mesh_part.log"))
    info = json.loads(stdout)
    inp = os.path.join(out, "mesh_part.inp")
    run([hexfem, "convert", msh, inp], out, os.path.join(out, "convert_part.log"))
    direct = os.path.join(out, "mesh_part_direct.inp")
    run([hexfem, "mesh", step, "--h", f"{h:g}", "-o", direct], out,
        os.path.join(out, "mesh_part_direct.log"))
    clean_msh = os.path.join(out, "mesh_part_clean.msh")
    dropped, median, clean_cells = drop_flat_cells(msh, clean_msh)
    r = report["part"] = {
        "mesh_command": shell_line(cmd), "mesh_seconds": secs, "cells": info.get("cells"),
        "h_vol_percent": info.get("h_vol_percent"), "h_nbr_percent": info.get("h_nbr_percent"),
        "nc_percent": info.get("nc_percent"), "inverted": info.get("inverted"),
        "mesh_volume": info.get("mesh_volume"), "cad_volume": info.get("cad_volume"),
        "repeatable": open(direct).read() == open(inp).read(),
        "median_cell_volume": median, "flat_cells": dropped}
    print(f"steel part h = {h:g}: {r['cells']}, repeatable {r['repeatable']}, "
          f"{len(dropped)} flat cell(s)", flush=True)
    # With flat cells the problem is ill-conditioned: the as-exported run is the acceptance
    # figure; the attribution is made where it means something, without them.
    full = list(FORMS)
    r["exported"] = part_case(args, out, "part", msh, inp,
                              ["native", "exact"] if dropped else full, not dropped)
    if dropped:
        clean_inp = os.path.join(out, "mesh_part_clean.inp")
        run([hexfem, "convert", clean_msh, clean_inp], out, os.path.join(out, "convert_clean.log"))
        r["clean"] = part_case(args, out, "clean", clean_msh, clean_inp, full, True)
        r["clean"]["cells"] = clean_cells


# ---------------------------------------------------------------- report


def table(rows, n):
    """Markdown table: rows = [(header, [values])]; floats as %.7g, relative ones as %+.2e."""
    head = "| mode | " + " | ".join(h for h, _ in rows) + " |"
    lines = [head, "|---:" * (len(rows) + 1) + "|"]
    for m in range(n):
        cells = [f"{v[m]:+.2e}" if h.startswith("rel") or h.startswith("(") else f"{v[m]:.7g}"
                 for h, v in rows]
        lines.append(f"| {m + 1} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def relv(a, b, n):
    return [rel(x, y) for x, y in zip(a[:n], b[:n])]


def maxrel(a, b, n):
    return max(abs(v) for v in relv(a, b, n))


def summarize(args, report):
    n, md, worst = args.compare, [], {}
    st = report.get("structured", {})
    if st:
        md += ["### Structured meshes (100 x 10 x 10 mm cantilever, clamped at x = 0)", "",
               "| mesh | cells | hexfem vs ccx as exported | hexfem vs ccx, exact formulation"
               " | hexfem (--hex8 incompatible) vs ccx C3D8I |", "|---|---|---:|---:|---:|"]
        for key, r in st.items():
            hx, c = r["hexfem"]["freq"], r["ccx"]
            worst[f"{key}/native"] = maxrel(hx, c["native"]["freq"], n)
            lab = r.get("exact_label")
            ex = f"{maxrel(hx, c[lab]['freq'], n):.1e} ({lab})" if lab else "-"
            inc = "-"
            if r.get("hexfem_incompatible") and "exact+c3d8i" in c:
                inc = f"{maxrel(r['hexfem_incompatible']['freq'], c['exact+c3d8i']['freq'], n):.1e}"
            cells = ", ".join(f"{v} {k}" for k, v in r["cells"].items() if v)
            md.append(f"| {key} | {cells} | {worst[f'{key}/native']:.1e} | {ex} | {inc} |")
        md.append("")
        for key in ("hex", "hex_jitter"):
            hx, cx = st[key]["hexfem"]["freq"], st[key]["ccx"]["native"]["freq"]
            md += [f"#### {key}: hexfem hex8 (2x2x2 Gauss) vs ccx C3D8, acceptance 1e-6", "",
                   table([("hexfem [Hz]", hx), ("ccx C3D8 [Hz]", cx),
                          ("rel. diff.", relv(hx, cx, n))], n), ""]
        if "tet4" in st and "numpy" in st["tet4"]:
            hx, cx = st["tet4"]["hexfem"]["freq"], st["tet4"]["ccx"]["native"]["freq"]
            npc, np1 = st["tet4"]["numpy"]["consistent"], st["tet4"]["numpy"]["centroid"]
            md += ["#### tet4 box: hexfem and ccx against an independent numpy assembly", "",
                   table([("hexfem [Hz]", hx), ("numpy, exact consistent mass [Hz]", npc),
                          ("ccx C3D4 [Hz]", cx), ("numpy, centroid mass [Hz]", np1),
                          ("rel hexfem vs numpy consistent", relv(hx, npc, n)),
                          ("rel ccx C3D4 vs numpy centroid", relv(cx, np1, n))], n), ""]
    p = report.get("part")
    if p:
        md += [f"### Steel part, h = {args.h:g}: "
               + ", ".join(f"{v} {k}" for k, v in p["cells"].items()), ""]
        for key, title in (("exported", "the mesh as exported"),
                           ("clean", "the same mesh without its zero-volume cells")):
            if key in p:
                md += part_tables(p[key], f"{title}", n, worst, key)
    return "\n".join(md), worst


def part_tables(r, title, n, worst, key):
    hx, c = r["hexfem"]["freq"], r["ccx"]
    nat = c["native"]["freq"]
    worst[f"{key}/native"] = max(abs(v) for v in relv(hx, nat, n))
    worst[f"{key}/exact"] = max(abs(v) for v in relv(hx, c["exact"]["freq"], n))
    md = [f"#### hexfem vs ccx, {title}", "",
          table([("hexfem [Hz]", hx), ("ccx as exported [Hz]", nat),
                 ("rel. diff.", relv(hx, nat, n)),
                 ("ccx, exact formulations [Hz]", c["exact"]["freq"]),
                 ("rel. diff. (exact)", relv(hx, c["exact"]["freq"], n))], n), ""]
    if "tets" in c:
        one = {k: relv(c[k]["freq"], nat, n) for k in ("tets", "wedges", "pyramids")}
        md += [f"#### What each of ccx's element formulations moves, {title} "
               "(ccx with that kind made exact, relative to ccx as exported)", "",
               table([("(hexfem - ccx)/ccx", relv(hx, nat, n)),
                      ("(C3D4 mass) tets tied C3D10", one["tets"]),
                      ("(C3D6) wedges as C3D8", one["wedges"]),
                      ("(collapsed C3D8) pyramids tied C3D20", one["pyramids"]),
                      ("(sum of the three)", [sum(v) for v in zip(*one.values())]),
                      ("(all three at once)", relv(c["exact"]["freq"], nat, n)),
                      ("(residual) hexfem vs ccx exact", relv(hx, c["exact"]["freq"], n))], n),
               ""]
    if r.get("hexfem_incompatible") and "exact+c3d8i" in c:
        hi = r["hexfem_incompatible"]["freq"]
        worst[f"{key}/c3d8i"] = max(abs(v) for v in relv(hi, c["exact+c3d8i"]["freq"], n))
        md += [f"#### hexfem's default hexes (--hex8 incompatible) vs ccx C3D8I + exact others, "
               f"{title}", "",
               table([("hexfem incompatible [Hz]", hi),
                      ("ccx C3D8I + exact [Hz]", c["exact+c3d8i"]["freq"]),
                      ("rel. diff.", relv(hi, c["exact+c3d8i"]["freq"], n)),
                      ("rel. vs hexfem full hexes", relv(hi, hx, n))], n), ""]
    return md



def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--h", type=float, default=1.0, help="mesh size of the steel part (mm)")
    ap.add_argument("--out", default=os.path.join(ROOT, "validation", "out", "crosscheck"))
    ap.add_argument("--hexfem", default=os.environ.get(
        "HEXFEM", os.path.join(ROOT, "build", "app", "hexfem")))
    ap.add_argument("--modes", type=int, default=10, help="modes asked of both solvers")
    ap.add_argument("--compare", type=int, default=6, help="modes compared")
    ap.add_argument("--json", help="write every figure to this JSON file")
    ap.add_argument("--skip-part", action="store_true", help="only the structured meshes")
    ap.add_argument("--reuse-ccx", action="store_true",
                    help="reuse ccx results of identical decks and meshes from an earlier run")
    ap.add_argument("--timeout", type=float, default=TIMEOUT, help="seconds per solver run")
    args = ap.parse_args()
    globals()["TIMEOUT"] = args.timeout
    args.hexfem = os.path.abspath(args.hexfem)
    if not os.access(args.hexfem, os.X_OK):
        sys.exit(f"crosscheck: no hexfem binary at {args.hexfem} (--hexfem or $HEXFEM)")
    help_text = subprocess.run([args.hexfem, "modal", "--help"], stdout=subprocess.PIPE,
                               text=True).stdout
    args.hex8_option = "--hex8" in help_text
    out = os.path.abspath(args.out)
    os.makedirs(out, exist_ok=True)
    git = subprocess.run(["git", "-C", ROOT, "describe", "--always", "--dirty"],
                         stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True).stdout
    ccx_version = subprocess.run(["ccx", "-v"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                 text=True).stdout.strip()
    report = {"h": args.h, "hexfem": args.hexfem, "out": out, "argv": sys.argv[1:],
              "source": git.strip(), "ccx": ccx_version,
              "hexfem_binary_mtime": time.ctime(os.path.getmtime(args.hexfem))}
    print(f"hexfem {args.hexfem} (built {report['hexfem_binary_mtime']}, tree {report['source']}); "
          f"{ccx_version}", flush=True)
    t0 = time.time()
    structured(args, out, report)
    if not args.skip_part:
        steel_part(args, out, report)
    md, worst = summarize(args, report)
    report["max_rel"] = worst
    report["seconds"] = time.time() - t0
    print("\n" + md)
    with open(os.path.join(out, "tables.md"), "w") as f:
        f.write(md + "\n")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(report, f, indent=1)
    checks = [("pure hex, hexfem hex8 vs ccx C3D8", max(worst["hex/native"],
                                                        worst["hex_jitter/native"]), TOL_HEX)]
    if "exported/native" in worst:
        checks.append(("steel part, hexfem vs ccx on the exported mesh", worst["exported/native"],
                       TOL_MIXED))
    if "clean/native" in worst:
        checks.append(("steel part without its zero-volume cells, hexfem vs ccx as exported",
                       worst["clean/native"], TOL_MIXED))
    ok = True
    for what, value, tol in checks:
        ok = ok and value <= tol
        print(f"acceptance: {what}: max |rel| {value:.2e} (<= {tol:g}): "
              f"{'PASS' if value <= tol else 'FAIL'}")
    print(f"({report['seconds']:.0f} s)")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
