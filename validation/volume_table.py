#!/usr/bin/python3
"""Validation of the volume mesher (issue 5): writes validation/volume.md.

    /usr/bin/python3 validation/volume_table.py [--build build-vol] [--out validation/volume.md]
        [--models /work/shared/models] [--timeout 600] [--only NAME ...] [--skip-extra]

1. Every shared CAD model at two sizes, h = bounding-box diagonal / 30 and / 60:
   `hexfem mesh --json -o x.msh` then `hexfem stats --json x.msh` (an independent reading of the
   written file): H_nbr, H_vol, Q, NC, min scaled Jacobian per kind, inverted and degenerate
   cells, watertightness, volume gap against the tet mesh, each tet used once, vertices, time.
   A model that cannot be meshed must give one error line and a non-zero exit (no crash, no
   hang: each run is bounded by --timeout).
2. Hex ratios at the issue's sizes: box.stp and cylinder.stp at ~10k vertices, ANC101 at ~100k.
3. Random versus frontal interior points (--random-points) on the same parts.
4. Determinism: the same .msh, byte for byte, on repeated runs (2 threads, and 1 thread).
Raw JSON of every run goes to validation/out/volume/.
"""
import argparse
import hashlib
import json
import os
import re
import subprocess
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
from study_util import CAD_EXT, run  # noqa: E402  (sibling module)
KINDS = ["hex8", "wedge6", "pyramid5", "tet4"]


def bbox_diagonal(hexfem, model, timeout):
    code, out, err, _ = run([hexfem, "info", str(model)], timeout)
    if code != 0:
        return None, (err.strip().splitlines() or [f"exit {code}"])[-1]
    m = re.search(r"bbox \[([^\]]*)\] - \[([^\]]*)\]", out)
    lo = [float(x) for x in m.group(1).split()]
    hi = [float(x) for x in m.group(2).split()]
    return sum((b - a) ** 2 for a, b in zip(lo, hi)) ** 0.5, None


def mesh(args, model, h, extra=(), tag="", env=None):
    """One `hexfem mesh` + `hexfem stats` run: a dict of figures, or {'error': line}."""
    outdir = ROOT / "validation/out/volume"
    outdir.mkdir(parents=True, exist_ok=True)
    stem = f"{Path(model).stem}_h{h:.4g}{tag}"
    msh = outdir / f"{stem}.msh"
    cmd = [args.hexfem, "mesh", str(model), "--h", f"{h:.6g}", "--json", "-o", str(msh), *extra]
    code, out, err, secs = run(cmd, args.timeout, env)
    row = {"model": Path(model).name, "h": h, "seconds": secs, "command": " ".join(cmd[1:])}
    if code != 0:
        lines = [ln for ln in err.strip().splitlines() if ln.strip()]
        if code == "timeout":
            row["error"] = f"timeout after {args.timeout} s"
        elif isinstance(code, int) and code < 0:
            row["error"] = f"CRASH (signal {-code})"
        else:
            row["error"] = lines[-1] if lines else f"exit {code}, no message"
            row["error_lines"] = len(lines)
        return row
    rep = json.loads(out)
    code, sout, serr, _ = run([args.hexfem, "stats", "--json", str(msh)], args.timeout)
    st = json.loads(sout) if code == 0 else {}
    (outdir / f"{stem}.json").write_text(json.dumps({"mesh": rep, "stats": st}, indent=1))
    row.update(rep=rep, st=st, msh=msh)
    if not args.keep_msh:
        row["sha256"] = hashlib.sha256(msh.read_bytes()).hexdigest()
        msh.unlink()
    return row


def tets_used_once(rep):
    """TetGen's tets = in elements + absorbed slivers + replaced by flips + tets left."""
    tets_left = rep["cells"]["tet4"] - rep.get("tets_from_flips", 0)
    return (rep["tets_in_elements"] + rep["absorbed_slivers"] + rep.get("flipped_tets", 0) +
            rep.get("flat_boundary_tets", 0) + tets_left) == rep["tets_from_tetgen"]


def fmt_row(r):
    if "error" in r:
        return f"| {r['model']} | {r['h']:.3g} | — | | | | | | | | | | {r['error']} | {r['seconds']:.1f} |"
    rep, st = r["rep"], r["st"]
    sj = st.get("min_scaled_jacobian", {})
    cells = st.get("cells_per_kind", {})
    msj = " / ".join(f"{sj[k]:.3f}" if cells.get(k) else "–" for k in KINDS)
    ok = "yes" if tets_used_once(rep) else "**NO**"
    wt = "yes" if st.get("watertight") else f"**NO ({st.get('open_boundary_edges')})**"
    vs = rep["vertices"] / rep["total_seconds"] if rep.get("total_seconds") else 0
    return (f"| {r['model']} | {r['h']:.3g} | {rep['vertices']} | {st['H_nbr']:.1f} | "
            f"{st['H_vol']:.1f} | {st['Q_mean']:.3f} | {st['NC']:.2f} | {msj} | "
            f"{st['inverted']} | {st.get('degenerate', '?')} | {wt} | "
            f"{rep['volume_rel_gap']:.1e} | {ok} | {r['seconds']:.1f} ({vs:.0f} v/s) |")


