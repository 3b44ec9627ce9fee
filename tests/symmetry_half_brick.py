#!/usr/bin/env python3
"""Symmetry plane = the missing half (issue 14): the paper brick at even n is mirror symmetric in
y = 0.5 and its loads have no y component, so half of it (geo/paper_brick.edp -width 0.5) with
u_y = 0 on the cut ([[boundary.displacement]], pipeline/scenes/paper_brick_half.toml) must give the
whole brick's displacement on y <= 0.5, half its contact force and clamp reaction, and balanced
resultant forces. Both solve with tight tolerances so the comparison is not blurred by them.

    symmetry_half_brick.py <contact3d> <repo root> [n]
"""
import csv
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "pipeline"))
from c3d.run import solve, summary  # noqa: E402

binary, root = sys.argv[1], Path(sys.argv[2])
n = int(sys.argv[3]) if len(sys.argv) > 3 else 4
scenes = root / "pipeline" / "scenes"
tight = ["solver.fixed_point_tol=1e-9", "solver.qp_rtol=1e-11"]


def fail(msg):
    print("FAIL:", msg)
    sys.exit(1)


def contact_nodes(out):
    with open(Path(out) / "contact_nodes.csv") as f:
        return {(round(float(r["x"]), 9), round(float(r["y"]), 9)): [float(r[k]) for k in ("u1", "u2", "u3")]
                for r in csv.DictReader(f)}


def close(a, b, tol):
    scale = max(max(abs(x) for x in a), max(abs(x) for x in b), 1e-300)
    return max(abs(x - y) for x, y in zip(a, b)) <= tol * scale


with tempfile.TemporaryDirectory() as tmp:
    whole, half = Path(tmp) / "whole", Path(tmp) / "half"
    for scene, out, sets in [("paper_brick_freefem", whole, [f"mesh.parameters.n={n}"]),
                             ("paper_brick_half", half, [f"mesh.parameters.n={n}", f"mesh.parameters.ny={n // 2}"])]:
        proc, _ = solve(binary, scenes / f"{scene}.toml", out, sets + tight)
        if proc.returncode != 0:
            fail(f"{scene}: exit {proc.returncode}: {proc.stderr}")
    a, b = contact_nodes(whole), contact_nodes(half)
    if not b or any(k not in a for k in b) or any(k[1] > 0.5 for k in b):
        fail("the half's contact nodes are not the whole's on y <= 0.5")
    scale = max(abs(c) for u in a.values() for c in u)
    diff = max(abs(p - q) for k in b for p, q in zip(a[k], b[k]))
    if diff > 1e-7 * scale:
        fail(f"half and whole differ on y <= 0.5: max |du| = {diff:.3g}, max |u| = {scale:.3g}")
    sw, sh = summary(whole)["forces"], summary(half)["forces"]
    for s, name in [(sw, "whole"), (sh, "half")]:
        if not s["balance"] < 1e-8:
            fail(f"{name}: forces do not balance: {s['balance']}")
    if not close([x / 2 for x in sw["contact"][::2]], sh["contact"][::2], 1e-6):
        fail(f"contact force x, z: whole {sw['contact']} half {sh['contact']}")
    if not close([x / 2 for x in sw["reactions"][0]["force"][::2]], sh["reactions"][0]["force"][::2], 1e-6):
        fail(f"clamp reaction x, z: whole {sw['reactions'][0]} half {sh['reactions'][0]}")
    aw, ah = summary(whole)["contact_area"], summary(half)["contact_area"]
    if not (close([aw["in_contact"]], [aw["stick"] + aw["slip"]], 1e-12) and aw["in_contact"] > 0
            and close([aw["in_contact"] + aw["separated"]], [3.0], 1e-9)):
        fail(f"whole: contact areas do not add up: {aw}")
    if not close([aw[k] / 2 for k in ("in_contact", "stick", "slip")], [ah[k] for k in ("in_contact", "stick", "slip")], 1e-9):
        fail(f"contact areas: whole {aw} half {ah}")
    whole_summary = summary(whole)
    torque, t1 = whole_summary["friction_torque"], whole_summary["contact_force"]["t1"]
    if not abs(torque) <= 1e-6 * abs(t1) * 1.0:  # mirror-symmetric friction: no moment about the normal (arm ~1 m)
        fail(f"whole: friction torque {torque} N m on a mirror-symmetric solve (friction force {t1} N)")
    print(f"ok: n={n}: half = whole on y <= 0.5 to {diff / scale:.2g}; contact force z {sh['contact'][2]:.6g} N "
          f"(whole {sw['contact'][2]:.6g} N); symmetry-plane reaction {sh['reactions'][1]['force']}")
