#!/usr/bin/python3
"""Independent modal reference chain: Gmsh tet10 mesh -> CalculiX C3D10 deck -> frequencies.

Shares no code with hexfem. Used by make_reference.sh. Subcommands:
  deck  MESH.msh DECK.inp    write a *FREQUENCY deck clamped at x = min (steel, mm/N/t/s -> Hz)
  freqs JOB.dat              print the frequencies (Hz) found in a ccx .dat file
  resummarize OUT.json       the Richardson extrapolation of OUT.json again, from its runs
  study NAME GEOMETRY OUT.json H1,H2[,H3] WORKDIR [NOTE [CLAMP_H]]
                             for each size: gmsh tet10 mesh, deck, ccx; then Richardson
                             extrapolation of f1..f6 from the two finest sizes -> OUT.json;
                             with CLAMP_H the mesh has size CLAMP_H within 2 mm of x = 0

Units: lengths in mm, E in MPa (N/mm^2), density in t/mm^3, so ccx's frequencies are in Hz.
Clamp: every node with x = min(x) fixed; REFERENCE_CLAMP_AXIS=y or z clamps at min(y) or min(z).
Graded clamp face: REFERENCE_CLAMP_SIZE=S (mm, or "0.35h", a fraction of h) meshes the clamp face
at size S and grows the size at 0.3 mm per mm back to h, as hexfem's --size-at face:ID=S does.
Free-free: REFERENCE_FREE=1 (or free=True to write_deck / run_size / study) writes no *BOUNDARY,
asks ccx for nmodes + 6 and keeps only the elastic frequencies (the six rigid-body ones, checked
to be below 1e-3 of the first elastic one, are dropped; run records keep them as rigid_hz).
"""
import json
import os
import subprocess
import sys
import time

import numpy as np

E_MPA = 210000.0
NU = 0.3
RHO_T_PER_MM3 = 7.85e-9  # 7850 kg/m^3

# Gmsh tet10 edge nodes: 4:(0,1) 5:(1,2) 6:(2,0) 7:(3,0) 8:(3,2) 9:(3,1).
# Abaqus/CalculiX C3D10: 4:(0,1) 5:(1,2) 6:(2,0) 7:(0,3) 8:(1,3) 9:(2,3) -> swap 8 and 9.
GMSH_TO_CCX_TET10 = [0, 1, 2, 3, 4, 5, 6, 7, 9, 8]
CCX_TET10_EDGES = [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)]
GMSH_TET10 = 11  # MSH element type id


def read_msh22(path):
    """Nodes {id: (x,y,z)} and the tet10 connectivity (gmsh order) of an ASCII MSH 2.2 file."""
    nodes = {}
    tets = []
    with open(path) as f:
        line = f.readline()
        while line:
            tag = line.strip()
            if tag == "$MeshFormat":
                version = f.readline().split()
                if not version[0].startswith("2") or version[1] != "0":
                    sys.exit(f"{path}: need ASCII MSH 2.2 (gmsh -format msh22), got {version}")
            elif tag == "$Nodes":
                n = int(f.readline())
                for _ in range(n):
                    p = f.readline().split()
                    nodes[int(p[0])] = (float(p[1]), float(p[2]), float(p[3]))
            elif tag == "$Elements":
                n = int(f.readline())
                for _ in range(n):
                    p = f.readline().split()
                    if int(p[1]) == GMSH_TET10:
                        ntags = int(p[2])
                        tets.append([int(v) for v in p[3 + ntags:]])
            line = f.readline()
    if not tets:
        sys.exit(f"{path}: no tet10 elements (mesh with -3 -order 2)")
    return nodes, tets


