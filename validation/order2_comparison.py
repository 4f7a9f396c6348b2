#!/usr/bin/python3
"""The comparison that decides issue 12: max error of f1-f4 against DOF and against wall time
(mesh + solve, same machine, same run) for hexfem order 1, hexfem order 2, and the independent
chain Gmsh P2 tets + CalculiX C3D10 (validation/reference/reference_chain.py).

  validation/order2_comparison.py [--hexfem BIN] [--out validation/out/order2_comparison]
      [--models steel,cylinder,cone,sphere,cylinder_graded] [--json validation/order2_comparison.json]
      [--png validation/order2_comparison.png] [--reference MODEL=FILE ...]

Each model: its reference (the model's "reference" file in validation/reference/, or
--reference MODEL=FILE: the chain's Richardson extrapolation from its finest sizes, the C3D20
O-grid for the cylinder, Lamb's analytic frequencies for the sphere), hexfem
`modal PART --h H --order 1|2 --fix ... --json` at each size (wall clock of the whole process:
CAD read, mesh, order-2 nodes, assembly, solve), and the chain at coarser sizes (wall of gmsh +
deck + ccx, ccx on one thread as the chain runs it).
Free-free models ("free"): hexfem `--free --modes 16`, the chain with no *BOUNDARY; both drop the
six rigid-body modes after checking them (|f| < 1e-3 of the first elastic one). Graded models
("clamp_face", "clamp_fraction" F): hexfem `--size-at face:ID=Fh`, the chain graded alike
(size F*h on the clamp face, +0.3 mm per mm back to h: reference_chain.py REFERENCE_CLAMP_SIZE).
Runs one after the other, never two at once. Writes the JSON, a Markdown table and the PNG
(gnuplot). Only stdlib + numpy; run with /usr/bin/python3.
"""
import argparse
import json
import shlex
import math
import os
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(HERE, "reference"))
import reference_chain as chain  # noqa: E402

