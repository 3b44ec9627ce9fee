#!/usr/bin/env python3
"""Friction at its limit is said (tests/scenes/brick_on_incline.toml): a brick held by contact alone on
a 20° incline, Coulomb F = tan 20° · s for s = 1 (at the limit: the slide down the slope undetermined),
1.0001 (just above: barely determined) and 1.05 (clear of it). The run's friction_hold_share must equal
the share computed here from its cells, |Σ λ_t A| / Σ c A (the slide down the slope: the work of the
friction forces against the most their bounds allow), and tan 20° / F; the warning must come exactly
where the share is within 0.1% of 1, naming the slide along y — also on an unstructured mesh, where the
least-squares minimum carries a remainder of a turn."""
import csv
import json
import math
import os
import subprocess
import sys
import tempfile

binary, source = sys.argv[1], sys.argv[2]
scene = os.path.join(source, "tests", "scenes", "brick_on_incline.toml")
slope = math.tan(math.radians(20))
failures = []
for scale, warned, wording in ((1.0, True, "friction is at its limit"), (1.0001, True, "friction is within"),
                               (1.05, False, None)):
    with tempfile.TemporaryDirectory() as tmp:
        run = subprocess.run([binary, "solve", scene, "--quiet", "--out", tmp, "--set",
                              f"friction.value={slope * scale!r}"], capture_output=True, text=True)
        if run.returncode != 0:
            failures.append(f"F = {scale} tan 20°: exit {run.returncode}: {run.stderr.strip()[:300]}")
            continue
        summary = json.load(open(os.path.join(tmp, "summary.json")))
        cells = list(csv.DictReader(open(os.path.join(tmp, "contact_cells.csv"))))
    t1 = sum(float(c["lambda_t1"]) * float(c["area"]) for c in cells)
    t2 = sum(float(c["lambda_t2"]) * float(c["area"]) for c in cells)
    bound = sum(float(c["radius"]) * float(c["area"]) for c in cells)
    from_cells = math.hypot(t1, t2) / bound
    share = summary.get("friction_hold_share")
    limit_warnings = [w for w in summary["warnings"] if "of its limit" in w or "at its limit" in w]
    line = f"F = {scale} tan 20°: share {share}, from the cells {from_cells:.9f}, tan 20°/F {1 / scale:.9f}"
    print(line)
    if share is None or abs(share - from_cells) > 1e-6 or abs(share - 1 / scale) > 1e-5:
        failures.append(line)
    if warned != bool(limit_warnings):
        failures.append(f"F = {scale} tan 20°: limit warning {'missing' if warned else 'given'}: {limit_warnings}")
    elif warned and not (limit_warnings[0].startswith(wording) and "a translation along (0, 1, 0)" in limit_warnings[0]):
        failures.append(f"F = {scale} tan 20°: warning does not say '{wording}' along y: {limit_warnings[0][:200]}")
# The same slope on an unstructured mesh (pipeline/scenes/brick_unstructured.toml) at 1.001 tan 20°: the
# least-squares minimum carries a turn a million times weaker than the slide, which was named "a rotation
# about the axis along (0, 0, 1) through (68350, …)"; it must be named the slide.
unstructured = os.path.join(source, "pipeline", "scenes", "brick_unstructured.toml")
with tempfile.TemporaryDirectory() as tmp:
    run = subprocess.run([binary, "solve", unstructured, "--quiet", "--out", tmp, "--set", "boundary.clamped=[]",
                          "--set", "boundary.traction=[]", "--set", "boundary.pressure=[]", "--set",
                          "material.body_force=[0.0, 26335.55103607649, -72356.33180051495]", "--set",
                          'friction.model="coulomb"', "--set", 'friction.law="constant"', "--set",
                          "friction.slip_bound=0", "--set", f"friction.value={slope * 1.001!r}"],
                         capture_output=True, text=True)
    named = [w for w in run.stderr.splitlines() if "of its limit" in w]
    print(f"unstructured, F = 1.001 tan 20°: exit {run.returncode}, {named[0][:120] if named else 'no warning'}")
    if run.returncode != 0 or not named or "along a translation along" not in named[0]:
        failures.append(f"unstructured brick at 1.001 tan 20°: exit {run.returncode}, warning {named}")
if failures:
    sys.exit("FAIL:\n" + "\n".join(failures))
print("ok: friction's share of its hold measured and the limit said")
