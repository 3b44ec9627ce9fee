"""Run `contact3d solve` and read its summary.json and contact displacements."""
import csv
import json
import subprocess
import time
from pathlib import Path


def solve_command(binary, scene, out, sets=(), mesh=None, quiet=True, launcher=(), extra_args=()):
    """The argument list of one solve: scene, output folder, optional mesh, `extra_args` as given, then
    the `--set key=value` overrides (so they win over extra_args). `launcher` goes first, e.g.
    ["mpirun", "-np", "2"] for the distributed binary."""
    cmd = [str(x) for x in launcher] + [str(binary), "solve", str(scene), "--out", str(out)]
    if mesh is not None:
        cmd += ["--mesh", str(mesh)]
    cmd += list(extra_args)
    for s in sets:
        cmd += ["--set", s]
    if quiet:
        cmd.append("--quiet")
    return cmd


def solve(binary, scene, out, sets=(), mesh=None, quiet=True, timeout=None):
    """Runs one solve; returns (CompletedProcess with text stdout/stderr, wall seconds).

    Exit codes are contact3d's: 0 converged, 1 a named exit (see summary.json), 2 bad input.
    Raises subprocess.TimeoutExpired when `timeout` (s) passes.
    """
    cmd = solve_command(binary, scene, out, sets, mesh, quiet)
    t0 = time.time()
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    return proc, time.time() - t0


def summary(out):
    """summary.json of a finished solve in folder `out` as a dict."""
    return json.loads((Path(out) / "summary.json").read_text())


def face_displacements(out):
    """u on Γc of a finished solve in folder `out`: {node id: [u1, u2, u3]} from contact_nodes.csv."""
    with open(Path(out) / "contact_nodes.csv") as f:
        return {r["node"]: [float(r[k]) for k in ("u1", "u2", "u3")] for r in csv.DictReader(f)}


def largest_difference(u, reference):
    """The largest difference of two face_displacements() over the reference's nodes, relative to the
    reference's largest component."""
    scale = max(max(abs(x) for x in v) for v in reference.values())
    return max(abs(a - b) for n in reference for a, b in zip(u[n], reference[n])) / scale