SHARED = "/work/shared/models"
MODELS = {
    "steel": {"step": os.path.join(ROOT, "models", "steel_part.step"), "fix": "face:8",
              "axis": "x", "reference": "steel_part.json",
              "order1": [2, 1.4142136, 1, 0.7071068], "order2": [4, 2.8284271, 2, 1.4142136],
              "tet10": [4, 3.2, 2.5, 2, 1.6]},
    # the C3D20 O-grid reference (order2.md section 5); --reference cylinder=cylinder.json for
    # the chain's own
    "cylinder": {"step": os.path.join(SHARED, "cylinder.stp"), "fix": "y<177.501", "axis": "y",
                 "reference": "cylinder_c20.json", "order1": [2, 1.4142136, 1, 0.7071068],
                 "order2": [4, 2.8284271, 2, 1.4142136], "tet10": [4, 3.2, 2.5, 2, 1.6]},
    "cone": {"step": os.path.join(SHARED, "Cone_1.brep"), "fix": "z<0.001", "axis": "z",
             "reference": "cone.json", "order1": [20, 14.142136, 10, 7.0710678],
             "order2": [40, 28.284271, 20, 14.142136], "tet10": [40, 28, 20, 16]},
    # free-free, no singularity: Lamb's analytic frequencies (reference/sphere_lamb.py)
    "sphere": {"step": os.path.join(SHARED, "sphere.stp"), "free": True,
               "reference": "sphere.json", "order1": [1.4142136, 1, 0.7071068, 0.5, 0.4],
               # the chain's sizes, and h = 1; at h >= 3 hexfem's first mesh is over 5 % off the
               # volume and its volume retry (24 elements per turn) gives 4.4-5.7k DOF
               "order2": [5, 4, 3, 2.5, 2, 1.5, 1], "tet10": [5, 4, 3, 2.5, 2, 1.5]},
    # free-free, one doubly periodic face, no singularity; the chain's own extrapolation from
    # h = 30, 20, 15 (reference/torus.json). The shared parts with edges that were tried (ANC101,
    # NIST CTC, crankshaft) stop the chain: ccx refuses Gmsh's curved tets (order2.md section 4)
    "torus": {"step": os.path.join(SHARED, "Torus_1.brep"), "free": True,
              "reference": "torus.json", "order1": [40, 28.284271, 20, 14.142136],
              "order2": [60, 50, 40, 30, 20], "tet10": [60, 50, 40, 30, 20]},
    # the same cylinder free-free: no clamp, so no singular edge (the convex 90-degree rims are
    # not singular); reference: the structured C3D20 O-grid, free (reference/cylinder_c20.py)
    "cylinder_free": {"step": os.path.join(SHARED, "cylinder.stp"), "free": True,
                      "reference": "cylinder_free_c20.json", "order1": [2, 1.4142136, 1, 0.7071068],
                      "order2": [4, 2.8284271, 2, 1.4142136], "tet10": [4, 3.2, 2.5, 2, 1.6]},
    # the unit cube (box.stp, 1 mm), free-free: flat faces, convex edges only, no singularity;
    # the chain's own extrapolation from h = 0.1, 0.07, 0.05 (reference/box_free.json). hexfem
    # meshes it with hexes alone at h = 1/n, so this is the best case of a hex-dominant mesh
    "box_free": {"step": os.path.join(SHARED, "box.stp"), "free": True,
                 "reference": "box_free.json", "order1": [0.25, 0.1666667, 0.125, 0.1],
                 "order2": [0.5, 0.3333333, 0.25, 0.2, 0.1666667, 0.125, 0.1],
                 "tet10": [0.4, 0.3, 0.2, 0.15, 0.125, 0.1]},
    # the cylinder with the clamp face (CAD face 3, y = 177.5) graded in both chains
    "cylinder_graded": {"step": os.path.join(SHARED, "cylinder.stp"), "fix": "y<177.501",
                        "axis": "y", "clamp_face": 3, "clamp_fraction": 0.5,
                        "reference": "cylinder_c20.json", "order1": [2, 1.4142136, 1, 0.7071068],
                        "order2": [4, 2.8284271, 2, 1.4142136], "tet10": [4, 3.2, 2.5, 2, 1.6]},
}
NF = 4  # f1..f4
NRIGID = 6  # rigid-body modes of a free-free model, dropped


def max_error(freqs, ref):
    return max(abs(f - r) / r for f, r in zip(freqs[:NF], ref[:NF]))


def drop_rigid(freqs, where):
    """The elastic frequencies of a free-free run: the six lowest must be rigid-body modes."""
    rigid, elastic = freqs[:NRIGID], freqs[NRIGID:]
    if not elastic or max(abs(f) for f in rigid) >= 1e-3 * elastic[0]:
        raise RuntimeError(f"{where}: the six lowest frequencies {rigid} are not rigid-body modes")
    return elastic, rigid


def hexfem_run(args, model, h, order, work):
    if model.get("free"):
        bc = ["--free", "--modes", str(10 + NRIGID)]
    else:
        bc = ["--fix", model["fix"], "--modes", "6"]
    if "clamp_face" in model:
        bc += ["--size-at", f"face:{model['clamp_face']}={model['clamp_fraction']:g}h"]
    cmd = [args.hexfem, "modal", model["step"], "--h", f"{h:g}", "--order", str(order)] + bc + [
        "--json"] + shlex.split(args.hexfem_switches)
    t0 = time.time()
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=work)
    wall = time.time() - t0
    if p.returncode != 0:
        return {"h": h, "order": order, "error": p.stderr.strip()[-500:], "command": " ".join(cmd)}
    d = json.loads(p.stdout)
    freqs, rigid = [m["frequency_hz"] for m in d["modes"]], None
    if model.get("free"):
        try:
            freqs, rigid = drop_rigid(freqs, f"hexfem h = {h:g} order {order}")
        except RuntimeError as e:
            return {"h": h, "order": order, "error": str(e), "command": " ".join(cmd)}
    return {"h": h, "order": order, "dofs": d["free_dofs"], "matrix_nnz": d.get("matrix_nnz"),
            "wall_s": wall, "mesh_s": d["mesh"].get("mesh_seconds"),
            "peak_memory_bytes": d["solver"].get("peak_memory_bytes"),
            "cells": {k: d["mesh"].get(k) for k in ("hex8", "wedge6", "pyramid5", "tet4")},
            "straightened": d.get("order2", {}).get("straightened_cells"),
            "frequencies_hz": freqs, **({} if rigid is None else {"rigid_hz": rigid}),
            "command": " ".join(cmd)}


