#!/usr/bin/python3
"""One scene end to end: solve it, then make its figures and a report.

usage: run_scene.py --bin BIN --scene S.toml --out DIR [--args "--set k=v ..."] [--figures [COPY_DIR] | --no-figures]
                    [--compare RUN_DIR ...] [--compare-params 2e4,3e5]

Runs `BIN solve S.toml --out DIR <args>` with its output streamed, then (unless --no-figures)
writes the paper-style figures into DIR/figures/ (pipeline/plots/make_figures.py) and DIR/report.md:
scene, mesh statistics, timings per stage, the fixed-point convergence table (history.csv),
the KKT residuals (summary.json) and the figures inline. Exit code: the solver's (figures that
fail are reported in report.md and on stderr, and do not change it); 2 if the solver wrote no
summary.json.
--figures COPY_DIR also copies the figures and report.md (links adjusted) into COPY_DIR (e.g.
results/figures). --compare-params P1,P2 solves the scene again with friction.param = P1, P2 (into
DIR/compare/param_P) for the combined convergence plot, as in the paper's Table 2 / Fig. 6.
"""
import argparse
import csv
import json
import os
import shlex
import shutil
import subprocess
import sys

import c3d.run

HERE = os.path.dirname(os.path.abspath(__file__))


def read_history(out):
    p = os.path.join(out, "history.csv")
    if not os.path.isfile(p):
        return []
    with open(p) as f:
        return list(csv.DictReader(f))


def engineering_results(s):
    """Forces, areas, torque, penetration, reactions, warnings and notes of summary.json, in the scene's units."""
    u = s.get("units", {"length": "m", "force": "N", "stress": "Pa"})
    L, F, A = u["length"], u["force"], f"{u['length']}²"
    f = s.get("forces", {})
    def vec(v):
        return "(" + ", ".join(f"{x:.4g}" for x in v) + ")"
    rows = []
    if f:
        rows.append(f"| applied load (x, y, z) [{F}] | {vec(f['applied'])} |")
        rows.append(f"| contact force on the body (x, y, z) [{F}] | {vec(f['contact'])} |")
        rows += [f"| reaction on {r['condition']} (x, y, z) [{F}] | {vec(r['force'])} |" for r in f.get("reactions", [])]
        rows.append(f"| force balance (relative) | {f.get('balance', 0):.2e} |")
    cf = s.get("contact_force")
    if cf and s.get("n_cells", 0) > 0:
        rows.append(f"| total normal / tangential contact force [{F}] | {cf['normal']:.4g} / {cf.get('tangential', 0):.4g} |")
        ca = s.get("contact_area", {})
        stick, slip = ca.get("stick"), ca.get("slip")
        rows.append(f"| area in contact / separated [{A}] | {ca.get('in_contact', 0):.4g} / {ca.get('separated', 0):.4g} |")
        if stick is not None:
            rows.append(f"| stick / slip area [{A}] | {stick:.4g} / {slip:.4g} |")
        if s.get("friction_torque") is not None:
            rows.append(f"| friction torque about Γc's centroid [{F} {L}] | {s['friction_torque']:.4g} |")
        rows.append(f"| max penetration (nodal w_n⁺) [{L}] | {s.get('max_penetration', 0):.3g} |")
        if s.get("friction_where_separated_area"):
            rows.append(f"| Tresca friction where lifted off [{A}] | {s['friction_where_separated_area']:.4g} |")
    if not rows:
        return []
    out = ["", f"## Results (units: {u.get('system', 'm-N-Pa')})", "", "| quantity | value |", "|---|---|"] + rows
    for w in s.get("warnings", []):
        out.append(f"\n**Warning:** {w}")
    for n in s.get("notes", []):
        out.append(f"\n**Note:** {n}")
    return out


