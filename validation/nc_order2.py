#!/usr/bin/python3
"""What the solver does at non-conformal quad faces, at order 1 and order 2 (validation/solver.md
section 7; issue 12 item 2).

  validation/nc_order2.py [--hexfem BIN] [--out validation/out/nc_order2] [--m 1,2,4,8]

The 100 x 10 x 10 mm cantilever (steel, clamped at x = 0) on 10m x m x m cubes: hexes for
x < 50 mm, Kuhn tets (6 per cube) beyond, so each m^2 quad face at x = 50 touches two triangles.
The conformal counterpart replaces the last hex layer by pyramid cubes (centre node, five
pyramids, the +x face as the two tets matching the Kuhn triangles). At order 2 the two triangles'
shared diagonal has a mid-edge node that the quad8 face does not have. Both meshes go to
`hexfem modal --order 1|2` as order-1 .msh files (straight mid-edge nodes).
"""
import argparse
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import crosscheck_ccx as xc  # noqa: E402


def cantilever(m, conformal):
    """(tags, xyz, cells) of the half-hex, half-tet cantilever with m cubes per 10 mm."""
    n = (10 * m, m, m)
    tags, xyz, [(_, hexes)] = xc.box_grid(n)
    h = 10.0 / m
    centre_x = xyz[hexes - 1][:, :, 0].mean(axis=1)
    left = centre_x < 50
    last = left & (centre_x > 50 - h)
    keep = hexes[left & ~last] if conformal else hexes[left]
    cells = [(xc.HEX, keep)]
    tets = [hexes[~left][:, path] for path in xc.KUHN]
    if conformal:
        lay = hexes[last]
        c = np.arange(len(xyz) + 1, len(xyz) + 1 + len(lay))
        xyz = np.vstack([xyz, xyz[lay - 1].mean(axis=1)])
        tags = np.arange(1, len(xyz) + 1)
        faces = [(0, 1, 2, 3), (4, 5, 6, 7), (0, 1, 5, 4), (2, 3, 7, 6), (3, 0, 4, 7)]
        pyr = np.vstack([np.column_stack([lay[:, list(f)], c]) for f in faces])
        cells.append((xc.PYR, xc.positive(xc.PYR, pyr, xyz)))
        # The +x face (1, 2, 6, 5) split along 1-6, as the Kuhn tets beyond split it (0-7 there).
        tets += [np.column_stack([lay[:, [1, 2, 6]], c]), np.column_stack([lay[:, [1, 6, 5]], c])]
    cells.append((xc.TET, xc.positive(xc.TET, np.vstack(tets), xyz)))
    return tags, xyz, cells


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--hexfem", default=os.environ.get(
        "HEXFEM", os.path.join(xc.ROOT, "build", "app", "hexfem")))
    ap.add_argument("--out", default=os.path.join(xc.ROOT, "validation", "out", "nc_order2"))
    ap.add_argument("--m", default="1,2,4,8")
    ap.add_argument("--json")
    args = ap.parse_args()
    args.hexfem = os.path.abspath(args.hexfem)
    out = os.path.abspath(args.out)
    os.makedirs(out, exist_ok=True)
    rows = []
    for order in (1, 2):
        for m in (int(v) for v in args.m.split(",")):
            res = {}
            for conformal in (True, False):
                key = f"m{m}_{'conf' if conformal else 'nc'}"
                tags, xyz, cells = cantilever(m, conformal)
                msh = os.path.join(out, key + ".msh")
                xc.write_msh22(msh, tags, xyz, cells, [])
                cmd = [args.hexfem, "modal", os.path.basename(msh), "--fix", "x<1e-6", "--units",
                       "mm", "--modes", "6", "--order", str(order), "--json", "--hex8", "full"]
                stdout, _ = xc.run(cmd, out, os.path.join(out, f"{key}_o{order}.log"))
                d = json.loads(stdout)
                res[conformal] = {"dofs": d["free_dofs"], "nc": d["mesh"]["nc_quad_faces"],
                                  "f": [q["frequency_hz"] for q in d["modes"]],
                                  "command": xc.shell_line(cmd)}
            conf, nc = res[True], res[False]
            diff = max(abs(a - b) / b for a, b in zip(nc["f"], conf["f"]))
            below = all(a <= b * (1 + 1e-12) for a, b in zip(nc["f"], conf["f"]))
            rows.append({"order": order, "m": m, "conformal": conf, "nc": nc, "max_diff": diff,
                         "nc_softer_every_mode": below})
            print(f"order {order} m {m}: conformal {conf['dofs']} DOF f1 {conf['f'][0]:.3f}, "
                  f"NC ({nc['nc']} faces) {nc['dofs']} DOF f1 {nc['f'][0]:.3f}, max diff "
                  f"{100 * diff:.3f} %", flush=True)
    lines = ["| order | m | mesh | NC faces | DOF | f1 | f3 | f5 | f6 | max diff f1-f6 vs conformal |",
             "|---|---|---|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        for kind in ("conformal", "nc"):
            q = r[kind]
            tail = f"{100 * r['max_diff']:.2f} %" if kind == "nc" else ""
            lines.append(f"| {r['order']} | {r['m']} | {'conformal (pyramid layer)' if kind == 'conformal' else 'NC'} "
                         f"| {q['nc']} | {q['dofs']} | {q['f'][0]:.2f} | {q['f'][2]:.1f} | "
                         f"{q['f'][4]:.1f} | {q['f'][5]:.1f} | {tail} |")
    print("\n".join(lines))
    with open(os.path.join(out, "table.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
