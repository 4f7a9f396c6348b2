#!/usr/bin/env python3
"""Where `--solver auto` should switch at order 2: direct and iterative on the same runs.

Each case runs `hexfem modal PART --h H ... --modes 10 --json` twice, with `--solver direct` and
`--solver iterative`, one after the other on one process, and prints DOF, wall seconds and peak
memory (GNU time) of each, and the largest relative difference of the elastic frequencies.

    /usr/bin/python3 validation/auto_threshold.py [--hexfem build/app/hexfem] [--out DIR]
"""
import argparse
import json
import os
import subprocess
import sys

MODELS = "../shared/models"
CASES = [  # (name, part, h, fixing switches)
    ("steel h 1.41 clamped", "models/steel_part.step", 1.41421, ["--fix", "face:8"]),
    ("steel h 1 clamped", "models/steel_part.step", 1.0, ["--fix", "face:8"]),
    ("gehause h 0.698 free", f"{MODELS}/gehause_rohteil.stp", 0.698, ["--free"]),
    ("gehause h 0.4653 free", f"{MODELS}/gehause_rohteil.stp", 0.4653, ["--free"]),
    ("tie_rod h 6 free", f"{MODELS}/tie_rod.step", 6.0, ["--free"]),
    ("ANC101 h 6 free", f"{MODELS}/ANC101.stp", 6.0, ["--free"]),
    ("crankshaft h 4 free", f"{MODELS}/SampleCrankshaft4A.stp", 4.0, ["--free"]),
    ("cylinder h 1 clamped", f"{MODELS}/cylinder.stp", 1.0, ["--fix", "y<177.501"]),
    ("nist h 8 free", f"{MODELS}/0083_nist_ctc_01_asme1_ap242_colored.stp", 8.0, ["--free"]),
]


def run(hexfem, part, h, fix, solver, out):
    cmd = ["/usr/bin/time", "-f", "%e %M", hexfem, "modal", part, "--h", str(h), *fix,
           "--modes", "10", "--solver", solver, "--json"]
    p = subprocess.run(cmd, capture_output=True, text=True)
    last = p.stderr.strip().splitlines()[-1].split()
    wall, kb = float(last[0]), float(last[1])
    if p.returncode != 0:
        lines = [x for x in p.stderr.splitlines() if x.startswith("hexfem: error")]
        return {"error": lines[-1] if lines else "failed", "wall": wall}
    d = json.loads(p.stdout)
    with open(out, "w") as f:
        f.write(p.stdout)
    return {"dofs": d["free_dofs"], "wall": wall, "peak_gb": kb / 1e6,
            "freqs": [m["frequency_hz"] for m in d["modes"]],
            "iterations": d["solver"].get("iterations", 0)}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--hexfem", default="build/app/hexfem")
    ap.add_argument("--out", default="/tmp/auto_threshold")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    print("| case | DOF | direct s | direct GB | iterative s | iterative GB | its | max rel diff |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    for name, part, h, fix in CASES:
        tag = name.replace(" ", "_")
        d = run(a.hexfem, part, h, fix, "direct", f"{a.out}/{tag}_direct.json")
        i = run(a.hexfem, part, h, fix, "iterative", f"{a.out}/{tag}_iterative.json")
        if "error" in i:
            print(f"| {name} | iterative failed: {i['error']} |")
            continue
        if "error" in d:  # the direct path refuses what does not fit
            print(f"| {name} | {i['dofs']:,} | {d['error']} | | {i['wall']:.1f} | "
                  f"{i['peak_gb']:.2f} | {i['iterations']} | |", flush=True)
            continue
        top = max(abs(f) for f in d["freqs"])
        diff = max(abs(x - y) / abs(y) for x, y in zip(i["freqs"], d["freqs"]) if abs(y) > 1e-3 * top)
        print(f"| {name} | {d['dofs']:,} | {d['wall']:.1f} | {d['peak_gb']:.2f} | {i['wall']:.1f} | "
              f"{i['peak_gb']:.2f} | {i['iterations']} | {diff:.1e} |", flush=True)


if __name__ == "__main__":
    sys.exit(main())