def report(scene_path, out, cmd, rc, figures, notes):
    s = json.load(open(os.path.join(out, "summary.json")))
    hist = read_history(out)
    L = [f"# Run report: {os.path.basename(scene_path)}", "",
         f"- scene: `{scene_path}`", f"- command: `{' '.join(shlex.quote(c) for c in cmd)}`",
         f"- solver exit code: {rc}; status: **{s.get('status')}** (converged: {s.get('converged')})", "",
         "## Mesh and discretisation", "",
         "| quantity | value |", "|---|---|",
         f"| mesh | {s.get('mesh')} |",
         f"| nodes / tetrahedra | {s.get('n_nodes')} / {s.get('n_tets')} |",
         f"| primal unknowns n_p | {s.get('n_primal')} |",
         f"| dual unknowns n_d | {s.get('n_dual')} |",
         f"| contact nodes / cells of T_H | {s.get('n_contact_nodes')} / {s.get('n_cells')} |",
         f"| contact h / cell size H [m] | {s.get('contact_h', 0):.4g} / {s.get('cell_size', 0):.4g} |",
         f"| fixed-point iterations it | {s.get('fixed_point_iterations')} |",
         f"| n_mult (K⁻¹ products) | {s.get('n_mult')} |",
         f"| ‖w_hn⁺‖₀ / ‖w_hn⁺‖∞ [m] | {s.get('wn_plus_L2', 0):.2e} / {s.get('wn_plus_inf', 0):.2e} |",
         f"| stability cond(Q) estimate | {s.get('stability_condition_estimate', 0):.3g} |"]
    cf = s.get("contact_force", {})
    if cf:
        L.append(f"| contact force (normal, t1, t2) [N] | {cf.get('normal', 0):.4g}, {cf.get('t1', 0):.4g}, "
                 f"{cf.get('t2', 0):.4g} |")
    L += engineering_results(s)
    L += ["", "## Timings per stage", "", "| stage | seconds |", "|---|---|"]
    L += [f"| {k} | {v:.3f} |" for k, v in s.get("time_s", {}).items()]
    L += ["", "## Convergence of the fixed point (history.csv)", ""]
    if hist:
        L += ["| k | input made by | err(k) | QP tolerance | QP iterations | n_mult (cumulative) | seconds |",
              "|---|---|---|---|---|---|---|"]
        L += [f"| {r['k']} | {r.get('update', '')} | {float(r['err']):.3e} | {float(r.get('qp_rtol', 'nan')):.0e} | "
              f"{r['qp_iterations']} | {r['n_mult']} | {float(r['seconds']):.3f} |" for r in hist]
    else:
        L.append("No fixed point in this run (frictionless, constant coefficient or no contact): one solve.")
    L += ["", "## KKT residuals of the final solution (summary.json)", "", "| residual | value |", "|---|---|"]
    L += [f"| {k} | {v:.3e} |" for k, v in s.get("kkt", {}).items()]
    L += ["", "## Figures", ""]
    if figures:
        for p in figures:
            rel = os.path.relpath(p, out)
            L += [f"![{os.path.basename(p)}]({rel})", ""]
    else:
        L.append("Figures were not made (--no-figures).")
    for n in notes:
        L.append(f"- note: {n}")
    L += ["", "## Scene as solved", "", "```toml", s.get("scene", "").rstrip(), "```", ""]
    # The title line is what a later solve into this folder recognises as this report (kRunReportTitle,
    # solver/io/run_folder.hpp) and removes with the run's files; another report.md stays.
    with open(os.path.join(out, "report.md"), "w") as f:
        f.write("\n".join(L))
    return os.path.join(out, "report.md")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", required=True)
    ap.add_argument("--scene", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--args", default="", help="extra solver arguments, one string")
    g = ap.add_mutually_exclusive_group()
    g.add_argument("--figures", nargs="?", const=True, default=True, metavar="COPY_DIR",
                   help="make figures (default); with a folder, also copy them and report.md there")
    g.add_argument("--no-figures", dest="figures", action="store_false")
    ap.add_argument("--compare", nargs="*", default=[], help="other run folders for a combined Fig. 6")
    ap.add_argument("--compare-params", default="", help="comma-separated friction.param values to solve too")
    a = ap.parse_args()

    cmd = c3d.run.solve_command(a.bin, a.scene, a.out, quiet=False, extra_args=shlex.split(a.args))
    print("+", " ".join(shlex.quote(c) for c in cmd), flush=True)
    try:
        rc = subprocess.call(cmd)  # inherits stdout/stderr: the progress lines stream as they come
    except OSError as e:
        print(f"error: cannot run {a.bin}: {e}", file=sys.stderr)
        return 2
    if not os.path.isfile(os.path.join(a.out, "summary.json")):
        print(f"run_scene: the solver wrote no summary.json (exit code {rc}); no report", file=sys.stderr)
        return rc if rc != 0 else 2
    compare = list(a.compare)
    for p in [x for x in a.compare_params.split(",") if x.strip()]:
        d = os.path.join(a.out, "compare", f"param_{p.strip()}")
        c = c3d.run.solve_command(a.bin, a.scene, d, [f"friction.param={p.strip()}"], extra_args=shlex.split(a.args))
        print("+", " ".join(shlex.quote(x) for x in c), flush=True)
        if subprocess.call(c) in (0, 1) and os.path.isfile(os.path.join(d, "summary.json")):
            compare.append(d)
        else:
            print(f"run_scene: the comparison run with param {p} failed; left out", file=sys.stderr)
    figures, notes = [], []
    if a.figures:
        try:
            sys.path.insert(0, os.path.join(HERE, "plots"))
            from make_figures import make_all
            figures, notes = make_all(a.out, os.path.join(a.out, "figures"), compare)
        except Exception as e:  # matplotlib/meshio missing or broken: still write the report
            notes.append(f"figures failed: {e}")
        for n in notes:
            print("run_scene: note:", n, file=sys.stderr)
    path = report(a.scene, a.out, cmd, rc, figures, notes)
    if isinstance(a.figures, str) and figures:
        os.makedirs(a.figures, exist_ok=True)
        for f in figures:
            shutil.copy2(f, a.figures)
        with open(path) as f:
            text = f.read().replace("](figures/", "](")
        name = f"report_{os.path.splitext(os.path.basename(a.scene))[0]}.md"
        with open(os.path.join(a.figures, name), "w") as f:
            f.write(text)
        print(f"copied {len(figures)} figures and {name} to {a.figures}")
    print(f"report: {path}" + (f" ({len(figures)} figures in {os.path.join(a.out, 'figures')})" if figures else ""))
    return rc


if __name__ == "__main__":
    sys.exit(main())
