#!/usr/bin/python3
"""Renders a cut-away picture of a hex-dominant mesh, coloured as in Baudouin et al. 2014:
hexahedra white, prisms yellow, pyramids red, tetrahedra blue.

usage: validation/render_cutaway.py MESH OUT.png [--axis x|y|z] [--at 0.5] [--flip]
           [--rotation RX,RY,RZ] [--zoom Z] [--size 1600x1200] [--no-edges] [--print-script]

MESH: a .msh (MSH 2.2 or 4.1) or a .vtu (or anything meshio reads) with linear volume cells
(VTK 12 hex, 13 wedge, 14 pyramid, 10 tet / MSH types 5, 6, 7, 4). The colour comes from the cell
type itself. The mesh is cut by the plane normal to --axis through the bounding box at fraction
--at; the whole elements on the far side of the plane are drawn (Gmsh's ClipWholeElements), so
the cut shows the elements as they are, not sliced. The picture is drawn by Debian's gmsh under
xvfb-run (package xvfb), offscreen; Mesa's software OpenGL is enough.
"""
import argparse
import contextlib
import io
import os
import shutil
import subprocess
import sys
import tempfile

import meshio
import numpy

# Colours of the paper's figures.
COLOURS = {"Hexahedra": (255, 255, 255), "Prisms": (255, 230, 0),
           "Pyramids": (230, 0, 0), "Tetrahedra": (40, 60, 255)}
MESHIO_KIND = {"hexahedron": "hex", "wedge": "prism", "pyramid": "pyramid", "tetra": "tet"}

# Per cut axis: the side kept (+1: coordinate >= plane) and the camera (Gmsh Euler angles,
# degrees) that looks at the cut face from the removed side, a little from above and aside.
# --flip keeps the other side and turns the camera by 180 degrees.
VIEWS = {"x": (1.0, (-60.0, 0.0, 60.0)), "y": (1.0, (-60.0, 0.0, 30.0)),
         "z": (-1.0, (-20.0, 0.0, 30.0))}
FLIP_TURN = {"x": (0.0, 0.0, 180.0), "y": (0.0, 0.0, 180.0), "z": (180.0, 0.0, 0.0)}


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("mesh")
    p.add_argument("png")
    p.add_argument("--axis", choices="xyz", default="y", help="normal of the cut plane")
    p.add_argument("--at", type=float, default=0.5, help="plane position, fraction of the bbox")
    p.add_argument("--flip", action="store_true", help="keep the other side of the plane")
    p.add_argument("--rotation", help="camera RX,RY,RZ in degrees (Gmsh General.Rotation*)")
    p.add_argument("--size", default="1600x1200", help="picture size WxH in pixels")
    p.add_argument("--zoom", type=float, help="scale of the view (default: fit the rotated box)")
    p.add_argument("--no-edges", action="store_true", help="no element edges (dense meshes)")
    p.add_argument("--print-script", action="store_true", help="print the Gmsh script used")
    a = p.parse_args(argv)
    if not 0.0 <= a.at <= 1.0:
        p.error("--at must be in [0, 1]")
    try:
        a.width, a.height = (int(v) for v in a.size.lower().split("x"))
    except ValueError:
        p.error("--size must look like 1600x1200")
    a.keep, a.view = VIEWS[a.axis]
    if a.flip:
        a.keep = -a.keep
        a.view = tuple(v + t for v, t in zip(a.view, FLIP_TURN[a.axis]))
    if a.rotation:
        try:
            a.view = tuple(float(v) for v in a.rotation.split(","))
            assert len(a.view) == 3
        except (ValueError, AssertionError):
            p.error("--rotation must be three numbers RX,RY,RZ")
    return a


def load(path):
    """Reads the mesh; returns it, the counts per kind and the bounding box."""
    if not os.path.isfile(path):
        sys.exit("render_cutaway: no such file: %s" % path)
    try:
        with contextlib.redirect_stdout(io.StringIO()):  # meshio's gmsh reader prints a blank line
            mesh = meshio.read(path)
    except Exception as e:  # meshio raises many types; one line for the user
        sys.exit("render_cutaway: cannot read %s: %s" % (path, e))
    counts = {k: 0 for k in MESHIO_KIND.values()}
    for block in mesh.cells:
        if block.type in MESHIO_KIND:
            counts[MESHIO_KIND[block.type]] += len(block.data)
    if sum(counts.values()) == 0:
        sys.exit("render_cutaway: %s has no hex, prism, pyramid or tet cells" % path)
    pts = mesh.points
    if pts.shape[1] == 2:
        sys.exit("render_cutaway: %s is a 2D mesh" % path)
    return mesh, counts, pts.min(axis=0), pts.max(axis=0)


def as_gmsh_file(path, mesh, tmp):
    """Gmsh reads .msh itself; anything else is converted to MSH 2.2 with meshio (volume cells only)."""
    if path.lower().endswith(".msh"):
        return os.path.abspath(path)
    cells = [(b.type, b.data) for b in mesh.cells if b.type in MESHIO_KIND]
    out = os.path.join(tmp, "mesh.msh")
    zeros = [numpy.zeros(len(c[1]), dtype=numpy.int32) for c in cells]  # no tags to carry over
    tags = {"gmsh:physical": zeros, "gmsh:geometrical": zeros}
    meshio.write(out, meshio.Mesh(mesh.points, cells, cell_data=tags), file_format="gmsh22",
                 binary=True)
    return out


def rotation(rx, ry, rz):
    """Gmsh's model rotation with General.Trackball = 0: glRotate about x, then y, then z."""
    def rot(axis, deg):
        c, s = numpy.cos(numpy.radians(deg)), numpy.sin(numpy.radians(deg))
        i, j = [k for k in range(3) if k != axis]
        m = numpy.eye(3)
        m[i, i], m[i, j], m[j, i], m[j, j] = c, -s, s, c
        return m
    return rot(0, rx) @ rot(1, ry) @ rot(2, rz)


