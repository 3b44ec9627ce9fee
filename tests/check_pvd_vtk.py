#!/usr/bin/python3
"""solution.pvd as ParaView opens it, read with VTK's own XML reader (python3-vtk9).

ParaView's PVD reader shows, at each time step, the data sets listed with that `timestep`, one
block per `part`. This script solves a small brick with the slip-dependent law, groups the
collection's data sets the same way and reads every file with vtkXMLUnstructuredGridReader. It
checks that every time step holds the body (tetrahedra, every mesh node) and the contact face
(triangles), each with every field; that the last step equals body.vtu / contact.vtu; that the
stress tensor is symmetric and gives the von Mises array; that the friction traction on the body
opposes the slip where the body slides; and that traction_on_body carries the pressure along the
foundation's normal. A negative check rewrites the collection the way earlier versions wrote it
(contact parts only, the body at the last step) and requires the checker to reject it.

usage: check_pvd_vtk.py --bin build/contact3d --scene pipeline/scenes/paper_brick.toml [--n 4]
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET
from collections import defaultdict

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "pipeline"))
import c3d.vtu  # noqa: E402

import meshio
import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader

POINT_FIELDS = {"displacement": 3, "gap": 1, "slip": 3, "contact_pressure": 1, "tangential_traction": 3,
                "traction_on_body": 3, "friction_coefficient": 1, "contact_status": 1}
CELL_FIELDS = {"stress": 9, "von_mises": 1, "physical_group": 1}
VTK_TETRA, VTK_TRIANGLE = 10, 5


def read_vtu(path):
    reader = vtkXMLUnstructuredGridReader()
    reader.SetFileName(path)
    reader.Update()
    grid = reader.GetOutput()
    return grid if grid is not None and grid.GetNumberOfPoints() > 0 else None


def arrays(data):
    return {data.GetArrayName(i): vtk_to_numpy(data.GetArray(i)).reshape(data.GetArray(i).GetNumberOfTuples(), -1)
            for i in range(data.GetNumberOfArrays())}


def time_steps(run):
    """{timestep: {part: file}} as ParaView's PVD reader groups the collection."""
    steps = defaultdict(dict)
    for d in ET.parse(os.path.join(run, "solution.pvd")).getroot().findall("./Collection/DataSet"):
        steps[float(d.get("timestep"))][int(d.get("part", "0"))] = d.get("file")
    return dict(sorted(steps.items()))


def check_part(run, file, kind, n_points, fails):
    grid = read_vtu(os.path.join(run, file))
    if grid is None:
        fails.append(f"{file}: VTK read no points")
        return None
    types = {grid.GetCellType(i) for i in range(grid.GetNumberOfCells())}
    want = VTK_TETRA if kind == "body" else VTK_TRIANGLE
    if types != {want}:
        fails.append(f"{file}: {kind} part has VTK cell types {sorted(types)}, expected {want}")
    if n_points is not None and grid.GetNumberOfPoints() != n_points:
        fails.append(f"{file}: {grid.GetNumberOfPoints()} points, the mesh has {n_points}")
    pd, cd = arrays(grid.GetPointData()), arrays(grid.GetCellData())
    for name, comps in POINT_FIELDS.items():
        if name not in pd:
            fails.append(f"{file}: point field '{name}' missing")
        elif pd[name].shape != (grid.GetNumberOfPoints(), comps) or not np.all(np.isfinite(pd[name])):
            fails.append(f"{file}: point field '{name}' has shape {pd[name].shape} or non-finite values")
    for name, comps in CELL_FIELDS.items():
        if name not in cd:
            fails.append(f"{file}: cell field '{name}' missing")
        elif cd[name].shape != (grid.GetNumberOfCells(), comps) or not np.all(np.isfinite(cd[name])):
            fails.append(f"{file}: cell field '{name}' has shape {cd[name].shape} or non-finite values")
    pts = vtk_to_numpy(grid.GetPoints().GetData())
    return {"points": pts, "point": pd, "cell": cd}


