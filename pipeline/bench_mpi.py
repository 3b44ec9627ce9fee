#!/usr/bin/python3
"""Benchmark of the distributed backend (issue 17): the paper's brick at several n, solved by the
serial binary (CHOLMOD, augmented factor) and by `mpirun -np P contact3d-mpi` (PETSc + MUMPS) for
each P, every run with solver.reference_factorization = true so that its total / one CHOLMOD
factorization of K is measured inside the same process (on rank 0 for the MPI runs).

Per run: time per stage, factor nonzeros (nnz(L) for CHOLMOD, MUMPS's INFOG(29) entries), peak
resident memory of every rank, the ratio (solve stages) / (one CHOLMOD factorization), and the
largest difference of u on Γc to the serial run (relative). Figures are measured, not modelled.

usage: bench_mpi.py --serial build/contact3d --mpi build/contact3d-mpi [--n 16 24 32] [--np 1 2]
                    [--out results/runs/distributed.md]
"""
import argparse
import csv
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

import c3d.run

HERE = os.path.dirname(os.path.abspath(__file__))
SCENE = os.path.join(HERE, "scenes", "paper_brick.toml")
ROUTE_LABELS = {"mumps": "MUMPS, our ND", "mumps_ooc": "MUMPS, our ND, out of core",
                "mumps_petsc": "MUMPS via PETSc (AMD)"}
STAGES = ["assembly", "contact", "factorization", "dual", "stability", "dual_solve", "postprocess"]


def run(cmd, out, n, extra=()):
    *launcher, binary = cmd
    argv = c3d.run.solve_command(binary, SCENE, out, ["mesh.generator=paper_brick", f"mesh.n={n}",
                                                     "solver.reference_factorization=true", "output.steps=final",
                                                     *extra],
                                 launcher=launcher)
    t0 = time.time()
    p = subprocess.run(argv, capture_output=True, text=True)
    wall = time.time() - t0
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(argv)}: exit {p.returncode}: {p.stderr[-500:]}")
    s = json.load(open(os.path.join(out, "summary.json")))
    return s, wall


def binding(ranks):
    """Open MPI binds each rank to one core when np <= 2, which leaves np = 1 one core for its BLAS
    threads (MUMPS factorization 5.2 s against 3.6 s unbound on the n = 24 brick): fewer ranks than
    cores run unbound, as a user would run them."""
    return ["--bind-to", "none"] if ranks < (os.cpu_count() or 1) else []


def face_u(out):
    with open(os.path.join(out, "contact_nodes.csv")) as f:
        return np.array([[float(r[k]) for k in ("u1", "u2", "u3")] for r in csv.DictReader(f)])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--serial", required=True)
    ap.add_argument("--mpi", required=True)
    ap.add_argument("--mpiexec", default="mpirun")
    ap.add_argument("--n", type=int, nargs="+", default=[16, 24, 32])
    ap.add_argument("--np", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--routes", nargs="+", default=["mumps", "mumps_ooc", "mumps_petsc"],
                    help="solver.schur values: mumps (MUMPS called directly, our nested dissection), "
                         "mumps_ooc (the same with the factor out of core: solver.out_of_core_dir in the run's "
                         "temporary folder), mumps_petsc (through PETSc, MUMPS's AMD)")
    ap.add_argument("--out", default=os.path.join(HERE, "..", "results", "runs", "distributed.md"))
    args = ap.parse_args()
    os.environ.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
    os.environ.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
    rows = []
    with tempfile.TemporaryDirectory(prefix="c3d_bench_mpi_") as tmp:
        ooc_dir = os.path.join(tmp, "ooc_files")
        os.makedirs(ooc_dir)
        route_sets = {"mumps": ["solver.schur=mumps"], "mumps_petsc": ["solver.schur=mumps_petsc"],
                      "mumps_ooc": ["solver.schur=mumps", f"solver.out_of_core_dir={ooc_dir}"]}
        for n in args.n:
            serial_dir = os.path.join(tmp, f"serial{n}")
            configs = [("CHOLMOD (serial)", [args.serial], serial_dir, [])]
            configs += [(f"{ROUTE_LABELS[route]} np={p}", [args.mpiexec, "-np", str(p), *binding(p), args.mpi],
                         os.path.join(tmp, f"{route}_np{p}_{n}"), route_sets[route])
                        for route in args.routes for p in args.np]
            for label, cmd, out, extra in configs:
                s, wall = run(cmd, out, n, extra)
                t = s["time_s"]
                solve = sum(t.get(k, 0.0) for k in STAGES)
                u_ref, u = face_u(serial_dir), face_u(out)
                row = {"n": n, "run": label, "n_p": s["n_primal"], "n_d": s["n_dual"],
                       "it": s["fixed_point_iterations"], "n_mult": s["n_mult"],
                       "factorization_s": t.get("factorization", 0), "dual_s": t.get("dual", 0),
                       "dual_solve_s": t.get("dual_solve", 0), "postprocess_s": t.get("postprocess", 0),
                       "solve_s": solve, "reference_s": t.get("reference_factorization", float("nan")),
                       "ratio": solve / t.get("reference_factorization", float("nan")),
                       "factor_nonzeros": s["factor_nonzeros"],
                       "peak_mib": s["backend"]["peak_memory_mib_per_rank"],
                       "du": float(np.abs(u - u_ref).max() / np.abs(u_ref).max()), "wall_s": wall}
                rows.append(row)
                print(f"n={n:3d} {label:30s} solve {solve:7.2f} s (factorization {row['factorization_s']:6.2f}, dual "
                      f"{row['dual_s']:5.2f}, QP {row['dual_solve_s']:5.2f}) ratio {row['ratio']:5.2f} "
                      f"nnz(L) {row['factor_nonzeros']:.3g} peak MiB/rank {[round(m) for m in row['peak_mib']]} "
                      f"du {row['du']:.1e}", flush=True)
    write_report(args, rows)
    return 0


