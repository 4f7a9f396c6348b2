#!/usr/bin/python3
"""What TetGen's Delaunay recovery buys (issue 16): every shared model at h = diagonal / 30 and
/ 60, meshed with and without --tetgen-delaunay-recovery on the same points. Prints a Markdown
table (H_nbr, H_vol, NC, mean Q, inverted, TetGen seconds) and the mean of each column.

    /usr/bin/python3 validation/delaunay_recovery.py [--hexfem build/app/hexfem]
        [--models ../shared/models] [--timeout 600] [--json out.json]
"""
import argparse
import json
import statistics
from pathlib import Path

from study_util import paired_runs

ROOT = Path(__file__).resolve().parent.parent


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--hexfem", default=str(ROOT / "build/app/hexfem"))
    ap.add_argument("--models", default=str(ROOT.parent / "shared/models"))
    ap.add_argument("--timeout", type=float, default=600)
    ap.add_argument("--json")
    a = ap.parse_args()
    rows = paired_runs(a.hexfem, a.models, (30, 60), [], ["--tetgen-delaunay-recovery"],
                       ("off", "on"), a.timeout)
    print("| model | h | vertices | H_nbr on → off | H_vol on → off | NC on → off | Q on → off |"
          " inverted off | TetGen s on → off |")
    print("|---|---:|---:|---|---|---|---|---:|---|")
    for r in rows:
        on, off = r["on"], r["off"]
        if "error" in on or "error" in off:
            print(f"| {r['model']} | {r['h']:.4g} | — | {on.get('error', 'ok')} / "
                  f"{off.get('error', 'ok')} | | | | | |")
            continue
        print(f"| {r['model']} | {r['h']:.4g} | {off['vertices']} | {on['h_nbr']:.2f} → "
              f"{off['h_nbr']:.2f} | {on['h_vol']:.2f} → {off['h_vol']:.2f} | {on['nc']:.2f} → "
              f"{off['nc']:.2f} | {on['q']:.4f} → {off['q']:.4f} | {off['inverted']} | "
              f"{on['tetgen_s']:.2f} → {off['tetgen_s']:.2f} |")
    ok = [r for r in rows if "error" not in r["on"] and "error" not in r["off"]]
    for key in ("h_nbr", "h_vol", "nc", "q"):
        print(f"- mean {key}: {statistics.mean(r['on'][key] for r in ok):.3f} (on) → "
              f"{statistics.mean(r['off'][key] for r in ok):.3f} (off), largest drop "
              f"{max(r['on'][key] - r['off'][key] for r in ok):+.3f}, over {len(ok)} meshes")
    print(f"- TetGen seconds summed: {sum(r['on']['tetgen_s'] for r in ok):.1f} (on) → "
          f"{sum(r['off']['tetgen_s'] for r in ok):.1f} (off); inverted (off): "
          f"{sum(r['off']['inverted'] for r in ok)}; refused: "
          f"{sum(1 for r in rows if r not in ok)} of {len(rows)} (both ways)")
    if a.json:
        Path(a.json).write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