def check_tet10(xyz, conn):
    """Guards the node ordering: positive corner volumes, each mid-edge node near its edge's midpoint.

    On curved boundaries the mid-edge nodes sit on the surface, off the chord midpoint by the
    sagitta (a few % of the edge); a wrong permutation puts them half an edge away.
    A small fillet meshed with edges longer than its radius bends a few edges by more (0.36 edge
    lengths measured on gehause_rohteil.stp at h = 1), so the test is on the share: a wrong
    permutation moves every element's nodes, a fillet only some.
    """
    c = xyz[conn]  # (ne, 10, 3)
    vol = np.einsum("ij,ij->i", np.cross(c[:, 1] - c[:, 0], c[:, 2] - c[:, 0]), c[:, 3] - c[:, 0]) / 6
    offs = []
    for k, (a, b) in enumerate(CCX_TET10_EDGES):
        length = np.linalg.norm(c[:, b] - c[:, a], axis=1)
        offs.append(np.linalg.norm(c[:, 4 + k] - 0.5 * (c[:, a] + c[:, b]), axis=1) / length)
    offs = np.concatenate(offs)
    worst, far = float(offs.max()), float((offs > 0.25).mean())
    if vol.min() <= 0:
        sys.exit(f"tet10 check: {int((vol <= 0).sum())} corner tets with non-positive volume")
    if far > 1e-3 or worst > 0.5:
        sys.exit(f"tet10 check: {100 * far:.2f} % of the mid-edge nodes more than 0.25 edge "
                 f"lengths off their edge midpoint (worst {worst:.2f})")
    return float(vol.sum()), worst


def clamp_axis():
    """0, 1 or 2: the axis whose minimum plane is clamped (REFERENCE_CLAMP_AXIS, default x)."""
    name = os.environ.get("REFERENCE_CLAMP_AXIS", "x")
    if name not in ("x", "y", "z"):
        sys.exit(f"REFERENCE_CLAMP_AXIS must be x, y or z, got {name!r}")
    return "xyz".index(name)


def free_free(free=None):
    """True when the model is free-free: the argument if given, else REFERENCE_FREE=1."""
    if free is not None:
        return bool(free)
    value = os.environ.get("REFERENCE_FREE", "0")
    if value not in ("0", "1"):
        sys.exit(f"REFERENCE_FREE must be 0 or 1, got {value!r}")
    return value == "1"


NRIGID = 6  # rigid-body modes of a free-free solid


def write_deck(msh, inp, nmodes=10, free=None):
    """Writes the ccx deck; returns mesh figures (counts, volume, ordering check).

    Free-free (free_free(free)): no *BOUNDARY, and ccx is asked for nmodes + 6 modes so that
    nmodes elastic ones remain after the six rigid-body modes.
    """
    free = free_free(free)
    nodes, tets = read_msh22(msh)
    used = sorted({v for t in tets for v in t})
    index = {nid: i for i, nid in enumerate(used)}
    xyz = np.array([nodes[n] for n in used])
    conn = np.array([[index[t[j]] for j in GMSH_TO_CCX_TET10] for t in tets])
    volume, worst = check_tet10(xyz, conn)

    if free:
        fixed = []
    else:
        axis = clamp_axis()
        xmin = xyz[:, axis].min()
        tol = 1e-6 * (xyz[:, axis].max() - xmin)
        fixed = [used[i] for i in np.nonzero(xyz[:, axis] <= xmin + tol)[0]]

    with open(inp, "w") as f:
        f.write("** generated by validation/reference/reference_chain.py from %s\n" % msh)
        f.write("*NODE, NSET=NALL\n")
        for nid, p in zip(used, xyz):
            f.write("%d, %.15g, %.15g, %.15g\n" % (nid, p[0], p[1], p[2]))
        f.write("*ELEMENT, TYPE=C3D10, ELSET=EALL\n")
        for eid, t in enumerate(conn, start=1):
            f.write("%d, %s\n" % (eid, ", ".join(str(used[v]) for v in t)))
        if fixed:
            f.write("*NSET, NSET=FIX\n")
            for i in range(0, len(fixed), 10):
                f.write(", ".join(str(n) for n in fixed[i:i + 10]) + ",\n")
            f.write("*BOUNDARY\nFIX, 1, 3\n")
        f.write("*MATERIAL, NAME=STEEL\n*ELASTIC\n%g, %g\n*DENSITY\n%g\n" % (E_MPA, NU, RHO_T_PER_MM3))
        f.write("*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL\n")
        f.write("*STEP\n*FREQUENCY\n%d\n*END STEP\n" % (nmodes + (NRIGID if free else 0)))
    info = {"nodes": len(used), "elements": len(tets), "dofs": 3 * (len(used) - len(fixed)),
            "fixed_nodes": len(fixed)}
    if free:
        info["free"] = True
    else:
        info["xyz"[axis] + "_fixed"] = float(xmin)
    info.update({"mesh_volume": volume, "max_midnode_offset": worst})
    return info


