#!/usr/bin/env python3
"""Cross-check contact3d against an independent FreeFEM reference on the same mesh.

For a scene (TOML) this script
  1. meshes the scene's .geo with gmsh into MSH 2.2 (or runs its FreeFEM .edp into a Medit .mesh, or uses
     its mesh file),
  2. runs the FreeFEM reference pipeline/freefem/contact_ref.edp on that mesh: nodal multipliers
     with lumped boundary mass, semi-smooth Newton iterated to a relative change <= 1e-10 (for a
     slip-dependent coefficient inside successive approximations on the nodal slip, err <= 1e-8),
  3. runs contact3d on the same .msh (`contact3d solve SCENE --mesh MSH --out DIR`),
  4. matches the contact nodes by coordinates and compares displacements on the contact face,
     the contact sets and the total contact forces, and records both run times,
  5. writes a markdown report (plus the numbers as JSON beside it) and exits
       0  all variants within tolerance,
       1  a difference exceeds its tolerance (each one is printed as `CROSSCHECK FAILED: ...`),
       2  a side failed (non-zero exit, not converged, NaN, missing output) or bad input.

Variants: frictionless (friction.law = none), tresca (law = constant, value = --F, slip_bound
from the scene: bound s = F*g), slipdep (the scene's own solution-dependent coefficient F(|u_t|),
law = ramp or table, the paper's actual problem: contact3d's successive approximations (5.7)
against FreeFEM's successive approximations on nodal bounds s_p = g F(|u_t,p|)), coulomb (the same
law with Coulomb's bound F(|u_t|)·λ_n: both sides start frictionless, then from the sticking slip
φ = 0, and iterate on the slip and λ_n together; FreeFEM's nodal bound s_p = F(φ_p) λ_n,p; a scene whose
Coulomb law is constant takes it as coulomb_constant), coulomb_constant (Coulomb's bound F·λ_n with F =
--F, on any scene: to FreeFEM a table law of two points with that F), scene (the
scene's own law, whichever it is), all (frictionless, tresca, and slipdep when the scene's law
depends on the slip; also the default). Both solvers get a derived copy of the scene with the
[friction] table of the variant (written to the work directory), so that the scene's other
friction keys (e.g. those of the ramp law) do not get in the way.

Optional table in the scene (all keys optional, command-line options win):
  [crosscheck]
  tolerance = 0.05            # max relative L2(Gc) difference of u (vector), per variant
  force_tolerance = 0.05      # max relative difference of the total contact force (normal;
                              #   tangential vector when there is friction, relative to the larger
                              #   of the net and the gross friction, the sum of |λ_t| over Γc)
  n = 8                       # mesh parameter `n` used by the cross-check (default: the scene's)
  variants = ["frictionless", "tresca", "slipdep"]   # default: as --variant all
  friction_coefficient = 0.3  # F of the tresca and coulomb_constant variants
  contact_tol = 1e-2          # a node is "in contact" when wn > -contact_tol * max|u| on Gc

A foundation plane other than z = 0 ([contact] plane_point, plane_normal): FreeFEM solves the body
moved into the plane's frame (x' = R(x − p), R the smallest rotation taking the normal to e_z, as
contact3d builds it) with its loads and prescribed displacements turned alike; contact3d solves the
scene as given, and its nodes and displacements are moved into that frame before the comparison.

Norms: the L2(Gc) norms are exact integrals of the P1 interpolant over the contact triangles
of the mesh (nodes of Gc on the clamped boundary carry u = 0 on both sides).
"""
from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import time
import tomllib
from pathlib import Path

import numpy as np

import c3d.run
from oracle.errors import SideFailed, children_cpu, finite_or_fail, log
from oracle.meshes import make_mesh, read_mesh, write_moved_mesh
from oracle.laws import expand_variants, law_F, law_label, perturb_law, scene_law_depends_on_slip, slipdep_law, variant_friction
from oracle.freefem import ff_checks, freefem_driver, run_freefem, toml_dump
from oracle.held_motions import motions_held_by_friction_alone
from oracle.compare import body_difference, compare, read_csv, read_vtu_points_and_displacement

REPO = Path(__file__).resolve().parent.parent

# The labels of [output] units (the solver is unit-free; the scene's numbers are in this system).
UNIT_LABELS = {"m-N-Pa": ("m", "N", "Pa"), "mm-N-MPa": ("mm", "N", "MPa"), "m-kN-kPa": ("m", "kN", "kPa")}


def units_of(scene: dict) -> tuple[str, str, str]:
    """(length, force, stress) labels of the scene's output.units."""
    return UNIT_LABELS.get(scene.get("output", {}).get("units", "m-N-Pa"), UNIT_LABELS["m-N-Pa"])

DEFAULTS = {
    "tolerance": 0.05,
    "force_tolerance": 0.05,
    "friction_coefficient": 0.3,
    "contact_tol": 1e-2,
    "variants": ["all"],
}
VARIANTS = ("frictionless", "tresca", "slipdep", "coulomb", "coulomb_constant", "scene")
CROSSCHECK_KEYS = {"tolerance", "force_tolerance", "n", "variants", "friction_coefficient", "contact_tol"}


# ----------------------------------------------------------------------------------------------
# small helpers


# ----------------------------------------------------------------------------------------------
# mesh


# ----------------------------------------------------------------------------------------------
# scene -> problem data


def plane_frame(scene: dict, scene_path: Path):
    """The foundation plane's frame as contact3d builds it (contact/foundation_frame.cpp): R the smallest
    rotation taking the plane's unit normal to e_z (a half turn about e_x for −e_z) and p the plane's
    point, so that x' = R(x − p) puts the plane at z' = 0; None for the plane z = 0 itself."""
    c = scene.get("contact", {})
    try:
        p = np.array([float(v) for v in c.get("plane_point", [0.0, 0.0, 0.0])])
        n = np.array([float(v) for v in c.get("plane_normal", [0.0, 0.0, 1.0])])
    except (TypeError, ValueError):
        raise SideFailed(f"{scene_path}: [contact] plane_point / plane_normal must be three numbers") from None
    if p.shape != (3,) or n.shape != (3,) or not np.all(np.isfinite(np.r_[p, n])) or not np.linalg.norm(n) > 0:
        raise SideFailed(f"{scene_path}: [contact] plane_point / plane_normal must be three finite numbers, "
                         "the normal not zero")
    n = n / np.linalg.norm(n)
    ez = np.array([0.0, 0.0, 1.0])
    if np.linalg.norm(n - ez) <= 1e-15:
        return None if not p.any() else (np.eye(3), p)
    if n[2] < -1 + 1e-15:
        return np.diag([1.0, -1.0, -1.0]), p
    v = np.cross(n, ez)
    K = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    return np.eye(3) + K + K @ K / (1 + n[2]), p


