#!/usr/bin/python3
"""MUMPS's out-of-core factor on a disk without room for it is refused before the factorization, on
every rank, with exit 2 and a message naming the directory, its free room and the factor's size, and
the output folder is left unfinished (RUNNING, no summary.json). Before, the factorization started and
ran out of disk: MUMPS's error (INFOG(1) = -90) in some runs, a rank waiting in MUMPS's asynchronous
writes for good in others (4 of 7 on a 4 MiB tmpfs).

The full disk is a 1 MiB tmpfs mounted for the test (root only): where it cannot be mounted the test
reports itself skipped (exit 77), not passed.

usage: check_mpi_ooc_room.py --mpi build/contact3d-mpi --mpiexec mpirun --source DIR
"""
import argparse
import os
import subprocess
import sys
import tempfile

parser = argparse.ArgumentParser()
parser.add_argument("--mpi", required=True)
parser.add_argument("--mpiexec", required=True)
parser.add_argument("--source", required=True)
args = parser.parse_args()

with tempfile.TemporaryDirectory(prefix="contact3d_ooc_room_") as work:
    disk = os.path.join(work, "disk")
    os.mkdir(disk)
    mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=1m", "tmpfs", disk], capture_output=True, text=True)
    if mounted.returncode != 0:
        print("skipped: cannot mount a 1 MiB tmpfs here (" + mounted.stderr.strip() + ")")
        sys.exit(77)
    try:
        out = os.path.join(work, "out")
        command = [args.mpiexec, "-np", "2", "--bind-to", "none", args.mpi, "solve",
                   os.path.join(args.source, "pipeline", "scenes", "paper_brick.toml"),
                   "--set", "mesh.generator=paper_brick", "--set", "mesh.n=8",
                   "--set", "solver.out_of_core_dir=" + disk, "--out", out, "--quiet"]
        try:
            run = subprocess.run(command, capture_output=True, text=True, timeout=120)
        except subprocess.TimeoutExpired:
            sys.exit("FAIL: the run with a full out-of-core disk hung (killed after 120 s)")
        errors = [line for line in run.stderr.splitlines() if line.startswith("error:")]
        failures = []
        if run.returncode != 2:
            failures.append(f"exit code {run.returncode}, expected 2")
        if len(errors) != 1:
            failures.append(f"{len(errors)} error lines, expected one (rank 0's)")
        message = errors[0] if errors else ""
        for fact in ["solver.out_of_core_dir '" + disk + "'", "GiB free on rank", "the factor MUMPS would write there",
                     "point it to a disk with room"]:
            if fact not in message:
                failures.append("message lacks " + repr(fact))
        if os.path.exists(os.path.join(out, "summary.json")) or not os.path.exists(os.path.join(out, "RUNNING")):
            failures.append("the output folder looks finished")
        if os.listdir(disk):
            failures.append("MUMPS's files were written: " + ", ".join(os.listdir(disk)))
        if failures:
            print(run.stdout[-2000:], run.stderr[-2000:])
            sys.exit("FAIL: " + "; ".join(failures))
        print("ok:", message)
    finally:
        subprocess.run(["umount", disk])
