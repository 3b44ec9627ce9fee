#!/usr/bin/env python3
"""Rotation: the paper's brick turned and moved together with its foundation plane and its loads
gives the paper's solution turned, through the whole command line (scene keys contact.plane_point
and contact.plane_normal, the writers' plane-frame fields).

The gmsh mesh of the brick (n) is turned by Q (0.6 rad about (1, 1, 0)/sqrt 2, the smallest rotation
taking e_z to the new normal, so the plane's frame undoes it exactly) and moved by c, node by node in
the MSH 2.2 text; the scene's traction vectors are turned by Q. Checks, node by node (same tags):
u_turned = Q u, and wn, wt_norm, pressure equal; the contact force (normal, t1, t2) equal; the
resultant contact force turned by Q. Exit 0 when all hold to 1e-6 relative, 1 when not, 2 on failure.

With `affine`, the loads and the clamp vary in space: the clamp is a prescribed displacement
u(x) = v + Gx (a small tilt, boundary.displacement's gradient), the end's traction gets a gradient and
the free side a pressure rising with height (boundary.pressure's gradient). Turned, such a field
f(x) = v + Gx reads f'(x') = Q(v − GQᵀc) + QGQᵀx' at x' = Qx + c (a pressure: p₀ − (Qg)·c + (Qg)·x').

Usage: rotated_brick.py BIN SOURCE_DIR [n] [affine]
"""
import csv
import math
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "pipeline"))
from c3d.run import solve, summary  # noqa: E402

binary, source = sys.argv[1], Path(sys.argv[2])
n = int(sys.argv[3]) if len(sys.argv) > 3 else 4
affine = len(sys.argv) > 4 and sys.argv[4] == "affine"
axis = np.array([1.0, 1.0, 0.0]) / math.sqrt(2.0)
angle = 0.6
K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
Q = np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K
shift = np.array([0.3, -0.2, 0.5])
tight = ["solver.qp_rtol=1e-10", "solver.fixed_point_tol=1e-8"]


def fail(msg, code=1):
    print(f"ROTATION FAILED: {msg}")
    sys.exit(code)


def turn_msh2(text):
    """The MSH 2.2 ASCII text with every node x replaced by Q x + c."""
    lines = text.splitlines()
    start = lines.index("$Nodes")
    count = int(lines[start + 1])
    for k in range(start + 2, start + 2 + count):
        tag, *xyz = lines[k].split()
        x = Q @ np.array([float(v) for v in xyz]) + shift
        lines[k] = f"{tag} {x[0]:.17g} {x[1]:.17g} {x[2]:.17g}"
    return "\n".join(lines) + "\n"


def vec(v):
    return "[" + ", ".join(f"{x:.17g}" for x in v) + "]"


def mat(m):
    return "[" + ", ".join(vec(r) for r in m) + "]"


# The affine conditions, flat: a clamp tilted by 1e-6 rad about y and lowered along the end's height,
# a traction on the end growing along z, a pressure on the free side growing with height.
TILT = (np.zeros(3), np.array([[0.0, 0.0, 1e-6], [0.0, 0.0, 0.0], [0.0, -2e-6, 0.0]]))
END_TRACTION = (np.array([1e7, 0.0, 2e7]), np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 4e6], [0.0, 0.0, -1e7]]))
SIDE_PRESSURE = (1e6, np.array([0.0, 0.0, 3e6]))


def affine_blocks(turn):
    """The scene's affine conditions, in the flat frame or turned by (Q, shift)."""
    def field(v, G):
        return (Q @ (v - G @ Q.T @ shift), Q @ G @ Q.T) if turn else (v, G)
    (dv, dG), (tv, tG) = field(*TILT), field(*END_TRACTION)
    p0, g = SIDE_PRESSURE
    if turn:
        p0, g = p0 - (Q @ g) @ shift, Q @ g
    return (f"[[boundary.displacement]]\ngroup = \"clamped\"\nx = {dv[0]:.17g}\ny = {dv[1]:.17g}\nz = {dv[2]:.17g}\n"
            f"gradient = {mat(dG)}\n\n"
            f"[[boundary.traction]]\ngroup = \"load_end\"\nvalue = {vec(tv)}\ngradient = {mat(tG)}\n\n"
            f"[[boundary.pressure]]\ngroup = \"free\"\nvalue = {p0:.17g}\ngradient = {vec(g)}\n\n")


def affine_scene(text, turn):
    """The paper's scene with its clamp and end traction replaced by the affine conditions."""
    for old in ('clamped = ["clamped"]', "[[boundary.traction]]            # Γp¹, Pa\ngroup = \"load_end\"\n"
                                          "value = [1e7, 0.0, 2e7]\n"):
        if old not in text:
            fail(f"paper_brick.toml no longer has '{old}'", 2)
    text = text.replace('clamped = ["clamped"]', "clamped = []")
    text = text.replace("[[boundary.traction]]            # Γp¹, Pa\ngroup = \"load_end\"\nvalue = [1e7, 0.0, 2e7]\n", "")
    return text.replace("[friction]\n", affine_blocks(turn) + "[friction]\n", 1)