def to_plane_frame(prob: dict, frame, scene_path: Path) -> dict:
    """The problem's loads and prescribed displacements in the plane's frame, x' = R(x − p): a vector
    field f(x) = v + Gx becomes R(v + Gp) + RGRᵀx', a pressure p₀ + g·x becomes p₀ + g·p + (Rg)·x'; a
    condition on some components must stay along axes of the frame (as contact3d requires)."""
    if frame is None:
        return prob
    R, p = frame

    def field(v, g9):
        G = np.array(g9).reshape(3, 3)
        return (R @ (np.array(v) + G @ p)).tolist(), (R @ G @ R.T).ravel().tolist()

    out = dict(prob)
    out["body_force"] = (R @ np.array(prob["body_force"])).tolist()
    out["regions"] = [(t, e, nu, (R @ np.array(b)).tolist()) for t, e, nu, b in prob["regions"]]
    out["traction"] = [(t, *field(v, g)) for t, v, g in prob["traction"]]
    out["pressure"] = [(t, v + float(np.dot(g, p)), (R @ np.array(g)).tolist()) for t, v, g in prob["pressure"]]
    disp = []
    for t, mask, val, g9 in prob["displacement"]:
        if all(mask):
            disp.append((t, mask, *field(val, g9)))
            continue
        G = np.array(g9).reshape(3, 3)
        mask2, val2, G2 = [0, 0, 0], [0.0] * 3, np.zeros((3, 3))
        for c in range(3):
            if not mask[c]:
                continue
            axis = R[:, c]  # e_c in the plane's frame
            k = int(np.argmax(np.abs(axis)))
            if abs(axis[k]) < 1 - 1e-12:
                raise SideFailed(f"{scene_path}: a condition on one component that the tilted plane's frame mixes "
                                 "with the others (contact3d refuses it too)")
            mask2[k], val2[k] = 1, axis[k] * (val[c] + G[c] @ p)
            G2[k] = axis[k] * (R @ G[c])
        disp.append((t, mask2, val2, G2.ravel().tolist()))
    out["displacement"] = disp
    return out


def problem_data(scene: dict, scene_path: Path, mesh: dict) -> dict:
    """problem_data_of, with a scene entry that lacks a key or has a wrong type reported as SideFailed."""
    try:
        return problem_data_of(scene, scene_path, mesh)
    except (KeyError, TypeError, ValueError) as e:
        raise SideFailed(f"{scene_path}: a [material] or [boundary] entry the FreeFEM reference needs is missing "
                         f"or malformed ({type(e).__name__}: {e})") from None


def problem_data_of(scene: dict, scene_path: Path, mesh: dict) -> dict:
    """The scene as the FreeFEM reference states it: materials (per volume group), clamped groups,
    prescribed displacement components, tractions, pressures, body force, contact groups. Scene keys
    the reference cannot state are refused (a cross-check of another problem would prove nothing)."""
    mat = scene.get("material", {})
    bnd = scene.get("boundary", {})
    names = mesh["names"]

    def tags(groups, role, table=names, kind="physical surface"):
        out = []
        for g in groups:
            if g not in table and str(g).isdigit():  # a Medit label or an unnamed gmsh group
                out.append(int(g))
                continue
            if g not in table:
                raise SideFailed(f"{scene_path}: {role}: group {g!r} is not a {kind} of the mesh "
                                 f"(have: {', '.join(sorted(table))})")
            out.append(table[g])
        return out

    def matrix_rows(entry, kind):  # a gradient, row by row (9 numbers; zero when absent)
        rows = entry.get("gradient", [[0.0] * 3] * 3)
        if len(rows) != 3 or any(len(r) != 3 for r in rows):
            raise SideFailed(f"{scene_path}: the {kind} gradient on {entry['group']!r} must be 3 rows of 3 numbers")
        return [float(x) for r in rows for x in r]

    try:
        young = float(mat["young"])
        poisson = float(mat["poisson"])
    except KeyError as e:
        raise SideFailed(f"{scene_path}: [material] needs {e}") from None
    body = [float(x) for x in mat.get("body_force", [0.0, 0.0, 0.0])]
    regions = []  # (tag, young, poisson, body force): a region's own body force, or [material]'s
    for r in mat.get("region", []):
        (tag,) = tags([r["group"]], "[[material.region]]", mesh.get("volume_names", {}), "physical volume")
        region_body = [float(x) for x in r.get("body_force", body)]
        if len(region_body) != 3:
            raise SideFailed(f"{scene_path}: the body_force of [[material.region]] {r['group']!r} must have 3 components")
        regions.append((tag, float(r["young"]), float(r["poisson"]), region_body))
    clamped = tags(bnd.get("clamped", []), "[boundary] clamped")
    contact = tags(bnd.get("contact", []), "[boundary] contact")
    if not contact:
        raise SideFailed(f"{scene_path}: no contact groups: nothing to cross-check")
    disp = []
    for d in bnd.get("displacement", []):
        (tag,) = tags([d["group"]], "[[boundary.displacement]]")
        mask = [1 if c in d else 0 for c in ("x", "y", "z")]
        disp.append((tag, mask, [float(d.get(c, 0.0)) for c in ("x", "y", "z")], matrix_rows(d, "displacement")))
    if not clamped and not disp:
        raise SideFailed(f"{scene_path}: the FreeFEM reference needs a clamped boundary or prescribed displacements")
    trac = []
    for t in bnd.get("traction", []):
        (tag,) = tags([t["group"]], "[[boundary.traction]]")
        val = [float(x) for x in t.get("value", [0.0, 0.0, 0.0])]
        if len(val) != 3:
            raise SideFailed(f"{scene_path}: traction on {t['group']!r} must have 3 components")
        trac.append((tag, val, matrix_rows(t, "traction")))
    for t in bnd.get("force", []):  # a resultant (N) spread over the group's area: the traction F / area
        (tag,) = tags([t["group"]], "[[boundary.force]]")
        force = np.array([float(x) for x in t["value"]])
        if force.shape != (3,):
            raise SideFailed(f"{scene_path}: force on {t['group']!r} must have 3 components")
        X, on = mesh["coords"], mesh["tris"][mesh["tri_tags"] == tag]
        area = 0.5 * np.linalg.norm(np.cross(X[on[:, 1]] - X[on[:, 0]], X[on[:, 2]] - X[on[:, 0]]), axis=1).sum()
        if not area > 0:
            raise SideFailed(f"{scene_path}: force on {t['group']!r}: the group has no area")
        trac.append((tag, list(force / area), [0.0] * 9))
    pressure = []
    for p in bnd.get("pressure", []):
        (tag,) = tags([p["group"]], "[[boundary.pressure]]")
        grad = [float(x) for x in p.get("gradient", [0.0, 0.0, 0.0])]
        if len(grad) != 3:
            raise SideFailed(f"{scene_path}: the pressure gradient on {p['group']!r} must have 3 components")
        pressure.append((tag, float(p.get("value", 0.0)), grad))
    return {"young": young, "poisson": poisson, "regions": regions, "body_force": body, "clamped": clamped,
            "displacement": disp, "contact": contact, "traction": trac, "pressure": pressure}


