#!/usr/bin/python3
"""The NC quad faces in hexfem's MSH and INP exports, read back by other programs (issue 15).

Meshes the cylinder (which has NC faces) and checks, each against an NC count this script derives
itself from the cells (a quad face of a cell that no other cell has as a quad, with a triangle of
another cell on three of its corners):
  - meshio reads the MSH: the quads of the physical group "nonconformal" are exactly those faces;
  - gmsh reads the MSH and writes it again (MSH 2.2): the group keeps the same number of quads;
  - hexfem stats reads its own MSH back: same NC count, watertight (the group is not boundary);
  - the INP: ELSET NC_ELEMENTS and SURFACE NONCONFORMAL name the same faces (CalculiX face
    numbers decoded with ccx's tables), and CalculiX runs a frequency step on the deck with them.
And --conformal on the same part: the same derivation finds no NC face, and hexfem stats finds the
mesh valid and watertight.
Usage: nc_exports.py HEXFEM CAD WORKDIR"""
import collections
import contextlib
import importlib.util
import io
import itertools
import json
import os
import re
import subprocess
import sys

import meshio
import numpy as np

hexfem, cad, work = sys.argv[1:4]
os.makedirs(work, exist_ok=True)
msh, inp = os.path.join(work, "nc.msh"), os.path.join(work, "nc.inp")
for out in (msh, inp):
    subprocess.run([hexfem, "mesh", cad, "--h", "0.9", "-o", out, "--json"], check=True,
                   stdout=subprocess.DEVNULL)

# Faces per meshio cell type (Gmsh/VTK corner order), outward or not: only the node sets count.
FACES = {"tetra": [(0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)],
         "pyramid": [(0, 1, 2, 3), (0, 1, 4), (1, 2, 4), (2, 3, 4), (3, 0, 4)],
         "wedge": [(0, 1, 2), (3, 4, 5), (0, 1, 4, 3), (0, 3, 5, 2), (1, 2, 5, 4)],
         "hexahedron": [(0, 1, 2, 3), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6),
                        (3, 0, 4, 7)]}


def nc_faces(mesh):
    """The quad faces no other cell has as a quad, with a triangle of another cell on three of
    their corners."""
    faces = collections.defaultdict(int)
    quads = set()
    for block in mesh.cells:
        for cell in block.data if block.type in FACES else []:
            for f in FACES[block.type]:
                key = frozenset(int(cell[i]) for i in f)
                faces[key] += 1
                if len(f) == 4:
                    quads.add(key)
    return {q for q in quads if faces[q] == 1 and
            any(faces.get(frozenset(t), 0) for t in itertools.combinations(q, 3))}


m = meshio.read(msh)
nc = nc_faces(m)
assert nc, "the cylinder at h = 0.9 should have NC faces"

# meshio: the quads of the physical group named "nonconformal".
tag = m.field_data["nonconformal"][0]
group = set()
for block, phys in zip(m.cells, m.cell_data["gmsh:physical"]):
    if block.type == "quad":
        group |= {frozenset(int(i) for i in q) for q, p in zip(block.data, phys) if p == tag}
assert group == nc, f"meshio: group has {len(group)} quads, the cells give {len(nc)} NC faces"

# gmsh: read, write back as MSH 2.2 (one physical tag per element), count the group's quads.
msh2 = os.path.join(work, "nc_gmsh.msh")
subprocess.run(["gmsh", msh, "-0", "-format", "msh22", "-o", msh2], check=True,
               stdout=subprocess.DEVNULL)
text = open(msh2).read()
names = re.search(r"\$PhysicalNames\n\d+\n(.*?)\$EndPhysicalNames", text, re.S).group(1)
gtag = next(int(l.split()[1]) for l in names.splitlines() if '"nonconformal"' in l)
elems = re.search(r"\$Elements\n\d+\n(.*?)\$EndElements", text, re.S).group(1).splitlines()
gquads = sum(1 for e in elems if e.split()[1] == "3" and int(e.split()[3]) == gtag)
assert gquads == len(nc), f"gmsh: {gquads} quads in the group, expected {len(nc)}"

# hexfem reads its own file back: the group is not taken for boundary faces.
stats = json.loads(subprocess.run([hexfem, "stats", msh, "--json"], check=True,
                                  capture_output=True, text=True).stdout)
assert stats["nonconformal_quads"] == len(nc) and stats["watertight"], stats

# INP: decode SURFACE NONCONFORMAL with CalculiX's face tables (C3D8: pyramids as 1 2 3 4 5 5 5 5).
CCX = {"C3D8": [(0, 1, 2, 3), (4, 7, 6, 5), (0, 4, 5, 1), (1, 5, 6, 2), (2, 6, 7, 3), (3, 7, 4, 0)],
       "C3D6": [(0, 1, 2), (3, 4, 5), (0, 1, 4, 3), (1, 2, 5, 4), (2, 0, 3, 5)]}
deck = open(inp).read()
elements = {}
for block in re.finditer(r"\*ELEMENT, TYPE=(\w+), ELSET=\w+\n([^*]*)", deck):
    for line in block.group(2).strip().splitlines():
        ids = [int(v) for v in line.split(",")]
        elements[ids[0]] = (block.group(1), [i - 1 for i in ids[1:]])
