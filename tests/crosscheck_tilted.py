#!/usr/bin/env python3
"""The cross-check with a moved foundation plane: the twisted puck (pipeline/scenes/twisted_puck.toml)
turned by Q (0.6 rad about (1, 1, 0)/√2) and moved by c, node by node in its MSH 2.2 text, with its
plane, its prescribed displacement, pressure and traction turned and moved alike (a field f(x) = v + Gx
becomes Q(v − GQᵀc) + QGQᵀx, a pressure p₀ + g·x becomes p₀ − (Qg)·c + (Qg)·x). contact3d solves that
scene as given; pipeline/crosscheck.py moves the body back onto z = 0 for FreeFEM and our answer into
the plane's frame. The other arguments go to crosscheck.py, whose exit code this returns.

Usage: crosscheck_tilted.py BIN SOURCE_DIR WORK_DIR [crosscheck.py options...]
"""
import math
import re
import subprocess
import sys
from pathlib import Path

import numpy as np

binary, source, work = sys.argv[1], Path(sys.argv[2]), Path(sys.argv[3])
extra = sys.argv[4:]
axis = np.array([1.0, 1.0, 0.0]) / math.sqrt(2.0)
angle = 0.6
K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
Q = np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K
c = np.array([0.3, -0.2, 0.5])


def vec(v):
    return "[" + ", ".join(f"{x:.17g}" for x in v) + "]"


def mat(m):
    return "[" + ", ".join(vec(r) for r in m) + "]"


def turned_field(v, G):
    v, G = np.array(v, dtype=float), np.array(G, dtype=float)
    return Q @ (v - G @ Q.T @ c), Q @ G @ Q.T


def turned_scene(text, mesh):
    """twisted_puck.toml turned and moved: each affine condition replaced, the plane added."""
    def replace(pattern, repl):
        nonlocal text
        text, count = re.subn(pattern, repl, text, count=1, flags=re.S)
        if count != 1:
            sys.exit(f"error: twisted_puck.toml no longer matches {pattern!r}")
    dv, dG = turned_field([0.0, 0.0, -2e-6], [[0, -4e-6, 0], [4e-6, 0, 0], [0, 0, 0]])
    replace(r'x = 0\.0\ny = 0\.0\nz = -2e-6\ngradient = \[\[0\.0, -4e-6, 0\.0\], \[4e-6, 0\.0, 0\.0\], \[0\.0, 0\.0, 0\.0\]\]',
            f"x = {dv[0]:.17g}\ny = {dv[1]:.17g}\nz = {dv[2]:.17g}\ngradient = {mat(dG)}")
    g = Q @ np.array([0.0, 0.0, -1e7])
    replace(r"value = 2e6\ngradient = \[0\.0, 0\.0, -1e7\]", f"value = {2e6 - g @ c:.17g}\ngradient = {vec(g)}")
    tv, tG = turned_field([0.0, 1e6, 0.0], [[0, 0, 0], [0, 0, 5e6], [0, 0, 0]])
    replace(r"value = \[0\.0, 1e6, 0\.0\]\ngradient = \[\[0\.0, 0\.0, 0\.0\], \[0\.0, 0\.0, 5e6\], \[0\.0, 0\.0, 0\.0\]\]",
            f"value = {vec(tv)}\ngradient = {mat(tG)}")
    replace(r'\[mesh\]\ngeo = "[^"]*"\nparameters = \{[^}]*\}', f'[mesh]\nfile = "{mesh}"')
    replace(r"\[output\]", f"[contact]\nplane_point = {vec(c)}\nplane_normal = {vec(Q @ [0.0, 0.0, 1.0])}\n\n[output]")
    return text


work.mkdir(parents=True, exist_ok=True)
flat = work / "puck-flat.msh"
subprocess.run(["gmsh", "-3", "-setnumber", "h", "0.05", str(source / "geo" / "puck.geo"), "-format", "msh22",
                "-o", str(flat)], check=True, capture_output=True)
lines = flat.read_text().splitlines()
start = lines.index("$Nodes")
for k in range(start + 2, start + 2 + int(lines[start + 1])):
    tag, *xyz = lines[k].split()
    x = Q @ np.array([float(v) for v in xyz]) + c
    lines[k] = f"{tag} {x[0]:.17g} {x[1]:.17g} {x[2]:.17g}"
turned = work / "puck-turned.msh"
turned.write_text("\n".join(lines) + "\n")
scene = work / "twisted_puck_tilted.toml"
scene.write_text(turned_scene((source / "pipeline" / "scenes" / "twisted_puck.toml").read_text(), turned))
cmd = [sys.executable, str(source / "pipeline" / "crosscheck.py"), "--bin", binary, "--scene", str(scene),
       "--workdir", str(work / "crosscheck"), "--report", str(work / "report.md"), *extra]
sys.exit(subprocess.run(cmd).returncode)
