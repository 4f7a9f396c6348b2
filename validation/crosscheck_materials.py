#!/usr/bin/python3
"""A material per solid on a real assembly: hexfem against CalculiX 2.20 on the same mesh.

  validation/crosscheck_materials.py [--h 16] [--out /tmp/xmat] [--hexfem build/app/hexfem]
      [--modes 10]

The CAX-IF AS1 assembly (tests/data/as1-oc-214.stp, 18 solids) glued (`--glue`) and meshed at
order 1 with hexes and tets only (`--no-prisms --no-pyramids`: ccx has no element that integrates
a distorted prism or pyramid as hexfem does, crosscheck.md): steel rod, bolts and nuts, aluminium plate (solid 11) and brackets (10, 18), its six bolt
tips clamped (z < -3.99 mm). hexfem solves it with `--material solid:10,11,18=aluminium --hex8
full`; ccx solves the .inp that `hexfem convert` writes, its kinds rewritten so that ccx integrates
hexfem's fields exactly (crosscheck_ccx.py: tets as tied C3D10 with their mid-edge nodes tied to the
edges' means), with one *MATERIAL and *SOLID SECTION per element set SOLID_n. Then the same with every
solid steel, to show what the aluminium parts change. Stdlib + numpy; exit 1 if a frequency differs
by more than 1e-6.
"""
import argparse
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import crosscheck_ccx as cc  # noqa: E402

ROOT = cc.ROOT
ALUMINIUM = (70000.0, 0.33, 2.7e-9)  # MPa, -, t/mm^3
STEEL = (cc.E_MPA, cc.NU, cc.RHO_T_MM3)
EXACT = {"hex8": "native", "tet4": "tied10", "wedge6": "c3d8", "pyramid5": "tied20"}


def deck(path, mesh_inp, clamp_ids, solids, modes, aluminium):
    lines = [f"*INCLUDE, INPUT={os.path.basename(mesh_inp)}", "*NSET, NSET=CLAMP"]
    lines += [",".join(map(str, clamp_ids[k:k + 16])) for k in range(0, len(clamp_ids), 16)]
    lines += ["*BOUNDARY", "CLAMP, 1, 3"]
    for s in solids:
        E, nu, rho = ALUMINIUM if s in aluminium else STEEL
        lines += [f"*MATERIAL, NAME=M{s}", "*ELASTIC", f"{E!r}, {nu!r}", "*DENSITY", f"{rho!r}",
                  f"*SOLID SECTION, ELSET=SOLID_{s}, MATERIAL=M{s}"]
    lines += ["*STEP", "*FREQUENCY, STORAGE=YES", str(modes), "*END STEP"]
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--h", type=float, default=16.0)
    ap.add_argument("--out", default="/tmp/xmat")
    ap.add_argument("--hexfem", default=os.path.join(ROOT, "build/app/hexfem"))
    ap.add_argument("--modes", type=int, default=10)
    args = ap.parse_args()
    out = os.path.abspath(args.out)
    os.makedirs(out, exist_ok=True)
    step = os.path.join(ROOT, "tests/data/as1-oc-214.stp")
    cc.run([args.hexfem, "mesh", step, "--glue", "--h", str(args.h), "--no-pyramids", "--no-prisms", "-o",
            "as1.msh"], out,
           os.path.join(out, "mesh.log"))
    cc.run([args.hexfem, "convert", "as1.msh", "as1.inp"], out, os.path.join(out, "convert.log"))
    cc.inp_with_formulations(os.path.join(out, "as1.inp"), os.path.join(out, "as1_exact.inp"),
                             EXACT)
    xyz = cc.inp_nodes(os.path.join(out, "as1.inp"))
    clamp = sorted(i for i, p in xyz.items() if p[2] < -3.99)
    text = open(os.path.join(out, "as1.inp")).read()
    solids = sorted(int(l.split("SOLID_")[1]) for l in text.split("\n")
                    if l.upper().startswith("*ELSET, ELSET=SOLID_"))
    fix = "z<-3.99"
    rows, ok = [], True
    for label, aluminium, spec in (("steel and aluminium", {10, 11, 18},
                                    ["--material", "solid:10,11,18=aluminium"]),
                                   ("all steel", set(), [])):
        job = "mixed" if aluminium else "steel"
        deck(os.path.join(out, job + ".inp"), "as1_exact.inp", clamp, solids, args.modes,
             aluminium)
        ccx = cc.run_ccx(out, job)
        cmd = [args.hexfem, "modal", "as1.msh", "--units", "mm", "--fix", fix, "--modes",
               str(args.modes), "--hex8", "full", "--json"] + spec
        hx = json.loads(cc.run(cmd, out, os.path.join(out, job + "_hexfem.log"))[0])
        fh = [m["frequency_hz"] for m in hx["modes"]]
        worst = max(abs(cc.rel(a, b)) for a, b in zip(fh, ccx["freq"]))
        ok &= worst <= 1e-6
        rows.append((label, hx["free_dofs"], hx["mass_kg"], fh, ccx["freq"], worst,
                     ccx["command"], cc.shell_line(cmd)))
    print(f"AS1 glued, h = {args.h} mm, order 1, {len(clamp)} nodes clamped ({fix}), "
          f"{len(solids)} solids\n")
    print("| materials | DOF | mass kg | " +
          " | ".join(f"f{i + 1} hexfem / ccx [Hz]" for i in range(4)) + " | max rel. diff |")
    print("|---|---:|---:|" + "---|" * 4 + "---:|")
    for label, dof, mass, fh, fc, worst, _, _ in rows:
        cells = " | ".join(f"{a:.3f} / {b:.3f}" for a, b in zip(fh[:4], fc[:4]))
        print(f"| {label} | {dof:,} | {mass:.6f} | {cells} | {worst:.1e} |")
    for label, *_, ccmd, hcmd in rows:
        print(f"\n{label}:\n  {hcmd}\n  {ccmd}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