# ----------------------------------------------------------------------------------------------
# FreeFEM side


# ----------------------------------------------------------------------------------------------
# comparison


# ----------------------------------------------------------------------------------------------
# one (mesh, variant) case


def apply_sets(scene: dict, sets: list[str]) -> None:
    """The --set KEY=VALUE overrides (a dotted key, a TOML value or a bare string, as contact3d reads
    them) applied to the scene that the FreeFEM side reads too: an override of a material, a load or
    the law must reach both solvers, or they would be compared on different problems."""
    for item in sets:
        key, eq, text = item.partition("=")
        if not eq or not key.strip():
            raise ValueError(f"{item!r} is not KEY=VALUE")
        try:
            value = tomllib.loads(f"v = {text}")["v"]
        except tomllib.TOMLDecodeError:
            value = text
        *parents, leaf = key.strip().split(".")
        table = scene
        for name in parents:
            table = table.setdefault(name, {})
            if not isinstance(table, dict):
                raise ValueError(f"{key!r}: {name!r} is not a table of the scene")
        table[leaf] = value
        if key.strip() in ("mesh.file", "mesh.geo", "mesh.edp", "mesh.generator"):  # replaces the scene's source
            if leaf != "generator" and "generator" in table:
                table.pop("n", None)
            for other in ("file", "geo", "edp", "generator"):
                if other != leaf:
                    table.pop(other, None)
            if leaf in ("file", "generator"):
                table.pop("parameters", None)


def mesh_label(n) -> str:
    """How a mesh of the sweep is named: n=8, h=0.025, or 'scene' (the scene's own parameters)."""
    if n is None:
        return "scene"
    return f"{n[0]}={n[1]:g}" if isinstance(n, tuple) else f"n={n}"


