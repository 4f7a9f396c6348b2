#!/usr/bin/python3
"""A mesher switch against the default (issue 16): every shared model at h = diagonal / 30 and
/ 60, meshed twice on the same CAD, once as is and once with the given switches. Prints a Markdown
table (vertices, H_nbr, H_vol, NC, mean Q, inverted, seconds), the mean change of each column and
the models that lose more than one point of H_vol.

    /usr/bin/python3 validation/switch_study.py --switch "--relax-points 5" [--base "..."]
        [--hexfem build/app/hexfem] [--models ../shared/models] [--divs 30,60] [--timeout 600]
        [--json out.json]
"""
import argparse
import json
import shlex
import statistics
from pathlib import Path

from study_util import paired_runs

ROOT = Path(__file__).resolve().parent.parent


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--switch", required=True, help="switches of the new run, one string")
    ap.add_argument("--base", default="", help="switches of the old run (default: none)")
    ap.add_argument("--hexfem", default=str(ROOT / "build/app/hexfem"))
    ap.add_argument("--models", default=str(ROOT.parent / "shared/models"))
    ap.add_argument("--divs", default="30,60")
    ap.add_argument("--timeout", type=float, default=600)
    ap.add_argument("--json")
    a = ap.parse_args()
    switch = shlex.split(a.switch)
    rows = paired_runs(a.hexfem, a.models, [int(x) for x in a.divs.split(",")],
                       shlex.split(a.base), switch,
                       ("old", "new"), a.timeout, progress=True)
    print(f"\n`{a.base or '(default)'}` → `{a.switch or '(default)'}`:\n")
    print("| model | h | vertices | H_nbr | H_vol | NC | Q | inverted | s |")
    print("|---|---:|---:|---|---|---|---|---:|---|")
    for r in rows:
        old, new = r["old"], r["new"]
        if "error" in old or "error" in new:
            print(f"| {r['model']} | {r['h']:.4g} | — | {old.get('error', 'ok')} / "
                  f"{new.get('error', 'ok')} | | | | | |")
            continue
        print(f"| {r['model']} | {r['h']:.4g} | {old['vertices']} | {old['h_nbr']:.2f} → "
              f"{new['h_nbr']:.2f} | {old['h_vol']:.2f} → {new['h_vol']:.2f} | {old['nc']:.2f} → "
              f"{new['nc']:.2f} | {old['q']:.4f} → {new['q']:.4f} | {new['inverted']} | "
              f"{old['total_s']:.1f} → {new['total_s']:.1f} |")
    ok = [r for r in rows if "error" not in r["old"] and "error" not in r["new"]]
    for div in sorted({r["div"] for r in ok}):
        sub = [r for r in ok if r["div"] == div]
        parts = []
        for key in ("h_nbr", "h_vol", "nc", "q"):
            parts.append(f"{key} {statistics.mean(r['old'][key] for r in sub):.3f} → "
                         f"{statistics.mean(r['new'][key] for r in sub):.3f}")
        worse = [f"{r['model']} {r['new']['h_vol'] - r['old']['h_vol']:+.2f}" for r in sub
                 if r["new"]["h_vol"] < r["old"]["h_vol"] - 1]
        print(f"- /{div}, {len(sub)} meshes, means: {', '.join(parts)}; H_vol worse by more "
              f"than 1 point: {', '.join(worse) or 'none'}")
    print(f"- meshes run again for flat tets (flat_retry_points > 0): old "
          f"{sum(1 for r in ok if r['old'].get('flat_retry_points', 0))}, new "
          f"{sum(1 for r in ok if r['new'].get('flat_retry_points', 0))}")
    print(f"- inverted (new): {sum(r['new']['inverted'] for r in ok)}; refused: "
          f"{sum(1 for r in rows if r not in ok)} of {len(rows)} (either way)")
    if a.json:
        Path(a.json).write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
