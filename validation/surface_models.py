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


def below5(cell):
    """(triangles below 5°, of them forced at CAD corners below 5°) from bench's cell
    `N (F, ≤ X°)`."""
    n5, rest = cell.split("(", 1)
    return int(n5), int(rest.split(",")[0])


SMALL_ANGLES = {}  # (model, D) -> bench --angles lines


def keep_angles(name, d, err):
    lines = [ln.strip().split(": ", 1)[1] for ln in err.splitlines()
             if ln.strip().startswith(f"{name}: ") and "forced" in ln]
    if lines:
        SMALL_ANGLES[(name, d)] = lines


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
        "forced by the CAD model — their smallest angle is at a corner of their CAD face whose "
        "own angle, measured on the CAD (edge_points.hpp `face_corners`: the edges' directions "
        "leaving the vertex, in the tangent plane), is below 5°, so the angles there of the "
        "face's triangles add up to less than 5° — and the widest such CAD corner (section 1c "
        "lists every triangle below 5° with its corner). "
        "Volume error: (mesh − CAD)/CAD. Curvature: 0, or the curvature bound (elements per "
        "turn) of the repair when the first mesh failed the checks (chords of a thin wall's two "
        "sides crossing). Time: bench_surface read + mesh + checks (+ first attempt), seconds, "
        "2 threads.",
        "",
        "| model | h | points | triangles | right-iso | min angle | <5° (at CAD corners < 5°, widest) "
        "| closed+oriented+no self-int. | volume error | curvature | time (s) | "
        "`hexfem mesh --dim 2` |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    summary = {"meshed": 0, "errors": 0, "crash": 0, "valid": 0, "angle_ok": 0, "angle_cad": 0}
    for f in files:
        code, rows, err, _ = bench(args, ["--div", "50", "--angles"], [f])
        keep_angles(f.name, 50, err)
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
        n5, forced = below5(r["below5"])
        summary["angle_ok"] += n5 == 0
        summary["angle_cad"] += n5 == forced
        lines.append(f"| {f.name} | {r['h']} | {r['points']} | {r['triangles']} | "
                     f"{r['right-iso']} | {r['min angle']} | {r['below5']} | {r['checks']} | "
                     f"{r['volume error']} | {r['curvature']} | {r['total']} | {cli} |")
    lines += [
        "",
        f"{len(files)} models: {summary['meshed']} meshed ({summary['valid']} pass all the "
        f"closed/oriented/self-intersection checks, {summary['angle_ok']} have no angle below "
        f"5°, {summary['angle_cad']} have none but at CAD face corners sharper than 5°), "
        f"{summary['errors']} refused with a one-line error, {summary['crash']} crashed "
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
        "| model | D | h | points | min angle | <5° (at CAD corners < 5°, widest) | checks | "
        "curvature | time (s) |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    worst = {"invalid": 0, "unforced": 0, "failed": 0}
    for f in files:
        for d in (25, 100):
            code, rows, err, _ = bench(args, ["--div", str(d), "--angles"], [f])
            keep_angles(f.name, d, err)
            if code != 0 or not rows:
                worst["failed"] += 1
                lines.append(f"| {f.name} | {d} | | {describe_failure(code, err)} | | | | | |")
                continue
            r = rows[0]
            if r["points"].startswith("error:"):
                continue
            solids = r["checks"].split("/")
            worst["invalid"] += solids[0] != solids[1]
            n5, forced = below5(r["below5"])
            worst["unforced"] += n5 - forced
            lines.append(f"| {f.name} | {d} | {r['h']} | {r['points']} | {r['min angle']} | "
                         f"{r['below5']} | {r['checks']} | {r['curvature']} | {r['total']} |")
    lines += [
        "",
        f"Meshes failing a check: {worst['invalid']}; triangles below 5° not forced by the "
        f"CAD model: {worst['unforced']}; crashes or timeouts: {worst['failed']}.",
        "",
    ]


def angles_section(args, lines):
    lines += [
        "## 1c. Every triangle below 5° (sections 1 and 1b)",
        "",
        "`bench_surface --div D --angles MODEL`: per model and size, each CAD face corner below "
        "5° (measured on the CAD) where triangles below 5° have their smallest angle, and every "
        "other triangle below 5° (*not forced*).",
        "",
        "| model | D | triangles below 5° |",
        "|---|---|---|",
    ]
    for (name, d) in sorted(SMALL_ANGLES, key=lambda k: (k[0], k[1])):
        lines.append(f"| {name} | {d} | {'<br>'.join(SMALL_ANGLES[(name, d)])} |")
    lines.append("")


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
        "- **Angles below 5°** (every one is listed in 1c): a triangle counts as forced only "
        "when its smallest angle sits at a CAD face corner whose own angle is below 5° on the "
        "CAD model: the tangent cusps (0.000°–0.01°) of the control arm, MVE, 917_fusee, "
        "SampleCrankshaft4A and the counterbore, and CrankArm's 1.6°–1.7° corners. How the "
        "others were removed (mesher/edge_points.cpp): a face corner below 5°, or an acute one "
        "whose chords close in below 5° at some size down to the floor (bottle.brep's threads: "
        "33° at the vertex, 2.6° 0.03 mm away; tie_rod's 10° corners), gets a *zone*: its "
        "edges' first point lies at the zone radius from the vertex (the vertex size, or the "
        "sizes of strips met there), so the corner is one triangle; beyond it the points "
        "across the wedge are spaced four times its width (a geometric progression along a "
        "straight wedge), down to 0.15 % of h; strips between edges that share no corner are "
        "refined to their width down to 1.5 % of h (was 5 %). Two more sources of needles "
        "were in the faces' interiors (40mm_capot face 215 at diagonal/100: 0.15 mm arc "
        "chords facing the other side of a 1.6 mm slot with no point between; 917_fusee faces "
        "107 and 133 next to face 106's cusp, whose zone segment is about 30 times the next one "
        "on the shared edge): where the size grows at the full gradation from a fine boundary, "
        "the packing (mesher/surface_points.cpp) refused every candidate as too close to the "
        "point it grew from, so nothing filled in; the exclusion now grows by at most a "
        "quarter from the spawning point's. And an interior point almost on the line between "
        "two neighbours (a flat triangle, >150° at it, <5° at the others) is taken out of the "
        "triangulation when its star's triangles get better (mesher/surface_triangulation.cpp). "
        "No unforced triangle below 5° is left.",
        "- **Repair**: when a first mesh fails the checks (chords of the two sides of a thin "
        "wall crossing at a coarse h: 40mm_capot at diagonal/25), mesh_surface meshes "
        "the part again with a curvature bound of 8 (then 16) elements per turn; the "
        "`curvature` column shows where that happened.",
        "- **Speed**: the checks (CGAL self-intersection test) are part of mesh_surface and of "
        "the timed total (`hexfem mesh` reuses them). The machine is shared, so a 2-thread run "
        "is no faster than a 1-thread run here.",
        "- **Downstream**: tests/volume (including the control arm at h = 10.1, whose flat "
        "tet from these surfaces is now lifted by mesher/volume_slivers.cpp) and tests/e2e "
        "pass with these surfaces.",
        "",
    ]


def main():
    global ARGS
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", default=str(ROOT / "build-cad"))
    ap.add_argument("--out", default=str(ROOT / "validation" / "surface.md"))
    ap.add_argument("--models", default="/work/shared/models")
    ap.add_argument("--timeout", type=int, default=300)
    ap.add_argument("--only", default="", help="comma list of sections: models,robust,angles,10k,"
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
    sections = {"models": models_section, "robust": robustness_section,
                "angles": angles_section, "10k": ten_k_section,
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