def run_case(args, scene: dict, scene_path: Path, n, variant: str, cfg: dict, work_root: Path) -> dict:
    name = scene_path.stem
    F = args.F if args.F is not None else float(cfg["friction_coefficient"])
    fr_table, ff_law, label = variant_friction(scene, variant, F, scene_path)
    if args.perturb_freefem_law:
        if ff_law["kind"] == 0:
            raise SideFailed("--perturb-freefem-law needs a variant with a law (slipdep, coulomb, coulomb_constant)")
        ff_law = perturb_law(ff_law, args.perturb_freefem_law)
    s = ff_law["s"]
    work = work_root / f"{name}-{mesh_label(n).replace('=', '')}-{variant}"
    if work.exists() and not args.reuse_freefem:
        shutil.rmtree(work)
    work.mkdir(parents=True, exist_ok=True)
    msh, params = make_mesh(scene, scene_path, n, work, args.gmsh, reuse=args.reuse_freefem)
    mesh = read_mesh(msh)
    prob = problem_data(scene, scene_path, mesh)
    # A moved foundation plane: FreeFEM solves the body moved into the plane's frame (the plane z = 0),
    # contact3d the scene as given; its answer is moved into that frame for the comparison.
    frame = plane_frame(scene, scene_path)
    ff_msh = msh
    if frame is not None:
        R, p = frame
        ff_msh = work / f"plane-frame-{msh.name}"
        write_moved_mesh(msh, ff_msh, lambda x: (x - p) @ R.T)
        mesh = dict(mesh, coords=(mesh["coords"] - p) @ R.T)
        prob = to_plane_frame(prob, frame, scene_path)
    for feature in args.perturb_freefem_drop or []:  # negative tests: FreeFEM solves without it
        if feature == "gradients":  # the loads' and displacements' gradients zeroed, their values kept
            prob["traction"] = [(t, val, [0.0] * 9) for t, val, _ in prob["traction"]]
            prob["pressure"] = [(t, v, [0.0] * 3) for t, v, _ in prob["pressure"]]
            prob["displacement"] = [(t, mask, val, [0.0] * 9) for t, mask, val, _ in prob["displacement"]]
        elif feature == "region_body_forces":  # the regions keep their materials, weigh as [material] says
            prob["regions"] = [(t, e, nu, list(prob["body_force"])) for t, e, nu, _ in prob["regions"]]
        else:
            prob[feature] = []
    sliding = motions_held_by_friction_alone(mesh, prob)
    if sliding:
        raise SideFailed(f"{scene_path}: the FreeFEM reference cannot hold {' and '.join(sliding)}: the prescribed "
                         "conditions leave it free and it moves no contact node along the foundation's normal, so "
                         "only friction holds it (or nothing), and the reference's frictionless Newton start is "
                         "singular; contact3d solves such a body on its own (`contact3d solve`), the cross-check "
                         "needs a condition holding that motion (e.g. a symmetry plane)")
    case = {"scene": name, "n": params.get("n"), "variant": variant,
            "mesh_label": mesh_label(n if n is not None else params.get("n")), "friction": label, "slip_bound_s": s,
            "ff_law": ff_law,
            "mesh": str(msh), "n_nodes": int(len(mesh["coords"])), "work": str(work)}
    log(f"== {name} {case['mesh_label']} {variant}: {label}; "
        f"mesh {msh.name} ({case['n_nodes']} nodes)")

    # FreeFEM
    ff_csv, ff_json = work / "freefem_contact_nodes.csv", work / "freefem_summary.json"
    ff_field_csv = work / "freefem_field.csv"
    drv = freefem_driver(prob, ff_msh, ff_law, ff_csv, ff_json, tol=args.ff_tol, maxit=args.ff_maxit,
                         perturb=args.perturb_freefem_traction, fp_tol=args.ff_fp_tol, fp_maxit=args.ff_fp_maxit,
                         out_field=str(ff_field_csv))
    timing = work / "freefem_time.json"
    old_drv = work / "freefem.edp"
    if (args.reuse_freefem and old_drv.exists() and old_drv.read_text() == drv and timing.exists()
            and ff_json.exists() and ff_csv.exists() and ff_field_csv.exists()):
        t = json.loads(timing.read_text())
        ff_wall, ff_cpu = t["wall"], t["cpu"]
        log("   FreeFEM: reusing the previous run in " + str(work))
    else:
        for f in (timing, ff_json, ff_csv, ff_field_csv):
            f.unlink(missing_ok=True)
        ff_wall, ff_cpu = run_freefem(args.freefem, drv, work, "freefem", args.timeout)
        timing.write_text(json.dumps({"wall": ff_wall, "cpu": ff_cpu}))
    try:
        ffres = json.loads(ff_json.read_text())
    except (OSError, json.JSONDecodeError) as e:
        raise SideFailed(f"FreeFEM summary {ff_json}: {e}") from None
    ff = read_csv(ff_csv, ["node", "x", "y", "z", "u1", "u2", "u3", "wn", "wt_norm", "lambda_n",
                           "lambda_t1", "lambda_t2", "mass"])
    for k in ("u1", "u2", "u3", "lambda_n", "lambda_t1", "lambda_t2", "mass"):
        finite_or_fail(ff[k], f"FreeFEM {k}")
    if s is None:  # Coulomb: the bound is F·λ_n, its scale the largest one FreeFEM used
        s = case["slip_bound_s"] = float(ffres["slip_bound"])
    bad = ff_checks(ffres, s)
    if bad:
        raise SideFailed("FreeFEM reference failed its own checks: " + "; ".join(bad))
    fp_txt = ""
    if ffres.get("slip_dependent"):
        fp_txt = (f"{ffres['fixed_point_iterations']} fixed-point steps (err "
                  + ", ".join(f"{e:.1e}" for e in ffres["fixed_point_err"]) + "), ")
    log(f"   FreeFEM: {fp_txt}{ffres['newton_iterations']} Newton steps, {ffres['n_in_contact']}/{ffres['n_contact_nodes']} "
        f"nodes in contact, {ff_wall:.2f} s wall, {ff_cpu:.2f} s CPU")

    # contact3d on a derived scene (same mesh file, the variant's friction table)
    derived = {k: v for k, v in scene.items() if k not in ("crosscheck", "friction", "mesh", "output")}
    derived["mesh"] = {"file": str(msh)}
    derived["friction"] = fr_table
    derived_path = work / f"{name}-{variant}.toml"
    derived_path.write_text("# derived by pipeline/crosscheck.py from " + str(scene_path) + "\n" + toml_dump(derived))
    out = work / "contact3d"
    shutil.rmtree(out, ignore_errors=True)
    # The mesh is made already, from the scene with the overrides applied: contact3d gets the file, and
    # a mesh.* override would be refused there (mesh.parameters beside a mesh file).
    ours = [s for s in args.set or [] if not s.strip().startswith("mesh.")]
    cmd = c3d.run.solve_command(args.bin, derived_path, out, ours, mesh=msh, quiet=False)
    t0, c0 = time.perf_counter(), children_cpu()
    try:
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=args.timeout)
    except subprocess.TimeoutExpired:
        raise SideFailed(f"contact3d: timed out after {args.timeout:g} s") from None
    except FileNotFoundError:
        raise SideFailed(f"contact3d binary {args.bin!r} not found (build it: cmake --build build --target contact3d)") from None
    ours_wall, ours_cpu = time.perf_counter() - t0, children_cpu() - c0
    (work / "contact3d.log").write_text(" ".join(cmd) + "\n" + r.stdout + r.stderr)
    if r.returncode != 0:
        raise SideFailed(f"contact3d exited with {r.returncode}:\n" + "\n".join((r.stdout + r.stderr).splitlines()[-15:]))
    try:
        summ = json.loads((out / "summary.json").read_text())
    except (OSError, json.JSONDecodeError) as e:
        raise SideFailed(f"contact3d summary.json: {e}") from None
    if summ.get("converged") is not True:
        raise SideFailed(f"contact3d did not converge (status {summ.get('status')!r})")
    ours = read_csv(out / "contact_nodes.csv", ["node", "x", "y", "z", "u1", "u2", "u3", "wn", "wt_norm"])
    cells = read_csv(out / "contact_cells.csv", ["area", "lambda_n", "lambda_t1", "lambda_t2"])
    for k in ("u1", "u2", "u3"):
        finite_or_fail(ours[k], f"contact3d {k}")
    for k in ("area", "lambda_n", "lambda_t1", "lambda_t2"):
        finite_or_fail(cells[k], f"contact3d cells {k}")
    ours_total = float(summ.get("time_s", {}).get("total", float("nan")))
    errs = summ.get("err_history") or []
    err_txt = (" (err " + ", ".join(f"{e:.1e}" for e in errs) + ")") if ff_law["kind"] != 0 and errs else ""
    log(f"   contact3d: {summ.get('fixed_point_iterations', '?')} fixed-point steps{err_txt}, n_mult {summ.get('n_mult', '?')}, "
        f"{ours_wall:.2f} s wall, {ours_cpu:.2f} s CPU")

    points, u_body = read_vtu_points_and_displacement(out / "body.vtu")
    if frame is not None:  # our nodes and displacements into the plane's frame (λ is written in it)
        R, p = frame
        xyz = (np.column_stack([ours["x"], ours["y"], ours["z"]]) - p) @ R.T
        u = np.column_stack([ours["u1"], ours["u2"], ours["u3"]]) @ R.T
        for k, name in enumerate(("x", "y", "z")):
            ours[name] = xyz[:, k]
        for k, name in enumerate(("u1", "u2", "u3")):
            ours[name] = u[:, k]
        points, u_body = (points - p) @ R.T, u_body @ R.T
        case["plane_frame"] = {"rotation": R.tolist(), "point": p.tolist()}
    cmp_ = compare(mesh, prob, ff, ours, cells, float(cfg["contact_tol"]))
    case.update(cmp_)
    case.update(body_difference(read_csv(ff_field_csv, ["x", "y", "z", "u1", "u2", "u3"]), points, u_body,
                                1e-6 * float(np.ptp(points, axis=0).max())))
    case.update({
        "ff_newton_iterations": ffres["newton_iterations"], "ff_final_change": ffres["final_relative_change"],
        "ff_fixed_point_iterations": ffres.get("fixed_point_iterations", 1),
        "ff_fixed_point_err": ffres.get("fixed_point_err", []),
        "ff_newton_per_fixed_point_step": ffres.get("newton_per_fixed_point_step", []),
        "ff_fixed_point_tolerance": ffres.get("fixed_point_tolerance", 0.0),
        "ff_max_law_residual": ffres.get("max_law_residual", 0.0),
        "ff_slip_bound_range": [ffres.get("slip_bound_min", s), ffres.get("slip_bound", s)],
        "ours_err_history": summ.get("err_history"), "ours_status": summ.get("status"),
        "ff_time_wall": ff_wall, "ff_time_cpu": ffres["time_s"]["total"], "ff_time_solve": ffres["time_s"]["solve"],
        "ff_time_process_cpu": ff_cpu, "ours_time_process_cpu": ours_cpu,
        "ours_time_wall": ours_wall, "ours_time_total": ours_total,
        "ours_fixed_point_iterations": summ.get("fixed_point_iterations"), "ours_n_mult": summ.get("n_mult"),
        "ours_n_cells": summ.get("n_cells"), "ours_wn_plus_inf": summ.get("wn_plus_inf"),
        "time_ratio_wall": ff_wall / max(ours_wall, 1e-9),
        "time_ratio_cpu": ff_cpu / max(ours_cpu, 1e-9),
        "time_ratio_internal": ffres["time_s"]["total"] / ours_total if ours_total > 0 else float("nan"),
        "perturb_freefem_traction": args.perturb_freefem_traction,
        "perturb_freefem_drop": args.perturb_freefem_drop or [],
        "perturb_freefem_law": list(args.perturb_freefem_law or []),
    })
    # verdict
    tol, ftol = float(cfg["tolerance"]), float(cfg["force_tolerance"])
    fails = []
    if case["nodes_only_ff"] or case["nodes_only_ours"]:
        fails.append(f"contact node sets differ ({case['nodes_only_ff']} only in FreeFEM, "
                     f"{case['nodes_only_ours']} only in contact3d)")
    if case["rel_l2"] > tol:
        fails.append(f"relative L2(Gc) difference of u {case['rel_l2']:.4g} exceeds tolerance {tol:g}")
    if case["rel_Fn"] > ftol:
        fails.append(f"relative difference of the normal contact force {case['rel_Fn']:.4g} exceeds tolerance {ftol:g}")
    if s > 0 and case["rel_Ft"] > ftol:
        fails.append(f"relative difference of the tangential contact force {case['rel_Ft']:.4g} exceeds tolerance {ftol:g}")
    case["tolerance"], case["force_tolerance"] = tol, ftol
    case["fails"] = fails
    case["status"] = "pass" if not fails else "FAIL"
    log(f"   rel L2(Gc) {case['rel_l2']:.3e} (normal {case['rel_l2_normal']:.3e}, tangential "
        f"{case['rel_l2_tangential']:.3e}), max |du| {case['max_diff']:.3e} {units_of(scene)[0]}, body: max|du|/max|u| "
        f"{case['body_rel_max_diff']:.3e}, contact-set mismatch "
        f"{case['contact_ff_only'] + case['contact_ours_only']}, Fn rel {case['rel_Fn']:.3e}, Ft rel {case['rel_Ft']:.3e}"
        f" -> {case['status']}")
    return case


