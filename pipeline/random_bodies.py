#!/usr/bin/env python3
"""Random bodies, conditions and laws, solved with default settings: do they converge?

Each seed draws one case: a body (box, cylinder, box with a through hole; a third of the boxes are
thin plates, 1-4% of their width thick and meshed about one element through it, as a user meshes a
plate, which contact.cell_size = "auto" starts on cells of 1.5h) meshed by gmsh, scaled
from 1 mm to 10 m, turned by up to 40° with its foundation plane (contact.plane_normal follows the
turn, the loads turn with it), E from 1e7 to 2.1e11 Pa, ν from 0 to 0.45, and one of these
conditions:

  lowered        the top face moved down by strain·Lz and sideways by up to 0.2·F of that
  pressed        the top pressed by E·strain, nothing else: held by contact alone
  sheared        the top pressed and sheared along the plane by up to 0.2·F of the pressure
  sides_held     the same on the plane z = 0, u_x held on the sides (a symmetry-like roller) and the
                 shear along y, so the contact holds a slide, a lift and a tilt
  incline        the body's weight only, the plane tilted: friction holds it on the slope

with Tresca (g = E·strain), Coulomb or no friction, a constant coefficient or the paper's ramp (6.1)
on the body's displacement scale.

Each case is labelled with what a correct solver must do, from the loads alone:
  converge   friction can carry the loads along the plane (|τ|/p <= 0.2 F, tan(tilt) < F/1.3) and the
             pressure's centre stays well inside the footprint (no tipping);
  refuse     frictionless contact with loads along a free slide: exit 2, the slide named;
  either     a ramp law on a body held by contact alone (its elastic slips may exceed t0, where the
             coefficient has fallen: a refusal is the model's answer) or a case near tipping.
A mesh gmsh made with a flat tetrahedron is refused as degenerate and the case skipped.
A case fails when its outcome contradicts its label: a `converge` case refused or not converged, a
`refuse` case solved, any crash, timeout or non-finite figure, or a converged case whose contact
forces do not balance the loads (balance > 1e-6) or whose KKT residuals exceed 1e-4, Coulomb's
law relation max|c − F̄λ_n| / max c 1e-3: the fixed point stops where its err, a relative change in
the l2 norm, is below 1e-4, which bounds the relation's largest cell only up to a factor (measured:
up to 2.3e-4 in results/robustness_coulomb.md, 1.2e-4 on seed 115 with err 7.4e-5) — unless the run
warns that the law holds only to that (seed 3052: a free plate on an incline, a slip-weakening law, steps
that do not contract, 1.6e-3; converged with nothing said before the warning).

usage: random_bodies.py --bin build/contact3d [--seeds 1 60] [--out results/runs/random_bodies.md]
                        [--work DIR]
Exit code 1 when a case fails.
"""
import argparse
import json
import math
import random
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import c3d.run

SHAPES = {
    "box": 'Box(1) = {{0, 0, 0, {Lx}, {Ly}, {Lz}}};\n',
    "cylinder": 'Cylinder(1) = {{{R}, {R}, 0, 0, 0, {Lz}, {R}}};\n',
    "holed": ('Box(1) = {{0, 0, 0, {Lx}, {Ly}, {Lz}}};\n'
              'Cylinder(2) = {{{hx}, {hy}, {below}, 0, 0, {through}, {hr}}};\n'
              'BooleanDifference(3) = {{ Volume{{1}}; Delete; }}{{ Volume{{2}}; Delete; }};\n'),
}
GROUPS = """eps = {eps};
Mesh.MeshSizeMin = {h}; Mesh.MeshSizeMax = {h};
bottom() = Surface In BoundingBox {{-1e9, -1e9, -eps, 1e9, 1e9, eps}};
top() = Surface In BoundingBox {{-1e9, -1e9, {Lz} - eps, 1e9, 1e9, {Lz} + eps}};
sides() = Surface{{:}};
sides() -= {{bottom(), top()}};
Physical Surface("contact") = {{bottom()}};
Physical Surface("top") = {{top()}};
Physical Surface("sides") = {{sides()}};
Physical Volume("body") = {{Volume{{:}}}};
Rotate {{{{{ax}, {ay}, {az}}}, {{0, 0, 0}}, {angle}}} {{ Volume{{:}}; }}
"""