def tet10_run(model, h, work):
    free = bool(model.get("free"))
    if not free:
        os.environ["REFERENCE_CLAMP_AXIS"] = model["axis"]
    # the graded clamp at the same size as hexfem's --size-at face:ID=Fh; "" = uniform
    os.environ["REFERENCE_CLAMP_SIZE"] = (f"{model['clamp_fraction']:g}h"
                                          if "clamp_face" in model else "")
    r = chain.run_size(model["step"], h, work, "cmp", 10 if free else 6, free=free)
    return {"h": h, "dofs": r["dofs"], "wall_s": r["seconds_total"], "elements": r["elements"],
            "seconds_gmsh": r["seconds_gmsh"], "seconds_ccx": r["seconds_ccx"],
            "frequencies_hz": r["frequencies_hz"],
            **({k: r[k] for k in ("rigid_hz", "clamp_size") if k in r}),
            "command": r["gmsh_command"] + " ; ccx (reference_chain.py deck)"}


def loglog_at(xs, ys, x):
    """log-log interpolation of y at x over the points (xs, ys) sorted by xs; None outside."""
    pts = sorted(zip(xs, ys))
    for (x0, y0), (x1, y1) in zip(pts, pts[1:]):
        if x0 <= x <= x1 and y0 > 0 and y1 > 0:
            t = (math.log(x) - math.log(x0)) / (math.log(x1) - math.log(x0))
            return math.exp(math.log(y0) + t * (math.log(y1) - math.log(y0)))
    return None


def first_below(xs, ys, target):
    """x at which the error first falls to target (log-log between the bracketing runs)."""
    pts = sorted(zip(xs, ys))
    for (x0, y0), (x1, y1) in zip(pts, pts[1:]):
        if y0 > target >= y1:
            t = (math.log(target) - math.log(y0)) / (math.log(y1) - math.log(y0))
            return math.exp(math.log(x0) + t * (math.log(x1) - math.log(x0)))
    return pts[0][0] if pts and pts[0][1] <= target else None


def analyse(name, m):
    ref = m["reference_hz"]
    series = {}
    for key in ("order1", "order2", "tet10"):
        ok = [r for r in m["runs"][key] if "frequencies_hz" in r]
        for r in ok:
            r["max_error_f1_f4"] = max_error(r["frequencies_hz"], ref)
        series[key] = ok
    s = {}
    o2, t10 = series["order2"], series["tet10"]
    ratios = []
    for r in o2:
        e = loglog_at([t["dofs"] for t in t10], [t["max_error_f1_f4"] for t in t10], r["dofs"])
        if e:
            ratios.append({"dofs": r["dofs"], "order2": r["max_error_f1_f4"], "tet10": e,
                           "ratio": r["max_error_f1_f4"] / e})
    s["equal_dof"] = ratios
    for key in series:
        s[f"{key}_seconds_to_0.1%"] = first_below([r["wall_s"] for r in series[key]],
                                                  [r["max_error_f1_f4"] for r in series[key]],
                                                  1e-3)
    m["summary"] = s
    return series


