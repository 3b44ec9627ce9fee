#!/usr/bin/python3
"""The QP's Newton steps through the stability check's factor of Q (solver.qp_newton_systems = "auto",
qp/bordered_newton.hpp) against factoring each reduced system ("reduced"), end to end: the thin slab at
h = 0.03 (3468 multipliers, nearly all cells touching; at h = 0.035 and 0.05 the border is too large a
share for the route to pay once MPGP hands over to Newton steps after windows of 25 iterations), with the default single-precision factor (refined in double) and with
solver.qp_precision = "double" (a factor in double), under a slip-dependent law. Both routes must give
the same contact displacements to the QP's accuracy (its tolerance is 1e-6 of ‖h‖: 1e-5 of max |u|
allows for the two routes' different iteration paths, ten times below the fixed point's 1e-4) and the same number of
fixed-point steps, and the default must have taken the bordered route (summary.json's
qp_newton_steps_bordered > 0) while "reduced" never does.

usage: check_newton_systems.py CONTACT3D SOURCE_DIR WORK_DIR
"""
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "pipeline"))
import c3d.run  # noqa: E402


def solve(binary, source, out, sets):
    scene = Path(source) / "pipeline" / "scenes" / "slab.toml"
    common = ["mesh.parameters.h=0.03", 'contact.cell_size="2h"', "output.steps=final", 'friction.law="ramp"',
              "friction.high=0.3", "friction.low=0.2", "friction.t0=2e-7", "friction.param=2e6"]
    subprocess.run(c3d.run.solve_command(binary, scene, out, [*common, *sets]), check=True)
    return c3d.run.summary(out), c3d.run.face_displacements(out)


def main():
    binary, source, work = sys.argv[1], sys.argv[2], Path(sys.argv[3])
    failures = []
    for precision in ["auto", "double"]:
        runs = {}
        for route in ["auto", "reduced"]:
            runs[route] = solve(binary, source, work / f"{precision}_{route}",
                                [f'solver.qp_precision="{precision}"', f'solver.qp_newton_systems="{route}"'])
        (sa, ua), (sr, ur) = runs["auto"], runs["reduced"]
        diff = c3d.run.largest_difference(ua, ur)
        print(f"qp_precision={precision}: steps {sa['fixed_point_iterations']} / {sr['fixed_point_iterations']}, "
              f"Newton steps {sa['qp_newton_steps']} ({sa['qp_newton_steps_bordered']} bordered) / "
              f"{sr['qp_newton_steps']} ({sr['qp_newton_steps_bordered']}), largest u difference {diff:.1e} of max |u|")
        if not (sa["converged"] and sr["converged"]):
            failures.append(f"{precision}: a run did not converge")
        if sa["fixed_point_iterations"] != sr["fixed_point_iterations"]:
            failures.append(f"{precision}: fixed-point steps differ")
        if sa["qp_newton_steps_bordered"] <= 0:
            failures.append(f"{precision}: the default took no Newton step through the factor of Q")
        if sr["qp_newton_steps_bordered"] != 0:
            failures.append(f"{precision}: qp_newton_systems = reduced took the bordered route")
        if not diff < 1e-5:
            failures.append(f"{precision}: contact displacements differ by {diff:.1e}")
    if failures:
        print("FAILED:\n  " + "\n  ".join(failures))
        return 1
    print("ok: both routes give the same answer")
    return 0


if __name__ == "__main__":
    sys.exit(main())