def rotation(axis, angle):
    """The matrix turning by `angle` about the unit vector `axis` (Rodrigues)."""
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k


def draw(seed):
    """One case: (geo text, scene text with {MESH}, {OUT}, description dict)."""
    r = random.Random(seed)
    shape = r.choice(list(SHAPES))
    scale = r.choice([1e-3, 1.0, 1.0, 10.0])
    Lz, Lx, Ly = (r.uniform(0.05, 1.0) * scale, r.uniform(0.2, 2.0) * scale, r.uniform(0.2, 2.0) * scale)
    R = r.uniform(0.1, 1.0) * scale
    footprint = (2 * R, 2 * R) if shape == "cylinder" else (Lx, Ly)
    h = max((footprint[0] * footprint[1] * Lz / 3000) ** (1 / 3), min(*footprint, Lz) / 4)
    # Plates from a stream of their own, so that the other seeds draw the cases they drew before plates.
    plates = random.Random(-seed)
    if shape == "box" and plates.random() < 1 / 3:
        shape = "plate"
        Lz = plates.uniform(0.01, 0.04) * max(Lx, Ly)
        h = max((Lx * Ly * Lz / 3000) ** (1 / 3), Lz * plates.uniform(0.7, 1.5))
    E = r.choice([1e7, 7e10, 2.1e11])
    nu = round(r.uniform(0.0, 0.45), 3)
    strain = r.choice([1e-5, 1e-4, 1e-3])
    condition = r.choice(["lowered", "pressed", "sheared", "sides_held", "incline"])
    model = r.choice(["tresca", "coulomb", "coulomb", "none"])
    law = r.choice(["constant", "ramp"]) if model != "none" else "none"
    F = round(r.uniform(0.1, 0.9), 3)
    axis = np.array([r.gauss(0, 1) for _ in range(3)])
    axis /= np.linalg.norm(axis)
    angle = r.uniform(0, 0.7) if condition != "sides_held" else 0.0  # x held on the sides: the plane z = 0
    turn = rotation(axis, angle)
    normal = turn @ np.array([0.0, 0.0, 1.0])
    tilt = math.acos(min(1.0, normal[2]))
    if condition == "incline" and model != "none" and math.tan(tilt) * 1.3 > F:
        F = round(min(1.0, 1.3 * math.tan(tilt) + 0.05), 3)
    # The faces are picked by bounding boxes, which OpenCASCADE pads by about 1e-7: a margin below that
    # misses the top of a plate a few µm thick.
    dims = dict(eps=max(1e-2 * Lz, 3e-7), Lx=Lx, Ly=Ly, Lz=Lz, R=R, hx=Lx / 2, hy=Ly / 2, hr=min(Lx, Ly) / 4, below=-scale,
                through=Lz + 2 * scale, h=h, ax=axis[0], ay=axis[1], az=axis[2], angle=angle)
    geo = 'SetFactory("OpenCASCADE");\n' + SHAPES["box" if shape == "plate" else shape].format(**dims) + \
        GROUPS.format(**dims)

    d = strain * Lz
    p = E * strain
    turned = lambda v: [float(x) for x in turn @ np.asarray(v, float)]
    shear = [0.2 * F * r.uniform(-1, 1), 0.2 * F * r.uniform(-1, 1)]
    material = f"[material]\nyoung = {E}\npoisson = {nu}\n"
    boundary = '[boundary]\ncontact = ["contact"]\nclamped = []\n'
    if condition == "lowered":
        x, y, z = turned([shear[0] * d, shear[1] * d, -d])
        boundary += f'[[boundary.displacement]]\ngroup = "top"\nx = {x!r}\ny = {y!r}\nz = {z!r}\n'
    elif condition == "pressed":
        boundary += f'[[boundary.pressure]]\ngroup = "top"\nvalue = {p!r}\n'
    elif condition in ("sheared", "sides_held"):
        if condition == "sides_held":
            shear[0] = 0.0
            boundary += '[[boundary.displacement]]\ngroup = "sides"\nx = 0.0\n'
        traction = turned([shear[0] * p, shear[1] * p, -p])
        boundary += f'[[boundary.traction]]\ngroup = "top"\nvalue = {traction!r}\n'
    else:  # incline: the weight, a pressure of E·strain at the bottom
        material += f"body_force = [0.0, 0.0, {-p / Lz!r}]\n"
    boundary += ("[contact]\nplane_point = [0.0, 0.0, 0.0]\nplane_normal = "
                 f"[{normal[0]!r}, {normal[1]!r}, {normal[2]!r}]\n")
    if model == "none":
        friction = '[friction]\nmodel = "tresca"\nlaw = "none"\n'
    else:
        friction = f'[friction]\nmodel = "{model}"\n'
        if model == "tresca":
            friction += f"slip_bound = {p!r}\n"
        if law == "constant":
            friction += f'law = "constant"\nvalue = {F}\n'
        else:
            t0 = 0.1 * d
            friction += f'law = "ramp"\nhigh = {F}\nlow = {F / 2}\nt0 = {t0!r}\nparam = {2 / t0!r}\n'
    scene = '[mesh]\nfile = "{MESH}"\n' + material + boundary + friction + '[output]\ndir = "{OUT}"\nsteps = "final"\n'

    held = condition != "lowered"
    along_plane = condition in ("sheared", "sides_held", "incline") and (condition == "incline" or any(shear))
    eccentricity = max(abs(s) for s in shear) * Lz if condition in ("sheared", "sides_held") else 0.0
    if condition == "incline":
        eccentricity = math.tan(tilt) * Lz / 2  # the weight through the centroid, half-way up
    tipping_margin = eccentricity / (min(footprint) / 2)
    if not held:
        expected = "converge"
    elif model == "none":
        expected = "refuse" if along_plane else "converge"
    elif law == "ramp" and along_plane:
        expected = "either"
    elif tipping_margin > 0.4:
        expected = "either"
    else:
        expected = "converge"
    description = dict(seed=seed, shape=shape, scale=scale, size=[*footprint, Lz], h=h, young=E, poisson=nu,
                       strain=strain, condition=condition, model=model, law=law, F=F,
                       tilt_deg=math.degrees(tilt), expected=expected)
    return geo, scene, description


