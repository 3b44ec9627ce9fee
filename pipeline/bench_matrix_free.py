#!/usr/bin/python3
"""The matrix-free dual (solver.schur = "matrix_free": Q never formed) against the default dense route on
the same scenes, one process each: what the route costs where a face is solved without its dense Q, with
the default QP (Newton steps by preconditioned CG there) and with the paper's MPGP alone.
`make bench-matrix-free` runs it.

Per case and route: the solve's stages (factorization, dual = forming Q, or h and Q's diagonal with the
forward-solved rows W; stability; dual solve), QP iterations, n_mult (products with Q, each one a full
K⁻¹ solve or a product Wᵀ(Wv) on the matrix-free route, or a column of a blocked solve), the ratio of the solve to one CHOLMOD
factorization of K in the same process (solver.reference_factorization), the peak memory of the child, and
the largest difference of u on Γc between the two routes relative to its largest value.

Writes <out>/matrix_free.md and <out>/matrix_free.json.
"""
import argparse
import csv
import json
import os
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "pipeline"))
import c3d.run  # noqa: E402

STAGES = ["assembly", "contact", "factorization", "dual", "stability", "dual_solve", "postprocess"]
# (label, scene, overrides): a body whose face is small against its volume (W kept) and the thin slab,
# whose forward-solved rows reach most of the factor (products by full solves).
CASES = [
    ("paper brick n = 16, ramp law", "paper_brick.toml", ["mesh.generator=paper_brick", "mesh.n=16"]),
    ("slab h = 0.05, constant", "slab.toml", ['contact.cell_size="2h"', "mesh.parameters.h=0.05"]),
    ("slab h = 0.035, constant", "slab.toml", ['contact.cell_size="2h"', "mesh.parameters.h=0.035"]),
    ("slab h = 0.025, constant", "slab.toml", ['contact.cell_size="2h"', "mesh.parameters.h=0.025"]),
    ("slab h = 0.0175, constant", "slab.toml", ['contact.cell_size="2h"', "mesh.parameters.h=0.0175"]),
]
# The default QP ("auto": MPGP with Newton steps, by CG without Q's entries) on both routes, the
# matrix-free one again with the diagonal as the CG's fine level instead of the lumped preconditioner,
# and the paper's MPGP alone on the matrix-free one, except where it takes many minutes (MPGP_UP_TO cases).
ROUTES = {"dense (auto)": [], "matrix-free": ['solver.schur="matrix_free"'],
          "matrix-free, diagonal CG": ['solver.schur="matrix_free"', 'solver.qp_cg_preconditioner="diagonal"'],
          "matrix-free, mpgp": ['solver.schur="matrix_free"', 'solver.qp="mpgp"']}
MPGP_UP_TO = 3


def run(binary, scene, out, sets, timeout):
    """One solve; returns (summary, peak MiB, wall s)."""
    args = c3d.run.solve_command(binary, ROOT / "pipeline" / "scenes" / scene, out,
                                 ["solver.reference_factorization=true", "output.steps=final", *sets])
    t0 = time.monotonic()
    proc = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    while True:  # os.wait4 gives this child's own peak memory
        pid, status, usage = os.wait4(proc.pid, os.WNOHANG)
        if pid:
            break
        if time.monotonic() - t0 > timeout:
            proc.kill()
            os.wait4(proc.pid, 0)
            raise RuntimeError(f"timeout after {timeout} s: {' '.join(args)}")
        time.sleep(0.1)
    code = os.waitstatus_to_exitcode(status)
    if code != 0:
        raise RuntimeError(f"exit {code}: {' '.join(args)}\n{proc.stderr.read()[-2000:]}")
    return c3d.run.summary(out), usage.ru_maxrss / 1024.0, time.monotonic() - t0