# ----------------------------------------------------------------------------------------------
# report


def fmt(x, spec=".3e"):
    if x is None:
        return "—"
    if isinstance(x, float) and not math.isfinite(x):
        return "nan"
    return format(x, spec)


def own_values_table(cases: list[dict]) -> list[str]:
    """Each code's own size of u on Γc by mesh, and how much it moved from the coarser mesh: on a face that
    sticks or is pressed flat u on Γc is small and both codes still change it from mesh to mesh (a puck
    under Coulomb F = 0.3: FreeFEM's rms slip 2.7 → 2.2 → 1.6 → 1.3 µm, contact3d's 2.3 → 1.7 → 1.2 →
    1.0 µm at h = 0.012 … 0.0035), so their relative difference stays flat while both converge."""
    rms = lambda c, k: c[k] / math.sqrt(c["contact_area"]) if c["contact_area"] > 0 else float("nan")
    L = ["\nu on Γc, each code on its own (rms = ‖·‖_L2(Γc)/√|Γc|; change = relative to the same variant on the "
         "previous mesh of the table): where a code's own value still changes between meshes by as much as the "
         "two codes differ, `rel L2` above measures how far both are from converged, not a disagreement.\n",
         "| mesh | variant | rms u_t FreeFEM | change | rms u_t contact3d | change | rms u_n FreeFEM | rms u_n contact3d |",
         "|" + "---|" * 8]
    last: dict[str, dict] = {}
    for c in cases:
        prev = last.get(c["variant"])
        change = lambda k: fmt(abs(rms(c, k) - rms(prev, k)) / max(rms(prev, k), 1e-300), ".2f") if prev else "—"
        L.append(f"| {c['mesh_label']} | {c['variant']} | {fmt(rms(c, 'l2_ut_ff'))} | {change('l2_ut_ff')} | "
                 f"{fmt(rms(c, 'l2_ut_ours'))} | {change('l2_ut_ours')} | {fmt(rms(c, 'l2_un_ff'))} | "
                 f"{fmt(rms(c, 'l2_un_ours'))} |")
        last[c["variant"]] = c
    return L