def table(name, m, series):
    lines = [f"### {name}: max |error| of f1–f4 against the reference "
             f"({', '.join(f'{v:.3f}' for v in m['reference_hz'][:NF])} Hz, "
             f"± {100 * max(m['reference_uncertainty_rel'][:NF]):.3f} %)", "",
             "| chain | h (mm) | DOF | nnz(K) | wall s | peak GB | max err f1–f4 |",
             "|---|---:|---:|---:|---:|---:|---:|"]
    label = {"order1": "hexfem order 1", "order2": "hexfem order 2",
             "tet10": "Gmsh P2 + ccx C3D10"}
    for key in ("order1", "order2", "tet10"):
        for r in series[key]:
            nnz = f"{r['matrix_nnz']:,}" if r.get("matrix_nnz") else "–"
            mem = f"{r['peak_memory_bytes'] / 1e9:.2f}" if r.get("peak_memory_bytes") else "–"
            lines.append(f"| {label[key]} | {r['h']:g} | {r['dofs']:,} | {nnz} | "
                         f"{r['wall_s']:.1f} | {mem} | {100 * r['max_error_f1_f4']:.3f} % |")
        for r in m["runs"][key]:
            if "error" in r:
                lines.append(f"| {label[key]} | {r['h']:g} | failed: {r['error'][:80]} |||||")
    s = m["summary"]
    lines.append("")
    for q in s["equal_dof"]:
        lines.append(f"- at {q['dofs']:,} DOF: order 2 {100 * q['order2']:.3f} %, tet10 chain "
                     f"(interpolated) {100 * q['tet10']:.3f} %: ratio {q['ratio']:.2f}")
    for key in ("order1", "order2", "tet10"):
        v = s[f"{key}_seconds_to_0.1%"]
        lines.append(f"- {label[key]} reaches 0.1 %: "
                     + ("not within the sizes run" if v is None else f"after {v:.1f} s"))
    return "\n".join(lines) + "\n"


