#!/usr/bin/env python3
"""A body held by contact alone that starts above the foundation: the loads bring it down, and the
solve says so. The free brick (pipeline/scenes/free_brick.toml, n = 4) with the plane 1 mm lower
(contact.plane_point) must give the displacement of the brick standing on the plane less 1 mm along z
at every contact node, and a note naming the 1 mm start; the brick on the plane gets no such note."""
import csv
import json
import os
import subprocess
import sys
import tempfile

binary, source = sys.argv[1], sys.argv[2]
scene = os.path.join(source, "pipeline", "scenes", "free_brick.toml")
GAP = 1e-3


def solve(out, *extra):
    cmd = [binary, "solve", scene, "--quiet", "--out", out, "--set", "mesh.parameters.n=4", *extra]
    run = subprocess.run(cmd, capture_output=True, text=True)
    if run.returncode != 0:
        sys.exit(f"FAIL: {' '.join(cmd)} exited {run.returncode}: {run.stderr}")
    notes = json.load(open(os.path.join(out, "summary.json")))["notes"]
    with open(os.path.join(out, "contact_nodes.csv")) as fh:
        nodes = {int(r["node"]): [float(r[k]) for k in ("u1", "u2", "u3")] for r in csv.DictReader(fh)}
    return notes, nodes


with tempfile.TemporaryDirectory() as tmp:
    on_notes, on_plane = solve(os.path.join(tmp, "on"))
    up_notes, above = solve(os.path.join(tmp, "up"), "--set", f"contact.plane_point=[0.0, 0.0, {-GAP}]")

said = [n for n in up_notes if "starts 0.001 above the foundation plane" in n]
if not said:
    sys.exit(f"FAIL: no note of the 1 mm start: {up_notes}")
if any("above the foundation plane at its lowest node" in n for n in on_notes):
    sys.exit("FAIL: the brick on the plane was said to start above it")
if sorted(on_plane) != sorted(above):
    sys.exit("FAIL: different contact nodes")
scale = max(max(abs(c) for c in u[:2]) for u in on_plane.values())
worst = 0.0
for node, u in on_plane.items():
    v = above[node]
    worst = max(worst, abs(v[0] - u[0]), abs(v[1] - u[1]), abs(v[2] - (u[2] - GAP)))
if worst > 1e-6 * max(scale, GAP):
    sys.exit(f"FAIL: the displacement is not the standing brick's less 1 mm along z: {worst:.3e} off")
print(f"ok: note given ({said[0][:60]}...), displacement = standing brick's − 1 mm to {worst:.1e}")
