#!/usr/bin/python3
"""Validation of the surface mesher (issue 4): writes validation/surface.md.

    /usr/bin/python3 validation/surface_models.py [--build build-cad] [--out validation/surface.md]
        [--models /work/shared/models] [--timeout 300]

1. Every CAD model at h = bounding-box diagonal / 50: bench_surface (figures and checks, one
   process per model so a crash or a hang is caught and bounded) and `hexfem mesh --dim 2`
   (what a user sees: a mesh, or one error line and a non-zero exit); then at diagonal / 25
   and / 100 (bench_surface only).
2. Box, cylinder, ANC101 at about 10k points: right-isosceles share, points against area/h^2.
3. Enclosed volume against the CAD volume: planar parts, and curved parts at three sizes.
4. Speed of ANC101 at about 50k points on 2 threads (and 1), time per stage; determinism: the
   .msh written twice on 2 threads and once on 1 thread must be byte-identical.
5. Bad input through the CLI: each case, its exit code and its one error line.
"""
import argparse
import hashlib
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
from study_util import CAD_EXT, run  # noqa: E402  (sibling module)


def bench_rows(out):
    """Data rows of bench_surface's Markdown table, as lists of cells."""
    rows = []
    for line in out.splitlines():
        if line.startswith("| ") and not line.startswith("| model") and "---" not in line:
            rows.append([c.strip() for c in line.strip().strip("|").split("|")])
    return rows


BENCH_COLS = ["model", "h", "points", "triangles", "area/h²", "right-iso", "min angle",
              "below5", "checks", "volume error", "curvature", "read", "size", "edges",
              "cross field", "packing", "triangulation", "assembly", "checks time", "repair",
              "total"]


def as_dict(row):
    return dict(zip(BENCH_COLS, row))


def bench(args, extra, files, env=None):
    code, out, err, secs = run([str(args.bench), *extra, *map(str, files)], args.timeout, env)
    return code, [as_dict(r) for r in bench_rows(out)], err, secs


def describe_failure(code, err):
    if code == "timeout":
        return f"timeout (> {ARGS.timeout} s)"
    if isinstance(code, int) and code < 0:
        return f"crashed (signal {-code})"
    return f"exit {code}: {err.strip().splitlines()[-1] if err.strip() else ''}"


