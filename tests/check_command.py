#!/usr/bin/env python3
"""Tests `contact3d check` on a good scene with the committed MSH 2.2 fixture: exit 0, every
physical group listed with its dimension and element count (counted independently here from
the file), the tet quality line with a number in (0, 1], the contact face summary with its initial gap (none on
the plane; 0.5 m with the plane lowered by contact.plane_point, said to start above it; 1e-9 m, rounding,
not said to; the plane 1e-9 m above the face, rounding, taken as touching, and 1e-3 m above it refused as
an initial penetration), the factor a solve forms (nnz(L) and flops as the solve's own analysis prints them)
and "ok"."""
import argparse
import os
import re
import subprocess
import sys
import tempfile

ap = argparse.ArgumentParser()
ap.add_argument("--bin", required=True)
ap.add_argument("--source", required=True)
a = ap.parse_args()
fixture = os.path.join(os.path.abspath(a.source), "meshes", "fixtures", "brick_n2_msh22.msh")

# Independent count of the fixture's groups (MSH 2.2: first tag = physical tag).
lines = open(fixture).read().split("\n")
i = lines.index("$PhysicalNames")
names = {}
for k in range(int(lines[i + 1])):
    dim, tag, name = lines[i + 2 + k].split(maxsplit=2)
    names[int(tag)] = (int(dim), name.strip('"'))
j = lines.index("$Elements")
count = {t: 0 for t in names}
seen_tets = set()
for line in lines[j + 2: j + 2 + int(lines[j + 1])]:
    t = line.split()
    etype, phys = int(t[1]), int(t[3])
    if etype == 4:
        key = tuple(t[-4:])
        if key in seen_tets:
            continue
        seen_tets.add(key)
    if etype in (2, 4) and phys in count:
        count[phys] += 1

scene = tempfile.NamedTemporaryFile("w", suffix=".toml", delete=False)
scene.write(f"""[mesh]
file = "{fixture}"
[material]
young = 2e11
poisson = 0.3
[boundary]
clamped = ["clamped"]
contact = ["contact"]
[[boundary.traction]]
group = "load_top"
value = [0.0, 0.0, -1e7]
[friction]
slip_bound = 1e7
law = "constant"
value = 0.3
""")
scene.close()
p = subprocess.run([a.bin, "check", scene.name], capture_output=True, text=True, timeout=60)
# The same scene on a plane 0.5 m below the body: the whole contact face starts above it.
lowered = subprocess.run([a.bin, "check", scene.name, "--set", "contact.plane_point=[0, 0, -0.5]"],
                         capture_output=True, text=True, timeout=60)
# A plane 1e-9 m below: a face that touches up to rounding (a meshed cylinder's tangent line) rests on it.
grazing = subprocess.run([a.bin, "check", scene.name, "--set", "contact.plane_point=[0, 0, -1e-9]"],
                         capture_output=True, text=True, timeout=60)
# A plane 1e-9 m above the face (a plane point given to 10 digits): rounding, the face taken as on it
# (refused as an initial penetration before); 1e-3 m above it is one.
rounded = subprocess.run([a.bin, "check", scene.name, "--set", "contact.plane_point=[0, 0, 1e-9]"],
                         capture_output=True, text=True, timeout=60)
pushed_in = subprocess.run([a.bin, "check", scene.name, "--set", "contact.plane_point=[0, 0, 1e-3]"],
                           capture_output=True, text=True, timeout=60)
# The partition's own warnings, as a solve gives them: one cell over the whole face (H in the wrong unit).
one_cell = subprocess.run([a.bin, "check", scene.name, "--set", "contact.cell_size=100"], capture_output=True, text=True)
# The factor a solve would form, predicted by CHOLMOD's symbolic analysis: the figures the solve prints
# after its own analysis, before factoring.
solved = subprocess.run([a.bin, "solve", scene.name, "--out", tempfile.mkdtemp()], capture_output=True, text=True,
                        timeout=120)
os.unlink(scene.name)
out = p.stdout
print(out, p.stderr)
problems = []
if p.returncode != 0:
    problems.append(f"exit {p.returncode}")
for tag, (dim, name) in names.items():
    m = re.search(rf"^\s*\"{re.escape(name)}\"\s+dim {dim}\s+(\d+) (?:triangles|tetrahedra)", out, re.M)
    if not m:
        problems.append(f"group {name} not listed")
    elif int(m.group(1)) != count[tag]:
        problems.append(f"group {name}: {m.group(1)} elements, file has {count[tag]}")
m = re.search(r"worst tet quality[^:]*:\s*([0-9.eE+-]+)", out)
if not m or not (0 < float(m.group(1)) <= 1):
    problems.append("no tet quality in (0, 1]")
if not re.search(r"contact face: \d+ triangles, \d+ contact nodes.*; on the foundation plane \(no initial gap\)$",
                 out, re.M):
    problems.append("no contact face summary resting on the plane")
if lowered.returncode != 0 or not re.search(
        r"contact face: .*; initial gap 0\.5 to 0\.5 m \(the whole face starts above the plane", lowered.stdout):
    problems.append(f"the face 0.5 m above a lowered plane is not said: exit {lowered.returncode}, {lowered.stdout}")
if grazing.returncode != 0 or "initial gap 1e-09 to 1e-09 m" not in grazing.stdout or "starts above" in grazing.stdout:
    problems.append(f"a face 1e-9 m above the plane (rounding) is said to start above it: {grazing.stdout}")
