"""Shared by the validation scripts (surface_models.py, volume_table.py, delaunay_recovery.py,
switch_study.py): CAD file extensions, a subprocess runner with a time bound, a model's diagonal
and one `hexfem mesh --json` run."""
import json
import os
import re
import subprocess
import time
from pathlib import Path

CAD_EXT = {".stp", ".step", ".igs", ".iges", ".brep", ".rle"}


def run(cmd, timeout, env=None):
    """(exit code or 'timeout', stdout, stderr, seconds)."""
    t0 = time.monotonic()
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout,
                           env={**os.environ, **(env or {})})
        return p.returncode, p.stdout, p.stderr, time.monotonic() - t0
    except subprocess.TimeoutExpired:
        return "timeout", "", "", time.monotonic() - t0


# The shared models' studies (delaunay_recovery.py, switch_study.py): the bounding-box diagonal
# from `hexfem info`, and one `hexfem mesh --json` run reduced to the figures they tabulate.
def diagonal(hexfem, model, timeout):
    code, out, _, _ = run([hexfem, "info", str(model)], timeout)
    if code != 0:
        return None
    m = re.search(r"bbox \[([^\]]*)\] - \[([^\]]*)\]", out)
    lo = [float(x) for x in m.group(1).split()]
    hi = [float(x) for x in m.group(2).split()]
    return sum((b - a) ** 2 for a, b in zip(lo, hi)) ** 0.5


def mesh(hexfem, model, h, extra, timeout):
    code, out, err, secs = run(
        [hexfem, "mesh", str(model), "--h", f"{h:.6g}", "--json", "-o", "/tmp/study_mesh.msh", *extra],
        timeout)
    if code != 0:
        lines = [ln for ln in err.splitlines() if ln.strip()]
        return {"error": lines[-1] if lines else f"exit {code}"}
    j = json.loads(out)
    tetgen = sum(s["seconds"] for s in j["pipeline_stages"] if "tetgen" in s.get("name", ""))
    return {"h_nbr": j["h_nbr_percent"], "h_vol": j["h_vol_percent"], "nc": j["nc_percent"],
            "q": j["q_mean"], "inverted": j["inverted"], "vertices": j["vertices"],
            "tetgen_s": tetgen, "total_s": j["total_seconds"],
            "flat_retry_points": j.get("flat_retry_points", 0)}


def paired_runs(hexfem, models_dir, divs, first, second, names, timeout, progress=False):
    """Every CAD model of models_dir at h = diagonal / div for each div, meshed with the switches
    `first` and then `second`; rows {"model", "div", "h", names[0]: figures, names[1]: figures}."""
    rows = []
    for model in sorted(Path(models_dir).iterdir()):
        if model.suffix.lower() not in CAD_EXT:
            continue
        d = diagonal(hexfem, model, timeout)
        if d is None:
            continue
        for div in divs:
            h = d / div
            a = mesh(hexfem, model, h, first, timeout)
            b = mesh(hexfem, model, h, second, timeout)
            rows.append({"model": model.name, "div": div, "h": h, names[0]: a, names[1]: b})
            if progress:
                print(f"{model.name} /{div}: {a.get('h_vol', a.get('error'))} -> "
                      f"{b.get('h_vol', b.get('error'))}", flush=True)
    return rows