def read_frequencies(dat):
    """Frequencies (cycles/time) of the EIGENVALUE OUTPUT block of a ccx .dat file."""
    freqs = []
    with open(dat) as f:
        lines = f.readlines()
    start = None
    for i, line in enumerate(lines):
        if "E I G E N V A L U E   O U T P U T" in line:
            start = i
    if start is None:
        sys.exit(f"{dat}: no eigenvalue output")
    for line in lines[start + 1:]:
        p = line.split()
        if len(p) == 5 and p[0].isdigit():
            freqs.append(float(p[3]))
        elif freqs and not p:
            break
    return freqs


def richardson(f_coarse, f_fine, ratio, p):
    return f_fine + (f_fine - f_coarse) / (ratio ** p - 1)


def observed_order(h, f):
    """Order p with (f0 - f1) / (f1 - f2) = (h0^p - h1^p) / (h1^p - h2^p), h0 > h1 > h2.

    None when the three values are not monotone or p falls outside [0.5, 10].
    """
    d1, d2 = f[0] - f[1], f[1] - f[2]
    if d1 * d2 <= 0:
        return None
    target = d1 / d2

    def g(p):
        return (h[0] ** p - h[1] ** p) / (h[1] ** p - h[2] ** p) - target

    lo, hi = 0.5, 10.0
    if g(lo) * g(hi) > 0:
        return None
    for _ in range(200):  # g is increasing in p: bisection
        mid = 0.5 * (lo + hi)
        if g(lo) * g(mid) <= 0:
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi)


def summarize(doc, nref=6, assumed_p=4.0, singular_p=1.5):
    """Extrapolates each of the first nref frequencies from the two finest sizes.

    C3D10 is quadratic: eigenvalue (and so frequency) errors go as h^(2*2) = h^4 for a smooth
    solution. The edge where the clamped face meets the free faces is singular, which lowers the
    order: asymptotically to about 1.5 (measured: p = 1.57 on the cantilever with structured
    C3D20 meshes, cantilever_c3d20.py). With three sizes the observed order is computed; the
    reference uses it when it is well defined (monotone, 1 <= p <= 6); an observed order below 1
    is the singular edge not yet asymptotic, so the singular order 1.5 is used (the cylinder's
    f1/f2 observed 0.97: h^4 there left them 0.043 % high against a graded C3D20 reference,
    cylinder_c20.py); else the assumed h^4.
    Uncertainty: the largest distance from the reference to the finest run and to the
    extrapolations with p = 4 and p = 1.5.
    """
    runs = sorted(doc["runs"], key=lambda r: -r["h"])  # coarse to fine
    nref = min([nref] + [len(r["frequencies_hz"]) for r in runs])
    c, m = runs[-2], runs[-1]
    ratio = c["h"] / m["h"]
    ref, p_used, p_obs_all, spread = [], [], [], []
    for k in range(nref):
        fc, ff = c["frequencies_hz"][k], m["frequencies_hz"][k]
        p_obs = None
        if len(runs) >= 3:
            p_obs = observed_order([r["h"] for r in runs[-3:]],
                                   [r["frequencies_hz"][k] for r in runs[-3:]])
        if p_obs is not None and 1.0 <= p_obs <= 6.0:
            p = p_obs
        elif p_obs is not None and 0.0 < p_obs < 1.0:
            p = singular_p
        else:
            p = assumed_p
        f_p = richardson(fc, ff, ratio, p)
        bounds = [ff] + [richardson(fc, ff, ratio, q) for q in (assumed_p, singular_p)]
        ref.append(f_p)
        p_used.append(p)
        p_obs_all.append(p_obs)
        spread.append(max(abs(f_p - b) for b in bounds))
    doc["runs"] = runs
    doc["richardson"] = {
        "from_h": [c["h"], m["h"]],
        "ratio": ratio,
        "assumed_order": assumed_p,
        "singular_order": singular_p,
        "uncertainty": "max |reference - x| over x = finest run, extrapolations with p = 4 and 1.5",
        "observed_order": p_obs_all,
        "order_used": p_used,
        "formula": "f_ref = f_fine + (f_fine - f_coarse) / (ratio^p - 1)",
    }
    doc["reference_hz"] = ref
    doc["reference_uncertainty_hz"] = spread
    doc["reference_uncertainty_rel"] = [s / f for s, f in zip(spread, ref)]
    print("%-10s" % "h" + "".join("%12s" % ("f%d" % (k + 1)) for k in range(nref))
          + "  elements      dofs  seconds")
    for r in runs:
        print("%-10.6g" % r["h"] + "".join("%12.3f" % v for v in r["frequencies_hz"][:nref])
              + "  %8d  %8d  %7.1f" % (r["elements"], r["dofs"], r["seconds_total"]))
    print("%-10s" % "p_obs" + "".join("%12s" % ("-" if p is None else "%.2f" % p)
                                      for p in p_obs_all))
    print("%-10s" % "reference" + "".join("%12.3f" % v for v in ref))
    print("%-10s" % "+-" + "".join("%12.3f" % v for v in spread))
    return doc