def write_report(path: Path, scene_path: Path, cases: list[dict], errors: list[str], cfg: dict, argv: list[str],
                 units: tuple[str, str, str] = UNIT_LABELS["m-N-Pa"]):
    path.parent.mkdir(parents=True, exist_ok=True)
    L = []
    L.append(f"# Cross-check: {scene_path.stem} — contact3d vs FreeFEM reference\n")
    L.append(f"Command: `{' '.join(argv)}`  ")
    L.append(f"Scene: `{os.path.relpath(scene_path, REPO)}`; tolerances: rel L2(Γc) of u ≤ {cfg['tolerance']:g}, "
             f"contact forces ≤ {cfg['force_tolerance']:g} (tangential: of the larger of the net and the gross friction Σ|λ_t|·area); \"in contact\": wn > −{cfg['contact_tol']:g}·max|u_ff| on Γc.\n")
    L.append("FreeFEM (`pipeline/freefem/contact_ref.edp`): nodal multipliers at the contact nodes with lumped "
             "boundary mass, semi-smooth Newton (primal-dual active set) to a relative change ≤ "
             "1e-10. contact3d: piecewise-constant multipliers on "
             "the cells T_H, dual QP (MPGP). Same P1 mesh; the two agree only as h → 0.\n")
    sd = [c for c in cases if c.get("ff_law", {}).get("kind", 0) != 0]
    if sd:
        L.append("Variant slipdep (solution-dependent coefficient, " + sd[0]["friction"] + "): both sides use the method "
                 "of successive approximations from φ⁰ = 0, err(k) = ‖φᵏ − φᵏ⁻¹‖/‖φᵏ‖ over the contact nodes. "
                 "contact3d: disc radii c_i = ∫_R_i g F(φ_h) dS / |R_i| per cell, stop at err ≤ its "
                 "`solver.fixed_point_tol`; FreeFEM: nodal bounds s_p = g F(φ_p) (lumped quadrature), warm-started "
                 f"Newton per step, stop at err ≤ {sd[0]['ff_fixed_point_tolerance']:g}.\n")
    L.append("rel L2 = ‖u_ff − u_ours‖/‖u_ff‖ in L2(Γc), exact integral of the P1 interpolants over the "
             "contact triangles (u_n, u_t: relative to ‖u_n,ff‖, ‖u_t,ff‖, but never to less than 1% of ‖u_ff‖: a sole "
             "pressed everywhere has almost no u_n); max |Δu| = max over contact nodes of the Euclidean nodal difference. "
             "Forces: FreeFEM Σ m_p λ_p (m_p the boundary mass projected on the plane, ∫ φ_p |n_z| dS; a tangential "
             "component that is prescribed, e.g. on a symmetry plane, carries its reaction there and no multiplier), "
             "contact3d Σ area·λ over cells (λ_n = pressure, λ_t = −tangential traction). "
             "Both processes include mesh reading and assembly.\n")
    ft = lambda v: "(" + ", ".join(format(x, ".4g") for x in v) + ")"
    L.append("Displacements on Γc and contact sets:\n")
    L.append(f"| mesh | variant | contact nodes | rel L2 u | rel L2 u_n | rel L2 u_t | max abs du ({units[0]}) "
             "| max du / max u | in contact FF/ours | mismatch | status |")
    L.append("|" + "---|" * 11)
    for c in cases:
        L.append(f"| {c['mesh_label']} | {c['variant']} | {c['n_contact_nodes_ff']} | {fmt(c['rel_l2'])} | {fmt(c['rel_l2_normal'])} | "
                 f"{fmt(c['rel_l2_tangential'])} | {fmt(c['max_diff'])} | {fmt(c['rel_max_diff'])} | "
                 f"{c['in_contact_ff']}/{c['in_contact_ours']} | {c['contact_ff_only'] + c['contact_ours_only']} | {c['status']} |")
    L.extend(own_values_table(cases))
    L.append(f"\nTotal contact forces ({units[1]}):\n")
    L.append("| mesh | variant | Fn FreeFEM | Fn contact3d | rel diff | Ft FreeFEM | Ft contact3d | rel diff |")
    L.append("|" + "---|" * 8)
    for c in cases:
        L.append(f"| {c['mesh_label']} | {c['variant']} | {c['Fn_ff']:.6g} | {c['Fn_ours']:.6g} | {fmt(c['rel_Fn'])} | "
                 f"{ft(c['Ft_ff'])} | {ft(c['Ft_ours'])} | {fmt(c['rel_Ft']) if c['slip_bound_s'] > 0 else '—'} |")
    L.append("\nCost (wall = elapsed time of the process; CPU = user+system time of the process; ratio = FreeFEM/contact3d):\n")
    L.append("| mesh | variant | FF fixed-point / Newton steps | contact3d steps / n_mult | FF wall (s) | FF CPU (s) | contact3d wall (s) "
             "| contact3d CPU (s) | ratio wall | ratio CPU |")
    L.append("|" + "---|" * 10)
    for c in cases:
        L.append(f"| {c['mesh_label']} | {c['variant']} | {c.get('ff_fixed_point_iterations', 1)} / {c['ff_newton_iterations']} | "
                 f"{c['ours_fixed_point_iterations']} / "
                 f"{c['ours_n_mult']} | {c['ff_time_wall']:.2f} | {c['ff_time_process_cpu']:.2f} | {c['ours_time_wall']:.3f} | "
                 f"{c['ours_time_process_cpu']:.3f} | {c['time_ratio_wall']:.1f} | {c['time_ratio_cpu']:.1f} |")
    if sd:
        L.append("\nFixed-point histories err(k) (slipdep):\n")
        L.append("| mesh | FreeFEM err(k) | FreeFEM Newton steps per step | contact3d err(k) |")
        L.append("|" + "---|" * 4)
        for c in sd:
            L.append(f"| {c['mesh_label']} | {', '.join(format(e, '.1e') for e in c['ff_fixed_point_err'])} | "
                     f"{', '.join(str(int(x)) for x in c['ff_newton_per_fixed_point_step'])} | "
                     f"{', '.join(format(e, '.1e') for e in (c.get('ours_err_history') or []))} |")
    L.append("")
    for c in cases:
        for f in c["fails"]:
            L.append(f"- FAIL {c['mesh_label']} {c['variant']}: {f}")
    for e in errors:
        L.append(f"- ERROR: {e}")
    if any(c.get("perturb_freefem_traction", 1.0) != 1.0 for c in cases):
        L.append(f"\nNote: FreeFEM tractions were scaled by {cases[0]['perturb_freefem_traction']:g} "
                 "(negative test of the cross-check).")
    if any(c.get("perturb_freefem_drop") for c in cases):
        L.append(f"\nNote: FreeFEM solved without the scene's {', '.join(cases[0]['perturb_freefem_drop'])} "
                 "(negative test of the cross-check).")
    if any(c.get("perturb_freefem_law") for c in cases):
        L.append(f"\nNote: the FreeFEM friction law was changed by {', '.join(cases[0]['perturb_freefem_law'])} "
                 "(negative test of the cross-check).")
    path.write_text("\n".join(L) + "\n")
    path.with_suffix(".json").write_text(json.dumps({"cases": cases, "errors": errors, "config": cfg}, indent=1))


# ----------------------------------------------------------------------------------------------
# self-test of the FreeFEM reference (no contact3d involved)


