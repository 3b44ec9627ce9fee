#!/usr/bin/python3
"""The bordered Newton steps' switch from a single-precision factor of Q to one in double
(qp/bordered_newton.hpp), end to end: the thin slab lying free (pipeline/scenes/slab.toml with
boundary.clamped = [], h = 0.035, 2 523 multipliers, cond(Q) 6e6) with the default precision, whose
stability check's factor is single and refines slowly there, against the same solve with
solver.qp_precision = "double" (a factor in double from the start, nothing to switch). The fixed point is
asked to 1e-10, so the equality loop's inner solves go to 1e-12, which the switched factor's solves
missed when they were taken without refinement: the Newton steps stalled and MPGP crawled (16 977
products against 346, on two BLAS threads; on one the run happened to escape, so two are set here). The
default run must have switched (summary.json qp_bordered_factor_in_double), taken at most twice the double
run's products (measured: 538 against 345), and both must give the same contact displacements to 1e-8 of
max |u| (measured: 3e-10).

usage: check_factor_switch.py CONTACT3D SOURCE_DIR WORK_DIR
"""
import os
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "pipeline"))
import c3d.run  # noqa: E402


def solve(binary, source, out, precision):
    scene = Path(source) / "pipeline" / "scenes" / "slab.toml"
    sets = ["boundary.clamped=[]", "mesh.parameters.h=0.035", 'contact.cell_size="2h"', "output.steps=final", "solver.fixed_point_tol=1e-10",
            f'solver.qp_precision="{precision}"']
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "2"}
    subprocess.run(c3d.run.solve_command(binary, scene, out, sets), check=True, env=env)
    return c3d.run.summary(out), c3d.run.face_displacements(out)


def main():
    binary, source, work = sys.argv[1], sys.argv[2], Path(sys.argv[3])
    (sa, ua), (sd, ud) = (solve(binary, source, work / p, p) for p in ("auto", "double"))
    diff = c3d.run.largest_difference(ua, ud)
    print(f"auto: n_mult {sa['n_mult']}, switched {sa.get('qp_bordered_factor_in_double')}; double: n_mult "
          f"{sd['n_mult']}, switched {sd.get('qp_bordered_factor_in_double')}; largest u difference {diff:.1e} of max |u|")
    failures = []
    if not (sa["converged"] and sd["converged"]):
        failures.append("a run did not converge")
    if sa.get("qp_bordered_factor_in_double") is not True:
        failures.append("the default run did not switch to a factor of Q in double")
    if sd.get("qp_bordered_factor_in_double") is not False:
        failures.append("the double-precision run reports a switch it cannot have made")
    if not sa["n_mult"] <= 2 * sd["n_mult"]:
        failures.append(f"the default run took {sa['n_mult']} products, over twice the double run's")
    if not diff < 1e-8:
        failures.append(f"contact displacements differ by {diff:.1e}")
    if failures:
        print("FAILED:\n  " + "\n  ".join(failures))
        return 1
    print("ok: switched, same answer")
    return 0


if __name__ == "__main__":
    sys.exit(main())