def check_physics(label, part, fails):
    """The stress tensor is symmetric and gives von_mises; friction opposes slip; the normal part of
    traction_on_body is the contact pressure (foundation z = 0, normal +z)."""
    s = part["cell"].get("stress")
    vm = part["cell"].get("von_mises")
    if s is not None and vm is not None:
        t = s.reshape(-1, 3, 3)
        scale = max(np.abs(t).max(), 1e-300)
        if np.abs(t - t.transpose(0, 2, 1)).max() > 1e-12 * scale:
            fails.append(f"{label}: the stress tensor is not symmetric")
        dev = t - np.trace(t, axis1=1, axis2=2)[:, None, None] * np.eye(3) / 3
        vm_from_tensor = np.sqrt(1.5 * np.einsum("kij,kij->k", dev, dev))
        if np.abs(vm_from_tensor - vm[:, 0]).max() > 1e-5 * max(vm.max(), 1e-300):
            fails.append(f"{label}: von_mises differs from the stress tensor's")
    p = part["point"]
    if all(k in p for k in ("slip", "tangential_traction", "contact_status", "traction_on_body", "contact_pressure")):
        sliding = (p["contact_status"][:, 0] == 2) & (np.linalg.norm(p["slip"], axis=1) > 1e-3 * np.abs(p["slip"]).max())
        dots = np.einsum("ij,ij->i", p["slip"][sliding], p["tangential_traction"][sliding])
        if sliding.sum() < 3 or np.mean(dots < 0) < 0.95:
            fails.append(f"{label}: the friction traction opposes the slip at {np.mean(dots < 0):.0%} of "
                         f"{sliding.sum()} sliding nodes (expected almost all)")
        if np.abs(p["traction_on_body"][:, 2] - p["contact_pressure"][:, 0]).max() > 1e-9 * max(p["contact_pressure"].max(), 1):
            fails.append(f"{label}: the normal part of traction_on_body is not the contact pressure")


def check_collection(run, summary):
    fails = []
    steps = time_steps(run)
    if len(steps) != summary["fixed_point_iterations"]:
        fails.append(f"solution.pvd has {len(steps)} time steps, the run {summary['fixed_point_iterations']} solves")
    last = {}
    for t, parts in steps.items():
        if sorted(parts) != [0, 1]:
            fails.append(f"time step {t:g} has parts {sorted(parts)}, expected body (0) and contact (1)")
            continue
        last = {"body": check_part(run, parts[0], "body", summary["n_nodes"], fails),
                "contact": check_part(run, parts[1], "contact", None, fails)}  # Γc with its nodes on Γu
    if not last or None in last.values():
        return fails or ["no readable time step"]
    for kind, final_file in (("body", "body.vtu"), ("contact", "contact.vtu")):
        final = check_part(run, final_file, kind, None, fails)
        a, b = last[kind]["point"].get("displacement"), None if final is None else final["point"].get("displacement")
        if a is None or b is None or a.shape != b.shape or not np.allclose(a, b, rtol=1e-9, atol=1e-15):
            fails.append(f"the last time step's {kind} differs from {final_file}")
            continue
        check_physics(f"last step, {kind}", last[kind], fails)
    # The body's contact fields at Γc's nodes are the contact part's (matched by coordinates).
    if fails:
        return fails
    body_at = {tuple(np.round(x, 9)): i for i, x in enumerate(last["body"]["points"])}
    for i, x in enumerate(last["contact"]["points"]):
        j = body_at.get(tuple(np.round(x, 9)))
        if j is None or abs(last["body"]["point"]["contact_pressure"][j, 0] -
                            last["contact"]["point"]["contact_pressure"][i, 0]) > 1e-9 * summary["contact_force"]["normal"]:
            fails.append(f"contact node {i} at {x}: body and contact parts disagree")
            break
    return fails


def old_style_collection(run, copy):
    """The collection as contact3d 0.9 wrote it: contact steps as part 0, the body once, at the end."""
    shutil.copytree(run, copy)
    steps = time_steps(copy)
    with open(os.path.join(copy, "solution.pvd"), "w") as f:
        f.write('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n  <Collection>\n')
        for t, parts in steps.items():
            f.write(f'    <DataSet timestep="{t:g}" group="" part="0" file="{parts[1]}"/>\n')
        f.write(f'    <DataSet timestep="{max(steps):g}" group="" part="1" file="body.vtu"/>\n  </Collection>\n</VTKFile>\n')


