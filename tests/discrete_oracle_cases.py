#!/usr/bin/env python3
"""contact3d against pipeline/discrete_oracle.py, an independent Python implementation of the same
discrete problem (P1, the cells, the half-lines and discs, the fixed point), on scenes that cover its
features: prescribed components moving Γc along the plane (the slip of (5.7) counts them), two materials
with symmetry planes, a curved face with a gap, pressure and gravity (capblock, merged cells read from
contact_cells.vtu), a face cut by a hole (clipped cells), a body held by contact alone under Coulomb
friction, a FreeFEM-made Medit mesh, a material region with its own body force. Each must agree to 1e-6 relative in u on Γc and in the body, λ and
the disc radii (they agree to 1e-9 … 1e-11). Negative case: the oracle taking prescribed components as 0 in the slip, the defect
fixed in b8b6335, must disagree with today's solver (4.7e-2 in λ_t), and so must the oracle taking the
slip as 0 at Γc's vertices held in all three components though moved along the plane (fixed after
f40e2db). A failure in λ alone where cond(Q) times the last QP's projected gradient exceeds --tol says so (lambda_only_hint; a T-plate two
elements thick, cond(Q) 5.6e7, failed so with two BLAS threads and gave no verdict with one)."""
import os
import subprocess
import sys
import tempfile

binary, source = sys.argv[1], os.path.abspath(sys.argv[2])
oracle = os.path.join(source, "pipeline", "discrete_oracle.py")
env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
TOL = "1e-6"
HEAVY_LAYER = 'material.region=[{group="layer",young=7.0e10,poisson=0.33,body_force=[1e6,0.0,-2e7]}]'


def run(cmd):
    return subprocess.run(cmd, capture_output=True, text=True, env=env)


def case(name, scene, sets=(), mesh=None, cells="csv", oracle_args=(), expect_agreement=True, expect_no_verdict=False,
         expect_in_verdict=None):
    out = os.path.join(tmp, name)
    mesh_args = ["--mesh", mesh] if mesh else []
    set_args = [a for s in (*sets, "solver.fixed_point_tol=1e-10") for a in ("--set", s)]
    solve = run([binary, "solve", scene, "--quiet", "--out", out, *mesh_args, *set_args])
    if solve.returncode != 0:
        return f"{name}: contact3d exited {solve.returncode}: {solve.stderr[-400:]}"
    set_args = [a for s in sets for a in ("--set", s)]
    check = run([sys.executable, oracle, scene, out, *mesh_args, *set_args, "--cells", cells, "--tol", TOL,
                 *oracle_args])
    verdict = (check.stdout.strip().splitlines() or ["(no output)"])[-1]
    print(f"{name}: {verdict}")
    if expect_no_verdict:  # the oracle's own answer too rough to judge: exit 3 and why, never a verdict
        if check.returncode != 3 or "no verdict" not in check.stderr:
            return f"{name}: expected no verdict (exit 3), got exit {check.returncode}: {verdict} {check.stderr[-300:]}"
        return None
    if check.returncode not in (0, 1) or (check.returncode == 1 and not verdict.startswith("ORACLE FAILED")):
        return f"{name}: the oracle failed (exit {check.returncode}): {check.stderr[-400:]}"
    if (check.returncode == 0) != expect_agreement:
        return f"{name}: expected {'agreement' if expect_agreement else 'a disagreement'}, got: {verdict}"
    if expect_in_verdict and expect_in_verdict not in verdict:
        return f"{name}: expected '{expect_in_verdict}' in the verdict, got: {verdict}"
    return None