def write_report(args, rows):
    L = ["# Distributed backend (MUMPS 5.5 under Open MPI, PETSc 3.18) against the serial CHOLMOD path", "",
         f"Generated by `bench_mpi.py` (`make bench-mpi`) on {time.strftime('%Y-%m-%d')}: the paper's brick, "
         "default scene (slip-dependent law), `output.steps = final`. ratio = (assembly + contact + factorization + "
         "dual + stability + QP + postprocess) / one CHOLMOD factorization of K timed in the same process "
         "(rank 0). nnz(L): CHOLMOD's factor of [K 𝔹ᵀ; 𝔹 σI], or MUMPS's INFOG(29) entries of the factor of "
         "[K 𝔹ᵀ; 𝔹 0]. 'MUMPS, our ND': MUMPS called directly with the nested dissection CHOLMOD's path uses "
         "as its pivot order (ICNTL(7) = 1); 'via PETSc (AMD)': PETSc's MUMPS interface, which cannot pass an "
         "ordering with a Schur complement, so MUMPS orders by AMD (Debian's MUMPS has no METIS); 'out of core': "
         "the direct route with the factor in files (solver.out_of_core_dir on the same disk, MUMPS's ICNTL(22) = 1), "
         "read back in every solve. Peak memory: each rank's peak "
         "resident set at the end of the solve. Ranks fewer than the cores run with `--bind-to none` (Open MPI binds "
         "each rank to one core by default, which leaves one rank's BLAS threads a single core). du: largest difference of u on Γc to the serial run, relative.", "",
         "| n | run | n_p | n_d | it | n_mult | factorization (s) | Q + h (s) | QP (s) | solve (s) | × serial solve | "
         "ratio | nnz(L) | peak MiB per rank | largest rank / serial peak | du |",
         "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    serial = {r["n"]: r for r in rows if r["run"].startswith("CHOLMOD")}
    for r in rows:
        base = serial[r["n"]]
        L.append(f"| {r['n']} | {r['run']} | {r['n_p']} | {r['n_d']} | {r['it']} | {r['n_mult']} | "
                 f"{r['factorization_s']:.2f} | {r['dual_s']:.2f} | {r['dual_solve_s']:.2f} | {r['solve_s']:.2f} | "
                 f"{r['solve_s'] / base['solve_s']:.2f} | {r['ratio']:.2f} | {r['factor_nonzeros']:.3g} | "
                 f"{' / '.join(str(round(m)) for m in r['peak_mib'])} | {max(r['peak_mib']) / base['peak_mib'][0]:.2f} | "
                 f"{r['du']:.1e} |")
    du_max = max(r["du"] for r in rows)
    L += ["", f"du (largest over the MUMPS runs: {du_max:.1e}): Q differs in its last digits between the "
          "factorizations, so the QP takes other iteration paths; with the QP tolerance tied to the fixed point's "
          "progress (solver.qp_rtol_per_err) the answers agree to that level (tests/check_mpi.py requires 1e-8 on "
          "the n = 8 brick, the holed prism and the PETSc route).", ""]
    with open(os.path.splitext(args.out)[0] + ".json", "w") as f:
        json.dump(rows, f, indent=1)
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    with open(args.out, "w") as f:
        f.write("\n".join(L) + "\n")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    sys.exit(main())