def compare_binary(ascii_run, binary_run, fails):
    """output.vtu = binary: the same arrays as the ASCII files (to their 12 printed digits; the body, the
    contact face at every step, and the cells of T_H), read by
    VTK's reader, by meshio (the plots' reader) and by pipeline/c3d/vtu.py (the scripts' reader)."""
    summary = json.load(open(os.path.join(binary_run, "summary.json")))
    if summary.get("output_vtu") != "binary":
        fails.append(f"output.vtu = binary: summary.json says output_vtu = {summary.get('output_vtu')!r}")
    files = [f for parts in time_steps(ascii_run).values() for f in parts.values()] + ["body.vtu", "contact.vtu",
                                                                                     "contact_cells.vtu"]
    for file in files:
        a_path, b_path = os.path.join(ascii_run, file), os.path.join(binary_run, file)
        with open(b_path, "rb") as f:
            if b'<AppendedData encoding="raw">' not in f.read():
                fails.append(f"{file}: output.vtu = binary wrote no raw appended data")
        a, b = read_vtu(a_path), read_vtu(b_path)
        if a is None or b is None:
            fails.append(f"{file}: VTK read no points from the {'ASCII' if a is None else 'binary'} file")
            continue
        mine = c3d.vtu.read_arrays(b_path)
        mesh = meshio.read(b_path)
        for where in ("point", "cell"):
            da = arrays(a.GetPointData() if where == "point" else a.GetCellData())
            db = arrays(b.GetPointData() if where == "point" else b.GetCellData())
            if sorted(da) != sorted(db):
                fails.append(f"{file}: {where} arrays {sorted(db)} in binary, {sorted(da)} in ASCII")
            for name, va in da.items():
                vb = db.get(name)
                if vb is None or vb.shape != va.shape or not np.allclose(va, vb, rtol=1e-11, atol=1e-300):
                    fails.append(f"{file}: {where} array {name!r} differs between binary and ASCII")
                elif not np.array_equal(np.asarray(mine[name]).reshape(vb.shape), vb):
                    fails.append(f"{file}: pipeline/c3d/vtu.py reads {name!r} unlike VTK")
                elif where == "point" and not np.array_equal(np.asarray(mesh.point_data[name]).reshape(vb.shape), vb):
                    fails.append(f"{file}: meshio reads {name!r} unlike VTK")
        if not np.array_equal(vtk_to_numpy(b.GetPoints().GetData()), mine["Points"]):
            fails.append(f"{file}: the points differ between VTK and pipeline/c3d/vtu.py")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--scene", required=True)
    ap.add_argument("--n", type=int, default=4)
    args = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="contact3d_pvd_")
    try:
        run = os.path.join(tmp, "run")
        cmd = [args.bin, "solve", args.scene, "--quiet", "--out", run, "--set", "mesh.generator=paper_brick",
               "--set", f"mesh.n={args.n}"]
        if subprocess.run(cmd).returncode != 0:
            print(f"FAIL: {' '.join(cmd)}")
            return 1
        summary = json.load(open(os.path.join(run, "summary.json")))
        fails = check_collection(run, summary)
        old = os.path.join(tmp, "old")
        old_style_collection(run, old)
        if not check_collection(old, summary):
            fails.append("negative check: a collection without the body at every step was accepted")
        # [output] steps = "final": one time step, the answer's own files, still body and contact.
        final = os.path.join(tmp, "final")
        if subprocess.run(cmd[:5] + [final] + cmd[6:] + ["--set", "output.steps=final"]).returncode != 0:
            fails.append("the solve with output.steps = final failed")
        else:
            steps = time_steps(final)
            if list(steps.values()) != [{0: "body.vtu", 1: "contact.vtu"}] or os.path.exists(os.path.join(final, "steps")):
                fails.append(f"output.steps = final: collection {steps}, expected body.vtu and contact.vtu only")
        # [output] vtu = "binary": the same files with raw values, read alike by VTK, meshio and c3d.vtu.
        binary = os.path.join(tmp, "binary")
        if subprocess.run(cmd[:5] + [binary] + cmd[6:] + ["--set", "output.vtu=binary"]).returncode != 0:
            fails.append("the solve with output.vtu = binary failed")
        else:
            fails += check_collection(binary, summary)
            compare_binary(run, binary, fails)
        if fails:
            print(f"FAIL ({len(fails)}):\n  " + "\n  ".join(fails[:30]))
            return 1
        print(f"ok: {summary['fixed_point_iterations']} time steps, each with body and contact and every field "
              "(VTK XML reader); friction opposes slip; stress tensor consistent; output.vtu = binary reads the same "
              "in VTK, meshio and c3d.vtu")
        return 0
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