HEADER = ("| model | h (mm) | vertices | H_nbr % | H_vol % | Q mean | NC % | "
          "min SJ hex / prism / pyr / tet | inverted | degenerate | watertight | "
          "vol gap vs tets | tets used once | time s (vertices/s) |\n"
          "|---|---:|---:|---:|---:|---:|---:|---|---:|---:|---|---:|---|---:|")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=str(ROOT / "build-vol"))
    ap.add_argument("--out", default=str(ROOT / "validation/volume.md"))
    ap.add_argument("--models", default="/work/shared/models")
    ap.add_argument("--timeout", type=float, default=600)
    ap.add_argument("--only", nargs="*")
    ap.add_argument("--skip-extra", action="store_true")
    ap.add_argument("--keep-msh", action="store_true")
    args = ap.parse_args()
    args.hexfem = str(Path(args.build) / "app/hexfem")
    models = sorted(p for p in Path(args.models).iterdir() if p.suffix.lower() in CAD_EXT)
    if args.only:
        models = [m for m in models if any(o in m.name for o in args.only)]

    # Everything above the marker in the existing file is hand-written (summary, notes): kept.
    marker = "<!-- generated by validation/volume_table.py below this line -->"
    out = Path(args.out)
    head = out.read_text().split(marker)[0] if out.exists() and marker in out.read_text() else \
        "# Volume mesher validation (issue 5)\n\n"
    lines = [head.rstrip("\n"), "", marker, "",
             f"Generated by `/usr/bin/python3 validation/volume_table.py` "
             f"({time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, hexfem "
             f"{args.hexfem}, 2 cores shared with other jobs: times are indicative).", "",
             "## 1. Every shared model at two sizes (h = bbox diagonal / 30 and / 60)", "",
             "min SJ: smallest scaled Jacobian per kind (`hexfem stats`, read back from the "
             ".msh); degenerate: SJ < 1e-6; vol gap: |V(mixed) − V(tets)| / V(tets); tets used "
             "once: TetGen's tets = tets in elements + absorbed flat slivers + tets replaced by "
             "sliver flips + flat tets on the surface dropped + tets left. Time: `hexfem mesh` wall clock, CAD read to file written.",
             "", HEADER]
    rows = []
    for m in models:
        diag, err = bbox_diagonal(args.hexfem, m, args.timeout)
        if diag is None:
            r = {"model": m.name, "h": 0, "seconds": 0, "error": f"info: {err}"}
            rows.append(r)
            lines.append(fmt_row(r))
            print(fmt_row(r), flush=True)
            continue
        for div in (30, 60):
            r = mesh(args, m, diag / div)
            rows.append(r)
            lines.append(fmt_row(r))
            print(fmt_row(r), flush=True)
    ok = [r for r in rows if "error" not in r]
    bad = [r for r in rows if "error" in r]
    lines += ["", f"{len(ok)} runs meshed, {len(bad)} refused with one error line "
              f"({sum(1 for r in bad if 'CRASH' in r['error'] or 'timeout' in r['error'])} "
              "crashes or timeouts). Inverted cells in all meshes: "
              f"{sum(r['st']['inverted'] for r in ok)}; degenerate: "
              f"{sum(r['st'].get('degenerate', 0) for r in ok)}; not watertight: "
              f"{sum(1 for r in ok if not r['st'].get('watertight'))}; tets not used once: "
              f"{sum(1 for r in ok if not tets_used_once(r['rep']))}; max vol gap: "
              f"{max((r['rep']['volume_rel_gap'] for r in ok), default=0):.1e}.", ""]
    Path(args.out).write_text("\n".join(lines) + "\n")
    if args.skip_extra:
        return

    data = ROOT / "tests/data"
    lines += ["## 2. Hex ratios at the issue's sizes", "", HEADER]
    # (model, vertices wanted, first guess of h); h is then scaled by (n / want)^(1/3).
    targets = [(data / "box.stp", 10e3, 0.05), (data / "cylinder.stp", 10e3, 0.9),
               (data / "ANC101.stp", 100e3, 4.5)]
    commands = []
    for model, want, h in targets:
        for _ in range(3):
            r = mesh(args, model, h, tag="_target")
            if "error" in r:
                break
            n = r["rep"]["vertices"]
            if abs(n - want) < 0.1 * want:
                break
            h *= (n / want) ** (1 / 3)
        lines.append(fmt_row(r))
        commands.append(f"- `hexfem {r['command']}`")
        print(fmt_row(r), flush=True)
    lines += ["", "Commands:", ""] + commands
    Path(args.out).write_text("\n".join(lines) + "\n")

    lines += ["", "## 3. Random versus frontal interior points", "", HEADER]
    for model in (data / "box.stp", data / "cylinder.stp", ROOT / "models/steel_part.step",
                  data / "ANC101.stp"):
        diag, _ = bbox_diagonal(args.hexfem, model, args.timeout)
        for extra, tag in (((), ""), (("--random-points",), "_random")):
            r = mesh(args, model, diag / 40, extra=extra, tag=tag)
            r["model"] += " random" if tag else " frontal"
            lines.append(fmt_row(r))
            print(fmt_row(r), flush=True)
    Path(args.out).write_text("\n".join(lines) + "\n")

    lines += ["", "## 4. Determinism (sha256 of the .msh)", "",
              "| model | h | run 1 (2 threads) | run 2 (2 threads) | run 3 (1 thread) | identical |",
              "|---|---:|---|---|---|---|"]
    for model in (ROOT / "models/steel_part.step", data / "ANC101.stp", data / "cylinder.stp"):
        diag, _ = bbox_diagonal(args.hexfem, model, args.timeout)
        h = diag / 50
        hs = [mesh(args, model, h, tag="_det").get("sha256", "error") for _ in range(2)]
        hs.append(mesh(args, model, h, tag="_det1", env={"OMP_NUM_THREADS": "1"})
                  .get("sha256", "error"))
        same = "yes" if len(set(hs)) == 1 and hs[0] != "error" else "**NO**"
        lines.append(f"| {model.name} | {h:.3g} | {hs[0][:12]} | {hs[1][:12]} | {hs[2][:12]} | "
                     f"{same} |")
        print(lines[-1], flush=True)
    Path(args.out).write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
