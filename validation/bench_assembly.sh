#!/bin/sh
# Times the iterative path's assembly on a CAD part (default: ANC101 at h 9, order 2, 339k DOF):
# the report's assembly seconds, setup, solve, LOBPCG iterations, f1-f10 to 10 digits and the
# peak resident memory of the whole run. Run it under the CPU lock so builds do not disturb it:
#   flock /tmp/hexfem-cpu.lock validation/bench_assembly.sh /tmp/hexfem-before
# Usage: bench_assembly.sh HEXFEM [MODEL] [H] [hexfem modal arguments; default --fix face:8]
set -eu
bin=$1
model=${2:-/work/shared/models/ANC101.stp}
h=${3:-9}
[ $# -ge 3 ] && shift 3 || shift $#
[ $# -eq 0 ] && set -- --fix face:8
out=$(mktemp)
/usr/bin/time -f "%e %M" -o "$out.time" "$bin" modal "$model" --h "$h" --order 2 \
  --solver iterative --json "$@" >"$out"
python3 - "$out" "$out.time" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
wall, kb = open(sys.argv[2]).read().split()[-2:]
s = r["solver"]
print(f"dof {r['free_dofs']}  assemble_s {s['assemble_s']:.3f}  setup_s {s['setup_s']:.2f}"
      f"  solve_s {s['solve_s']:.2f}  iterations {s['iterations']}  wall_s {wall}"
      f"  peak_rss_MB {int(kb) / 1024:.0f}"
      f"  peak_after_assembly_MB {s['peak_memory_after_assembly_bytes'] / 2**20:.0f}")
print("f_hz", " ".join(f"{m['frequency_hz']:.10g}" for m in r["modes"]))
PY
rm -f "$out" "$out.time"
