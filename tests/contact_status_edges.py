#!/usr/bin/env python3
"""The node status at the edge of a pressed zone (pipeline/scenes/filleted_block.toml): the flat sole
meets the fillets, whose cells stay open, so a node on the sole's edge lies half (a corner node three
quarters) in open cells while the sole's pressure peak sits there. contact_nodes.csv must call such a
node in contact, not "separated" at its pressure: status 0 exactly where the pressure is (almost) 0.
usage: contact_status_edges.py CONTACT3D SOURCE_DIR
"""
import csv
import subprocess
import sys
import tempfile
from pathlib import Path

binary, root = sys.argv[1], Path(sys.argv[2])
with tempfile.TemporaryDirectory() as tmp:
    p = subprocess.run([binary, "solve", str(root / "pipeline" / "scenes" / "filleted_block.toml"), "--quiet",
                        "--out", tmp], capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"FAIL: solve exited {p.returncode}: {p.stderr}")
    nodes = list(csv.DictReader(open(Path(tmp) / "contact_nodes.csv")))
p_max = max(float(r["pressure"]) for r in nodes)
wrong = [r for r in nodes if (r["status"] == "0") != (float(r["pressure"]) <= 1e-6 * p_max)]
z_sole = min(float(r["z"]) for r in nodes)
sole = [r for r in nodes if abs(float(r["z"]) - z_sole) < 1e-9]
xs = sorted({float(r["x"]) for r in sole})
edge = [r for r in sole if float(r["x"]) in (xs[0], xs[-1])]  # the sole's two edges along y
open_edge = [r for r in edge if r["status"] == "0"]
for r in wrong[:10]:
    print(f"FAIL: node {r['node']} at ({r['x']}, {r['y']}, {r['z']}) status {r['status']}, pressure {r['pressure']}")
if open_edge:
    print(f"FAIL: {len(open_edge)} of {len(edge)} nodes on the sole's edges called separated")
if wrong or open_edge or not edge:
    sys.exit(1)
print(f"ok: {len(nodes)} contact nodes, status 0 exactly where the pressure is below 1e-6 of its peak "
      f"({p_max:.3g} Pa); all {len(edge)} nodes on the sole's edges in contact")
