#!/usr/bin/python3
"""The distributed backend refuses, after MUMPS's analysis and before its factorization, what the
ranks' resources cannot hold — on every rank, with exit 2, one message and an unfinished output folder
(RUNNING, no summary.json):

--case disk: MUMPS's out-of-core factor on a disk without room for it, the message naming the
directory, its free room and the factor's size. Before, the factorization started and ran out of disk:
MUMPS's error (INFOG(1) = -90) in some runs, a rank waiting in MUMPS's asynchronous writes for good in
others (4 of 7 on a 4 MiB tmpfs). The full disk is a 1 MiB tmpfs mounted for the test (root only):
where it cannot be mounted the test reports itself skipped (exit 77), not passed.

--case memory: the brick n = 24 with 1 GB of address space per rank: the analysis's estimate for the
rank against what it can get, and the factor's size on the progress line before. Before, MUMPS failed
inside the factorization ("allocating 55250350 entries failed", INFOG(1) = -13) with no estimate.

--case blas: rank 1 alone with 450 MB of address space, too little for OpenBLAS's 128 MiB work space:
it retried its mapping for good inside MUMPS's factorization, every rank waiting; now every rank
reserves it first and rank 1's refusal names it.

usage: check_mpi_resources.py --mpi build/contact3d-mpi --mpiexec mpirun --source DIR --case disk|memory|blas
"""
import argparse
import os
import resource
import subprocess
import sys
import tempfile

parser = argparse.ArgumentParser()
parser.add_argument("--mpi", required=True)
parser.add_argument("--mpiexec", required=True)
parser.add_argument("--source", required=True)
parser.add_argument("--case", choices=["disk", "memory", "blas"], required=True)
args = parser.parse_args()


def run_refused(work, overrides, facts, stdout_facts=(), limit_bytes=None, rank1_limit_kb=None):
    out = os.path.join(work, "out")
    solve = [args.mpi, "solve", os.path.join(args.source, "pipeline", "scenes", "paper_brick.toml"),
             "--set", "mesh.generator=paper_brick", "--out", out]
    for o in overrides:
        solve += ["--set", o]
    if rank1_limit_kb:  # two app contexts: rank 1 under its own ulimit -v
        command = [args.mpiexec, "--bind-to", "none", "-np", "1", *solve, ":", "-np", "1", "sh", "-c",
                   f"ulimit -v {rank1_limit_kb}; exec " + " ".join(f"'{a}'" for a in solve)]
    else:
        command = [args.mpiexec, "-np", "2", "--bind-to", "none", *solve]

    def limit():
        if limit_bytes:
            resource.setrlimit(resource.RLIMIT_AS, (limit_bytes, limit_bytes))

    try:
        run = subprocess.run(command, capture_output=True, text=True, timeout=150, preexec_fn=limit)
    except subprocess.TimeoutExpired:
        sys.exit("FAIL: the run hung (killed after 150 s)")
    errors = [line for line in run.stderr.splitlines() if line.startswith("error:")]
    failures = []
    if run.returncode != 2:
        failures.append(f"exit code {run.returncode}, expected 2")
    if len(errors) != 1:
        failures.append(f"{len(errors)} error lines, expected one (rank 0's)")
    message = errors[0] if errors else ""
    failures += ["message lacks " + repr(f) for f in facts if f not in message]
    failures += ["progress lacks " + repr(f) for f in stdout_facts if f not in run.stdout]
    if os.path.exists(os.path.join(out, "summary.json")) or not os.path.exists(os.path.join(out, "RUNNING")):
        failures.append("the output folder looks finished")
    return run, message, failures


with tempfile.TemporaryDirectory(prefix="contact3d_mpi_resources_") as work:
    if args.case == "blas":
        run, message, failures = run_refused(
            work, ["mesh.n=4"], ["rank 1 failed to map OpenBLAS's work space", "address-space limit", "ulimit -v"],
            rank1_limit_kb=450000)
    elif args.case == "memory":
        run, message, failures = run_refused(
            work, ["mesh.n=24"],
            ["not enough memory for the factorization", "MUMPS's analysis estimates", "GiB on rank",
             "can get only", "solver.out_of_core_dir"],
            ["factor (MUMPS, 2 rank(s)): about", "GiB over all ranks", "GiB of memory on a rank"],
            limit_bytes=1000 * 10**6)
    else:
        disk = os.path.join(work, "disk")
        os.mkdir(disk)
        mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=1m", "tmpfs", disk], capture_output=True,
                                 text=True)
        if mounted.returncode != 0:
            print("skipped: cannot mount a 1 MiB tmpfs here (" + mounted.stderr.strip() + ")")
            sys.exit(77)
        try:
            run, message, failures = run_refused(
                work, ["mesh.n=8", "solver.out_of_core_dir=" + disk],
                ["solver.out_of_core_dir '" + disk + "'", "GiB free on rank", "the factor MUMPS would write there",
                 "point it to a disk with room"])
            if os.listdir(disk):
                failures.append("MUMPS's files were written: " + ", ".join(os.listdir(disk)))
        finally:
            subprocess.run(["umount", disk])
    if failures:
        print(run.stdout[-3000:], run.stderr[-3000:])
        sys.exit("FAIL: " + "; ".join(failures))
    print("ok:", message)
