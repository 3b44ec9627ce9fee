#!/usr/bin/python3
"""End-to-end check of the ParaView output: solve a small brick, read body.vtu, contact.vtu and
solution.pvd (with meshio / ElementTree) and compare them with the CSV tables and summary.json.

usage: check_vtu.py --bin build/contact3d --scene pipeline/scenes/paper_brick.toml [--n 4]
Exits non-zero with a list of failures.
"""
import argparse
import csv
import json
import os
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

import meshio
import numpy as np

POINT_FIELDS = {"displacement": 3, "contact_pressure": 1, "gap": 1, "slip": 3, "tangential_traction": 3,
                "friction_coefficient": 1, "contact_status": 1}
CELL_FIELDS = {"von_mises": 1, "physical_group": 1}

failures = []
TMP = []


def check(cond, msg):
    if not cond:
        failures.append(msg)
    return cond


def read_csv(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def field(mesh, name, where="point"):
    data = mesh.point_data if where == "point" else mesh.cell_data
    if name not in data:
        return None
    a = data[name] if where == "point" else np.concatenate(data[name])
    a = np.asarray(a, dtype=float)
    return a.reshape(len(a), -1)


def check_arrays(mesh, label):
    for name, comps in POINT_FIELDS.items():
        a = field(mesh, name)
        if check(a is not None, f"{label}: point data '{name}' missing"):
            check(a.shape == (len(mesh.points), comps), f"{label}: '{name}' has shape {a.shape}, "
                  f"expected ({len(mesh.points)}, {comps})")
            check(np.all(np.isfinite(a)), f"{label}: '{name}' has non-finite values")
    ncells = sum(len(c.data) for c in mesh.cells)
    for name, comps in CELL_FIELDS.items():
        a = field(mesh, name, "cell")
        if check(a is not None, f"{label}: cell data '{name}' missing"):
            check(a.shape == (ncells, comps), f"{label}: cell '{name}' has shape {a.shape}, expected ({ncells}, {comps})")


def node_lookup(points):
    return {tuple(np.round(p, 9)): i for i, p in enumerate(points)}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--scene", required=True)
    ap.add_argument("--n", type=int, default=4)
    ap.add_argument("--extra", default="", help="more solver arguments, one string")
    ap.add_argument("--keep", help="solve into this folder instead of a temporary one")
    args = ap.parse_args()

    out = args.keep or tempfile.mkdtemp(prefix="contact3d_vtu_")
    if not args.keep:
        TMP.append(out)
    cmd = [args.bin, "solve", args.scene, "--quiet", "--out", out, "--set", "mesh.generator=paper_brick",
           "--set", f"mesh.n={args.n}"] + args.extra.split()
    rc = subprocess.run(cmd).returncode
    if rc != 0:
        print(f"FAIL: {' '.join(cmd)} exited {rc}")
        return 1

    summary = json.load(open(os.path.join(out, "summary.json")))
    nodes = read_csv(os.path.join(out, "contact_nodes.csv"))
    history = read_csv(os.path.join(out, "history.csv"))
    body = meshio.read(os.path.join(out, "body.vtu"))
    contact = meshio.read(os.path.join(out, "contact.vtu"))

    # Sizes: the body is the whole mesh, the contact file the triangles of Γc.
    check(len(body.points) == summary["n_nodes"], f"body.vtu has {len(body.points)} points, mesh {summary['n_nodes']}")
    check([c.type for c in body.cells] == ["tetra"], f"body.vtu cell blocks {[c.type for c in body.cells]}")
    check(sum(len(c.data) for c in body.cells) == summary["n_tets"], "body.vtu cell count differs from n_tets")
    check([c.type for c in contact.cells] == ["triangle"], f"contact.vtu cell blocks {[c.type for c in contact.cells]}")
    n = args.n
    check(sum(len(c.data) for c in contact.cells) == 2 * (3 * n) * n,
          f"contact.vtu has {sum(len(c.data) for c in contact.cells)} triangles, the {n}-brick's Γc has {6 * n * n}")
    check(len(contact.points) == (3 * n + 1) * (n + 1), "contact.vtu point count is not the face's node count")
    check_arrays(body, "body.vtu")
    check_arrays(contact, "contact.vtu")
    if failures:
        return report(out)

    # Values: nodal tables agree with both files at the contact nodes (matched by coordinates).
    bl, cl = node_lookup(body.points), node_lookup(contact.points)
    for row in nodes:
        key = tuple(np.round([float(row["x"]), float(row["y"]), float(row["z"])], 9))
        u = np.array([float(row[c]) for c in ("u1", "u2", "u3")])
        for label, mesh, lookup in (("body.vtu", body, bl), ("contact.vtu", contact, cl)):
            if not check(key in lookup, f"{label}: contact node {row['node']} at {key} not found"):
                continue
            i = lookup[key]
            tol = 1e-9 * max(1.0, np.abs(u).max()) + 1e-15
            check(np.allclose(mesh.point_data["displacement"][i], u, rtol=1e-9, atol=1e-15),
                  f"{label}: displacement at node {row['node']} differs from contact_nodes.csv")
            check(abs(field(mesh, "contact_pressure")[i, 0] - float(row["pressure"])) <= 1e-9 * abs(float(row["pressure"])) + 1e-6,
                  f"{label}: contact_pressure at node {row['node']} differs from the CSV")
            check(int(field(mesh, "contact_status")[i, 0]) == int(row["status"]),
                  f"{label}: contact_status at node {row['node']} differs from the CSV")
            check(abs(field(mesh, "gap")[i, 0] - u[2]) <= tol, f"{label}: gap at node {row['node']} is not z + u3")
            check(np.allclose(field(mesh, "slip")[i], [u[0], u[1], 0.0], rtol=1e-9, atol=1e-15),
                  f"{label}: slip at node {row['node']} is not (u1, u2, 0)")
    for label, mesh in (("body.vtu", body), ("contact.vtu", contact)):
        status = field(mesh, "contact_status")[:, 0]
        check(set(np.unique(status)) <= {0.0, 1.0, 2.0}, f"{label}: contact_status values {np.unique(status)}")
        check(field(mesh, "contact_pressure").min() >= 0, f"{label}: negative contact_pressure")
        check(field(mesh, "von_mises", "cell").min() >= 0, f"{label}: negative von_mises")
        check(field(mesh, "von_mises", "cell").max() > 0, f"{label}: von_mises is identically zero")
    status = field(contact, "contact_status")[:, 0]
    check((status > 0).any() and (status == 0).any(), "the brick should have both open and closed contact nodes")
    check(np.all(field(contact, "physical_group", "cell") > 0), "contact.vtu: triangles without their contact group")
    F = field(contact, "friction_coefficient")[:, 0][status > 0]
    check(F.size and F.min() >= 0.2 - 1e-12 and F.max() <= 0.3 + 1e-12, "friction_coefficient outside [low, high]")
    # Node status agrees with the cells around it: where every cell of T_H touching a node has the
    # same status (open / stick / slip from λ_n, ‖λ_t‖ and the radius), the node has it too.
    cells = read_csv(os.path.join(out, "contact_cells.csv"))
    lam_max = max(float(c["lambda_n"]) for c in cells)
    def cstat(c):
        if float(c["lambda_n"]) <= 1e-6 * lam_max:
            return 0
        lt = np.hypot(float(c["lambda_t1"]), float(c["lambda_t2"]))
        return 2 if lt >= (1 - 1e-3) * float(c["radius"]) else 1
    cst = [cstat(c) for c in cells]
    checked = 0
    for row in nodes:
        x, y = float(row["x"]), float(row["y"])
        around = {s for c, s in zip(cells, cst) if float(c["xmin"]) - 1e-12 <= x <= float(c["xmax"]) + 1e-12
                  and float(c["ymin"]) - 1e-12 <= y <= float(c["ymax"]) + 1e-12}
        if len(around) == 1:
            checked += 1
            check(int(row["status"]) == around.pop(), f"node {row['node']} at ({x}, {y}) has status {row['status']}, "
                  "while all its cells agree on another")
    check(checked > len(nodes) // 4, f"only {checked} nodes lie inside cells of a single status")
    # Status and pressure tell one story: a separated node carries (almost) no pressure, a node in
    # contact some (the edge of a pressed zone is in contact, not "separated" at its pressure peak).
    p_max = max(float(r["pressure"]) for r in nodes)
    for row in nodes:
        p, st = float(row["pressure"]), int(row["status"])
        check((st == 0) == (p <= 1e-6 * p_max), f"node {row['node']}: status {st} with pressure {p:.4g} "
              f"(peak {p_max:.4g})")
    check({1, 2} <= set(cst), "the brick should have both stick and slip cells")
    # The normal force: λ_n integrated over the cells equals ∫ contact_pressure roughly (both are the same load).
    check(summary["contact_force"]["normal"] > 0, "no normal contact force")

    # The collection: per fixed-point step the body (part 0) and the contact face (part 1); the
    # last step's files equal body.vtu and contact.vtu.
    pvd = ET.parse(os.path.join(out, "solution.pvd")).getroot()
    sets = pvd.findall("./Collection/DataSet")
    bodies = [d for d in sets if d.get("part", "0") == "0"]
    faces = [d for d in sets if d.get("part") == "1"]
    check(len(bodies) == len(faces) == len(history) and len(history) > 1,
          f"solution.pvd lists {len(bodies)} body and {len(faces)} contact steps, history.csv has {len(history)} rows")
    check([float(d.get("timestep")) for d in bodies] == [float(r["k"]) for r in history], "pvd timesteps are not k")
    for d in sets:
        check(os.path.isfile(os.path.join(out, d.get("file"))), f"solution.pvd names missing file {d.get('file')}")
    if bodies and faces and not failures:
        for steps, final in ((bodies, body), (faces, contact)):
            first = meshio.read(os.path.join(out, steps[0].get("file")))
            last = meshio.read(os.path.join(out, steps[-1].get("file")))
            check(len(last.points) == len(final.points), f"{steps[-1].get('file')} and the final file differ in points")
            check(np.allclose(last.point_data["displacement"], final.point_data["displacement"], rtol=1e-9, atol=1e-15),
                  f"{steps[-1].get('file')}: the last step's displacement is not the final displacement")
            check(not np.allclose(first.point_data["displacement"], last.point_data["displacement"], rtol=1e-6, atol=0),
                  f"{steps[0].get('file')}: the first and last fixed-point steps have identical displacements")
    check_single_solve(args, out)
    return report(out)


def check_single_solve(args, out):
    """A constant coefficient needs one Tresca solve: history.csv, err_history and solution.pvd
    then all have exactly one step."""
    single = os.path.join(out, "constant")
    cmd = [args.bin, "solve", args.scene, "--quiet", "--out", single, "--set", "mesh.generator=paper_brick",
           "--set", "mesh.n=2", "--set", "friction.law=constant", "--set", "friction.value=0.3"] + args.extra.split()
    if not check(subprocess.run(cmd).returncode == 0, "constant-law solve failed"):
        return
    s = json.load(open(os.path.join(single, "summary.json")))
    rows = read_csv(os.path.join(single, "history.csv"))
    steps = [d for d in ET.parse(os.path.join(single, "solution.pvd")).getroot().findall("./Collection/DataSet")
             if d.get("part", "0") == "0"]
    check(len(rows) == len(steps) == len(s["err_history"]) == s["fixed_point_iterations"] == 1,
          f"constant law: history rows {len(rows)}, pvd steps {len(steps)}, err_history {len(s['err_history'])}, "
          f"fixed_point_iterations {s['fixed_point_iterations']} (all should be 1)")


def report(out):
    if failures:
        print(f"FAIL ({len(failures)} problems, output in {out}):")
        for f in failures[:30]:
            print("  -", f)
        return 1
    print(f"ok: body.vtu, contact.vtu and solution.pvd agree with the tables ({out})")
    return 0


if __name__ == "__main__":
    code = main()
    if code == 0 and "--keep" not in sys.argv:
        import shutil
        shutil.rmtree(TMP[0], ignore_errors=True) if TMP else None
    sys.exit(code)