def validate_freefem(args, scene: dict, scene_path: Path, n, work_root: Path) -> int:
    """(1) lifted body: frictionless contact solution == plain linear solve; (2) discrete conditions
    of frictionless and Tresca solutions; (3) Tresca with a tiny bound == frictionless; (4) for a
    scene with a slip-dependent law: discrete conditions and the fixed point of the successive
    approximations; (5) that law with high = low = F (ramp) or all F_k = F (table) == Tresca F."""
    work = work_root / f"{scene_path.stem}-n{n}-ffselftest"
    if work.exists():
        shutil.rmtree(work)
    work.mkdir(parents=True)
    msh, _ = make_mesh(scene, scene_path, n, work, args.gmsh)
    mesh = read_mesh(msh)
    prob = problem_data(scene, scene_path, mesh)
    if plane_frame(scene, scene_path) is not None:
        raise SideFailed(f"{scene_path}: the self-test of the FreeFEM reference runs on scenes whose foundation is z = 0")
    problems = []

    def load_field(p):
        d = read_csv(p, ["x", "y", "z", "u1", "u2", "u3"])
        return np.column_stack([d["u1"], d["u2"], d["u3"]])

    # (1) reverse every load: the body is pulled off the plane (checked: no node in contact)
    lifted = dict(prob)
    lifted["traction"] = [(t, [-v for v in val], [-g for g in grad]) for t, val, grad in prob["traction"]]
    lifted["body_force"] = [-v for v in prob["body_force"]]
    lifted["regions"] = [(t, e, nu, [-v for v in b]) for t, e, nu, b in prob["regions"]]
    lifted["pressure"] = [(t, -v, [-g for g in grad]) for t, v, grad in prob["pressure"]]
    lifted["displacement"] = [(t, mask, [-v for v in val], [-g for g in grad])
                              for t, mask, val, grad in prob["displacement"]]
    run_freefem(args.freefem, freefem_driver(lifted, msh, 0.0, work / "lift.csv", work / "lift.json", tol=args.ff_tol,
                                             maxit=args.ff_maxit, perturb=1.0, out_field=str(work / "lift_field.csv")),
                work, "lift", args.timeout)
    run_freefem(args.freefem, freefem_driver(lifted, msh, 0.0, work / "unused.csv", work / "unused.json", tol=0, maxit=0,
                                             perturb=1.0, out_field=str(work / "linear_field.csv"), contact=False),
                work, "linear", args.timeout)
    lj = json.loads((work / "lift.json").read_text())
    a, b = load_field(work / "lift_field.csv"), load_field(work / "linear_field.csv")
    dl = float(np.abs(a - b).max() / max(np.abs(b).max(), 1e-300))
    msg = f"lifted load: {lj['n_in_contact']} nodes in contact, max|u_contact - u_linear|/max|u| = {dl:.2e}"
    log("   " + msg)
    if lj["n_in_contact"] != 0:
        msg += " (reversed load still touches the plane: check skipped)"
    elif dl > 1e-10:
        problems.append(msg)

    # (2) the scene's frictionless and Tresca solutions satisfy their discrete conditions
    fr = scene.get("friction", {})
    g = float(fr.get("slip_bound", 0.0))
    F = args.F if args.F is not None else DEFAULTS["friction_coefficient"]
    res = {}
    runs = [("frictionless", 0.0), ("tresca", F * g), ("tiny", 1e-6 * max(F * g, 1.0))]
    if scene_law_depends_on_slip(scene):
        law = slipdep_law(fr, scene_path)
        flat = dict(law)  # the same law with a constant value F: must reproduce Tresca F*g
        if law["kind"] == 1:
            flat.update(high=F, low=F)
        else:
            flat.update(F=[F] * len(law["F"]))
        flat["s"] = F * g
        runs += [("slipdep", law), ("flatlaw", flat)]
    for tag, s in runs:
        if tag != "frictionless" and g <= 0:
            continue
        smax = s["s"] if isinstance(s, dict) else s
        run_freefem(args.freefem, freefem_driver(prob, msh, s, work / f"{tag}.csv", work / f"{tag}.json",
                                                 tol=args.ff_tol, maxit=args.ff_maxit, perturb=1.0,
                                                 fp_tol=args.ff_fp_tol, fp_maxit=args.ff_fp_maxit), work, tag, args.timeout)
        j = json.loads((work / f"{tag}.json").read_text())
        res[tag] = (j, read_csv(work / f"{tag}.csv", ["u1", "u2", "u3", "lambda_n", "mass"]))
        bad = ff_checks(j, smax)
        extra = ""
        if j.get("slip_dependent"):
            extra = (f", {j['fixed_point_iterations']} fixed-point steps (last err {j['fixed_point_err'][-1]:.1e}), "
                     f"bounds {j['slip_bound_min']:g}..{j['slip_bound']:g} Pa, |s - gF(|u_t|)| {j['max_law_residual']:.1e} Pa")
        log(f"   {tag}: s = {law_label(s) if isinstance(s, dict) else format(s, 'g') + ' Pa'}, {j['newton_iterations']} "
            f"Newton steps{extra}, {j['n_in_contact']} in contact, "
            f"{j.get('n_slip', 0)} slipping, penetration {j['max_penetration']:.1e} m, min lambda_n {j['min_lambda_n']:.1e}, "
            f"Tresca excess {j['max_tresca_excess']:.1e} Pa -> {'ok' if not bad else '; '.join(bad)}")
        problems += [f"{tag}: {x}" for x in bad]
    # (3) a vanishing Tresca bound reproduces the frictionless solution
    if "tiny" in res:
        u0 = np.column_stack([res["frictionless"][1][k] for k in ("u1", "u2", "u3")])
        u1 = np.column_stack([res["tiny"][1][k] for k in ("u1", "u2", "u3")])
        dt = float(np.abs(u0 - u1).max() / np.abs(u0).max())
        log(f"   Tresca with s = 1e-6*F*g vs frictionless: max rel difference {dt:.2e}")
        if dt > 1e-5:
            problems.append(f"tiny Tresca bound differs from frictionless by {dt:.2e}")
    # (5) a slip-dependent law that is constant in fact reproduces the Tresca solution
    if "flatlaw" in res and "tresca" in res:
        u0 = np.column_stack([res["tresca"][1][k] for k in ("u1", "u2", "u3")])
        u1 = np.column_stack([res["flatlaw"][1][k] for k in ("u1", "u2", "u3")])
        dt = float(np.abs(u0 - u1).max() / np.abs(u0).max())
        nfp = res["flatlaw"][0]["fixed_point_iterations"]
        log(f"   law with constant F = {F:g} vs Tresca F = {F:g}: max rel difference {dt:.2e}, {nfp} fixed-point steps")
        if dt > 1e-10 or nfp != 2:
            problems.append(f"constant slip-dependent law differs from Tresca by {dt:.2e} ({nfp} fixed-point steps, expected 2)")
    # the law of the edp == the law here (both are written after contact3d's friction_law.cpp)
    if "slipdep" in res:
        j, d = res["slipdep"]
        law = slipdep_law(fr, scene_path)
        ff_csv = read_csv(work / "slipdep.csv", ["u1", "u2", "slip_bound"])
        # bounds used in the last step come from the previous slip; after convergence they equal
        # g F(|u_t|) of the final slip, evaluated here with the Python formula
        want = np.array([law["g"] * law_F(law, math.hypot(a, b)) for a, b in zip(ff_csv["u1"], ff_csv["u2"])])
        dlaw = float(np.abs(want - ff_csv["slip_bound"]).max())
        log(f"   slipdep: bounds vs g F(|u_t|) evaluated in Python: max difference {dlaw:.1e} Pa")
        if dlaw > max(1e-6, 100 * args.ff_fp_tol) * law["s"]:
            problems.append(f"slipdep bounds differ from g F(|u_t|) by {dlaw:.2e} Pa")
    for p in problems:
        log(f"FREEFEM SELFTEST FAILED: {p}")
    if not problems:
        log("FreeFEM self-test passed")
    return 1 if problems else 0