def turned_scene(text):
    if affine:
        return turned_plane(turned_vector(text, "value = [0.0, 0.0, -3e7]"))
    return turned_plane(turned_vector(turned_vector(text, "value = [1e7, 0.0, 2e7]"), "value = [0.0, 0.0, -3e7]"))


def turned_vector(text, old):
    if old not in text:
        fail(f"paper_brick.toml no longer has '{old}'", 2)
    v = Q @ np.array([float(s) for s in old.split("[")[1].rstrip("]").split(",")])
    return text.replace(old, f"value = [{v[0]:.17g}, {v[1]:.17g}, {v[2]:.17g}]")


def turned_plane(text):
    normal = Q @ np.array([0.0, 0.0, 1.0])
    plane = (f"plane_point = [{shift[0]:.17g}, {shift[1]:.17g}, {shift[2]:.17g}]\n"
             f"plane_normal = [{normal[0]:.17g}, {normal[1]:.17g}, {normal[2]:.17g}]\n")
    return text.replace("[contact]\n", "[contact]\n" + plane, 1)


def nodes(out):
    with open(Path(out) / "contact_nodes.csv") as f:
        return {r["node"]: r for r in csv.DictReader(f)}


with tempfile.TemporaryDirectory() as tmp:
    tmp = Path(tmp)
    flat = tmp / "brick.msh"
    subprocess.run(["gmsh", "-3", "-setnumber", "n", str(n), str(source / "geo" / "brick.geo"), "-format", "msh2",
                    "-o", str(flat)], check=True, capture_output=True)
    turned = tmp / "turned.msh"
    turned.write_text(turn_msh2(flat.read_text()))
    scene_text = (source / "pipeline" / "scenes" / "paper_brick.toml").read_text()
    (tmp / "flat.toml").write_text(affine_scene(scene_text, False) if affine else scene_text)
    (tmp / "turned.toml").write_text(turned_scene(affine_scene(scene_text, True) if affine else scene_text))
    for name, msh in (("flat", flat), ("turned", turned)):
        proc, _ = solve(binary, tmp / f"{name}.toml", tmp / name, tight, mesh=msh)
        if proc.returncode != 0:
            fail(f"{name}: exit {proc.returncode}: {proc.stderr}", 2)
    a, b = nodes(tmp / "flat"), nodes(tmp / "turned")
    if set(a) != set(b):
        fail("the two runs have different contact nodes")
    scale = max(abs(float(r[k])) for r in a.values() for k in ("u1", "u2", "u3"))
    worst = 0.0
    for tag, r in a.items():
        u = np.array([float(r[k]) for k in ("u1", "u2", "u3")])
        v = np.array([float(b[tag][k]) for k in ("u1", "u2", "u3")])
        worst = max(worst, float(np.abs(v - Q @ u).max()))
        for k in ("wn", "wt_norm"):
            worst = max(worst, abs(float(r[k]) - float(b[tag][k])))
    if worst > 1e-6 * scale:
        fail(f"u_turned differs from Q u (or wn, wt_norm differ) by {worst:.3g} (max |u| {scale:.3g})")
    sa, sb = summary(tmp / "flat"), summary(tmp / "turned")
    fa, fb = sa["contact_force"], sb["contact_force"]
    fscale = max(abs(fa[k]) for k in ("normal", "t1", "t2"))
    if max(abs(fa[k] - fb[k]) for k in ("normal", "t1", "t2")) > 1e-6 * fscale:
        fail(f"contact force (plane frame): flat {fa} turned {fb}")
    ca, cb = np.array(sa["forces"]["contact"]), np.array(sb["forces"]["contact"])
    if np.abs(cb - Q @ ca).max() > 1e-6 * np.abs(ca).max():
        fail(f"resultant contact force: turned {cb}, Q x flat {Q @ ca}")
    ha, hb = np.array(sa["forces"]["contact_at_held_nodes"]), np.array(sb["forces"]["contact_at_held_nodes"])
    if np.abs(ha).max() <= 1e-4 * np.abs(ca).max() or np.abs(hb - Q @ ha).max() > 1e-6 * np.abs(ca).max():
        fail(f"contact force at the clamp's nodes on Gc: turned {hb}, Q x flat {Q @ ha} (it must not vanish)")
    if sa["fixed_point_iterations"] != sb["fixed_point_iterations"]:
        fail(f"steps: flat {sa['fixed_point_iterations']}, turned {sb['fixed_point_iterations']}")
    print(f"ok: n={n}: turned brick = Q x paper brick to {worst / scale:.2g} (u, wn, wt on Gc); contact force "
          f"{fb['normal']:.6g} N normal in both; {sb['fixed_point_iterations']} steps each")
