#!/usr/bin/env python3
"""Fuzz the hexfem CLI with mutated STEP, IGES, BREP and MSH files (issue 14).

Each input is a seed with bytes flipped, a cut, lines dropped or repeated, or numbers replaced
by NaN, inf or huge values. CAD inputs go through `info --json` and `mesh --dim 2`, MSH inputs
through `stats` and `convert` (to .msh, binary .msh, .vtu and .inp in turn), a tet mesh through
`stats` and `recombine`. OpenCASCADE's IGES
reader crashed on cut files and its BREP reader printed on stdout or hung (session 37). Every run has a time and a
memory limit. A run fails when it
  - ends by a signal or with an exit code >= 128 (a crash, an abort, an OOM kill),
  - passes its time limit (a hang),
  - prints a sanitizer report (AddressSanitizer, UBSan "runtime error:"),
  - exits non-zero without exactly one "hexfem: error: " line on stderr,
  - writes anything on stdout for `info --json` other than the JSON (nothing when it fails).
Failing inputs are kept in --keep with the command and its output. Exit status 0 when no run
failed. Deterministic for a given --seed.

  python3 tests/fuzz/fuzz_cli.py --hexfem build-asan/app/hexfem --count 10000 --jobs 2
"""
import argparse
import json
import os
import random
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(HERE, "..", "data")
STEP_SEEDS = ["box.stp", "cylinder.stp", "sphere.stp", "gehause_rohteil.stp"]
CAD_SEEDS = STEP_SEEDS + ["cube_10x10.igs", "sphere_Rhino3D_default.igs", "Cone_1.brep",
                          "Torus_1.brep"]
# Mesh size per CAD seed: coarse, so a valid input meshes in well under a second.
STEP_H = {"box.stp": 0.25, "cylinder.stp": 3.0, "sphere.stp": 3.0, "gehause_rohteil.stp": 1.4,
          "cube_10x10.igs": 2.0, "sphere_Rhino3D_default.igs": 0.4, "Cone_1.brep": 40.0,
          "Torus_1.brep": 90.0}
SANITIZER = re.compile(rb"ERROR: AddressSanitizer|ERROR: LeakSanitizer|runtime error:|"
                       rb"SUMMARY: UndefinedBehaviorSanitizer")
NUMBER = re.compile(rb"-?\d+\.?\d*(?:[eE][-+]?\d+)?")
REPLACEMENTS = [b"nan", b"NaN", b"inf", b"-inf", b"1e308", b"-1e308", b"1e-308", b"0",
                b"-1", b"2147483648", b"9223372036854775808", b"99999999999999999999", b"1e999"]


def mutate(data: bytes, rng: random.Random) -> bytes:
    """One to three mutations of one of the kinds the issue names."""
    b = bytearray(data)
    for _ in range(1 if rng.random() < 0.7 else rng.randint(2, 3)):
        kind = rng.choice(["flip", "flip", "truncate", "numbers", "numbers", "lines", "bytes"])
        if not b:
            break
        if kind == "flip":  # flip bits of a few bytes
            for _ in range(rng.randint(1, 3)):
                i = rng.randrange(len(b))
                b[i] ^= 1 << rng.randrange(8)
        elif kind == "bytes":  # overwrite a few bytes with arbitrary ones
            for _ in range(rng.randint(1, 3)):
                b[rng.randrange(len(b))] = rng.randrange(256)
        elif kind == "truncate":
            b = b[:rng.randrange(len(b))]
        elif kind == "numbers":  # replace some numbers by NaN, inf, huge or zero
            spans = [m.span() for m in NUMBER.finditer(bytes(b))]
            if not spans:
                continue
            picks = sorted(rng.sample(spans, min(len(spans), rng.randint(1, 2))), reverse=True)
            for s, e in picks:
                b[s:e] = rng.choice(REPLACEMENTS)
        else:  # drop, repeat or swap lines
            lines = bytes(b).split(b"\n")
            if len(lines) < 2:
                continue
            i = rng.randrange(len(lines))
            op = rng.randrange(3)
            if op == 0:
                del lines[i:i + rng.randint(1, 4)]
            elif op == 1:
                lines[i:i] = lines[i:i + rng.randint(1, 4)] * rng.randint(1, 3)
            else:
                j = rng.randrange(len(lines))
                lines[i], lines[j] = lines[j], lines[i]
            b = bytearray(b"\n".join(lines))
    return bytes(b)


def limit_memory(mb):
    def apply():
        if mb:
            resource.setrlimit(resource.RLIMIT_AS, (mb << 20, mb << 20))
        resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
    return apply


