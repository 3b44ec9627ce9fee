#!/usr/bin/env python3
"""End to end through the command line: write the paper's mesh with `contact3d mesh brick`,
solve the paper scene on it with --mesh, and check every output file the other tools rely on
(names, columns, sizes, finite values, convergence)."""
import csv
import json
import math
import os
import subprocess
import sys
import tempfile
from pathlib import Path

binary, root = sys.argv[1], Path(sys.argv[2])
scene = root / "pipeline" / "scenes" / "paper_brick.toml"


def fail(msg):
    print("FAIL:", msg)
    sys.exit(1)


with tempfile.TemporaryDirectory() as tmp:
    tmp = Path(tmp)
    msh = tmp / "brick4.msh"
    p = subprocess.run([binary, "mesh", "brick", "--n", "4", "-o", str(msh)], capture_output=True, text=True)
    if p.returncode != 0 or not msh.exists():
        fail(f"mesh brick: {p.returncode} {p.stderr}")
    out = tmp / "run"
    p = subprocess.run([binary, "solve", str(scene), "--mesh", str(msh), "--out", str(out)], capture_output=True, text=True)
    if p.returncode != 0:
        fail(f"solve exit {p.returncode}: {p.stderr}")
    progress = [l for l in p.stdout.splitlines() if l.startswith("k=")]
    if len(progress) < 5:
        fail(f"expected one progress line per fixed-point step, got {len(progress)}")
    s = json.loads((out / "summary.json").read_text())
    for key in ["n_primal", "n_dual", "n_contact_nodes", "n_cells", "fixed_point_iterations", "n_mult", "converged",
                "err_history", "wn_plus_L2", "wn_plus_inf", "time_s", "kkt", "scene"]:
        if key not in s:
            fail(f"summary.json lacks {key}")
    for stage in ["total", "mesh", "assembly", "factorization", "dual"]:
        if stage not in s["time_s"]:
            fail(f"time_s lacks {stage}")
    expected_settings = {"qp": "auto", "qp_scaling": "jacobi", "qp_precision": "auto", "fixed_point": "accelerated",
                         "schur": "auto", "qp_rtol": 1e-6, "fixed_point_tol": 1e-4}
    if any(s.get("settings", {}).get(k) != v for k, v in expected_settings.items()):
        fail(f"summary.json settings are not the resolved defaults: {s.get('settings')}")
    # The law as solved, with every parameter (a scene that gives law = "ramp" alone gets (6.1)'s, which
    # summary.json did not say; the paper's brick gives them all).
    # How the run was started, enough to start it again from its folder alone.
    run = s.get("run", {})
    if run.get("scene_file") != os.path.abspath(scene) or run.get("mesh_override") != os.path.abspath(msh) or \
            not run.get("contact3d_version") or run.get("overrides") != [] or not run.get("working_directory"):
        fail(f"summary.json run: {run}")
    if s.get("friction_law") != {"kind": "ramp", "high": 0.3, "low": 0.2, "t0": 1e-5, "param": 6e4}:
        fail(f"summary.json friction_law: {s.get('friction_law')}")
    if (s["n_primal"], s["n_dual"], s["n_cells"], s["n_contact_nodes"]) != (900, 36, 12, 60):
        fail(f"sizes {s['n_primal']} {s['n_dual']} {s['n_cells']} {s['n_contact_nodes']}")
    if not s["converged"] or len(s["err_history"]) != s["fixed_point_iterations"] or len(progress) != len(s["err_history"]):
        fail("convergence bookkeeping inconsistent")
    if max(v for v in s["kkt"].values()) > 1e-4:
        fail(f"KKT residuals too large: {s['kkt']}")
    if not {"normal_cellwise", "friction_cellwise"} <= s["kkt"].keys() or \
            not 0 <= s.get("kkt_worst_cell", -1) < s["n_cells"]:
        fail(f"summary.json lacks the cell by cell residuals or names no cell: {s['kkt']}, {s.get('kkt_worst_cell')}")
    with open(out / "contact_nodes.csv") as f:
        rows = list(csv.DictReader(f))
    if list(rows[0].keys())[:10] != "node,x,y,z,u1,u2,u3,wn,wt_norm,F".split(","):
        fail(f"contact_nodes.csv columns {list(rows[0].keys())}")
    if len(rows) != 60 or any(not math.isfinite(float(v)) for r in rows for v in r.values()):
        fail("contact_nodes.csv rows")
    for r in rows:
        if abs(float(r["wn"]) + float(r["u3"])) > 1e-15 or abs(float(r["z"])) > 1e-12:
            fail("wn must equal -u3 on z = 0")
    with open(out / "contact_cells.csv") as f:
        cells = list(csv.DictReader(f))
    if list(cells[0].keys()) != "cell,xmin,xmax,ymin,ymax,area,lambda_n,lambda_t1,lambda_t2,radius".split(","):
        fail("contact_cells.csv columns")
    if abs(sum(float(c["area"]) for c in cells) - 3.0) > 1e-12:
        fail("cell areas must add up to |Γc| = 3")
    with open(out / "history.csv") as f:
        if len(list(csv.DictReader(f))) != s["fixed_point_iterations"]:
            fail("history.csv rows")
    for name in ["body.vtu", "contact.vtu"]:
        if not (out / name).exists():
            fail(f"{name} missing")
    print("1 passed, 0 failed")
