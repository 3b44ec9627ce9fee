#!/usr/bin/python3
"""The matrix-free dual (solver.schur = "matrix_free": Q never formed, the QP's Newton steps by CG) against
the default dense route, end to end, on bodies other than the brick the unit tests use: the capped block
(two materials, rollers, prescribed displacement, pressure, gravity, a curved face with a gap), the
hexagonal prism (slip-dependent law) and the thin slab at h = 0.05. Each must converge, to the same
contact displacements within the QP's accuracy (1e-5 of max |u|, ten times below the fixed point's 1e-4),
in at most one fixed-point step more, with predicted steps where the dense route takes them (their
sensitivity by CG: 5 steps against 5 on the capped block, 2 of them predicted), and take Newton steps; on the slab the default QP must need
fewer products than the paper's MPGP alone on the same matrix-free dual (624 against 3 732 measured),
and its Newton steps' CG must use the two-level preconditioner (qp_coarse_products > 0); with
solver.qp_precision = "mixed" its products must go through the float copy of the factor
(qp_single_products > 0) to the same answer.

usage: check_matrix_free_bodies.py CONTACT3D SOURCE_DIR WORK_DIR
"""
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "pipeline"))
import c3d.run  # noqa: E402

CASES = [("capblock", []), ("hexprism", []), ("slab", ["mesh.parameters.h=0.05", 'contact.cell_size="2h"'])]


def solve(binary, source, scene, out, sets):
    scene_file = Path(source) / "pipeline" / "scenes" / f"{scene}.toml"
    subprocess.run(c3d.run.solve_command(binary, scene_file, out, ["output.steps=final", *sets]), check=True)
    return c3d.run.summary(out), c3d.run.face_displacements(out)


def main():
    binary, source, work = sys.argv[1], sys.argv[2], Path(sys.argv[3])
    failures = []
    for scene, sets in CASES:
        sd, ud = solve(binary, source, scene, work / f"{scene}_dense", sets)
        sm, um = solve(binary, source, scene, work / f"{scene}_matrix_free", [*sets, 'solver.schur="matrix_free"'])
        diff = c3d.run.largest_difference(um, ud)
        print(f"{scene}: steps {sd['fixed_point_iterations']} / {sm['fixed_point_iterations']}, n_mult {sd['n_mult']} / "
              f"{sm['n_mult']}, Newton steps {sd['qp_newton_steps']} / {sm['qp_newton_steps']}, route "
              f"{sm['schur_method']}, largest u difference {diff:.1e} of max |u|")
        if not (sd["converged"] and sm["converged"]):
            failures.append(f"{scene}: a run did not converge")
        if sm["schur_method"] != "matrix_free":
            failures.append(f"{scene}: the matrix-free run took {sm['schur_method']}")
        if sm["fixed_point_iterations"] > sd["fixed_point_iterations"] + 1:
            failures.append(f"{scene}: {sm['fixed_point_iterations']} fixed-point steps against "
                            f"{sd['fixed_point_iterations']}")
        predicted = [s.get("fixed_point", {}).get("predicted_steps", 0) for s in (sd, sm)]
        if predicted[0] > 0 and predicted[1] == 0:
            failures.append(f"{scene}: the matrix-free fixed point took no predicted step ({predicted[0]} dense)")
        if sm["qp_newton_steps"] <= 0:
            failures.append(f"{scene}: the matrix-free QP took no Newton step")
        if not diff < 1e-5:
            failures.append(f"{scene}: contact displacements differ by {diff:.1e}")
        if scene == "slab":
            sp, _ = solve(binary, source, scene, work / f"{scene}_matrix_free_mpgp",
                          [*sets, 'solver.schur="matrix_free"', 'solver.qp="mpgp"'])
            print(f"{scene}: MPGP alone on the matrix-free dual: n_mult {sp['n_mult']}")
            if not sm["n_mult"] < sp["n_mult"]:
                failures.append(f"{scene}: Newton steps by CG took {sm['n_mult']} products, MPGP alone {sp['n_mult']}")
            # Its products go through the factor, so CG deflates the coarse space (blocked products).
            if not 0 < sm.get("qp_coarse_products", 0) < sm["n_mult"]:
                failures.append(f"{scene}: the two-level CG computed {sm.get('qp_coarse_products')} coarse columns")
            # Single-precision products through a float copy of the factor ("auto" takes them from
            # 2 000 multipliers on; the slab here has fewer): used, and the dense route's answer.
            ss, us = solve(binary, source, scene, work / f"{scene}_matrix_free_single",
                           [*sets, 'solver.schur="matrix_free"', 'solver.qp_precision="mixed"'])
            single_diff = c3d.run.largest_difference(us, ud)
            print(f"{scene}: single products on the matrix-free dual: {ss['qp_single_products']} of n_mult "
                  f"{ss['n_mult']}, largest u difference {single_diff:.1e} of max |u|")
            if not (ss["converged"] and ss["qp_single_products"] > 0 and single_diff < 1e-5):
                failures.append(f"{scene}: with single products: converged {ss['converged']}, "
                                f"{ss['qp_single_products']} single products, u difference {single_diff:.1e}")
    if failures:
        print("FAILED:\n  " + "\n  ".join(failures))
        return 1
    print("ok: the matrix-free dual gives the dense route's answer")
    return 0


if __name__ == "__main__":
    sys.exit(main())
