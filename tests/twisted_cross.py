#!/usr/bin/env python3
"""A body held by contact alone, twisted to 97% of what its friction holds (tests/scenes/twisted_cross.toml):
the default run must converge, its friction torque equal to the applied one, k·J with J the footprint's
polar moment computed here from its two arms (the run once refused it: an accelerated input of the
successive approximations asked for radii that could not hold the turn)."""
import json
import os
import subprocess
import sys
import tempfile

binary, source = sys.argv[1], sys.argv[2]
scene = os.path.join(source, "tests", "scenes", "twisted_cross.toml")
k, arm, width = 0.048, 120.0, 30.0


def polar_moment(a, b):  # of an a x b rectangle about its centre
    return a * b * (a * a + b * b) / 12.0


applied = k * (2 * polar_moment(arm, width) - polar_moment(width, width))
with tempfile.TemporaryDirectory() as tmp:
    run = subprocess.run([binary, "solve", scene, "--quiet", "--out", tmp], capture_output=True, text=True)
    if run.returncode != 0:
        sys.exit(f"FAIL: exit {run.returncode}: {run.stderr.strip()}")
    summary = json.load(open(os.path.join(tmp, "summary.json")))
if summary["status"] != "converged":
    sys.exit(f"FAIL: status {summary['status']}")
torque = abs(summary["friction_torque"])
if abs(torque - applied) > 1e-6 * applied:
    sys.exit(f"FAIL: friction torque {torque:.6g} N mm, applied {applied:.6g}")
# The share of friction's hold the twist takes, 97% by the scene's construction (Coulomb's bound on a
# uniform pressure): measured by the run over all turns and slides, it must be that, and not warned.
share = summary.get("friction_hold_share")
if share is None or not 0.96 <= share <= 0.99:
    sys.exit(f"FAIL: friction_hold_share {share}, expected about 0.97")
if any("its limit" in w for w in summary["warnings"]):
    sys.exit("FAIL: friction at 97% of its hold warned as at its limit")
print(f"ok: converged in {summary['fixed_point_iterations']} steps, friction torque {torque:.6g} = applied {applied:.6g} N mm, "
      f"{100 * share:.2f}% of friction's hold")
