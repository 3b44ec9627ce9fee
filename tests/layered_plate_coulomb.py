#!/usr/bin/env python3
"""The steel plate on a rubber-like layer of pipeline/scenes/layered_plate.toml (held by contact alone, pushed
sideways, Coulomb friction), coarsened to h = 0.012 with cells of 2h (867 multipliers): its first Coulomb solve
(fixed-point step 2) must not crawl. The whole joint Newton steps on (λ, μ) of that solve ran away (merit
0.4 → 1.2e3 → 4e4 → 1.4e6) and were given up, and the steps on μ alone then took 2 216 QP iterations (4 901
products in the run); with the damped second try of qp/equality_newton.hpp 78 (1 154), the same answer to 1e-10.
The run must also meet its optimality conditions (summary.json kkt). Work is checked by counts, not by time.
usage: layered_plate_coulomb.py CONTACT3D SOURCE_DIR
"""
import csv
import json
import subprocess
import sys
import tempfile
from pathlib import Path

binary, root = sys.argv[1], Path(sys.argv[2])
scene = root / "pipeline" / "scenes" / "layered_plate.toml"
MAX_STEP2_QP_ITERATIONS = 500  # 78 with the damped try, 2 216 without
MAX_N_MULT = 2500  # 1 154 with it, 4 901 without
MAX_KKT = 1e-8  # equilibrium 6.8e-12, the rest 1e-15
failures = []
with tempfile.TemporaryDirectory() as tmp:
    out = Path(tmp) / "run"
    p = subprocess.run([binary, "solve", str(scene), "--quiet", "--out", str(out), "--set", "mesh.parameters.h=0.012",
                        "--set", 'contact.cell_size="2h"'], capture_output=True, text=True)
    if p.returncode != 0:
        failures.append(f"exit {p.returncode}: {p.stderr[-300:]}")
    else:
        summary = json.loads((out / "summary.json").read_text())
        steps = list(csv.DictReader(open(out / "history.csv")))
        print({k: summary.get(k) for k in ("status", "n_mult", "qp_iterations")},
              [int(s["qp_iterations"]) for s in steps])
        if summary.get("status") != "converged":
            failures.append(f"status {summary.get('status')}")
        if len(steps) < 2 or int(steps[1]["qp_iterations"]) > MAX_STEP2_QP_ITERATIONS:
            failures.append(f"the first Coulomb solve took more than {MAX_STEP2_QP_ITERATIONS} QP iterations")
        if summary["n_mult"] > MAX_N_MULT:
            failures.append(f"n_mult {summary['n_mult']} (at most {MAX_N_MULT})")
        for key in ("equilibrium", "normal_feasibility", "normal_complementarity", "disc_feasibility",
                    "slip_alignment", "projected_gradient"):
            if not summary["kkt"][key] <= MAX_KKT:
                failures.append(f"kkt {key} {summary['kkt'][key]:.2e} (at most {MAX_KKT})")
for f in failures:
    print("FAIL:", f)
print(f"{len(failures)} checks failed" if failures else "ok: the layered plate's first Coulomb solve does not crawl")
sys.exit(1 if failures else 0)
