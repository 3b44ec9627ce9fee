#!/usr/bin/python3
"""The contact tractions written on Γc integrate to the contact force of summary.json. A half-cylinder
(geo/roller.geo) pressed on its curved side and moved sideways, Tresca friction with a ramp law: the
nodal `contact_pressure` and `tangential_traction` of contact.vtu, integrated over the written triangles
as ParaView's Integrate Variables does (P1: the mean of the corners times the area), must give
summary.json's contact_force normal and tangential to 1e-9. The cells' multipliers are per unit of Γc's
projection onto the plane; written unconverted on the curved face, the friction integrated to 2.35 times
its force and the pressure to 1.0016 times.

usage: contact_tractions_integrate.py BIN SOURCE_DIR WORK_DIR
"""
import json
import os
import shutil
import subprocess
import sys

import meshio
import numpy as np

binary, source, work = sys.argv[1], os.path.abspath(sys.argv[2]), sys.argv[3]
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
scene = os.path.join(work, "roller.toml")
with open(scene, "w") as f:
    f.write(f'[mesh]\ngeo = "{os.path.join(source, "geo", "roller.geo")}"\nparameters = {{ h = 0.05 }}\n'
            '[material]\nyoung = 7e10\npoisson = 0.33\n[boundary]\nclamped = []\ncontact = ["contact"]\n'
            '[[boundary.displacement]]\ngroup = "top"\nx = 4e-4\ny = 0.0\nz = -1e-2\n'
            '[friction]\nslip_bound = 1e9\nlaw = "ramp"\nhigh = 0.4\nlow = 0.2\nt0 = 1e-4\nparam = 1e4\n')
out = os.path.join(work, "out")
run = subprocess.run([binary, "solve", scene, "--out", out, "--quiet"], capture_output=True, text=True)
if run.returncode != 0:
    sys.exit(f"FAIL: solve exited {run.returncode}: {run.stderr[-2000:]}")
summary = json.load(open(os.path.join(out, "summary.json")))
face = meshio.read(os.path.join(out, "contact.vtu"))
triangles = face.cells_dict["triangle"]
corners = face.points[triangles]
areas = 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1)


def integral(name):
    values = np.asarray(face.point_data[name], dtype=float).reshape(len(face.points), -1)
    return (values[triangles].mean(axis=1) * areas[:, None]).sum(axis=0)


normal = integral("contact_pressure")[0]
tangential = np.linalg.norm(integral("tangential_traction"))
force = summary["contact_force"]
failures = []
for label, written, expected in (("normal", normal, force["normal"]), ("tangential", tangential, force["tangential"])):
    if not abs(written - expected) <= 1e-9 * abs(expected):
        failures.append(f"{label}: the written traction integrates to {written:.10g}, summary.json says {expected:.10g}")
if failures:
    sys.exit("FAIL: " + "; ".join(failures))
print(f"ok: normal {normal:.10g}, tangential {tangential:.10g} as in summary.json (Γc's area {areas.sum():.4g})")