def run_env(memory_mb):
    env = dict(os.environ, OMP_NUM_THREADS="1")
    # ASan reserves terabytes of address space, so RLIMIT_AS cannot bound it: it enforces
    # the limit itself (hard_rss_limit_mb) and reports like any other sanitizer error.
    # Leak checks are off: OpenCASCADE keeps allocations alive until exit by design.
    env["ASAN_OPTIONS"] = (f"hard_rss_limit_mb={memory_mb}:exitcode=86:detect_leaks=0:"
                           "abort_on_error=0:allocator_may_return_null=1")
    env["UBSAN_OPTIONS"] = "halt_on_error=1:exitcode=87:print_stacktrace=1"
    return env


def run(cmd, timeout, memory_mb, sanitized, cwd):
    env = run_env(memory_mb)
    t0 = time.monotonic()
    try:
        p = subprocess.run(cmd, capture_output=True, timeout=timeout, env=env, cwd=cwd,
                           preexec_fn=limit_memory(0 if sanitized else memory_mb))
        return p.returncode, p.stdout, p.stderr, time.monotonic() - t0
    except subprocess.TimeoutExpired as e:
        return "timeout", e.stdout or b"", e.stderr or b"", time.monotonic() - t0


def verdict(code, err):
    if code == "timeout":
        return "hang"
    if SANITIZER.search(err):
        return "sanitizer"
    if code < 0 or code >= 128 or code in (86, 87):
        return "crash"
    if code != 0:
        lines = err.decode(errors="replace").strip().split("\n")
        errors = [l for l in lines if l.startswith("hexfem: error: ")]
        if len(errors) != 1:
            return "not one error line"
    return None


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--hexfem", required=True)
    ap.add_argument("--count", type=int, default=50, help="number of mutated inputs")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--timeout", type=float, default=60, help="seconds per run")
    ap.add_argument("--memory-mb", type=int, default=4096, help="memory per run")
    ap.add_argument("--keep", default=None, help="folder for failing inputs")
    ap.add_argument("--sanitized", action="store_true",
                    help="the binary has ASan (memory limit by ASan, not RLIMIT_AS)")
    a = ap.parse_args()
    hexfem = os.path.abspath(a.hexfem)
    work = tempfile.mkdtemp(prefix="hexfem-fuzz-")
    try:
        return fuzz(a, hexfem, work)
    finally:
        shutil.rmtree(work, ignore_errors=True)


def make_seeds(hexfem, work, memory_mb):
    """CAD seeds from tests/data; MSH seeds meshed from STEP ones (4.1 ASCII and binary, 2.2)."""
    seeds = []
    for name in CAD_SEEDS:
        with open(os.path.join(DATA, name), "rb") as f:
            seeds.append((name, "step", f.read()))
    for name in STEP_SEEDS[:2]:
        for binary in (False, True):
            out = os.path.join(work, f"seed_{name}_{int(binary)}.msh")
            cmd = [hexfem, "mesh", os.path.join(DATA, name), "--h", str(STEP_H[name]), "-o", out]
            subprocess.run(cmd + (["--binary"] if binary else []), check=True,
                           capture_output=True, env=run_env(memory_mb))
            with open(out, "rb") as f:
                seeds.append((os.path.basename(out), "msh", f.read()))
    seeds.append(("seed_22.msh", "msh", MSH22))
    seeds.append(("seed_tets.msh", "tets", cubes_of_tets_msh(2)))
    return seeds


def cubes_of_tets_msh(n):
    """MSH 2.2: n^3 unit cubes, six tets each along the cube's diagonal, and the boundary
    triangles tagged by box side (1-6): an input for `recombine`."""
    node = lambda i, j, k: 1 + i + (n + 1) * (j + (n + 1) * k)
    lines, elements = [], []
    for k in range(n + 1):
        for j in range(n + 1):
            for i in range(n + 1):
                lines.append(f"{node(i, j, k)} {i} {j} {k}")
    axes = [(1, 0, 0), (0, 1, 0), (0, 0, 1)]
    perms = [(0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)]
    for k in range(n):
        for j in range(n):
            for i in range(n):
                for p in perms:
                    a = (i, j, k)
                    b = tuple(x + y for x, y in zip(a, axes[p[0]]))
                    c = tuple(x + y for x, y in zip(b, axes[p[1]]))
                    d = (i + 1, j + 1, k + 1)
                    elements.append(("4 2 1 1", [node(*a), node(*b), node(*c), node(*d)]))
    for side in range(6):
        axis, top = side // 2, side % 2
        u, v = [x for x in range(3) if x != axis]
        for s in range(n):
            for t in range(n):
                def at(ds, dt):
                    q = [0, 0, 0]
                    q[axis], q[u], q[v] = top * n, s + ds, t + dt
                    return node(*q)
                tag = f"2 2 {side + 1} {side + 1}"
                elements.append((tag, [at(0, 0), at(1, 0), at(1, 1)]))
                elements.append((tag, [at(0, 0), at(1, 1), at(0, 1)]))
    out = ["$MeshFormat", "2.2 0 8", "$EndMeshFormat", "$Nodes", str(len(lines))] + lines
    out += ["$EndNodes", "$Elements", str(len(elements))]
    out += [f"{e + 1} {tag} {' '.join(map(str, ids))}" for e, (tag, ids) in enumerate(elements)]
    out += ["$EndElements", ""]
    return "\n".join(out).encode()