def run_case(binary, seed, work):
    geo, scene, desc = draw(seed)
    folder = work / f"case{seed}"
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "body.geo").write_text(geo)
    mesh = folder / "body.msh"
    g = subprocess.run(["gmsh", "-3", str(folder / "body.geo"), "-format", "msh22", "-o", str(mesh)],
                       capture_output=True, text=True)
    row = dict(desc)
    if g.returncode != 0 or not mesh.exists():
        row.update(outcome="mesh failed", verdict="skipped", detail=g.stderr.strip()[-200:])
        return row
    out = folder / "out"
    scene_file = folder / "scene.toml"
    scene_file.write_text(scene.replace("{MESH}", str(mesh)).replace("{OUT}", str(out)))
    t0 = time.time()
    try:
        proc = subprocess.run([binary, "solve", str(scene_file), "--quiet"], capture_output=True, text=True,
                              timeout=600)
    except subprocess.TimeoutExpired:
        row.update(outcome="timeout", verdict="FAIL", detail="more than 600 s")
        return row
    row["time_s"] = time.time() - t0
    errors = [line for line in proc.stderr.splitlines() if line.startswith("error")]
    if proc.returncode == 2:
        message = errors[0] if errors else proc.stderr.strip()[-300:]
        if "degenerate" in message:  # gmsh's flat tetrahedron: the mesh, not the case, is refused
            row.update(outcome="mesh degenerate", verdict="skipped", detail=message)
            return row
        row.update(outcome="refused", detail=message)
        row["verdict"] = "ok" if desc["expected"] in ("refuse", "either") else "FAIL"
        return row
    if proc.returncode != 0:
        row.update(outcome=f"exit {proc.returncode}", verdict="FAIL", detail=proc.stderr.strip()[-300:])
        return row
    s = c3d.run.summary(out)
    kkt = max(s["kkt"].values())
    residuals = {name: value for name, value in s["kkt"].items() if name != "coulomb_relation"}
    law_relation = s["kkt"].get("coulomb_relation", 0.0)
    law_warned = any(w.startswith("Coulomb's law holds only to") for w in s.get("warnings", []))
    kkt_sound = (all(math.isfinite(v) and v <= 1e-4 for v in residuals.values())
                 and math.isfinite(law_relation) and (law_relation <= 1e-3 or law_warned))
    balance = s["forces"]["balance"]
    row.update(outcome="converged" if s["converged"] else s["status"], steps=s["fixed_point_iterations"],
               n_mult=s["n_mult"], n_primal=s["n_primal"], kkt=kkt, balance=balance,
               warnings=len(s.get("warnings", [])))
    sound = s["converged"] and kkt_sound and math.isfinite(balance) and balance <= 1e-6
    if desc["expected"] == "refuse":
        row["verdict"] = "FAIL"
        row["detail"] = "solved a frictionless slide whose loads do not balance"
    else:
        row["verdict"] = "ok" if sound else "FAIL"
    return row