def tool_versions():
    g = subprocess.run(["gmsh", "--version"], capture_output=True, text=True)
    c = subprocess.run(["ccx", "-v"], capture_output=True, text=True)
    words = (c.stdout + c.stderr).split()  # "This is Version 2.20"
    return {"gmsh": (g.stdout + g.stderr).strip(), "ccx": words[-1] if words else "unknown"}


def graded_geo(geometry, h, clamp_h, clamp_depth, path):
    """A Gmsh script: size h, but clamp_h within clamp_depth of the face x = 0 (the clamp)."""
    with open(path, "w") as f:
        f.write('Merge "%s";\n' % os.path.abspath(geometry))
        f.write("Field[1] = Box; Field[1].VIn = %r; Field[1].VOut = %r;\n" % (clamp_h, h))
        f.write("Field[1].XMin = -1e3; Field[1].XMax = %r;\n" % clamp_depth)
        f.write("Field[1].YMin = -1e3; Field[1].YMax = 1e3; Field[1].ZMin = -1e3;"
                " Field[1].ZMax = 1e3;\n")
        f.write("Background Field = 1;\n")
        f.write("Mesh.MeshSizeExtendFromBoundary = 0; Mesh.MeshSizeFromPoints = 0;\n")


def split_rigid(freqs, nmodes, where):
    """(elastic, rigid): drops the six lowest frequencies of a free-free run after checking that
    they are rigid-body modes (|f| below 1e-3 of the first elastic frequency)."""
    if len(freqs) < NRIGID + nmodes:
        raise RuntimeError("%s: %d frequencies, expected %d (%d rigid + %d elastic)"
                           % (where, len(freqs), NRIGID + nmodes, NRIGID, nmodes))
    rigid, elastic = freqs[:NRIGID], freqs[NRIGID:]
    if max(abs(f) for f in rigid) >= 1e-3 * elastic[0]:
        raise RuntimeError("%s: the six lowest frequencies %s are not all rigid-body modes "
                           "(limit 1e-3 of f7 = %g)" % (where, rigid, elastic[0]))
    return elastic, rigid


GRADING_RATE = 0.3  # hexfem's --size-at face grading: the size grows 0.3 mm per mm


def clamp_size(h, size=None):
    """The clamp-face size in mm for mesh size h: the argument, else REFERENCE_CLAMP_SIZE
    (mm, or a fraction of h written like hexfem's --size-at: "0.35h"); None when neither is set."""
    if size is None:
        size = os.environ.get("REFERENCE_CLAMP_SIZE") or None
    if size is None:
        return None
    text = str(size).strip()
    try:
        value = float(text[:-1]) * h if text.endswith("h") else float(text)
    except ValueError:
        sys.exit(f"clamp size must be a size in mm or a fraction of h like 0.35h, got {size!r}")
    if not 0 < value <= h:
        sys.exit(f"clamp size {text} gives {value:g} mm, outside (0, h = {h:g}]")
    return value


