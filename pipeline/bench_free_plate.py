#!/usr/bin/python3
"""Contact-dominated bodies held by contact alone over a series of mesh sizes h: the free plate
(pipeline/scenes/free_plate.toml, 1 x 1 x 0.02 m, nothing clamped, Coulomb 0.3; `make bench-free-plate`)
and, with --body slab, the free slab (pipeline/scenes/slab.toml with boundary.clamped = [], 2 x 2 x
0.05 m, Tresca 0.3; `make bench-free-slab`).

Their dual QP carries the equality constraints Gλ = e of the rigid motions the contact holds
(qp/dual_qp_solver.hpp), and their Q is ill-conditioned (bending). Per h one CLI run of the
default solver with `solver.reference_factorization = true` (cells of 2h, as bench_slab.py), so that
    ratio = (assembly + contact + factorization + dual + stability + dual_solve) / reference_factorization
is taken inside one process. With --bin-before, the same runs of another binary (an earlier commit)
in the rows below, labelled with its name.

Writes <out>/free_plate.{csv,md} (or free_slab.{csv,md}).
"""
import argparse
import csv
import os
import subprocess
from pathlib import Path

from bench_slab import ROOT, STAGES, run

SCENES = ROOT / "pipeline" / "scenes"
# Per body: its scene, the scene's settings that make it free, its geometry's gmsh parameters besides h,
# the default series of h, and the report's name and description.
BODIES = {
    "plate": {"scene": SCENES / "free_plate.toml", "sets": [], "geo": "free_plate.geo", "params": {"T": 0.02},
              "h": "0.04,0.025,0.02,0.0125", "name": "free_plate", "title": "Free plate held by contact alone",
              "what": "Plate 1 x 1 x 0.02 m lying free (pipeline/scenes/free_plate.toml), Coulomb 0.3"},
    "slab": {"scene": SCENES / "slab.toml", "sets": ["boundary.clamped=[]"], "geo": "slab.geo",
             "params": {"Lx": 2, "Ly": 2, "t": 0.05}, "h": "0.05,0.035,0.025,0.0175", "name": "free_slab",
             "title": "Free slab held by contact alone",
             "what": "Slab 2 x 2 x 0.05 m lying free (pipeline/scenes/slab.toml, boundary.clamped = []), "
                     "Tresca 0.3"},
}