if rounded.returncode != 0 or "on the foundation plane (no initial gap)" not in rounded.stdout:
    problems.append(f"a face 1e-9 m below the plane (rounding) is refused: {rounded.stdout} {rounded.stderr}")
if pushed_in.returncode != 2 or "initial penetration" not in pushed_in.stderr:
    problems.append(f"a face 1e-3 m below the plane is not refused: exit {pushed_in.returncode}")
# The dual a solve would form: 3 multipliers per cell with friction, and the dense route on a face this small.
m = re.search(r"^dual: (\d+) cells \(H = [0-9.eE+-]+ m\), (\d+) multipliers; the dense Q with its working copies "
              r"[0-9.eE+-]+ [MG]iB, [0-9.eE+-]+ [MG]iB available: solver.schur = \"augmented\"$", out, re.M)
if not m or int(m.group(1)) == 0 or int(m.group(2)) != 3 * int(m.group(1)):
    problems.append("no dual plan line (cells, 3 multipliers per cell, the dense route)")
predicted = re.search(r"^factor: nnz\(L\) = ([0-9.e+]+) \([0-9.]+ [KMG]iB\), ([0-9.e+-]+) GFlop \(CHOLMOD's symbolic "
                      r"analysis\); the solve needs about [0-9.]+ [KMG]iB beyond the mesh and K$", out, re.M)
formed = re.search(r"factor: nnz\(L\) = ([0-9.e+]+) \([0-9.]+ [KMG]iB\), ([0-9.e+-]+) GFlop", solved.stdout)
if not predicted or not formed or predicted.groups() != formed.groups():
    problems.append(f"check's factor line missing or not the solve's: {predicted and predicted.groups()} against "
                    f"{formed and formed.groups()}")
if "63 nodes" not in out or f"{len(seen_tets)} tets" not in out:
    problems.append("node/tet counts missing or wrong")
if not out.strip() or not out.rstrip().splitlines()[-1].startswith("ok"):
    problems.append("last line is not ok")
# A body about one element thick over its contact face (the slab at h = t = 0.05 m) is warned that P1
# tetrahedra that few through a thickness are too stiff in bending; the same slab 0.1 m thick (two
# elements through) is not. The brick fixture above: no such warning.
slab = os.path.join(os.path.abspath(a.source), "pipeline", "scenes", "slab.toml")
thin = subprocess.run([a.bin, "check", slab], capture_output=True, text=True)
thick = subprocess.run([a.bin, "check", slab, "--set", "mesh.parameters.t=0.1"], capture_output=True, text=True)
layers = re.compile(r"^warning: the body is [0-9.e+-]+ m thick over most of Γc \(the median\) and the mesh has about "
                    r"[0-9.]+ element\(s\) through that thickness: linear tetrahedra \(P1\) that few", re.M)
if thin.returncode != 0 or not layers.search(thin.stderr):
    problems.append(f"the slab one element thick is not warned about its elements through the thickness: {thin.stderr}")
# check's mesh made by gmsh: named as a temporary file (it named a path removed at its exit), or kept
# with --keep-mesh for solve --mesh; a mesh the scene reads from a file has nothing to keep
if "a temporary file, removed at exit (check --keep-mesh FILE keeps it)" not in thin.stdout:
    problems.append(f"check's temporary mesh not said to be removed: {thin.stdout[:300]}")
kept = os.path.join(tempfile.mkdtemp(), "slab.msh")
keep = subprocess.run([a.bin, "check", slab, "--keep-mesh", kept], capture_output=True, text=True)
if (keep.returncode != 0 or f"(kept: solve it with --mesh {kept})" not in keep.stdout or not os.path.exists(kept)
        or not open(kept).read(11) == "$MeshFormat"):
    problems.append(f"check --keep-mesh did not keep the mesh: exit {keep.returncode} {keep.stdout[:300]} {keep.stderr}")
brick = os.path.join(os.path.abspath(a.source), "pipeline", "scenes", "paper_brick.toml")
nothing = subprocess.run([a.bin, "check", brick, "--set", "mesh.generator=paper_brick", "--keep-mesh", kept + ".2"],
                         capture_output=True, text=True)
if nothing.returncode != 2 or "is not one check makes with gmsh or FreeFEM" not in nothing.stderr:
    problems.append(f"check --keep-mesh on a scene that reads a mesh file: exit {nothing.returncode} {nothing.stderr}")
if thick.returncode != 0 or "element(s) through" in thick.stderr:
    problems.append(f"the slab two elements thick is warned, or refused: exit {thick.returncode} {thick.stderr}")
if "element(s) through" in p.stderr:
    problems.append("the brick fixture is warned about its elements through the thickness")
# One element through but no plate: 0.4 x 0.4 m, 0.05 m thick (a span of 8 thicknesses) does not bend as
# a plate, so it is not warned (a solid spherical cap was, its force within 0.7% of a mesh twice as fine).
block = subprocess.run([a.bin, "check", slab, "--set", "mesh.parameters.Lx=0.4", "--set", "mesh.parameters.Ly=0.4",
                        "--set", "mesh.parameters.p=0.1"], capture_output=True, text=True)
if block.returncode != 0 or "element(s) through" in block.stderr:
    problems.append(f"a block 8 times as wide as thick is warned as a plate, or refused: {block.stderr}")
if one_cell.returncode != 0 or "warning: contact.cell_size: one cell of H = 100" not in one_cell.stderr:
    problems.append(f"check does not warn of one cell over the whole face: {one_cell.stderr}")
if problems:
    print("FAIL:", "; ".join(problems))
    sys.exit(1)
print("check command ok")