def report(rows, seeds, out):
    counts = {}
    for row in rows:
        key = (row["expected"], row["outcome"] if row["verdict"] != "FAIL" else "failed")
        counts[key] = counts.get(key, 0) + 1
    failed = [row for row in rows if row["verdict"] == "FAIL"]
    lines = [
        "# Random bodies with default settings",
        "",
        f"Generated by `pipeline/random_bodies.py --seeds {seeds[0]} {seeds[1]}` (`make random-bodies`). "
        "Each seed draws a body (box, cylinder, holed box, thin plate about one element thick; 1 mm to 10 m; turned up to 40° with its "
        "foundation plane), a material, a condition and a friction law; `expected` is what a correct solver "
        "must do, judged from the loads alone (see the script's docstring). balance: "
        "|contact + applied forces| / |applied|; KKT max: the largest of summary.json's residuals, Coulomb's "
        "relation among them (judged against 1e-3, the others against 1e-4).",
        "",
        f"**{len(rows)} cases, {len(failed)} failed.** Outcomes by label: " +
        ", ".join(f"{e} → {o}: {n}" for (e, o), n in sorted(counts.items())) + ".",
        "",
        "| seed | body | scale | condition | friction | F | tilt° | expected | outcome | steps | n_mult | KKT max "
        "| balance | time (s) | verdict |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for row in rows:
        kkt = f"{row['kkt']:.1e}" if "kkt" in row else ""
        balance = f"{row['balance']:.1e}" if "balance" in row else ""
        seconds = f"{row['time_s']:.2f}" if "time_s" in row else ""
        lines.append(f"| {row['seed']} | {row['shape']} | {row['scale']:g} | {row['condition']} | "
                     f"{row['model']}/{row['law']} | {row['F']} | {row['tilt_deg']:.1f} | {row['expected']} | "
                     f"{row['outcome']} | {row.get('steps', '')} | {row.get('n_mult', '')} | {kkt} | {balance} | "
                     f"{seconds} | {row['verdict']} |")
    refused = [row for row in rows if row["outcome"] in ("refused", "mesh degenerate")]
    if refused:
        lines += ["", "Refusals (exit 2), first line of the message:", ""]
        lines += [f"- seed {row['seed']} ({row['expected']}): {row['detail'][:400]}" for row in refused]
    if failed:
        lines += ["", "Failures:", ""]
        lines += [f"- seed {row['seed']}: {row['outcome']} {row.get('detail', '')[:400]}" for row in failed]
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text("\n".join(lines) + "\n")
    out.with_suffix(".json").write_text(json.dumps(rows, indent=1))
    return failed


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", required=True)
    ap.add_argument("--seeds", type=int, nargs=2, default=[1, 60], metavar=("FIRST", "LAST"))
    ap.add_argument("--out", type=Path, default=Path("results/runs/random_bodies.md"))
    ap.add_argument("--work", type=Path, default=None, help="keep meshes and runs here (default: a temporary folder)")
    args = ap.parse_args()
    if args.seeds[1] < args.seeds[0]:
        ap.error("--seeds FIRST LAST with FIRST <= LAST")
    with tempfile.TemporaryDirectory(prefix="c3d_random_bodies_") as tmp:
        work = args.work or Path(tmp)
        rows = []
        for seed in range(args.seeds[0], args.seeds[1] + 1):
            row = run_case(args.bin, seed, work)
            rows.append(row)
            print(f"seed {seed}: {row['shape']} {row['condition']} {row['model']}/{row['law']} expected "
                  f"{row['expected']}: {row['outcome']} -> {row['verdict']}", flush=True)
    failed = report(rows, args.seeds, args.out)
    print(f"{len(rows)} cases, {len(failed)} failed; report in {args.out}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
