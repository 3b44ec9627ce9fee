#!/usr/bin/env python3
"""The FreeFEM-meshed pipeline: paper_brick_freefem.toml runs geo/paper_brick.edp through FreeFem++
(the `[mesh] edp` key), reads the Medit mesh it writes, and must give the same discrete problem and
the same solution as the built-in generator's brick (paper_brick.toml with
mesh.generator = paper_brick) at the same n: equal n_p, n_d,
fixed-point steps and n_mult, and contact-node displacements equal to rounding. Then FreeFEM's
other ways out: the same mesh written by `savegmsh` (MSH 2.2 without $PhysicalNames, groups by
number) must give the same solution, and reflected by `movemesh3` (transfo = [x, 1 - y, z], every
tetrahedron negatively oriented) the reflected one: u(x, 1 - y, z) = (u1, -u2, u3).

    freefem_mesh_pipeline.py <contact3d> <repo root> [n]
"""
import csv
import os
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "pipeline"))
from c3d.run import solve, summary  # noqa: E402

binary, root = sys.argv[1], Path(sys.argv[2])
n = int(sys.argv[3]) if len(sys.argv) > 3 else 4
scenes = root / "pipeline" / "scenes"


def fail(msg):
    print("FAIL:", msg)
    sys.exit(1)


def contact_nodes(out):
    """{(x, y, z) rounded: (u1, u2, u3)} of contact_nodes.csv (node numbers differ between meshers)."""
    with open(Path(out) / "contact_nodes.csv") as f:
        return {(round(float(r["x"]), 9), round(float(r["y"]), 9), round(float(r["z"]), 9)):
                (float(r["u1"]), float(r["u2"]), float(r["u3"])) for r in csv.DictReader(f)}


with tempfile.TemporaryDirectory() as tmp:
    runs = {}
    # paper_brick.toml meshed by the built-in generator (the paper's five-tet split) against the
    # same scene meshed by FreeFEM.
    sets = {"paper_brick": ["mesh.generator=paper_brick", f"mesh.n={n}"],
            "paper_brick_freefem": [f"mesh.parameters.n={n}"]}
    for name in ["paper_brick", "paper_brick_freefem"]:
        out = Path(tmp) / name
        proc, _ = solve(binary, scenes / f"{name}.toml", out, sets[name])
        if proc.returncode != 0:
            fail(f"{name}: exit {proc.returncode}: {proc.stderr}")
        runs[name] = out
    ref, ff = summary(runs["paper_brick"]), summary(runs["paper_brick_freefem"])
    if not str(ff["mesh"]).endswith(".mesh"):
        fail(f"the FreeFEM scene did not solve on a Medit mesh: mesh = {ff['mesh']}")
    for key in ["n_primal", "n_dual", "n_cells", "fixed_point_iterations", "n_mult"]:
        if ref[key] != ff[key]:
            fail(f"{key}: generator {ref[key]} FreeFEM mesh {ff[key]}")
    a, b = contact_nodes(runs["paper_brick"]), contact_nodes(runs["paper_brick_freefem"])
    if a.keys() != b.keys():
        fail(f"contact nodes differ: {len(a)} generator, {len(b)} FreeFEM, {len(a.keys() ^ b.keys())} unmatched")
    scale = max(abs(c) for u in a.values() for c in u)
    diff = max(abs(p - q) for k in a for p, q in zip(a[k], b[k]))
    if not scale > 0 or diff > 1e-8 * scale:
        fail(f"contact displacements differ: max |du| = {diff:.3g} against max |u| = {scale:.3g}")
    # FreeFEM's savegmsh and a mirror image of the same mesh, solved with --mesh.
    medit = Path(tmp) / "brick.mesh"
    ff_env = dict(os.environ, FF_LOADPATH=os.environ.get("FF_LOADPATH", "/usr/lib/freefem++"))
    subprocess.run(["FreeFem++", "-nw", "-v", "0", str(root / "geo" / "paper_brick.edp"), "-out", str(medit),
                    "-n", str(n)], check=True, env=ff_env, capture_output=True)
    driver = Path(tmp) / "ways_out.edp"
    driver.write_text(f"""load "msh3"
load "gmsh"
mesh3 Th = readmesh3("{medit}");
savegmsh(Th, "{Path(tmp) / 'brick_gmsh'}");
mesh3 M = movemesh3(Th, transfo = [x, 1 - y, z]);
savemesh(M, "{Path(tmp) / 'mirrored.mesh'}");
""")
    subprocess.run(["FreeFem++", "-nw", "-v", "0", str(driver)], check=True, env=ff_env, capture_output=True)
    for name, mesh_file in [("savegmsh", "brick_gmsh.msh"), ("mirrored", "mirrored.mesh")]:
        out = Path(tmp) / name
        proc, _ = solve(binary, scenes / "paper_brick_freefem.toml", out, [], mesh=Path(tmp) / mesh_file)
        if proc.returncode != 0:
            fail(f"{name}: exit {proc.returncode}: {proc.stderr}")
        c = contact_nodes(out)
        if name == "mirrored":
            described = str(summary(out)["mesh"])
            if "mirrored" not in described:
                fail(f"the mirrored mesh's run does not say it was reoriented: {described}")
            checked = subprocess.run([binary, "check", str(scenes / "paper_brick_freefem.toml"), "--mesh",
                                      str(Path(tmp) / mesh_file)], capture_output=True, text=True)
            if "note: the mesh: every tetrahedron negatively oriented" not in checked.stdout:
                fail(f"`check` on the mirrored mesh does not say it is reoriented: {checked.stdout[-400:]}")
            c = {(x, round(1 - y, 9), z): (u1, -u2, u3) for (x, y, z), (u1, u2, u3) in c.items()}
        if c.keys() != b.keys():
            fail(f"{name}: contact nodes differ from the Medit mesh's ({len(c.keys() ^ b.keys())} unmatched)")
        d = max(abs(p - q) for k in b for p, q in zip(b[k], c[k]))
        if d > 1e-6 * scale:
            fail(f"{name}: contact displacements differ from the Medit mesh's: max |du| = {d:.3g}, max |u| = {scale:.3g}")
        print(f"ok: {name}: max|du|/max|u| = {d / scale:.2g}")
    print(f"ok: n={n} n_p={ff['n_primal']} n_d={ff['n_dual']} it={ff['fixed_point_iterations']} "
          f"n_mult={ff['n_mult']} max|du|/max|u| = {diff / scale:.2g}")