def measure(body, binary, label, h, msh, work, timeout):
    summ, rss, wall, code = run(binary, work / f"h{h:g}_{label}", body["sets"], mesh=msh, timeout=timeout,
                                scene=body["scene"])
    if summ is None:
        return {"h": h, "binary": label, "status": f"timeout {timeout:g} s"}
    t = summ["time_s"]
    solve = sum(t.get(k, 0.0) for k in STAGES)
    row = {"h": h, "binary": label, "status": summ["status"], "n_p": summ["n_primal"], "n_dual": summ["n_dual"],
           "steps": summ["fixed_point_iterations"], "qp_iterations": summ["qp_iterations"],
           "newton_steps": summ.get("qp_newton_steps", 0), "n_mult": summ["n_mult"],
           "factor_in_double": summ.get("qp_bordered_factor_in_double", False),
           "cond_Q": summ.get("stability_condition_estimate"),
           "kkt_max": max(v for v in summ["kkt"].values() if isinstance(v, (int, float))),
           "solve_s": round(solve, 3), "reference_factorization_s": round(t["reference_factorization"], 3),
           "ratio": round(solve / t["reference_factorization"], 2), "peak_rss_mib": round(rss), "wall_s": round(wall, 2)}
    for k in STAGES:
        row[f"t_{k}"] = round(t.get(k, 0.0), 3)
    print(f"h={h:<7g} {label:8s} n_dual {row['n_dual']:5d} steps {row['steps']:2d} qp_it {row['qp_iterations']:5d} "
          f"newton {row['newton_steps']:4d} n_mult {row['n_mult']:6d} dual_solve {row['t_dual_solve']:7.2f} s "
          f"ratio {row['ratio']:6.2f} kkt {row['kkt_max']:.1e} {row['status']}", flush=True)
    return row


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--body", choices=sorted(BODIES), default="plate")
    ap.add_argument("--bin", default=str(ROOT / "build" / "contact3d"))
    ap.add_argument("--bin-before", help="a second binary (an earlier commit) run on the same meshes")
    ap.add_argument("--before-label", default="before")
    ap.add_argument("--h", help="mesh sizes, coarse to fine (default: the body's series)")
    ap.add_argument("--timeout", type=float, default=1800)
    ap.add_argument("--out", default=str(ROOT / "results" / "runs" / "bench_free_plate"))
    ap.add_argument("--work", help="meshes and runs (default: /tmp/contact3d_bench_<name>)")
    args = ap.parse_args()
    body = BODIES[args.body]
    name = body["name"]
    out_dir, work = Path(args.out), Path(args.work or f"/tmp/contact3d_bench_{name}")
    out_dir.mkdir(parents=True, exist_ok=True)
    work.mkdir(parents=True, exist_ok=True)
    binaries = [(args.bin, "this")] + ([(args.bin_before, args.before_label)] if args.bin_before else [])
    rows = []
    for h in [float(x) for x in (args.h or body["h"]).split(",")]:
        # Mesh once, then every run reads the same file (a frictionless run, as bench_slab.py meshes, is
        # refused here: friction alone holds the body's slide).
        msh = work / f"h{h:g}" / "mesh.msh"
        msh.parent.mkdir(parents=True, exist_ok=True)
        params = [a for k, v in {"h": h, **body["params"]}.items() for a in ("-setnumber", k, f"{v}")]
        subprocess.run(["gmsh", "-3", *params, "-format", "msh41", str(ROOT / "geo" / body["geo"]), "-o", str(msh)],
                       check=True, stdout=subprocess.DEVNULL)
        for binary, label in binaries:
            rows.append(measure(body, binary, label, h, msh, work, args.timeout))
    keys = list(dict.fromkeys(k for r in rows for k in r))
    with open(out_dir / f"{name}.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)
    threads = os.environ.get("OPENBLAS_NUM_THREADS", "(default)")
    target = "bench-free-plate" if args.body == "plate" else "bench-free-slab"
    L = [f"# {body['title']}: the dual solve against the factorization\n",
         f"Generated by `make {target}` (pipeline/bench_free_plate.py --body {args.body}; "
         f"OPENBLAS_NUM_THREADS={threads}). {body['what']}, cells of 2h, default solver. `ratio` = (assembly + "
         "contact + factorization + forming Q + stability check + dual solve) / one CHOLMOD factorization of K in the same process. `double`: the Newton steps through the factor of Q "
         "switched to one in double (summary.json qp_bordered_factor_in_double). `binary`: this = the binary "
         "benchmarked"
         + (f", {args.before_label} = {args.bin_before}" if args.bin_before else "") + ". Wall seconds, 2-core machine.\n",
         "| h | binary | n_p | multipliers | steps | QP it. | Newton | n_mult | double | factor. | stability | "
         "dual solve | ratio | peak MiB | cond(Q) | KKT max | status |",
         "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if "n_p" not in r:
            L.append(f"| {r['h']} | {r['binary']} | | | | | | | | | | | | | | | {r['status']} |")
            continue
        L.append(f"| {r['h']} | {r['binary']} | {r['n_p']} | {r['n_dual']} | {r['steps']} | {r['qp_iterations']} | "
                 f"{r['newton_steps']} | {r['n_mult']} | {'yes' if r['factor_in_double'] else 'no'} | "
                 f"{r['t_factorization']:.2f} | {r['t_stability']:.2f} | "
                 f"{r['t_dual_solve']:.2f} | {r['ratio']:.2f} | {r['peak_rss_mib']} | {r['cond_Q']:.1e} | "
                 f"{r['kkt_max']:.1e} | {r['status']} |")
    (out_dir / f"{name}.md").write_text("\n".join(L) + "\n")
    print(f"wrote {out_dir / f'{name}.md'}")


if __name__ == "__main__":
    main()