# ----------------------------------------------------------------------------------------------


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default=str(REPO / "build" / "contact3d"), help="the contact3d binary")
    ap.add_argument("--scene", required=True, help="scene TOML")
    ap.add_argument("--n", default=None, help="mesh parameter n (comma-separated list for a sweep)")
    ap.add_argument("--mesh-param", default=None, metavar="NAME=V1,V2,...",
                    help="a sweep over another mesh parameter of the scene's script, e.g. h=0.05,0.035,0.025")
    ap.add_argument("--variant", default=None,
                    help="frictionless | tresca | slipdep | coulomb | coulomb_constant | scene | all (= "
                         "frictionless,tresca[,slipdep if the scene's law is ramp/table]; for a Coulomb scene "
                         "frictionless[,coulomb]); comma-separated list allowed")
    ap.add_argument("--F", type=float, default=None,
                    help="friction coefficient of the tresca and coulomb_constant variants (default 0.3)")
    ap.add_argument("--tolerance", type=float, default=None, help="max relative L2(Gc) difference of u")
    ap.add_argument("--force-tolerance", type=float, default=None, help="max relative difference of contact forces")
    ap.add_argument("--contact-tol", type=float, default=None, help="'in contact' threshold relative to max|u|")
    ap.add_argument("--report", default=None, help="markdown report (default results/runs/crosscheck/<scene>.md; the committed ones in results/crosscheck/ are written only when named here)")
    ap.add_argument("--workdir", default=None, help="scratch folder (default build/crosscheck beside --bin)")
    ap.add_argument("--set", action="append", help="extra --set KEY=VALUE passed to contact3d")
    ap.add_argument("--freefem", default="FreeFem++")
    ap.add_argument("--gmsh", default="gmsh")
    ap.add_argument("--timeout", type=float, default=3600.0, help="seconds per solver run")
    ap.add_argument("--ff-tol", type=float, default=1e-10, help="FreeFEM Newton: relative change to stop")
    ap.add_argument("--ff-maxit", type=int, default=100, help="FreeFEM Newton: max steps (per fixed-point step)")
    ap.add_argument("--ff-fp-tol", type=float, default=1e-8,
                    help="FreeFEM successive approximations (slipdep): err(k) to stop")
    ap.add_argument("--ff-fp-maxit", type=int, default=100, help="FreeFEM successive approximations: max steps")
    ap.add_argument("--reuse-freefem", action="store_true",
                    help="reuse a FreeFEM result of the same driver and mesh left in the work folder")
    ap.add_argument("--validate-freefem", action="store_true",
                    help="self-test the FreeFEM reference only (no contact3d run)")
    ap.add_argument("--perturb-freefem-traction", type=float, default=1.0, help=argparse.SUPPRESS)
    # negative tests of the slipdep variant: KEY=VALUE (high, low, t0, param, g) for FreeFEM's law only
    ap.add_argument("--perturb-freefem-law", action="append", default=None, help=argparse.SUPPRESS)
    # negative tests of the scene's features: FreeFEM solves without the materials' regions, the regions' own
    # body forces, the pressures or the gradients of the loads and prescribed displacements
    ap.add_argument("--perturb-freefem-drop", action="append", default=None,
                    choices=["regions", "region_body_forces", "pressure", "gradients"],
                    help=argparse.SUPPRESS)
    args = ap.parse_args(argv)

    scene_path = Path(args.scene).resolve()
    try:
        with open(scene_path, "rb") as fh:
            scene = tomllib.load(fh)
    except (OSError, tomllib.TOMLDecodeError) as e:
        log(f"error: {scene_path}: {e}")
        return 2
    try:  # both sides solve the scene as overridden, not only contact3d
        apply_sets(scene, args.set or [])
    except ValueError as e:
        log(f"error: --set: {e}")
        return 2
    cc = scene.get("crosscheck", {})
    unknown = set(cc) - CROSSCHECK_KEYS
    if unknown:
        log(f"error: {scene_path}: unknown key(s) in [crosscheck]: {', '.join(sorted(unknown))} "
            f"(allowed: {', '.join(sorted(CROSSCHECK_KEYS))})")
        return 2
    cfg = dict(DEFAULTS)
    cfg.update(cc)
    for k, v in (("tolerance", args.tolerance), ("force_tolerance", args.force_tolerance),
                 ("contact_tol", args.contact_tol)):
        if v is not None:
            cfg[k] = v
    if args.F is not None:
        cfg["friction_coefficient"] = args.F
    if args.n is not None and args.mesh_param is not None:
        log("error: give --n or --mesh-param, not both")
        return 2
    if args.mesh_param is not None:
        key, _, values = args.mesh_param.partition("=")
        try:
            ns = [(key.strip(), float(x)) for x in values.split(",") if x.strip()]
        except ValueError:
            ns = []
        if not key.strip() or not ns:
            log(f"error: --mesh-param {args.mesh_param!r}: expected NAME=V1,V2,... with numbers")
            return 2
    elif args.n is not None:
        ns = [int(x) for x in str(args.n).split(",") if x.strip()]
    elif "n" in cc:
        ns = [int(cc["n"])]
    else:
        ns = [None]
    if args.variant is not None:
        variants = expand_variants(args.variant.split(","), scene)
    else:
        variants = expand_variants(list(cfg["variants"]), scene)
    for v in variants:
        if v not in VARIANTS:
            log(f"error: unknown variant {v!r} (frictionless | tresca | slipdep | coulomb | scene | all)")
            return 2

    bin_path = Path(args.bin).resolve()
    args.bin = str(bin_path)
    work_root = Path(args.workdir).resolve() if args.workdir else bin_path.parent / "crosscheck"
    work_root.mkdir(parents=True, exist_ok=True)

    if args.validate_freefem:
        rc = 0
        for n in ns:
            log(f"== FreeFEM self-test: {scene_path.stem} n={n}")
            try:
                rc = max(rc, validate_freefem(args, scene, scene_path, n, work_root))
            except SideFailed as e:
                log(f"error: {e}")
                rc = 2
        return rc

    cases, errors = [], []
    for n in ns:
        for v in variants:
            try:
                cases.append(run_case(args, scene, scene_path, n, v, cfg, work_root))
            except SideFailed as e:
                msg = f"{mesh_label(n)} {v}: {e}"
                log(f"error: {msg}")
                errors.append(msg)
    report = Path(args.report) if args.report else REPO / "results" / "runs" / "crosscheck" / f"{scene_path.stem}.md"
    if cases or errors:
        write_report(report.resolve(), scene_path, cases, errors, cfg, [Path(sys.argv[0]).name] + (argv or sys.argv[1:]),
                     units_of(scene))
        log(f"report: {report}")
    for c in cases:
        for f in c["fails"]:
            log(f"CROSSCHECK FAILED: {c['scene']} {c['mesh_label']} {c['variant']}: {f}")
    if errors:
        return 2
    return 1 if any(c["fails"] for c in cases) else 0


if __name__ == "__main__":
    sys.exit(main())