def plot(doc, png):
    """Two columns (error vs DOF, error vs wall s), one row per model; gnuplot."""
    data = png + ".dat"
    names = list(doc["models"])
    with open(data, "w") as f:
        for name in names:
            for key in ("order1", "order2", "tet10"):
                f.write(f"# {name} {key}\n")
                for r in doc["models"][name]["runs"][key]:
                    if "max_error_f1_f4" in r:
                        f.write(f"{r['dofs']} {r['wall_s']:.3f} {100 * r['max_error_f1_f4']:.6g}\n")
                f.write("\n\n")
    g = [f"set terminal pngcairo size 1100,{330 * len(names)} font ',10'", f"set output '{png}'",
         f"set multiplot layout {len(names)},2", "set logscale xy", "set grid",
         "set ylabel 'max error f1-f4 (%)'", "set key top right", "set format y '%g'"]
    styles = ["lc rgb '#999999' pt 6", "lc rgb '#d62728' pt 7", "lc rgb '#1f77b4' pt 5"]
    titles = ["hexfem order 1", "hexfem order 2", "Gmsh P2 + ccx C3D10"]
    for i, name in enumerate(names):
        for col, xl in ((1, "DOF"), (2, "wall time, mesh + solve (s)")):
            # noenhanced: an underscore in a model name is not a subscript
            g += [f"set title '{name}' noenhanced", f"set xlabel '{xl}'"]
            parts = [f"'{data}' index {3 * i + k} using {col}:3 with linespoints {styles[k]} "
                     f"title '{titles[k]}'" for k in range(3)]
            parts.append("0.1 with lines dt 2 lc rgb 'black' title '0.1 %'")
            g.append("plot " + ", ".join(parts))
    g.append("unset multiplot")
    subprocess.run(["gnuplot"], input="\n".join(g), text=True, check=True)
    os.remove(data)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--hexfem", default=os.environ.get("HEXFEM",
                                                       os.path.join(ROOT, "build", "app", "hexfem")))
    ap.add_argument("--out", default=os.path.join(ROOT, "validation", "out", "order2_comparison"))
    ap.add_argument("--models", default=",".join(MODELS))
    ap.add_argument("--hexfem-switches", default="",
                    help="more switches for every hexfem run, one string (e.g. '--relax-points 30')")
    ap.add_argument("--json", default=os.path.join(HERE, "order2_comparison.json"))
    ap.add_argument("--png", default=os.path.join(HERE, "order2_comparison.png"))
    ap.add_argument("--md", default=None, help="Markdown tables (default: <out>/tables.md)")
    ap.add_argument("--replot", action="store_true", help="only redraw the PNG from --json")
    ap.add_argument("--reference", action="append", default=[], metavar="MODEL=FILE",
                    help="another reference file (in validation/reference/) for a model")
    args = ap.parse_args()
    if args.replot:
        plot(json.load(open(args.json)), args.png)
        return 0
    args.hexfem = os.path.abspath(args.hexfem)
    out = os.path.abspath(args.out)
    os.makedirs(out, exist_ok=True)
    os.environ.setdefault("OMP_NUM_THREADS", "1")  # ccx: see reference/make_reference.sh
    git = subprocess.run(["git", "-C", ROOT, "describe", "--always", "--dirty"],
                         stdout=subprocess.PIPE, text=True).stdout.strip()
    doc = {"source": git, "hexfem": args.hexfem, "argv": sys.argv[1:], "models": {},
           "machine": "2 cores shared with other agents' builds and runs; runs one at a time",
           "started": time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime())}
    refs = {}
    for item in args.reference:
        model, _, path = item.partition("=")
        if model not in MODELS or not path:
            ap.error(f"--reference {item!r}: want MODEL=FILE with MODEL in {', '.join(MODELS)}")
        refs[model] = path
    md = []
    for name in args.models.split(","):
        spec = dict(MODELS[name])
        spec["reference"] = refs.get(name, spec["reference"])
        ref = json.load(open(os.path.join(HERE, "reference", spec["reference"])))
        m = {"step": spec["step"], "fix": "free-free" if spec.get("free") else spec["fix"],
             **({k: spec[k] for k in ("clamp_face", "clamp_fraction") if k in spec}),
             "reference": spec["reference"],
             "reference_hz": ref["reference_hz"],
             "reference_uncertainty_rel": ref["reference_uncertainty_rel"], "runs": {}}
        work = os.path.join(out, name)
        os.makedirs(work, exist_ok=True)
        # hexfem gets the threads it uses by default; ccx runs on one (the chain's setting).
        env_threads = os.environ.pop("OMP_NUM_THREADS")
        for order in (1, 2):
            m["runs"][f"order{order}"] = []
            for h in spec[f"order{order}"]:
                r = hexfem_run(args, spec, h, order, work)
                m["runs"][f"order{order}"].append(r)
                print(f"{name} order {order} h = {h:g}: "
                      + (r["error"] if "error" in r else
                         f"{r['dofs']} DOF, {r['wall_s']:.1f} s, f1 {r['frequencies_hz'][0]:.3f}"),
                      flush=True)
        os.environ["OMP_NUM_THREADS"] = env_threads
        m["runs"]["tet10"] = [tet10_run(spec, h, work) for h in spec["tet10"]]
        series = analyse(name, m)
        doc["models"][name] = m
        md.append(table(name, m, series))
        with open(args.json, "w") as f:
            json.dump(doc, f, indent=1)
    doc["finished"] = time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime())
    with open(args.json, "w") as f:
        json.dump(doc, f, indent=1)
    text = "\n".join(md)
    print("\n" + text)
    with open(args.md or os.path.join(out, "tables.md"), "w") as f:
        f.write(text)
    plot(doc, args.png)
    return 0


if __name__ == "__main__":
    sys.exit(main())