def face_graded_geo(geometry, h, size, axis, path, rate=GRADING_RATE):
    """A Gmsh script grading like hexfem's --size-at face:ID=S: size S on the clamp surfaces
    (every surface inside the plane axis = min of the part's bounding box), growing linearly
    away from them at `rate` mm per mm back to h (Threshold on a Distance field, reached at
    the distance (h - S) / rate); the background field alone sets the size."""
    a = "xyz".index(axis) if isinstance(axis, str) else axis
    lo = ["bb(0) - e", "bb(1) - e", "bb(2) - e"]
    hi = ["bb(3) + e", "bb(4) + e", "bb(5) + e"]
    hi[a] = "bb(%d) + e" % a  # the slab around the minimum plane
    with open(path, "w") as f:
        f.write('Merge "%s";\n' % os.path.abspath(geometry))
        f.write("// the part's bounding box over all volumes\n")
        f.write("v() = Volume{:};\nbb() = BoundingBox Volume{v(0)};\n")
        f.write("For i In {1:#v()-1}\n  b() = BoundingBox Volume{v(i)};\n  For k In {0:2}\n"
                "    bb(k) = (b(k) < bb(k)) ? b(k) : bb(k);\n"
                "    bb(k+3) = (b(k+3) > bb(k+3)) ? b(k+3) : bb(k+3);\n  EndFor\nEndFor\n")
        f.write("e = 1e-3 * (bb(%d) - bb(%d));\n" % (a + 3, a))
        f.write("clamp() = Surface In BoundingBox{%s, %s};\n" % (", ".join(lo), ", ".join(hi)))
        f.write('If (#clamp() == 0)\n  Error("no surface in the plane %s = min");\n  Abort;\n'
                'EndIf\n' % "xyz"[a])
        f.write('Printf("clamp surfaces (%s = min): %%g", #clamp());\n' % "xyz"[a])
        f.write("Field[1] = Distance; Field[1].FacesList = {clamp()};\n")
        f.write("Field[2] = Threshold; Field[2].InField = 1;\n")
        f.write("Field[2].SizeMin = %r; Field[2].SizeMax = %r;\n" % (size, h))
        f.write("Field[2].DistMin = 0; Field[2].DistMax = %r;\n" % ((h - size) / rate))
        f.write("Background Field = 2;\n")
        f.write("Mesh.MeshSizeExtendFromBoundary = 0; Mesh.MeshSizeFromPoints = 0;\n")
        f.write("Mesh.MeshSizeFromCurvature = 0;\n")