surface = re.search(r"\*SURFACE, NAME=NONCONFORMAL, TYPE=ELEMENT\n([^*]*)", deck).group(1)
inp_faces, inp_cells = set(), set()
for line in surface.strip().splitlines():
    e, s = line.split(",")
    etype, nodes = elements[int(e)]
    inp_faces.add(frozenset(nodes[i] for i in CCX[etype][int(s.strip()[1:]) - 1]))
    inp_cells.add(int(e))
assert inp_faces == nc, f"INP: {len(inp_faces)} faces in SURFACE NONCONFORMAL, expected {len(nc)}"
elset = re.search(r"\*ELSET, ELSET=NC_ELEMENTS\n([^*]*)", deck).group(1)
assert {int(v) for v in elset.replace("\n", ",").split(",") if v.strip()} == inp_cells

# CalculiX runs the mesh with the sets in it.
with open(os.path.join(work, "nc_job.inp"), "w") as f:
    f.write("*INCLUDE, INPUT=nc.inp\n*MATERIAL, NAME=STEEL\n*ELASTIC\n210000, 0.3\n*DENSITY\n"
            "7.85e-9\n*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL\n*STEP\n*FREQUENCY\n4\n"
            "*END STEP\n")
subprocess.run(["ccx", "-i", "nc_job"], cwd=work, check=True, stdout=subprocess.DEVNULL)
dat = open(os.path.join(work, "nc_job.dat")).read()
assert "E I G E N V A L U E   O U T P U T" in dat, "ccx wrote no eigenvalues"
# --conformal: no NC face left, by the same derivation and by hexfem stats; valid, watertight.
conformal = os.path.join(work, "conformal.msh")
subprocess.run([hexfem, "mesh", cad, "--h", "0.9", "-o", conformal, "--conformal"], check=True,
               stdout=subprocess.DEVNULL)
left = nc_faces(meshio.read(conformal))
assert not left, f"--conformal left {len(left)} NC faces"
stats = json.loads(subprocess.run([hexfem, "stats", conformal, "--json"], check=True,
                                  capture_output=True, text=True).stdout)
assert stats["nonconformal_quads"] == 0 and stats["watertight"], stats
assert stats["inverted"] == 0 and stats["degenerate"] == 0, stats
# The independent check (validation/conformal_check.py): NC faces as derived here on the default
# mesh, and on the conformal one every face matched, boundary faces = the file's boundary
# elements, nothing inverted, the volume the one enclosed by the outer faces.
check = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "validation",
                     "conformal_check.py")
for path, want_nc in ((msh, len(nc)), (conformal, 0)):
    run = subprocess.run(["/usr/bin/python3", check, path], capture_output=True, text=True)
    j = json.loads(run.stdout)
    assert j["nc_quads"] == want_nc, (path, j)
    assert j["conformal"] == (want_nc == 0) and run.returncode == (0 if want_nc == 0 else 1), j
    assert j["unmatched_faces"] == 0 and j["boundary_elements_not_a_face"] == 0, j
assert abs(j["volume"] - j["enclosed_volume"]) <= 1e-9 * j["volume"], j
# The check fails on the conformal mesh spoilt: a tet turned inside out, one left out, one twice.
spec = importlib.util.spec_from_file_location("conformal_check", check)
checker = importlib.util.module_from_spec(spec)
spec.loader.exec_module(checker)
read = meshio.read
for spoil, field in (("flip", "inverted"), ("drop", "unmatched_faces"),
                     ("dup", "faces_of_3_or_more_cells")):
    def spoilt(*args, **kwargs):
        mesh = read(*args, **kwargs)
        block = next(b for b in mesh.cells if b.type == "tetra")
        if spoil == "flip":
            block.data[0, [1, 2]] = block.data[0, [2, 1]]
        else:
            block.data = block.data[1:] if spoil == "drop" else np.vstack([block.data,
                                                                          block.data[:1]])
        return mesh
    checker.meshio.read = spoilt
    with contextlib.redirect_stdout(io.StringIO()) as out:
        code = checker.main(conformal)
    j = json.loads(out.getvalue())
    assert code == 1 and not j["conformal"] and j[field] > 0, (spoil, j)
checker.meshio.read = read
# Cone_1 at its diagonal / 30: the default mesh's boundary quads bulge its enclosed volume 1.13e-3
# off the tets' (the independent check's half slivers); --conformal gives the most bulging ones
# two triangles, so the enclosed volume comes within 1e-3 of the tet mesh.
cone = os.path.join(os.path.dirname(os.path.abspath(cad)), "Cone_1.brep")
for flags, within in (([], False), (["--conformal"], True)):
    out = os.path.join(work, "cone.msh")
    rep = json.loads(subprocess.run([hexfem, "mesh", cone, "--h", "13.7437", "-o", out, "--json"]
                                    + flags, check=True, capture_output=True, text=True).stdout)
    j = json.loads(subprocess.run(["/usr/bin/python3", check, out], capture_output=True,
                                  text=True).stdout)
    gap = (j["enclosed_volume"] - rep["volume_tets"]) / rep["volume_tets"]
    assert (abs(gap) <= 1e-3) == within and j["inverted"] == 0, (flags, gap, j)
    print(f"Cone_1 h = 13.7437 {' '.join(flags) or 'default'}: enclosed volume {gap:+.2e} of the "
          f"tets' (meshio), conformal {j['conformal']}")
print(f"{len(nc)} NC faces: meshio, gmsh, hexfem stats and the INP sets agree; ccx ran")
