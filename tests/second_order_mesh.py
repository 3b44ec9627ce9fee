#!/usr/bin/env python3
"""A second-order gmsh mesh (gmsh -order 2: 10-node tetrahedra, 6-node triangles) goes straight in:
read by its corner nodes it is the P1 mesh gmsh makes at order 1 on the same vertices, so the solve
on it equals the solve on that mesh (u on Γc, contact force), in MSH 4.1 and 2.2, and the run says
how it read the mesh."""
import csv
import json
import subprocess
import sys
import tempfile
from pathlib import Path

binary, root = sys.argv[1], Path(sys.argv[2])
scene = root / "pipeline" / "scenes" / "lblock.toml"
geo = root / "geo" / "lblock.geo"


def fail(msg):
    print("FAIL:", msg)
    sys.exit(1)


def solve(mesh, out):
    p = subprocess.run([binary, "solve", str(scene), "--mesh", str(mesh), "--out", str(out),
                        "--set", 'output.steps="final"'], capture_output=True, text=True)
    if p.returncode != 0:
        fail(f"solve on {mesh.name}: exit {p.returncode}: {p.stderr[-400:]}")
    with open(out / "contact_nodes.csv") as f:
        # keyed by position: gmsh numbers the nodes of an order-2 mesh otherwise
        u = {tuple(round(float(r[k]), 9) for k in ("x", "y", "z")): [float(r[k]) for k in ("u1", "u2", "u3")]
             for r in csv.DictReader(f)}
    return p.stdout, json.loads((out / "summary.json").read_text()), u


with tempfile.TemporaryDirectory() as tmp:
    tmp = Path(tmp)
    meshes = {}
    for name, args in {"order1": ["-order", "1"], "order2": ["-order", "2"],
                       "order2_msh22": ["-order", "2", "-format", "msh22"]}.items():
        meshes[name] = tmp / f"{name}.msh"
        p = subprocess.run(["gmsh", "-3", "-setnumber", "h", "0.1", *args, str(geo), "-o", str(meshes[name])],
                           capture_output=True, text=True)
        if p.returncode != 0:
            fail(f"gmsh {' '.join(args)}: {p.stderr[-300:]}")
    log1, s1, u1 = solve(meshes["order1"], tmp / "run1")
    if "corner nodes" in log1 or "corner nodes" in s1["mesh"]:
        fail("a first-order mesh is reported as read by its corner nodes")
    for name in ("order2", "order2_msh22"):
        log2, s2, u2 = solve(meshes[name], tmp / name)
        if "second-order elements read by their corner nodes" not in log2 or "corner nodes" not in s2["mesh"] or \
                not any("second-order elements read by their corner nodes" in n for n in s2.get("notes", [])):
            fail(f"{name}: the run does not say it read second-order elements by their corners")
        if s2["n_nodes"] != s1["n_nodes"] or s2["n_tets"] != s1["n_tets"] or u2.keys() != u1.keys():
            fail(f"{name}: {s2['n_nodes']} nodes, {s2['n_tets']} tets, {len(u2)} on Γc; order 1: "
                 f"{s1['n_nodes']}, {s1['n_tets']}, {len(u1)}")
        scale = max(abs(x) for v in u1.values() for x in v)
        worst = max(abs(a - b) for k in u1 for a, b in zip(u1[k], u2[k]))
        if worst > 1e-9 * scale:
            fail(f"{name}: u on Γc differs from order 1 by {worst:.3g} (max |u| {scale:.3g})")
        f1, f2 = s1["contact_force"]["normal"], s2["contact_force"]["normal"]
        if abs(f1 - f2) > 1e-9 * abs(f1):
            fail(f"{name}: normal force {f2} against {f1}")
        print(f"ok: {name}: {s2['n_nodes']} corner nodes, u on Γc as at order 1 to {worst / scale:.1e}, "
              f"normal force {f2:.6g} N")
