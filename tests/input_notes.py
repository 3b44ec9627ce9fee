#!/usr/bin/env python3
"""Inputs accepted on purpose but not in silence: summary.json's notes say
1. which [friction] keys the chosen law does not read (`--set friction.law="none"` on the paper's brick,
   written for "ramp": its ramp parameters and slip_bound take no part), and none where the law reads
   every key given (and slip_bound = 0 under Coulomb's model, whose bound is the normal pressure); a
   warning where slip_bound = 0 under Tresca's model leaves the law given no part (the run frictionless),
   and where one component held at 0 (a symmetry plane's condition) is put on a face not normal to it;
2. that without contact groups the foundation plane holds nothing, where nodes start or end below it:
   a warning where the whole body starts on or above it (the paper's brick bent down through z = 0 with
   boundary.contact = []: a forgotten contact group, likely), a note where it starts through it (the plane
   moved to z = 0.5), and nothing where the body stays above it (the same brick pulled up);
3. `contact3d check` prints the notes about the scene as given (the unread keys of 1) before any solve.
usage: input_notes.py CONTACT3D SOURCE_DIR
"""
import json
import subprocess
import sys
import tempfile
from pathlib import Path

binary, root = sys.argv[1], Path(sys.argv[2])
scene = root / "pipeline" / "scenes" / "paper_brick.toml"
failures = []


def notes(tmp, name, *sets, kind="notes"):
    out = Path(tmp) / name
    args = [a for s in ("mesh.parameters.n=4", *sets) for a in ("--set", s)]
    p = subprocess.run([binary, "solve", str(scene), "--quiet", "--out", str(out), *args], capture_output=True, text=True)
    if p.returncode != 0:
        failures.append(f"{name}: exit {p.returncode}: {p.stderr[-300:]}")
        return []
    return json.loads((out / "summary.json").read_text()).get(kind, [])


def expect(name, found, present):
    if bool(found) != present:
        failures.append(f"{name}: note {'missing' if present else 'given'}: {found}")


with tempfile.TemporaryDirectory() as tmp:
    unread = [n for n in notes(tmp, "law_none", 'friction.law="none"') if "not read by law" in n]
    expect("law none", unread, True)
    if unread and not unread[0].startswith("friction.high, low, t0, param, slip_bound are not read by law 'none'"):
        failures.append(f"law none: the note names {unread[0]!r}")
    expect("law ramp", [n for n in notes(tmp, "law_ramp") if "not read by law" in n], False)
    coulomb = [n for n in notes(tmp, "coulomb", 'friction.model="coulomb"', "friction.slip_bound=0")
               if "not read by law" in n]
    expect("coulomb with slip_bound = 0", coulomb, True)
    if coulomb and not coulomb[0].startswith("friction.slip_bound is not read"):
        failures.append(f"coulomb: the note names {coulomb[0]!r}")
    dropped = [n for n in notes(tmp, "tresca_g0", "friction.slip_bound=0", kind="warnings")
               if "friction.slip_bound = 0 makes Tresca's bound" in n]
    expect("tresca with slip_bound = 0 and a ramp law: a warning", dropped, True)
    expect("coulomb with slip_bound = 0: no such warning",
           [n for n in notes(tmp, "coulomb_g0", 'friction.model="coulomb"', "friction.slip_bound=0", kind="warnings")
            if "friction.slip_bound = 0 makes" in n], False)
    off_plane = [n for n in notes(tmp, "y_on_top", 'boundary.displacement=[{group="load_top",y=0.0}]',
                                  kind="warnings") if "as a symmetry plane does" in n]
    expect("y = 0 on the top face (normal z): a warning", off_plane, True)
    if off_plane and "leans" not in off_plane[0] and "lean 90" not in off_plane[0]:
        failures.append(f"y on top: the warning says {off_plane[0]!r}")
    expect("x = 0 on the end face (normal x): no warning",
           [n for n in notes(tmp, "x_on_end", 'boundary.displacement=[{group="load_end",x=0.0}]', kind="warnings")
            if "as a symmetry plane does" in n], False)
    below = [n for n in notes(tmp, "no_contact_down", "boundary.contact=[]", kind="warnings") if "no contact group" in n]
    expect("no contact, bent down: a warning", below, True)
    if below and "node(s) end below it" not in below[0]:
        failures.append(f"no contact, bent down: the warning says {below[0]!r}")
    through = [n for n in notes(tmp, "no_contact_through", "boundary.contact=[]", "contact.plane_point=[0,0,0.5]")
               if "no contact group" in n and "start or end below it" in n]
    expect("no contact, plane through the body: a note", through, True)
    up = 'boundary.traction=[{group="load_end",value=[0,0,1e5]}]'
    expect("no contact, pulled up", [n for n in notes(tmp, "no_contact_up", "boundary.contact=[]", up)
                                     if "no contact group" in n], False)
def check_notes(*sets):
    args = [a for s in ("mesh.parameters.n=4", *sets) for a in ("--set", s)]
    p = subprocess.run([binary, "check", str(scene), *args], capture_output=True, text=True)
    if p.returncode != 0:
        failures.append(f"check {sets}: exit {p.returncode}: {p.stderr[-300:]}")
    return [line for line in p.stdout.splitlines() if line.startswith("note: ") and "not read by law" in line]


expect("check, law none", check_notes('friction.law="none"'), True)
expect("check, law ramp", check_notes(), False)
for f in failures:
    print("FAIL:", f)
print(f"{len(failures)} checks failed" if failures else "ok: the notes name the unread keys and the plane that holds nothing, and check prints them")
sys.exit(1 if failures else 0)
