#!/usr/bin/env python3
"""Bodies held by contact alone whose contact zone spans few cells, with the default cells.

1. A soft ball (R = 0.5 m, E = 1e8 Pa, meshed uniformly at h = 0.04, nothing prescribed, its weight
   and a pressure on its upper part, F = 0.3): with cells of 2h it rests on two cells, which cannot
   balance the loads' moments, and is refused (exit 2, "rests on"); contact.cell_size = "auto" (the
   default) must then solve it again with cells of 1.5h and give that answer (exit 0, summary.json's
   partition_refinement says the 2h cells were refused), the contact force balancing the load.
2. A half-cylinder (geo/roller.geo, h = 0.04) on its curved side, pressed by 2e7 Pa on its flat top,
   its ends held along the axis only, frictionless, cells of 1.5h: nothing in the frictionless dual
   acts along the lateral slide, whose loads balance by themselves. The equalities' loop jumped along
   that slide by 1e11-1e14 times the body's size and the run was refused (before that, reported
   "converged" with an equilibrium residual of 18). It must converge with the equilibrium to 1e-8,
   the normal force equal to the pressure times the top's area (1e-6), and the same displacement with
   one BLAS thread and with two (1e-6), of the body's scale: its strip is narrower than a cell, so
   the cells hold its roll weakly and it turns by 0.04 rad (2.3 cm on Γc), with the warning that
   the contact zone is not resolved.

3. The paper's brick (n = 4), frictionless, its top moved down by 1e-5 m (z only), nothing else
   prescribed: every free motion (the slides, the turn about the normal) lies in the plane and the
   loads along them are rounding. Refused before ("100% of them left unbalanced"); it must converge.
4. The same brick with Tresca's friction (g = 1e6) and with Coulomb's: friction alone holds those
   motions, their loads still rounding. Refused before ("more than the contact's friction carries",
   the equalities' residual measured against the loads' own size); it must converge, the equilibrium
   to 1e-8 and the total friction force below 1e-9 of the normal one.

5. A steel bar 500 x 10 x 40 mm standing free on its 10 mm face (gmsh, h = 5 mm: two elements across),
   1 MPa on top, Coulomb F = 0.3: cells of 2h lie in one row, whose forces hold no turn about it, and the
   run was refused as friction overloaded although nothing loads it sideways; the refusal must name the
   row (exit 2, "one cell wide"), and the default cells must solve it with cells of 1.5h (exit 0), the
   normal force the load (5000 N) to 1e-6.

6. The brick of item 3, frictionless, on one cell over its whole contact face (contact.cell_size = 10 m):
   its top moved down 1e-5 m and no load: the prescribed top holds the lift and the tilts, and the free
   slides and turn lie in the plane, so one cell is enough; the normal force is E A δ / H to 1e-6. Refused before as resting "on 1 of the 1 cells ... too few to balance the loads'
   moments"; it must converge (with the one-cell warning), the equilibrium to 1e-8.

Usage: held_by_contact_cells.py BIN SOURCE_DIR WORK_DIR
Exit 0 when all hold, 1 when one does not.
"""
import csv
import json
import math
import os
import subprocess
import sys

from bad_inputs import SPHERE_GEO


def solve(binary, scene, out, sets=(), threads=None):
    env = dict(os.environ)
    if threads:
        env["OPENBLAS_NUM_THREADS"] = str(threads)
    cmd = [binary, "solve", scene, "--out", out, "--quiet"] + [a for s in sets for a in ("--set", s)]
    p = subprocess.run(cmd, capture_output=True, text=True, env=env)
    summary = json.load(open(os.path.join(out, "summary.json"))) if p.returncode == 0 else None
    return p.returncode, p.stderr, summary


def refused_on_2h_then_solved(binary, work, name, geo, scene_text, refusal, fails):
    """Writes NAME.geo and NAME.toml; the scene with cells of 2h must be refused (exit 2, `refusal` in
    the message) and with the default cells solved (exit 0). Returns the default run's summary or None."""
    with open(os.path.join(work, name + ".geo"), "w") as f:
        f.write(geo)
    scene = os.path.join(work, name + ".toml")
    with open(scene, "w") as f:
        f.write(scene_text)
    code, err, _ = solve(binary, scene, os.path.join(work, name + "_2h"), ['contact.cell_size="2h"'])
    if code != 2 or refusal not in err:
        fails.append(f"{name}, cells of 2h: exit {code}, expected the refusal (exit 2, {refusal!r}): {err[-300:]}")
    code, err, s = solve(binary, scene, os.path.join(work, name + "_auto"))
    if code != 0:
        fails.append(f"{name}, cells auto: exit {code}: {err[-400:]}")
        return None
    refinement = s.get("partition_refinement") or {}
    if not refinement.get("kept_finer") or "cells of 2h were refused" not in refinement.get("outcome", ""):
        fails.append(f"{name}, cells auto: partition_refinement {refinement}")
    return s


