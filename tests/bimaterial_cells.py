#!/usr/bin/env python3
"""Where two materials meet on Γc no cell averages over both (contact/partition.hpp): the scene
pipeline/scenes/bimaterial.toml, rubber (E = 1e7 Pa) beside steel (2.1e11 Pa), pushed down 100 µm
with Coulomb F = 0.4. A cell across their interface let the steel sink and the rubber lift with the
cell's mean gap 0: at h = 3 mm the contact nodes' normal displacement ranged from −18 µm (into the
foundation) to +45 µm. With the cells split by material it stays within 7.6 µm; this test asks for
less than 15 µm (15% of the push) on every contact node, balanced forces and a converged solve.

    bimaterial_cells.py <contact3d> <repo root> [h]
"""
import csv
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "pipeline"))
from c3d.run import solve, summary  # noqa: E402

binary, root = sys.argv[1], Path(sys.argv[2])
h = sys.argv[3] if len(sys.argv) > 3 else "0.003"
scene = root / "pipeline" / "scenes" / "bimaterial.toml"
PUSH = 1e-4  # m, the scene's prescribed z on the top face


def fail(msg):
    print("FAIL:", msg)
    sys.exit(1)


with tempfile.TemporaryDirectory() as tmp:
    proc, _ = solve(binary, scene, tmp, [f"mesh.parameters.h={h}"])
    if proc.returncode != 0:
        fail(f"contact3d exited with {proc.returncode}: {proc.stderr[-2000:]}")
    s = summary(tmp)
    if s.get("status") != "converged":
        fail(f"status {s.get('status')}")
    if s.get("contact_regions") != 2:
        fail(f"summary.json's contact_regions is {s.get('contact_regions')}, expected 2 (steel, rubber)")
    if not s["forces"]["balance"] < 1e-8:
        fail(f"forces do not balance: {s['forces']['balance']}")
    with open(Path(tmp) / "contact_nodes.csv") as f:
        u3 = [float(r["u3"]) for r in csv.DictReader(f)]
    worst = max(abs(x) for x in u3)
    print(f"h = {h}: {len(u3)} contact nodes, u3 from {min(u3):.3g} to {max(u3):.3g} m (push {PUSH:g} m)")
    if not worst < 0.15 * PUSH:
        fail(f"a contact node moves {worst:.3g} m along the normal, more than 15% of the push {PUSH:g} m: "
             "a cell spans the two materials")
print("ok")