def face_u(out):
    with open(Path(out) / "contact_nodes.csv") as f:
        return [[float(r[k]) for k in ("u1", "u2", "u3")] for r in csv.DictReader(f)]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", default=str(ROOT / "build" / "contact3d"))
    ap.add_argument("--out", default=str(ROOT / "results" / "runs" / "bench"))
    ap.add_argument("--work", default="/tmp/contact3d_bench_matrix_free")
    ap.add_argument("--timeout", type=float, default=1800)
    args = ap.parse_args()
    rows = []
    for index, (label, scene, sets) in enumerate(CASES):
        dense_u = None
        for route, route_sets in ROUTES.items():
            if "mpgp" in route and index >= MPGP_UP_TO:
                continue
            out = Path(args.work) / f"{label}_{route}".replace(" ", "_").replace(",", "").replace("=", "")
            s, peak, wall = run(args.bin, scene, out, [*sets, *route_sets], args.timeout)
            t = s["time_s"]
            solve = sum(t.get(k, 0.0) for k in STAGES)
            u = face_u(out)
            if dense_u is None:
                dense_u = u
            scale = max(abs(x) for row in dense_u for x in row)
            du = max(abs(a - b) for ra, rb in zip(u, dense_u) for a, b in zip(ra, rb)) / scale
            row = {"case": label, "route": route, "method": s["schur_method"], "n_p": s["n_primal"],
                   "multipliers": s["n_dual"], "steps": s["fixed_point_iterations"], "qp_iterations": s["qp_iterations"],
                   "n_mult": s["n_mult"], "factor_nonzeros": s["factor_nonzeros"],
                   **{f"{k}_s": t.get(k, 0.0) for k in ("factorization", "dual", "stability", "dual_solve")},
                   "reference_factorization_s": t["reference_factorization"],
                   "ratio": solve / t["reference_factorization"], "peak_mib": peak, "wall_s": wall,
                   "cond_estimate": s["stability_condition_estimate"], "du_vs_dense": du}
            rows.append(row)
            print(f"{label:30s} {route:24s} ratio {row['ratio']:7.2f} dual solve {row['dual_solve_s']:7.2f} s "
                  f"QP it {row['qp_iterations']:6d} n_mult {row['n_mult']:6d} peak {peak:6.0f} MiB du {du:.1e}",
                  flush=True)
    Path(args.out).mkdir(parents=True, exist_ok=True)
    (Path(args.out) / "matrix_free.json").write_text(json.dumps(rows, indent=1))
    lines = ["# The matrix-free dual against the dense route", "",
             f"Generated by `make bench-matrix-free` (pipeline/bench_matrix_free.py --bin {args.bin}). One process per "
             "row; `ratio` = (assembly + contact + factorization + dual + stability + dual solve + postprocess) / one "
             "CHOLMOD factorization of K in the same process. `dual`: forming Q (dense), or h, Q's diagonal and the "
             "forward-solved rows W (matrix-free). QP `auto` takes Newton steps, their reduced systems by CG on the "
             "matrix-free route with a two-level preconditioner where products go through the factor: aggregates solved "
             "exactly, the rest by FETI's lumped preconditioner (`diagonal CG`: by the diagonal, solver.qp_cg_preconditioner "
             "= \"diagonal\"); n_mult counts the CG "
             "products and the coarse space's columns, which blocked solves compute at a sixth to an eighth of a product's "
             "time each; `mpgp` is the paper's algorithm alone. `du`: largest difference of u on Γc from the dense route's, "
             "relative to its largest value. Wall seconds, 2-core machine.", "",
             "| case | route | multipliers | steps | QP it. | n_mult | factor. | dual | stability | dual solve | ratio | "
             "peak MiB | cond(Q) est. | du |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['case']} | {r['route']} | {r['multipliers']} | {r['steps']} | {r['qp_iterations']} | "
                     f"{r['n_mult']} | {r['factorization_s']:.2f} | {r['dual_s']:.2f} | {r['stability_s']:.2f} | "
                     f"{r['dual_solve_s']:.2f} | {r['ratio']:.2f} | {r['peak_mib']:.0f} | {r['cond_estimate']:.3g} | "
                     f"{r['du_vs_dense']:.1e} |")
    (Path(args.out) / "matrix_free.md").write_text("\n".join(lines) + "\n")
    print(f"wrote {Path(args.out) / 'matrix_free.md'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
