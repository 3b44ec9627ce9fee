#!/usr/bin/env python3
"""The slender strip of pipeline/scenes/strip.toml (cond(Q) ~ 1.8e9, ramp law), default settings: its fixed
point must not stop on a step whose QP did not move (0 iterations: G(x) is the last answer again and err is
~1e-13 whatever the distance) unless that QP was solved to the final step's tolerance (history.csv's qp_rtol:
then λ does solve the QP of the new radii). Before 2fad37e the run stopped at step 6 on such a step at a looser
tolerance, right after a repeat that had found err 4.1e-3. The answer is not compared with a tighter run's here: with cond(Q) ~ 1e9 the QP's
own tolerance moves u on Γc by about 1% (0.7% / 1.1% for u1 / u2 between the default run and one at
fixed_point_tol = 1e-8, qp_rtol = 1e-10; 0.9% / 1.6% before the fix).
usage: strip_fixed_point.py CONTACT3D SOURCE_DIR
"""
import csv
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

binary, root = sys.argv[1], Path(sys.argv[2])
scene = root / "pipeline" / "scenes" / "strip.toml"
failures = []


def solve(out, *sets):
    args = [a for s in sets for a in ("--set", s)]
    p = subprocess.run([binary, "solve", str(scene), "--quiet", "--out", str(out), *args], capture_output=True,
                       text=True)
    if p.returncode != 0:
        failures.append(f"{out.name}: exit {p.returncode}: {p.stderr[-300:]}")
        return None
    nodes = np.genfromtxt(out / "contact_nodes.csv", delimiter=",", names=True)
    with open(out / "history.csv") as f:
        history = list(csv.DictReader(f))
    return nodes, history


with tempfile.TemporaryDirectory() as tmp:
    default = solve(Path(tmp) / "default")
    if default:
        last = default[1][-1]
        print("last step:", dict(last))
        final_rtol = min(float(step["qp_rtol"]) for step in default[1])
        if int(last["qp_iterations"]) == 0 and float(last["qp_rtol"]) > final_rtol:
            failures.append(f"stopped on a step whose QP did not move, at a tolerance above {final_rtol:g}: {dict(last)}")
for f in failures:
    print("FAIL:", f)
print(f"{len(failures)} checks failed" if failures else "ok: the strip's fixed point stops on a step that solved")
sys.exit(1 if failures else 0)