scenes = os.path.join(source, "pipeline", "scenes")
with tempfile.TemporaryDirectory() as tmp:
    brick = os.path.join(tmp, "brick_n4.msh")
    if run([binary, "mesh", "brick", "--n", "4", "-o", brick]).returncode != 0:
        sys.exit("FAIL: contact3d mesh brick")
    moved_end = os.path.join(source, "tests", "scenes", "brick_moved_end.toml")
    in_plane = os.path.join(source, "tests", "scenes", "brick_end_moved_in_plane.toml")
    failures = [
        case("brick_moved_end", moved_end, mesh=brick),
        case("capblock", os.path.join(scenes, "capblock.toml"), sets=["mesh.parameters.h=0.05"], cells="vtu"),
        # a material region with a body force of its own (a heavy layer pushed along x)
        case("capblock_region_body_force", os.path.join(scenes, "capblock.toml"),
             sets=["mesh.parameters.h=0.05", HEAVY_LAYER], cells="vtu"),
        case("holed", os.path.join(scenes, "holed.toml")),
        # a resultant force (N) on the top spread over its area ([[boundary.force]])
        case("total_force", os.path.join(scenes, "paper_brick.toml"), mesh=brick,
             sets=["boundary.traction=[]", 'boundary.force=[{group="load_top", value=[3e6, 0.0, -9e7]}]']),
        case("free_brick_coulomb", os.path.join(scenes, "free_brick.toml"), sets=["mesh.parameters.n=4"]),
        case("brick_end_moved_in_plane", in_plane, mesh=brick),
        # a patch of Γc held at slip 0 under a table law with a static/kinetic jump: F(0) is the static value
        case("held_patch_static_table", os.path.join(source, "tests", "scenes", "brick_held_patch_static_table.toml")),
        # two parts, each held by its own contact (Coulomb), with cells merged at a sole's edge
        case("pads_two_parts_held", os.path.join(scenes, "pads.toml"), cells="vtu"),
        # FreeFEM's mesh (the scene's edp route leaves mesh.mesh, Medit, beside the results)
        case("freefem_made_mesh", os.path.join(scenes, "paper_brick_freefem.toml"), sets=["mesh.parameters.n=4"]),
        # the oracle given the layer without its own body force must see the difference
        case("negative_region_body_force_ignored", os.path.join(scenes, "capblock.toml"),
             sets=["mesh.parameters.h=0.05", HEAVY_LAYER], cells="vtu",
             oracle_args=["--set", 'material.region=[{group="layer",young=7.0e10,poisson=0.33}]'],
             expect_agreement=False),
        case("negative_slip_without_prescribed", moved_end, mesh=brick, oracle_args=["--slip-free-dofs-only"],
             expect_agreement=False),
        case("negative_held_vertices_at_rest", in_plane, mesh=brick, oracle_args=["--phi-zero-held"],
             expect_agreement=False),
        # the oracle's fixed point stopped far from its tolerance: its own answer fails its KKT audit
        # and the differences it sees may be its own, so it gives no verdict
        case("negative_sloppy_oracle_gives_no_verdict", moved_end, mesh=brick, oracle_args=["--fp-tol", "1e-3"],
             expect_no_verdict=True),
    ]
sys.path.insert(0, os.path.join(source, "pipeline"))
from discrete_oracle import lambda_only_hint  # noqa: E402

explained = {"cond_Q": 5.6e7, "c3d_qp_projected_gradient": 8e-12}
if "(5.6e+07 x 8.0e-12)" not in lambda_only_hint(explained, {"lambda_t_rel": 5.5e-6}, 1e-6):
    failures.append("a λ-only failure at cond(Q)·ε = 4.5e-4 is not explained")
if lambda_only_hint(explained, {"lambda_t_rel": 5.5e-6, "u_contact_rel": 2e-6}, 1e-6):
    failures.append("a failure in u too is explained away by cond(Q)")
if lambda_only_hint({"cond_Q": 1e3, "c3d_qp_projected_gradient": 1e-10}, {"lambda_t_rel": 5.5e-6}, 1e-6):
    failures.append("a λ failure on a well-conditioned, tightly solved dual is explained away")
failures = [f for f in failures if f]
if failures:
    sys.exit("FAIL:\n" + "\n".join(failures))
print("ok: contact3d and the discrete oracle agree on every case, disagree on the negative ones, and a sloppy oracle gives no verdict")