def ball(binary, work, fails):
    s = refused_on_2h_then_solved(
        binary, work, "ball", SPHERE_GEO,
        '[mesh]\ngeo = "ball.geo"\n[material]\nyoung = 1e8\npoisson = 0.3\nbody_force = [0.0, 0.0, -7.7e4]\n'
        '[boundary]\nclamped = []\ncontact = ["contact"]\n[[boundary.pressure]]\ngroup = "upper"\nvalue = 1e5\n'
        '[friction]\nslip_bound = 1e6\nlaw = "constant"\nvalue = 0.3\n', "rests on", fails)
    if s is None:
        return
    refinement = s.get("partition_refinement") or {}
    applied, contact = s["forces"]["applied"], s["forces"]["contact"]
    imbalance = math.dist(applied, [-c for c in contact]) / math.hypot(*applied)
    print(f"ball, cells auto: {refinement.get('outcome', '')[-60:]}; contact force balances the load to "
          f"{imbalance:.1e}, equilibrium {s['kkt']['equilibrium']:.1e}")
    if s["kkt"]["equilibrium"] > 1e-8 or imbalance > 1e-8:
        fails.append(f"ball, cells auto: equilibrium residual {s['kkt']['equilibrium']:.1e}, load imbalance "
                     f"{imbalance:.1e}")


BAR_GEO = """SetFactory("OpenCASCADE");
DefineConstant[ h = 0.005 ];
Box(1) = {0, 0, 0, 0.5, 0.01, 0.04};
Mesh.MeshSizeMax = h;
e = 1e-6;
Physical Surface("contact") = Surface In BoundingBox{-e, -e, -e, 1, 1, e};
Physical Surface("top") = Surface In BoundingBox{-e, -e, 0.04 - e, 1, 1, 0.04 + e};
Physical Volume("body") = {1};
"""


def bar_on_narrow_face(binary, work, fails):
    s = refused_on_2h_then_solved(
        binary, work, "bar", BAR_GEO,
        '[mesh]\ngeo = "bar.geo"\n[material]\nyoung = 2.1e11\npoisson = 0.3\n[boundary]\nclamped = []\n'
        'contact = ["contact"]\n[[boundary.pressure]]\ngroup = "top"\nvalue = 1e6\n[friction]\n'
        'model = "coulomb"\nlaw = "constant"\nvalue = 0.3\n', "one cell wide", fails)
    if s is None:
        return
    refinement = s.get("partition_refinement") or {}
    normal, load = s["contact_force"]["normal"], 1e6 * 0.5 * 0.01
    print(f"bar, cells auto: {refinement.get('outcome', '')[-60:]}; normal force {normal:.9g} N (load {load:g}), "
          f"equilibrium {s['kkt']['equilibrium']:.1e}")
    if abs(normal - load) > 1e-6 * load or s["kkt"]["equilibrium"] > 1e-8:
        fails.append(f"bar, cells auto: normal force {normal} against {load}, equilibrium {s['kkt']['equilibrium']}")


def roller(binary, source, work, fails):
    scene = os.path.join(work, "roller.toml")
    with open(scene, "w") as f:
        f.write('[mesh]\ngeo = "' + os.path.join(source, "geo", "roller.geo") + '"\nparameters = { h = 0.04 }\n'
                '[material]\nyoung = 7e10\npoisson = 0.33\n[boundary]\nclamped = []\ncontact = ["contact"]\n'
                '[[boundary.displacement]]\ngroup = "ends"\nx = 0.0\n[[boundary.pressure]]\ngroup = "top"\n'
                'value = 2e7\n[friction]\nlaw = "none"\n[contact]\ncell_size = "1.5h"\n')
    load = 2e7 * 0.8 * 1.0  # the pressure on the flat top, L = 0.8 by 2R = 1
    answers = []
    for threads in (1, 2):
        code, err, s = solve(binary, scene, os.path.join(work, f"roller_{threads}"), threads=threads)
        label = f"roller, {threads} BLAS thread(s)"
        if code != 0:
            fails.append(f"{label}: exit {code}: {err[-400:]}")
            continue
        normal, eq = s["contact_force"]["normal"], s["kkt"]["equilibrium"]
        with open(os.path.join(work, f"roller_{threads}", "contact_nodes.csv")) as f:
            u_max = max(math.hypot(float(r["u1"]), float(r["u2"]), float(r["u3"])) for r in csv.DictReader(f))
        print(f"{label}: {s['status']}, normal force {normal:.9g} N (load {load:.9g}), equilibrium {eq:.1e}, "
              f"largest |u| on Γc {u_max:.3g} m")
        if s["status"] != "converged" or eq > 1e-8:
            fails.append(f"{label}: {s['status']}, equilibrium residual {eq:.1e}")
        if abs(normal - load) > 1e-6 * load:
            fails.append(f"{label}: normal force {normal} against {load}")
        if not u_max < 0.1:  # the pressed strip is narrower than a cell: the body rolls by 0.04 rad on it
            fails.append(f"{label}: largest displacement {u_max} m on a body of 1 m")
        answers.append(u_max)
    if len(answers) == 2 and abs(answers[0] - answers[1]) > 1e-6 * answers[0]:
        fails.append(f"roller: largest displacement {answers[0]} with one BLAS thread, {answers[1]} with two")