def auto_zoom(a, lo, hi):
    """Scale so that the rotated bounding box fills ~85 % of the picture.

    Gmsh fits the unrotated x-y extent of the box to the window (with a margin: 1/1.5 of the
    window, measured on Gmsh 4.8.4 pictures), then rotates: a long part seen at an angle ends up
    small, a cube-like one overflows.
    """
    ext = numpy.maximum(hi - lo, 1e-12 * max(1.0, float(numpy.abs(hi - lo).max())))
    fit = min(a.width / ext[0], a.height / ext[1]) / 1.5  # pixels per unit at scale 1
    corners = numpy.array([[x, y, z] for x in (0, ext[0]) for y in (0, ext[1]) for z in (0, ext[2])])
    proj = (rotation(*a.view) @ (corners - ext / 2).T)[:2]
    span = proj.max(axis=1) - proj.min(axis=1)
    return 0.85 * min(a.width / (span[0] * fit), a.height / (span[1] * fit))


def geo_script(msh, png, a, counts, lo, hi):
    axis = "xyz".index(a.axis)
    plane = [0.0, 0.0, 0.0]
    plane[axis] = a.keep  # Gmsh keeps A x + B y + C z + D >= 0
    d = -a.keep * (lo[axis] + a.at * (hi[axis] - lo[axis]))
    zoom = a.zoom if a.zoom else auto_zoom(a, lo, hi)
    colour = "\n".join("Mesh.Color.%s = {%d, %d, %d};" % (k, *v) for k, v in COLOURS.items())
    # One legend line per kind. Gmsh under Xvfb draws no spaces in text, so none are used.
    names = [("hex", "white"), ("prism", "yellow"), ("pyramid", "red"), ("tet", "blue")]
    step = max(12, a.height // 50) + 6
    legend = "\n".join('T2(10, %d, 0){"%s:%d(%s)"};' % (-10 - step * (3 - i), k, counts[k], c)
                       for i, (k, c) in enumerate(names))
    return f"""// written by validation/render_cutaway.py
// Window size before Merge so that the initial fit uses it.
General.GraphicsWidth = {a.width}; General.GraphicsHeight = {a.height};
General.DetachedMenu = 1;  // the graphics window alone is the picture, at the size asked
General.GraphicsFontSize = {max(12, a.height // 50)};
Merge "{msh}";
General.ScaleX = {zoom:.4f}; General.ScaleY = {zoom:.4f}; General.ScaleZ = {zoom:.4f};
General.Axes = 0; General.SmallAxes = 0; General.Trackball = 0;
General.RotationX = {a.view[0]}; General.RotationY = {a.view[1]}; General.RotationZ = {a.view[2]};
General.Color.Background = {{255, 255, 255}}; General.Color.Foreground = {{0, 0, 0}};
General.Color.Text = {{0, 0, 0}};
Geometry.Points = 0; Geometry.Curves = 0; Geometry.Surfaces = 0;
Mesh.ColorCarousel = 0;  // colour by element type
{colour}
Mesh.Points = 0; Mesh.Lines = 0; Mesh.SurfaceFaces = 0; Mesh.SurfaceEdges = 0;
Mesh.VolumeFaces = 1; Mesh.VolumeEdges = {0 if a.no_edges else 1};
General.Clip0A = {plane[0]}; General.Clip0B = {plane[1]}; General.Clip0C = {plane[2]};
General.Clip0D = {d!r};
Mesh.Clip = 1; General.ClipWholeElements = 1; General.ClipOnlyVolume = 1;
View "legend" {{
{legend}
}};
View[0].ShowScale = 0;
Draw;
Print "{png}";
Exit;
"""


def main(argv):
    a = parse_args(argv)
    mesh, counts, lo, hi = load(a.mesh)
    gmsh = shutil.which("gmsh")
    if gmsh is None:
        sys.exit("render_cutaway: gmsh not found (Debian package gmsh)")
    if shutil.which("xvfb-run"):
        # -a picks a free display; the screen must hold the graphics window.
        runner = ["xvfb-run", "-a", "-s", "-screen 0 %dx%dx24" % (a.width + 400, a.height + 400)]
    elif os.environ.get("DISPLAY"):
        runner = []
    else:
        sys.exit("render_cutaway: no X display and no xvfb-run (apt-get install xvfb)")
    png = os.path.abspath(a.png)
    with tempfile.TemporaryDirectory(prefix="cutaway.") as tmp:
        geo = os.path.join(tmp, "cutaway.geo")
        with open(geo, "w") as f:
            f.write(geo_script(as_gmsh_file(a.mesh, mesh, tmp), png + ".tmp.png", a, counts, lo, hi))
        if a.print_script:
            with open(geo) as f:
                print(f.read())
        r = subprocess.run(runner + [gmsh, geo], capture_output=True, text=True, timeout=1800)
        if r.returncode != 0 or not os.path.isfile(png + ".tmp.png"):
            sys.stderr.write(r.stdout[-2000:] + r.stderr[-2000:])
            sys.exit("render_cutaway: gmsh did not write the picture")
        os.replace(png + ".tmp.png", png)  # never leave a half-written picture
    axis = "xyz".index(a.axis)
    print("wrote %s: %s hex, %s prism, %s pyramid, %s tet; cut %s = %.4g, kept %s %s it" % (
        a.png, counts["hex"], counts["prism"], counts["pyramid"], counts["tet"], a.axis,
        lo[axis] + a.at * (hi[axis] - lo[axis]), a.axis, ">=" if a.keep > 0 else "<="))


if __name__ == "__main__":
    main(sys.argv[1:])