MSH22 = b"""$MeshFormat
2.2 0 8
$EndMeshFormat
$PhysicalNames
1
3 1 "solid"
$EndPhysicalNames
$Nodes
6
1 0 0 0
2 1 0 0
3 0 1 0
4 0 0 1
5 1 0 1
6 0 1 1
$EndNodes
$Elements
2
1 6 2 1 1 1 2 3 4 5 6
2 2 2 1 1 1 2 3
$EndElements
"""


def json_or_nothing(code, out):
    """`info --json` prints its JSON and nothing else, and nothing at all when it fails."""
    if code != 0:
        return not out.strip()
    try:
        json.loads(out)
        return True
    except ValueError:
        return False


def commands(kind, name, path, i, work):
    if kind == "step":
        h = STEP_H.get(name, 4.0)
        return [["info", "--json", path], ["mesh", path, "--h", str(h), "--dim", "2"]]
    out = os.path.join(work, f"out{i}." + ["msh", "msh", "vtu", "inp"][i % 4])
    if kind == "tets":
        return [["stats", path], ["recombine", path, "-o", out]]
    convert = ["convert", path, out] + (["--binary"] if i % 4 == 1 else [])
    return [["stats", path], convert]


def fuzz(a, hexfem, work):
    rng = random.Random(a.seed)
    seeds = make_seeds(hexfem, work, a.memory_mb)
    jobs = []
    for i in range(a.count):
        name, kind, data = seeds[i % len(seeds)]
        ext = os.path.splitext(name)[1] if kind == "step" else ".msh"
        path = os.path.join(work, f"in{i}{ext}")
        with open(path, "wb") as f:
            f.write(mutate(data, rng))
        for cmd in commands(kind, name, path, i, work):
            jobs.append((i, path, cmd))

    stats = {"runs": 0, "exit0": 0, "exit1": 0, "exit_other": 0, "failures": 0}
    slowest = 0.0
    t0 = time.monotonic()

    def one(job):
        i, path, cmd = job
        code, out, err, secs = run([hexfem] + cmd, a.timeout, a.memory_mb, a.sanitized, work)
        bad = verdict(code, err)
        if not bad and cmd[:2] == ["info", "--json"] and not json_or_nothing(code, out):
            bad = "stdout holds more than the JSON"
        return job, code, err, secs, bad

    failures = []
    with ThreadPoolExecutor(max_workers=a.jobs) as pool:
        for job, code, err, secs, bad in pool.map(one, jobs):
            stats["runs"] += 1
            slowest = max(slowest, secs)
            if code == 0:
                stats["exit0"] += 1
            elif code == 1:
                stats["exit1"] += 1
            else:
                stats["exit_other"] += 1
            if bad:
                stats["failures"] += 1
                failures.append((job, code, err, bad))
                print(f"FAIL {bad}: hexfem {' '.join(job[2])} (exit {code})\n"
                      f"  {err.decode(errors='replace')[-2000:]}", file=sys.stderr)
                if a.keep:
                    os.makedirs(a.keep, exist_ok=True)
                    dst = os.path.join(a.keep, os.path.basename(job[1]))
                    shutil.copy(job[1], dst)
                    with open(dst + ".txt", "wb") as f:
                        f.write(" ".join(job[2]).encode() + b"\n" + err)
    elapsed = time.monotonic() - t0
    print(f"inputs {a.count} (seed {a.seed}), runs {stats['runs']}: exit 0 {stats['exit0']}, "
          f"exit 1 {stats['exit1']}, other {stats['exit_other']}; slowest run {slowest:.1f} s, "
          f"total {elapsed:.0f} s; limits {a.timeout:g} s, {a.memory_mb} MB"
          f"{', sanitized' if a.sanitized else ''}")
    print(f"{stats['runs'] - stats['failures']} passed, {stats['failures']} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
