#!/usr/bin/env python3
"""A body held by contact alone whose first Coulomb solve (fixed-point step 2) crawled must not crawl again:
the scene is solved as given plus --set overrides, and step 2's QP iterations and the run's n_mult must stay
under the bounds, the run converged and meeting its optimality conditions (summary.json kkt). Work is checked
by counts, not by time. The cases (tests/cli.cmake):
- the steel plate on a rubber-like layer of pipeline/scenes/layered_plate.toml, pushed sideways, at h = 0.012
  with cells of 2h: the whole joint Newton steps on (λ, μ) ran away (merit 0.4 → 1.2e3 → 4e4 → 1.4e6) and the
  steps on μ alone then took 2 216 QP iterations (n_mult 4 901); with the damped second try of
  qp/equality_newton.hpp 78 (1 154), the same answer to 1e-10;
- the pressed shell of pipeline/scenes/shell_segment.toml at h = 0.012, every cell of its contact strip
  slipping the same way at the start: its friction flips across a stick window 2e-4 of the Newton step on μ
  wide, and halving that step to 1/256 before searching the window took 1 383 QP iterations (n_mult
  3 715); searching it at once (qp/dual_qp_solver.cpp, take_halved_step) 950 (2 958).
usage: first_coulomb_solve.py CONTACT3D SCENE MAX_STEP2_QP_ITERATIONS MAX_N_MULT [--set KEY=VALUE]...
"""
import csv
import json
import subprocess
import sys
import tempfile
from pathlib import Path

binary, scene, max_step2, max_n_mult = sys.argv[1], Path(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
overrides = sys.argv[5:]
MAX_KKT = 1e-8  # the layered plate: equilibrium 6.8e-12, the rest 1e-15
failures = []
with tempfile.TemporaryDirectory() as tmp:
    out = Path(tmp) / "run"
    p = subprocess.run([binary, "solve", str(scene), "--quiet", "--out", str(out), *overrides],
                       capture_output=True, text=True)
    if p.returncode != 0:
        failures.append(f"exit {p.returncode}: {p.stderr[-300:]}")
    else:
        summary = json.loads((out / "summary.json").read_text())
        steps = list(csv.DictReader(open(out / "history.csv")))
        print({k: summary.get(k) for k in ("status", "n_mult", "qp_iterations")},
              [int(s["qp_iterations"]) for s in steps])
        if summary.get("status") != "converged":
            failures.append(f"status {summary.get('status')}")
        if len(steps) < 2 or int(steps[1]["qp_iterations"]) > max_step2:
            failures.append(f"the first Coulomb solve took more than {max_step2} QP iterations")
        if summary["n_mult"] > max_n_mult:
            failures.append(f"n_mult {summary['n_mult']} (at most {max_n_mult})")
        for key in ("equilibrium", "normal_feasibility", "normal_complementarity", "disc_feasibility",
                    "slip_alignment", "projected_gradient"):
            if not summary["kkt"][key] <= MAX_KKT:
                failures.append(f"kkt {key} {summary['kkt'][key]:.2e} (at most {MAX_KKT})")
for f in failures:
    print("FAIL:", f)
print(f"{len(failures)} checks failed" if failures else f"ok: the first Coulomb solve of {scene.name} does not crawl")
sys.exit(1 if failures else 0)
