#!/usr/bin/python3
"""Order 2 as the default on every shared model (validation/order2.md section 6): each CAD part,
free-free at h = bounding-box diagonal / 30, with modal's defaults (order 2, its curvature bound),
one after the other (8 modes; CrankArm 14). Prints a Markdown table: DOF, the curvature bound used, cells straightened,
NC faces made conformal, hanging nodes kept, rigid modes found, the first elastic frequency, wall
time, or the one-line error.

    /usr/bin/python3 validation/order2_default_sweep.py [--hexfem build/app/hexfem]
        [--models ../shared/models] [--skip NAME ...] [--timeout 900]
"""
import argparse
import json
import re
from pathlib import Path

from study_util import CAD_EXT, run

ROOT = Path(__file__).resolve().parent.parent
# Modes asked: 8 (six rigid, two elastic) as in session 14's table; CrankArm's two solids are
# meshed apart and have twelve rigid modes.
MODES = {"CrankArm.brep": 14}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--hexfem", default=str(ROOT / "build/app/hexfem"))
    ap.add_argument("--models", default=str(ROOT.parent / "shared/models"))
    ap.add_argument("--skip", nargs="*", default=[])
    ap.add_argument("--timeout", type=float, default=900)
    a = ap.parse_args()
    print("| model | h (mm) | DOF | curvature bound | cells straightened | NC faces made conformal |"
          " hanging nodes kept | rigid modes | first elastic f (Hz) | wall s | result |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|", flush=True)
    for model in sorted(Path(a.models).iterdir()):
        if model.suffix.lower() not in CAD_EXT or model.name in a.skip:
            continue
        code, out, err, _ = run([a.hexfem, "info", str(model)], a.timeout)
        if code != 0:
            continue  # not a solid the reader takes (bearing.iges: an open shell)
        m = re.search(r"bbox \[([^\]]*)\] - \[([^\]]*)\]", out)
        lo = [float(x) for x in m.group(1).split()]
        hi = [float(x) for x in m.group(2).split()]
        h = sum((b - x) ** 2 for x, b in zip(lo, hi)) ** 0.5 / 30
        code, out, err, secs = run([a.hexfem, "modal", str(model), "--h", f"{h:.4g}", "--free",
                                    "--modes", str(MODES.get(model.name, 8)), "--json"], a.timeout)
        if code != 0:
            lines = [ln for ln in err.splitlines() if ln.strip()]
            why = f"timeout after {a.timeout:.0f} s" if code == "timeout" else (
                lines[-1] if lines else f"exit {code}")
            print(f"| {model.name} | {h:.4g} | | | | | | | | {secs:.1f} | {why} |", flush=True)
            continue
        j = json.loads(out)
        f = [mode["frequency_hz"] for mode in j["modes"]]
        elastic = [x for x in f if abs(x) > 1e-3 * max(abs(y) for y in f)] or [float("nan")]
        rigid = sum(1 for x in f if abs(x) <= 1e-3 * max(abs(y) for y in f))
        o2 = j.get("order2", {})
        print(f"| {model.name} | {h:.4g} | {j['free_dofs']:,} | {j['mesh'].get('curvature_bound')} |"
              f" {o2.get('straightened_cells')} | {o2.get('nc_made_conformal')} |"
              f" {o2.get('hanging_kept')} | {rigid} | {elastic[0]:.6g} | {secs:.1f} | ok |",
              flush=True)


if __name__ == "__main__":
    main()
