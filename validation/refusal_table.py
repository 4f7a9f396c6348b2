#!/usr/bin/python3
"""Every shared model at h = bbox diagonal / 30, / 45, / 60 and / 90 (issue 14): meshed and
valid, or refused with one line for a reason in the CAD itself. Prints a Markdown table.

    /usr/bin/python3 validation/refusal_table.py --build build [--models ../shared/models]
        [--divisors 30,45,60,90] [--timeout 600] [--only NAME ...] > table.md

Each run is `hexfem mesh --json -o x.msh` then `hexfem stats --json x.msh` (volume_table.py's
runner: an independent reading of the written file). A refusal is classed by its message: a CAD
reason (open shell, non-manifold edge, overlapping solids, no solid) or not; a crash, a timeout
or a message of more than one line is a failure whatever it says.
"""
import argparse
import re
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from study_util import CAD_EXT  # noqa: E402
from volume_table import bbox_diagonal, mesh  # noqa: E402

# Messages that name a defect of the CAD model itself, not of the mesher.
CAD_REASONS = re.compile(r"not manifold|do not close|open shell|free edges|overlap|no solid|"
                         r"not closed", re.I)


def classify(r):
    if "error" not in r:
        st = r["st"]
        valid = (st.get("inverted") == 0 and st.get("degenerate") == 0 and st.get("watertight"))
        return "meshed" if valid else "INVALID MESH"
    e = r["error"]
    if "CRASH" in e or "timeout" in e:
        return "FAILURE"
    if r.get("error_lines", 1) != 1:
        return "FAILURE (not one line)"
    return "refused: CAD" if CAD_REASONS.search(e) else "REFUSED: NOT CAD"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--models", default="/work/shared/models")
    ap.add_argument("--divisors", default="30,45,60,90")
    ap.add_argument("--timeout", type=float, default=600)
    ap.add_argument("--only", nargs="*")
    args = ap.parse_args()
    args.hexfem = str(Path(args.build) / "app/hexfem")
    args.keep_msh = False
    divisors = [int(d) for d in args.divisors.split(",")]
    models = sorted(p for p in Path(args.models).iterdir() if p.suffix.lower() in CAD_EXT)
    if args.only:
        models = [m for m in models if any(o in m.name for o in args.only)]

    print("| model | /d | h (mm) | outcome | vertices | H_vol % | NC % | CAD volume error | "
          "time s | refusal (the one line) |")
    print("|---|---:|---:|---|---:|---:|---:|---:|---:|---|")
    counts, slowest = {}, 0.0
    for m in models:
        diag, err = bbox_diagonal(args.hexfem, m, args.timeout)
        runs = []
        if diag is None:
            r = {"model": m.name, "h": 0, "seconds": 0, "error": err, "error_lines": 1}
            runs = [(d, r) for d in divisors]  # `info` refuses: every size refused alike
        else:
            runs = [(d, mesh(args, m, diag / d)) for d in divisors]
        for d, r in runs:
            outcome = classify(r)
            counts[outcome] = counts.get(outcome, 0) + 1
            slowest = max(slowest, r["seconds"])
            if "error" in r:
                print(f"| {m.name} | {d} | {r['h']:.4g} | {outcome} | | | | | "
                      f"{r['seconds']:.1f} | {r['error']} |", flush=True)
                continue
            rep, st = r["rep"], r["st"]
            cad = rep.get("volume_error")
            cad = f"{cad:+.2%}" if isinstance(cad, (int, float)) else "–"
            print(f"| {m.name} | {d} | {r['h']:.4g} | {outcome} | {rep['vertices']} | "
                  f"{st['H_vol']:.1f} | {st['NC']:.2f} | {cad} | {r['seconds']:.1f} | |",
                  flush=True)
    print()
    print(f"{sum(counts.values())} runs: " +
          ", ".join(f"{k} {v}" for k, v in sorted(counts.items())) +
          f"; slowest run {slowest:.0f} s.")
    bad = sum(v for k, v in counts.items() if k not in ("meshed", "refused: CAD"))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
