#!/usr/bin/python3
"""Contact-dominated bodies: the thin slab (geo/slab.geo, 2 x 2 x 0.05 m, sides clamped, a patch
pressed and pushed) over a series of mesh sizes h, with the QP solvers side by side. `make
bench-slab` runs it.

For every (h, law, qp) one CLI run with `solver.reference_factorization = true`, so that
    ratio = (assembly + contact + factorization + dual + stability + dual_solve) / reference_factorization
is taken inside one process (reference: CHOLMOD's own analyze + factorize of K). Reported per run:
the time of each stage, QP iterations, Newton steps, products Q·v (n_mult), seconds per product of
the MPGP-only runs, peak memory (the child's ru_maxrss) and cond(Q). Laws: the scene's constant
coefficient 0.3 (one Tresca solve) and the paper's ramp (6.1) placed on the slab's own slip scale s
(the largest slip of the constant run): 0.3 below 0.2 s falling to 0.2 over a width s (`make
robustness` runs the harsher laws: steep ramps, jumps, slip weakening).

Writes <out>/slab.csv and <out>/slab.md.
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

SCENE = ROOT / "pipeline" / "scenes" / "slab.toml"
STAGES = ["assembly", "contact", "factorization", "dual", "stability", "dual_solve"]


def run(binary, out, sets, mesh=None, timeout=None, scene=SCENE):
    """One solve of `scene`; returns (summary dict or None on timeout, peak RSS MiB, wall s, exit code)."""
    # Cells of 2h throughout: the default contact.cell_size = "auto" solves a case a second time with cells
    # of 1.5h where the penetration exceeds 10% (a slab thinner than a cell may); this benchmark measures
    # one solve.
    args = c3d.run.solve_command(binary, scene, out, ["solver.reference_factorization=true", 'contact.cell_size="2h"',
                                                      *sets], mesh=mesh)
    Path(out).mkdir(parents=True, exist_ok=True)
    t0 = time.monotonic()
    with open(Path(out).parent / (Path(out).name + ".stderr"), "w+") as err:
        proc = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=err)
        while True:  # os.wait4 gives this child's own peak memory
            pid, status, usage = os.wait4(proc.pid, os.WNOHANG)
            if pid:
                break
            if timeout and time.monotonic() - t0 > timeout:
                proc.kill()
                os.wait4(proc.pid, 0)
                return None, 0.0, time.monotonic() - t0, "timeout"
            time.sleep(0.2)
        code = os.waitstatus_to_exitcode(status)
        if code not in (0, 1):
            err.seek(0)
            raise RuntimeError(f"run failed ({code}): {' '.join(args)}\n{err.read()[-2000:]}")
    wall = time.monotonic() - t0
    return json.loads((Path(out) / "summary.json").read_text()), usage.ru_maxrss / 1024.0, wall, code


def slip_scale(out):
    with open(Path(out) / "contact_nodes.csv") as f:
        return max(float(r["wt_norm"]) for r in csv.DictReader(f))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default=str(ROOT / "build" / "contact3d"))
    ap.add_argument("--h", default="0.05,0.035,0.025,0.0175", help="mesh sizes, coarse to fine")
    ap.add_argument("--qps", default="auto,auto:double,ssn,mpgp",
                    help="solver.qp values to compare; qp:precision also sets solver.qp_precision (auto:double is "
                         "the default solver with every product in double)")
    ap.add_argument("--compare-max-multipliers", type=int, default=5000,
                    help="above this many multipliers run only qp=auto (the others take minutes to an hour per solve)")
    ap.add_argument("--timeout", type=float, default=1800)
    ap.add_argument("--out", default=str(ROOT / "results" / "runs" / "bench_slab"))
    ap.add_argument("--work", default="/tmp/contact3d_bench_slab")
    args = ap.parse_args()
    out_dir, work = Path(args.out), Path(args.work)
    out_dir.mkdir(parents=True, exist_ok=True)
    work.mkdir(parents=True, exist_ok=True)
    env_note = f"OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS', '(default)')}"

    rows = []
    for h in [float(x) for x in args.h.split(",")]:
        hw = work / f"h{h:g}"
        # Mesh once (through the scene's gmsh call), then every run reads the same file.
        mesh_run = hw / "mesh_run"
        s, _, _, _ = run(args.bin, mesh_run, [f"mesh.parameters.h={h}", "friction.law=none",
                                              "solver.reference_factorization=false"])
        msh = mesh_run / "mesh.msh"
        scale = None
        for law in ["constant", "ramp"]:
            law_sets = [] if law == "constant" else [
                "friction.law=ramp", "friction.high=0.3", "friction.low=0.2", f"friction.t0={0.2 * scale:.6g}",
                f"friction.param={2.0 / scale:.6g}"]
            for qp in args.qps.split(","):
                qp_name, _, precision = qp.partition(":")
                out = hw / f"{law}_{qp_name}_{precision or 'default'}"
                n_dual = 3 * s["n_cells"]  # with friction
                if qp_name != "auto" and n_dual > args.compare_max_multipliers:
                    print(f"skip h={h} {law} {qp} ({n_dual} multipliers > --compare-max-multipliers)", flush=True)
                    continue
                precision_set = [f"solver.qp_precision={precision}"] if precision else []
                summ, rss, wall, code = run(args.bin, out, [f"solver.qp={qp_name}", *precision_set, *law_sets], mesh=msh,
                                            timeout=args.timeout)
                if summ is None:
                    rows.append({"h": h, "law": law, "qp": qp, "status": f"timeout {args.timeout:g} s"})
                    print(f"h={h} {law} {qp}: timeout", flush=True)
                    continue
                if law == "constant" and scale is None:
                    scale = slip_scale(out)
                t = summ["time_s"]
                solve = sum(t.get(k, 0.0) for k in STAGES)
                ref = t.get("reference_factorization", float("nan"))
                products = summ["n_mult"]
                row = {"h": h, "law": law, "qp": qp, "status": summ["status"], "n_p": summ["n_primal"],
                       "n_dual": summ["n_dual"], "steps": summ["fixed_point_iterations"],
                       "qp_iterations": summ["qp_iterations"], "newton_steps": summ.get("qp_newton_steps", 0),
                       "n_mult": products, "single_products": summ.get("qp_single_products", 0), "kkt_max": max(v for v in summ["kkt"].values() if isinstance(v, (int, float))),
                       "cond_Q": summ.get("stability_condition_estimate"),
                       "max_penetration": summ.get("max_penetration"),
                       "s_per_product": round(t.get("dual_solve", 0.0) / products, 6) if qp_name == "mpgp" else "",
                       "solve_s": round(solve, 3), "reference_factorization_s": round(ref, 3),
                       "ratio": round(solve / ref, 2), "peak_rss_mib": round(rss, 0), "wall_s": round(wall, 2)}
                for k in STAGES:
                    row[f"t_{k}"] = round(t.get(k, 0.0), 3)
                rows.append(row)
                print(f"h={h:<7g} {law:9s} {qp:5s} n_dual {row['n_dual']:6d} steps {row['steps']:2d} "
                      f"qp_it {row['qp_iterations']:6d} newton {row['newton_steps']:3d} n_mult {products:6d} "
                      f"dual_solve {row['t_dual_solve']:8.2f} s  total {solve:8.2f} s  ratio {row['ratio']:6.2f}  "
                      f"kkt {row['kkt_max']:.1e}  {row['status']}", flush=True)

    keys = sorted({k for r in rows for k in r}, key=lambda k: list(rows[0]).index(k) if k in rows[0] else 99)
    with open(out_dir / "slab.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)
    L = ["# Thin slab: the dual solve against the factorization\n",
         f"Generated by `make bench-slab` (pipeline/bench_slab.py; {env_note}). Slab 2 x 2 x 0.05 m "
         "(pipeline/scenes/slab.toml), cells of 2h (contact.cell_size = \"2h\": the default \"auto\" solves a case again "
         "with cells of 1.5h where the penetration exceeds 10% of the deformation, as a slab thinner than a cell "
         "may). `ratio` = (assembly + contact + factorization + "
         "forming Q + stability check + dual solve) / one CHOLMOD factorization of K in the same process. "
         "`qp`: auto (the default: MPGP switching to semismooth Newton steps where slow), ssn (Newton, MPGP "
         "fallback), mpgp (the paper's algorithm on the Jacobi-scaled dual); `:double` = solver.qp_precision = double "
         "(the others use the default, single-precision products from 2000 multipliers on; `single` counts "
         "them; Newton steps solve through the stability check's factor of Q wherever that is cheaper than "
         "factoring their reduced system, solver.qp_newton_systems = auto). Wall seconds, 2-core machine.\n",
         "| h | law | qp | n_p | multipliers | steps | QP it. | Newton | n_mult | single | factor. | Q | stability | "
         "dual solve | ratio | peak MiB | KKT max | status |",
         "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if "n_p" not in r:
            L.append(f"| {r['h']} | {r['law']} | {r['qp']} | | | | | | | | | | | | | | | {r['status']} |")
            continue
        L.append(f"| {r['h']} | {r['law']} | {r['qp']} | {r['n_p']} | {r['n_dual']} | {r['steps']} | "
                 f"{r['qp_iterations']} | {r['newton_steps']} | {r['n_mult']} | {r['single_products']} | "
                 f"{r['t_factorization']:.2f} | "
                 f"{r['t_dual']:.2f} | {r['t_stability']:.2f} | {r['t_dual_solve']:.2f} | {r['ratio']:.2f} | "
                 f"{r['peak_rss_mib']:.0f} | {r['kkt_max']:.1e} | {r['status']} |")
    (out_dir / "slab.md").write_text("\n".join(L) + "\n")
    print(f"wrote {out_dir / 'slab.md'}")


if __name__ == "__main__":
    main()