def run_size(geometry, h, workdir, name, nmodes, clamp_h=None, clamp_depth=2.0, free=None,
             clamp_size_mm=None):
    """Meshes at size h, writes the deck, runs ccx; returns the run record.

    Mesh: uniform h; with clamp_h, size clamp_h within clamp_depth of x = 0 (Box field); with a
    clamp size (clamp_size_mm, or REFERENCE_CLAMP_SIZE: mm or "0.35h"), graded like hexfem's
    --size-at face: that size on the clamp face (the axis of clamp_axis() = min), growing at
    0.3 mm per mm back to h. Free-free (free_free(free)): frequencies_hz holds the elastic
    frequencies only, rigid_hz the six rigid-body ones dropped."""
    free = free_free(free)
    size = None if clamp_h is not None else clamp_size(h, clamp_size_mm)
    if size is not None and free:
        sys.exit("a graded clamp face needs a clamp: not with REFERENCE_FREE=1")
    base = os.path.join(workdir, "%s_h%g" % (name, h))
    msh, job = base + ".msh", base
    if clamp_h is not None:
        graded_geo(geometry, h, clamp_h, clamp_depth, base + ".geo")
        gmsh_cmd = ["gmsh", base + ".geo", "-3", "-order", "2", "-format", "msh22", "-o", msh]
    elif size is not None:
        face_graded_geo(geometry, h, size, clamp_axis(), base + ".geo")
        gmsh_cmd = ["gmsh", base + ".geo", "-3", "-order", "2", "-format", "msh22", "-o", msh]
    else:
        gmsh_cmd = ["gmsh", geometry, "-3", "-order", "2", "-clmax", repr(h), "-clmin", repr(h),
                    "-format", "msh22", "-o", msh]
    t0 = time.time()
    with open(base + ".gmsh.log", "w") as log:
        subprocess.run(gmsh_cmd, check=True, stdout=log, stderr=subprocess.STDOUT)
    t1 = time.time()
    info = write_deck(msh, job + ".inp", nmodes, free)
    t2 = time.time()
    ccx_cmd = ["ccx", "-i", os.path.basename(job)]
    with open(base + ".ccx.log", "w") as log:
        subprocess.run(ccx_cmd, check=True, stdout=log, stderr=subprocess.STDOUT, cwd=workdir)
    t3 = time.time()
    with open(base + ".ccx.log") as log:
        errors = [l.strip() for l in log if "*ERROR" in l]
    if errors:
        sys.exit("ccx failed on %s: %s" % (job + ".inp", errors[0]))
    freqs = read_frequencies(job + ".dat")
    rigid = None
    if free:
        freqs, rigid = split_rigid(freqs, nmodes, job + ".dat")
    if len(freqs) < nmodes:
        sys.exit("%s: %d frequencies, expected %d" % (job + ".dat", len(freqs), nmodes))
    run = {"h": h, **info, "frequencies_hz": freqs,
           **({} if rigid is None else {"rigid_hz": rigid}),
           **({} if clamp_h is None else {"clamp_h": clamp_h, "clamp_depth": clamp_depth}),
           **({} if size is None else {"clamp_size": size, "grading_rate": GRADING_RATE}),
           "seconds_gmsh": round(t1 - t0, 2), "seconds_deck": round(t2 - t1, 2),
           "seconds_ccx": round(t3 - t2, 2), "seconds_total": round(t3 - t0, 2),
           "gmsh_command": " ".join(gmsh_cmd), "ccx_command": " ".join(ccx_cmd)}
    print("h = %g: %d tet10, %d dofs, f1..f3 = %s Hz, %.1f s (gmsh %.1f, ccx %.1f)"
          % (h, info["elements"], info["dofs"], ", ".join("%.3f" % f for f in freqs[:3]),
             t3 - t0, t1 - t0, t3 - t2), flush=True)
    return run


def study(name, geometry, out, sizes, workdir, nmodes=10, note="", clamp_h=None, free=None):
    free = free_free(free)
    os.makedirs(workdir, exist_ok=True)
    os.environ.setdefault("OMP_NUM_THREADS", "1")  # see make_reference.sh
    doc = {
        "what": note,
        "command": os.environ.get("HEXFEM_REFERENCE_COMMAND", " ".join(sys.argv)),
        "geometry": geometry,
        "units": "mm, N, t (tonne), s: E in MPa, density in t/mm^3, frequencies in Hz",
        "material": {"E_MPa": E_MPA, "nu": NU, "density_t_per_mm3": RHO_T_PER_MM3},
        "boundary": ("free-free (no fixed DOF); the six rigid-body modes dropped" if free else
                     "all nodes with {0} = min({0}) fixed in x, y, z".format("xyz"[clamp_axis()])),
        "element": "CalculiX C3D10 (Gmsh -order 2 tets, nodes 8 and 9 swapped to Abaqus order)",
        "versions": tool_versions(),
        "runs": [run_size(geometry, h, workdir, name, nmodes, clamp_h, free=free)
                 for h in sorted(sizes, reverse=True)],
    }
    doc = summarize(doc)
    with open(out, "w") as f:
        json.dump(doc, f, indent=2)
        f.write("\n")
    print("wrote", out)


def main(argv):
    if len(argv) == 3 and argv[0] == "deck":
        print(json.dumps(write_deck(argv[1], argv[2])))
    elif len(argv) == 2 and argv[0] == "freqs":
        print(json.dumps(read_frequencies(argv[1])))
    elif len(argv) == 2 and argv[0] == "resummarize":  # the extrapolation again, same runs
        with open(argv[1]) as f:
            doc = summarize(json.load(f))
        with open(argv[1], "w") as f:
            json.dump(doc, f, indent=2)
            f.write("\n")
    elif len(argv) in (6, 7, 8) and argv[0] == "study":
        sizes = [float(v) for v in argv[4].split(",")]
        study(argv[1], argv[2], argv[3], sizes, argv[5], note=argv[6] if len(argv) >= 7 else "",
              clamp_h=float(argv[7]) if len(argv) == 8 else None)
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main(sys.argv[1:])