def models_section(args, lines):
    files = sorted(p for p in Path(args.models).iterdir() if p.suffix.lower() in CAD_EXT)
    lines += [
        "## 1. Every model at h = bounding-box diagonal / 50",
        "",
        f"`bench_surface --div 50 MODEL` (one process per model, {args.timeout} s bound) and "
        "`hexfem mesh MODEL --h H --dim 2 -o out.msh`. Checks: closed 2-manifold, consistent "
        "outward orientation, no self-intersection (CGAL PMP `does_self_intersect`), per "
        "solid. `<5°`: triangles with an angle below 5°; in brackets, how many of them are "
        "forced by the CAD geometry: *sharp corner* = the small angle lies between two CAD "
        "edges (a face corner sharper than 5° in the model, which every triangulation keeps); "
        "*cusp gap* = all three corners on CAD edges and the short side a chord across the "
        "face (a sliver of the face narrower than its edge spacing, next to a corner below "
        "10° such as a tangent cusp). "
        "Volume error: (mesh − CAD)/CAD. Curvature: 0, or the curvature bound (elements per "
        "turn) of the repair when the first mesh failed the checks (chords of a thin wall's two "
        "sides crossing). Time: bench_surface read + mesh + checks (+ first attempt), seconds, "
        "2 threads.",
        "",
        "| model | h | points | triangles | right-iso | min angle | <5° (sharp corner + cusp gap) "
        "| closed+oriented+no self-int. | volume error | curvature | time (s) | "
        "`hexfem mesh --dim 2` |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    summary = {"meshed": 0, "errors": 0, "crash": 0, "valid": 0, "angle_ok": 0, "angle_cad": 0}
    for f in files:
        code, rows, err, _ = bench(args, ["--div", "50"], [f])
        if code != 0 or not rows:
            summary["crash"] += 1
            lines.append(f"| {f.name} | | | | | | | | | | | bench: {describe_failure(code, err)} |")
            continue
        r = rows[0]
        if r["points"].startswith("error:"):
            cli_code, cli_out, cli_err, _ = run(
                [str(args.hexfem), "mesh", str(f), "--h", "1", "--dim", "2"], args.timeout)
            msg = (cli_out + cli_err).strip()
            one_line = isinstance(cli_code, int) and cli_code > 0 and "\n" not in msg
            summary["errors"] += 1
            lines.append(f"| {f.name} | | | | | | | | | | | exit {cli_code}"
                         f"{'' if one_line else ' (NOT one line)'}: `{msg}` |")
            continue
        with tempfile.TemporaryDirectory() as tmp:
            cli_code, cli_out, cli_err, _ = run(
                [str(args.hexfem), "mesh", str(f), "--h", r["h"], "--dim", "2", "-o",
                 f"{tmp}/out.msh"], args.timeout)
        if cli_code == 0:
            cli = "ok, written"
        else:
            msg = (cli_out + cli_err).strip()
            cli = f"exit {cli_code}: `{msg}`" if isinstance(cli_code, int) and cli_code > 0 \
                else describe_failure(cli_code, msg)
        summary["meshed"] += 1
        solids = r["checks"].split("/")
        summary["valid"] += solids[0] == solids[1]
        summary["angle_ok"] += r["below5"].split()[0] == "0"
        n5, sharp, _, gap = r["below5"].replace("(", "").replace(")", "").split()
        summary["angle_cad"] += int(n5) == int(sharp) + int(gap)
        lines.append(f"| {f.name} | {r['h']} | {r['points']} | {r['triangles']} | "
                     f"{r['right-iso']} | {r['min angle']} | {r['below5']} | {r['checks']} | "
                     f"{r['volume error']} | {r['curvature']} | {r['total']} | {cli} |")
    lines += [
        "",
        f"{len(files)} models: {summary['meshed']} meshed ({summary['valid']} pass all the "
        f"closed/oriented/self-intersection checks, {summary['angle_ok']} have no angle below "
        f"5°, {summary['angle_cad']} have none but at sharp corners and cusp gaps of the CAD "
        f"model), {summary['errors']} refused with a one-line error, {summary['crash']} crashed "
        "or timed out.",
        "",
    ]


def robustness_section(args, lines):
    files = sorted(p for p in Path(args.models).iterdir() if p.suffix.lower() in CAD_EXT)
    lines += [
        "## 1b. The same models at h = diagonal / 25 and diagonal / 100",
        "",
        "`bench_surface --div D MODEL`, one process per model and size. Columns as in 1; "
        "the two refused models give the same error at every size and are left out.",
        "",
        "| model | D | h | points | min angle | <5° (sharp corner + cusp gap) | checks | "
        "curvature | time (s) |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    worst = {"invalid": 0, "unforced": 0, "failed": 0}
    for f in files:
        for d in (25, 100):
            code, rows, err, _ = bench(args, ["--div", str(d)], [f])
            if code != 0 or not rows:
                worst["failed"] += 1
                lines.append(f"| {f.name} | {d} | | {describe_failure(code, err)} | | | | | |")
                continue
            r = rows[0]
            if r["points"].startswith("error:"):
                continue
            solids = r["checks"].split("/")
            worst["invalid"] += solids[0] != solids[1]
            n5, sharp, _, gap = r["below5"].replace("(", "").replace(")", "").split()
            worst["unforced"] += int(n5) - int(sharp) - int(gap)
            lines.append(f"| {f.name} | {d} | {r['h']} | {r['points']} | {r['min angle']} | "
                         f"{r['below5']} | {r['checks']} | {r['curvature']} | {r['total']} |")
    lines += [
        "",
        f"Meshes failing a check: {worst['invalid']}; triangles below 5° not forced by the "
        f"CAD model: {worst['unforced']}; crashes or timeouts: {worst['failed']}.",
        "",
    ]


def ten_k_section(args, lines):
    names = ["box.stp", "cylinder.stp", "ANC101.stp"]
    code, rows, err, _ = bench(args, ["--points", "10000"], [Path(args.models) / n for n in names])
    lines += [
        "## 2. Box, cylinder and ANC101 at about 10k points",
        "",
        "`bench_surface --points 10000 box.stp cylinder.stp ANC101.stp` "
        "(h = sqrt(area / 10000)). Targets: right-isosceles-like ≥ 70 %, points within 25 % "
        "of area/h².",
        "",
        "| model | h | points | area/h² | points / (area/h²) | right-iso | min angle | checks |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        if r["points"].startswith("error:"):
            lines.append(f"| {r['model']} | | {r['points']} | | | | | |")
            continue
        ratio = float(r["points"]) / float(r["area/h²"])
        lines.append(f"| {r['model']} | {r['h']} | {r['points']} | {r['area/h²']} | "
                     f"{ratio:.3f} | {r['right-iso']} | {r['min angle']} | {r['checks']} |")
    if code != 0:
        lines.append(f"\nbench_surface: {describe_failure(code, err)}")
    lines.append("")


def volume_section(args, lines):
    lines += [
        "## 3. Enclosed volume against the CAD volume",
        "",
        "`bench_surface --div D MODEL` for D = 25, 50, 100 (h = diagonal / D). Planar-faced "
        "parts must match to 1e-9 relative; curved parts must converge as h shrinks.",
        "",
        "| model | faces | D | h | points | volume error (mesh − CAD)/CAD |",
        "|---|---|---|---|---|---|",
    ]
    for name, kind in [("box.stp", "planar"), ("cube_10x10.igs", "planar"),
                       ("cylinder.stp", "curved"), ("sphere.stp", "curved"),
                       ("Torus_1.brep", "curved"), ("ANC101.stp", "curved")]:
        for d in (25, 50, 100):
            code, rows, err, _ = bench(args, ["--div", str(d)], [Path(args.models) / name])
            if code != 0 or not rows or rows[0]["points"].startswith("error:"):
                msg = rows[0]["points"] if rows else describe_failure(code, err)
                lines.append(f"| {name} | {kind} | {d} | | | {msg} |")
                continue
            r = rows[0]
            lines.append(f"| {name} | {kind} | {d} | {r['h']} | {r['points']} | "
                         f"{r['volume error']} |")
    lines.append("")


def sha(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def speed_section(args, lines):
    anc = Path(args.models) / "ANC101.stp"
    stages = ["read", "size", "edges", "cross field", "packing", "triangulation", "assembly",
              "checks time", "total"]
    lines += [
        "## 4. Speed and determinism",
        "",
        "`OMP_NUM_THREADS=T bench_surface --points 50000 --repeat 3 ANC101.stp` (best of 3; "
        "seconds; `read` is the STEP import, `checks time` the closed/oriented/self-intersection "
        "checks that mesh_surface runs on its result; `total` includes both). "
        f"Machine: {os.cpu_count()} cores, shared with other builds, so figures vary by "
        "±30 %. Target: under 5 s on 2 cores.",
        "",
        "| threads | h | points | " + " | ".join(stages) + " |",
        "|---" * (3 + len(stages)) + "|",
    ]
    for threads, extra in [(2, ["--points", "50000"]), (1, ["--points", "50000"]),
                           (2, ["--h", "2"])]:
        code, rows, err, _ = bench(args, [*extra, "--repeat", "3"], [anc],
                                   {"OMP_NUM_THREADS": str(threads)})
        if code != 0 or not rows or rows[0]["points"].startswith("error:"):
            lines.append(f"| {threads} | failed: {describe_failure(code, err)} |")
            continue
        r = rows[0]
        lines.append(f"| {threads} | {r['h']} | {r['points']} | " +
                     " | ".join(r[s] for s in stages) + " |")
    with tempfile.TemporaryDirectory() as tmp:
        hashes = []
        for i, threads in enumerate([2, 2, 1]):
            out = f"{tmp}/anc{i}.msh"
            code, o, e, _ = run([str(args.hexfem), "mesh", str(anc), "--h", "3", "--dim", "2",
                                 "-o", out], args.timeout, {"OMP_NUM_THREADS": str(threads)})
            hashes.append(sha(out) if code == 0 else f"failed: {(o + e).strip()}")
    same = len(set(hashes)) == 1
    lines += [
        "",
        "Determinism: `hexfem mesh ANC101.stp --h 3 --dim 2 -o anc.msh` run twice with "
        "OMP_NUM_THREADS=2 and once with 1: sha256 "
        + ", ".join(f"`{h[:16]}`" for h in hashes)
        + (" — byte-identical." if same else " — DIFFERENT."),
        "",
    ]


def bad_input_section(args, lines):
    box = Path(args.models) / "box.stp"
    with tempfile.TemporaryDirectory() as tmp:
        empty = Path(tmp) / "empty.step"
        empty.write_bytes(b"")
        text = Path(tmp) / "text.step"
        text.write_text("this is not a CAD file\n")
        trunc = Path(tmp) / "truncated.step"
        data = box.read_bytes()
        trunc.write_bytes(data[: len(data) // 2])
        cases = [
            ("missing file", [f"{tmp}/missing.step", "--h", "1"]),
            ("empty file", [str(empty), "--h", "1"]),
            ("truncated STEP", [str(trunc), "--h", "1"]),
            ("text file named .step", [str(text), "--h", "1"]),
            ("h = 0", [str(box), "--h", "0"]),
            ("h < 0", [str(box), "--h", "-1"]),
            ("over 50M points (box, h = 1e-4)", [str(box), "--h", "1e-4"]),
            ("IGES surfaces that do not close (bearing.iges)",
             [str(Path(args.models) / "bearing.iges"), "--h", "5"]),
        ]
        lines += [
            "## 5. Bad input",
            "",
            "`hexfem mesh FILE --h H --dim 2` (tested in tests/cad/test_cli_surface.cpp "
            "`CliSurface.BadInputFailsWithOneLine` and test_cad_model.cpp "
            "`CadModel.BadInputGivesOneLineErrors`).",
            "",
            "| case | exit code | output (must be one line) |",
            "|---|---|---|",
        ]
        for what, a in cases:
            code, o, e, _ = run([str(args.hexfem), "mesh", *a, "--dim", "2"], args.timeout)
            msg = (o + e).strip()
            flag = "" if "\n" not in msg else " (NOT one line)"
            lines.append(f"| {what} | {code} | `{msg}`{flag} |")
    lines.append("")


def notes_section(args, lines):
    lines += [
        "## Notes: what is not met and why",
        "",
        "- **bearing.iges** is refused: its trimmed surfaces leave 25 free edges after sewing at "
        "every tolerance tried (1e-6 to 1e-3 of the diagonal in the code; 1e-2 was tried by hand "
        "with the same 25), so some surfaces are missing. Its coordinates span about 0.1 × 0.12 "
        "× 0.03 in the file's declared unit (mm); gmsh 4.8.4 reads the same extents.",
        "- **gehause_rohteil.stp** is refused: edge 51 bounds four face sides (faces 18, 20, 23, "
        "44: four planes meeting on the line x = 4, z = 3), so the solid touches itself along "
        "that edge: a non-manifold B-rep of which no closed 2-manifold surface mesh exists. "
        "gmsh tets it because it never requires one.",
        "- **Angles below 5°**: at h = diagonal/50 every one is forced by the CAD model (a face "
        "corner sharper than 5°, or a sliver next to a tangent cusp that no edge spacing can "
        "follow; e.g. control arm face 89, where edges 40 and 250 leave vertex 28 at about 2° "
        "and stay 0.04 mm apart for a millimetre). At diagonal/25 and /100 a few are not "
        "(table 1b): a short curved CAD edge facing points across a gap that the size "
        "gradation leaves coarse (40mm_capot face 215), a cone apex 0.004 mm from another edge "
        "of its face (freecad counterbore face 25), and Block after its repair.",
        "- **Repair**: when a first mesh fails the checks (chords of the two sides of a thin "
        "wall crossing at a coarse h: 40mm_capot and Block at diagonal/25), mesh_surface meshes "
        "the part again with a curvature bound of 8 (then 16) elements per turn; the "
        "`curvature` column shows where that happened.",
        "- **Speed**: the checks (CGAL self-intersection test) are now part of mesh_surface and "
        "of the timed total; `hexfem mesh` runs check_solids a second time (app/cmd_mesh.cpp "
        "could use SurfaceReport::checks instead). The machine is shared, so a 2-thread run is "
        "no faster than a 1-thread run here.",
        "",
    ]


def main():
    global ARGS
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", default=str(ROOT / "build-cad"))
    ap.add_argument("--out", default=str(ROOT / "validation" / "surface.md"))
    ap.add_argument("--models", default="/work/shared/models")
    ap.add_argument("--timeout", type=int, default=300)
    ap.add_argument("--only", default="", help="comma list of sections: models,robust,10k,"
                    "volume,speed,bad,notes (default all)")
    args = ARGS = ap.parse_args()
    args.bench = Path(args.build) / "validation" / "bench_surface"
    args.hexfem = Path(args.build) / "app" / "hexfem"
    for exe in (args.bench, args.hexfem):
        if not exe.exists():
            sys.exit(f"{exe} not built")
    head = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"],
                          capture_output=True, text=True).stdout.strip()
    lines = [
        "# Surface mesher validation (issue 4)",
        "",
        f"Produced by `/usr/bin/python3 validation/surface_models.py` (commit {head}, "
        f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}); Release build. "
        "bench_surface is validation/bench_surface.cpp.",
        "",
    ]
    sections = {"models": models_section, "robust": robustness_section, "10k": ten_k_section,
                "volume": volume_section, "speed": speed_section, "bad": bad_input_section,
                "notes": notes_section}
    only = [s for s in args.only.split(",") if s] or list(sections)
    for name in only:
        sections[name](args, lines)
        print(f"{name}: done", file=sys.stderr)
    Path(args.out).write_text("\n".join(lines) + "\n")
    print(f"wrote {args.out}", file=sys.stderr)


ARGS = None
if __name__ == "__main__":
    main()