def brick_sliding_free(binary, source, work, fails):
    """Items 3 and 4: the brick with its top moved down and nothing else prescribed, frictionless, with
    Tresca's friction and with Coulomb's. Each must converge, the equilibrium to 1e-8 and the total
    friction force below 1e-9 of the normal one (the loads along the slides are rounding)."""
    scene = os.path.join(source, "pipeline", "scenes", "paper_brick.toml")
    free = ["mesh.parameters.n=4", "boundary.clamped=[]", 'boundary.displacement=[{group="load_top", z=-1e-5}]',
            'boundary.traction=[{group="load_end", value=[0.0, 0.0, 2e7]}]']
    for label, friction in (("frictionless", ["friction.slip_bound=0"]),
                            ("tresca", ["friction.slip_bound=1e6"]),
                            ("coulomb", ["friction.slip_bound=0", 'friction.model="coulomb"'])):
        code, err, s = solve(binary, scene, os.path.join(work, "brick_" + label), free + friction)
        if code != 0:
            fails.append(f"brick free to slide, {label}: exit {code}: {err[-400:]}")
            continue
        contact = s["forces"]["contact"]
        normal, tangential = contact[2], math.hypot(contact[0], contact[1])
        print(f"brick free to slide, {label}: {s['status']}, equilibrium {s['kkt']['equilibrium']:.1e}, "
              f"friction force {tangential:.1e} N against {normal:.2e} N")
        if s["status"] != "converged" or s["kkt"]["equilibrium"] > 1e-8 or not tangential <= 1e-9 * normal:
            fails.append(f"brick free to slide, {label}: {s['status']}, equilibrium {s['kkt']['equilibrium']:.1e}, "
                         f"friction force {tangential:.1e} of {normal:.2e}")


def brick_on_one_cell(binary, source, work, fails):
    """Item 6: one cell, the lift and tilts prescribed; only in-plane motions are free."""
    scene = os.path.join(source, "pipeline", "scenes", "paper_brick.toml")
    sets = ["mesh.parameters.n=4", "boundary.clamped=[]", 'boundary.displacement=[{group="load_top", z=-1e-5}]',
            "boundary.traction=[]", "friction.slip_bound=0", "contact.cell_size=10.0"]
    code, err, s = solve(binary, scene, os.path.join(work, "brick_one_cell"), sets)
    if code != 0:
        fails.append(f"brick on one cell: exit {code}: {err[-400:]}")
        return
    one_cell = any("one cell of H" in w for w in s["warnings"])
    print(f"brick on one cell: {s['status']}, equilibrium {s['kkt']['equilibrium']:.1e}, "
          f"normal force {s['contact_force']['normal']:.6g} N, one-cell warning {one_cell}")
    uniaxial = 21.19e10 * 3.0 * 1e-5 / 1.0  # E A δ / H: the brick 3 x 1 x 1 squeezed 1e-5, free to widen
    if abs(s["contact_force"]["normal"] - uniaxial) > 1e-6 * uniaxial:
        fails.append(f"brick on one cell: normal force {s['contact_force']['normal']} N, E A delta / H {uniaxial} N")
    if s["status"] != "converged" or s["kkt"]["equilibrium"] > 1e-8 or not one_cell:
        fails.append(f"brick on one cell: {s['status']}, equilibrium {s['kkt']['equilibrium']:.1e}, "
                     f"one-cell warning {one_cell}")


def main():
    binary, source, work = sys.argv[1], os.path.abspath(sys.argv[2]), sys.argv[3]
    os.makedirs(work, exist_ok=True)
    fails = []
    ball(binary, work, fails)
    roller(binary, source, work, fails)
    brick_sliding_free(binary, source, work, fails)
    bar_on_narrow_face(binary, work, fails)
    brick_on_one_cell(binary, source, work, fails)
    for f in fails:
        print("FAIL:", f)
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
