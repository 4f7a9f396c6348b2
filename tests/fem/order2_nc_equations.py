#!/usr/bin/python3
"""The order-2 INP carries the NC faces' hanging-node ties as *EQUATION, and CalculiX then
agrees with hexfem's solver, which ties them the same way (issue 15 item 3, fem/nc_ties.hpp).

  order2_nc_equations.py HEXFEM WORKDIR

Mesh: the cantilever of validation/nc_order2.py at m = 2 (100 x 10 x 10 mm, hexes for x < 50,
Kuhn tets beyond: 4 quad faces at x = 50 each against two triangles), raised to order 2 by
`hexfem convert --order 2`. Checks:
  - one tie per NC face's mid-diagonal node, three equations each, dependent term first with
    coefficient 1, weights summing to 1 (a rigid translation of the face moves the node with it);
  - ccx on the deck with the equations equals `hexfem modal --order 2` on the same mesh to the
    C3D10 mass-rule gap (ccx integrates the tet10 mass with 4 points; validation/order2.md §1:
    1.1e-4 on an all-tet10 box, 5e-6 measured here, where half the cells are hex20): bound
    5e-5 on f1-f6;
  - a .msh cannot carry the ties: writing one says that the 4 nodes are free there;
  - ccx on the same deck with the equations removed (the nodes free: a crack) is off by far more
    (0.8 % at m = 2, validation/order2.md §2), so the comparison above can tell the two apart.
"""
import json
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "validation"))
import crosscheck_ccx as xc  # noqa: E402
import nc_order2  # noqa: E402

hexfem, work = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
os.makedirs(work, exist_ok=True)
os.chdir(work)
tags, xyz, cells = nc_order2.cantilever(2, False)
xc.write_msh22("c.msh", tags, xyz, cells, [])
subprocess.run([hexfem, "convert", "c.msh", "c.inp", "--order", "2"], check=True)

warn = subprocess.run([hexfem, "convert", "c.msh", "c2.msh", "--order", "2"], check=True,
                      capture_output=True, text=True).stderr
assert "4 order-2 hanging nodes (4 NC quad faces) are free in" in warn, warn

# The equations: blocks of (count line, terms) after *EQUATION.
text = open("c.inp").read()
assert text.count("*EQUATION") == 1, "expected one *EQUATION block"
body = text.split("*EQUATION\n", 1)[1].split("\n*", 1)[0].strip().split("\n")
equations, i = [], 0
while i < len(body):
    n = int(body[i])
    vals, i = [], i + 1
    while len(vals) < 3 * n:
        vals += [v for v in body[i].split(",") if v.strip()]
        i += 1
    equations.append([(int(vals[3 * k]), int(vals[3 * k + 1]), float(vals[3 * k + 2]))
                      for k in range(n)])
nodes = xc.inp_nodes("c.inp")
dependent = {(e[0][0], e[0][1]) for e in equations}
assert len(equations) == 3 * 4 and len(dependent) == 12, f"{len(equations)} equations"
for e in equations:
    node, dof, c = e[0]
    assert c == 1.0 and all(t[1] == dof for t in e), e
    assert abs(sum(-t[2] for t in e[1:]) - 1) < 1e-12, "weights do not sum to 1"
    assert abs(nodes[node][0] - 50) < 1e-9, "the tied node is not on the NC interface"
    # The tie reproduces the node's own position (a linear field stays linear across the face).
    for a in range(3):
        assert abs(sum(-t[2] * nodes[t[0]][a] for t in e[1:]) - nodes[node][a]) < 1e-9

fixed = sorted(k for k, p in nodes.items() if p[0] < 1e-6)
xc.write_deck("tied.inp", "c.inp", "FIXED", 6, ("FIXED", fixed))
with open("c_free.inp", "w") as f:
    f.write(re.sub(r"\*EQUATION\n(?:[^*].*\n)*", "", text))
xc.write_deck("free.inp", "c_free.inp", "FIXED", 6, ("FIXED", fixed))
ccx_tied = xc.run_ccx(work, "tied")["freq"]
ccx_free = xc.run_ccx(work, "free")["freq"]
out = subprocess.run([hexfem, "modal", "c.msh", "--order", "2", "--fix", "x<1e-6", "--units",
                      "mm", "--modes", "6", "--json"], check=True, capture_output=True, text=True)
hx = [m["frequency_hz"] for m in json.loads(out.stdout)["modes"]]
gap = max(abs(a - b) / b for a, b in zip(ccx_tied, hx))
crack = max(abs(a - b) / b for a, b in zip(ccx_free, hx))
print("hexfem   ", " ".join(f"{v:.3f}" for v in hx))
print("ccx tied ", " ".join(f"{v:.3f}" for v in ccx_tied), f"max rel diff {gap:.2e}")
print("ccx free ", " ".join(f"{v:.3f}" for v in ccx_free), f"max rel diff {crack:.2e}")
assert gap < 5e-5, f"ccx with the *EQUATIONs is {gap:.2e} off hexfem (bound 5e-5)"
assert crack > 10 * gap, f"the free nodes' crack ({crack:.2e}) is not clear of the gap"
print(f"{len(equations) // 3} ties as *EQUATION: ccx within {gap:.1e} of hexfem "
      f"(free nodes: {crack:.1e})")
