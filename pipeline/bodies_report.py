#!/usr/bin/python3
"""Bodies report (issue #4): solve every body scene, plot its contact face, run a refinement
study, and write results/bodies/README.md. Also the checks used by tests/bodies.cmake.

  bodies_report.py report --bin build/contact3d [--out results/bodies]
  bodies_report.py check --bin B --scene S --out DIR [--set k=v ...]   # converged, KKT small
  bodies_report.py stability --bin B --scene S --out DIR               # H = h/4 must be rejected
"""
import argparse
import math
import pathlib
import sys

import c3d.run

ROOT = pathlib.Path(__file__).resolve().parent.parent
SCENES = ["lblock", "wedge", "holed", "ufoot", "punch", "brick_unstructured"]
DEMOS = [("ufoot_H1.5", "ufoot", ["contact.cell_size=1.5"],
          "the rectangle [1,2] x [0,1.5] covers both legs: it is split into one cell per leg (3 cells, not 2)"),
         ("holed_H0.35", "holed", ["contact.cell_size=0.35"],
          "rectangles around the hole are cut to crescents; slivers merged into their largest neighbour")]
REFINE = {"holed": [0.2, 0.1, 0.05], "wedge": [0.2, 0.1, 0.05]}
KKT_TOL = 1e-3


def run(binary, scene, out, sets=()):
    return c3d.run.solve(binary, scene, out, sets)


def load(out):
    return c3d.run.summary(out)


def contact_max_u(out):
    import csv
    with open(pathlib.Path(out) / "contact_nodes.csv") as f:
        return max(math.sqrt(float(r["u1"]) ** 2 + float(r["u2"]) ** 2 + float(r["u3"]) ** 2) for r in csv.DictReader(f))


def verdict(out, check_penetration=True):
    """List of failures (empty = fine): converged, KKT residuals and w_hn+ small."""
    s = load(out)
    bad = []
    if not s.get("converged") or s.get("status") != "converged":
        bad.append(f"status {s.get('status')}")
    kkt = s.get("kkt", {})
    for k, v in kkt.items():
        if not (isinstance(v, (int, float)) and math.isfinite(v) and v <= KKT_TOL):
            bad.append(f"kkt.{k} = {v} > {KKT_TOL}")
    umax = contact_max_u(out)
    # (5.2) holds cell by cell (mean of w_n over R_i <= 0), so nodes may penetrate by O(H) of the
    # gradient of w_n; a quarter of the largest contact displacement flags a broken solve, not that.
    if check_penetration and not (s["wn_plus_inf"] <= 0.25 * umax):
        bad.append(f"|w_hn+|_inf = {s['wn_plus_inf']} > 0.25 max|u| on Γc = {0.25 * umax}")
    return bad


def cmd_check(a):
    p, _ = run(a.bin, a.scene, a.out, a.set or [])
    if p.returncode != 0:
        print(p.stdout, p.stderr)
        sys.exit(f"FAIL: exit code {p.returncode}")
    bad = verdict(a.out)
    s = load(a.out)
    print(f"{a.scene}: status={s['status']} it={s['fixed_point_iterations']} n_cells={s['n_cells']} "
          f"kkt_max={max(s['kkt'].values()):.2e} wn+_inf={s['wn_plus_inf']:.2e}")
    if bad:
        sys.exit("FAIL: " + "; ".join(bad))


def cmd_stability(a):
    p, _ = run(a.bin, a.scene, a.out, ['contact.cell_size="0.25h"'])
    if p.returncode != 2 or "(5.1)" not in p.stderr or "cell " not in p.stderr:
        print(p.stdout, p.stderr)
        sys.exit(f"FAIL: expected exit 2 naming (5.1) and cells, got {p.returncode}")
    print("rejected as expected:", p.stderr.splitlines()[0][:160])


def plot_face(out, png, title):
    """Contact pressure, slip and the cells of T_H (pieces coloured by cell, from contact_cells.vtu)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.tri as mtri
    import meshio
    import numpy as np
    from matplotlib.collections import PolyCollection
    m = meshio.read(pathlib.Path(out) / "contact.vtu")
    tri = mtri.Triangulation(m.points[:, 0], m.points[:, 1], m.cells_dict["triangle"])
    fig, axes = plt.subplots(1, 3, figsize=(16, 4.2))
    for ax, key, label in [(axes[0], "contact_pressure", "contact pressure (Pa)"),
                           (axes[1], "slip_norm", "slip |u_t| (m)")]:
        v = m.point_data[key]
        v = v if v.ndim == 1 else v.reshape(len(v), -1)[:, 0]
        h = ax.tripcolor(tri, v, shading="gouraud", cmap="viridis")
        ax.triplot(tri, lw=0.15, color="w", alpha=0.5)
        fig.colorbar(h, ax=ax, shrink=0.8)
        ax.set_title(label)
    c = meshio.read(pathlib.Path(out) / "contact_cells.vtu")
    polys, owner = [], []
    for block, ids in zip(c.cells, c.cell_data["cell"]):
        for conn, cid in zip(block.data, np.ravel(ids)):
            polys.append(c.points[conn][:, :2])
            owner.append(int(cid))
    owner = np.array(owner)
    rng = np.random.default_rng(0)
    perm = rng.permutation(max(owner.max() + 1, 1))  # neighbouring cells get unrelated colours
    pc = PolyCollection(polys, array=perm[owner] % 20, cmap="tab20", edgecolors="none")
    axes[2].add_collection(pc)
    axes[2].autoscale()
    axes[2].set_title(f"cells of T_H ({owner.max() + 1} cells; pieces coloured by cell)")
    for ax in axes:
        ax.set_aspect("equal")
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(png, dpi=100)
    plt.close(fig)


def face_field(out):
    import matplotlib.tri as mtri
    import meshio
    m = meshio.read(pathlib.Path(out) / "contact.vtu")
    tri = mtri.Triangulation(m.points[:, 0], m.points[:, 1], m.cells_dict["triangle"])
    return m, tri


def face_error(coarse, fine):
    """RMS over the finest contact nodes of |u_coarse - u_fine| (P1 interpolation of the coarse
    trace on its own triangles), relative to the RMS of |u_fine|."""
    import matplotlib.tri as mtri
    import numpy as np
    mc, tc = face_field(coarse)
    mf, _ = face_field(fine)
    uc, uf = mc.point_data["displacement"], mf.point_data["displacement"]
    x, y = mf.points[:, 0], mf.points[:, 1]
    diff = []
    for k in range(3):
        vals = mtri.LinearTriInterpolator(tc, uc[:, k])(x, y)
        diff.append(np.ma.filled(vals, np.nan) - uf[:, k])
    d = np.sqrt(np.sum(np.array(diff) ** 2, axis=0))
    ok = np.isfinite(d)  # points outside the coarse polygonal face (curved hole) are skipped
    return float(np.sqrt(np.mean(d[ok] ** 2)) / np.sqrt(np.mean(np.sum(uf[ok] ** 2, axis=1))))


def cmd_report(a):
    out = pathlib.Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    work = pathlib.Path(a.work)
    rows, fails = [], []
    for name in SCENES:
        run_dir = work / name
        p, wall = run(a.bin, ROOT / "pipeline/scenes" / f"{name}.toml", run_dir)
        if p.returncode != 0:
            fails.append(f"{name}: exit {p.returncode}: {p.stderr.strip()[:300]}")
            continue
        s = load(run_dir)
        bad = verdict(run_dir)
        if bad:
            fails.append(f"{name}: " + "; ".join(bad))
        import csv
        with open(run_dir / "contact_nodes.csv") as f:
            status = [int(r["status"]) for r in csv.DictReader(f)]
        plot_face(run_dir, out / f"{name}.png", name)
        rows.append((name, s, status))
        print(f"{name}: {s['status']} it={s['fixed_point_iterations']} ({wall:.1f} s)", flush=True)

    demos = []  # (name, scene, sets, what it shows)
    for tag, scene, sets, what in DEMOS:
        d = work / tag
        p, _ = run(a.bin, ROOT / "pipeline/scenes" / f"{scene}.toml", d, sets)
        if p.returncode != 0:
            fails.append(f"{tag}: exit {p.returncode}: {p.stderr.strip()[:300]}")
            continue
        bad = verdict(d, check_penetration=False)  # coarse H on purpose: penetration O(H)
        if bad:
            fails.append(f"{tag}: " + "; ".join(bad))
        plot_face(d, out / f"{tag}.png", f"{scene} with " + " ".join(sets))
        demos.append((tag, scene, sets, what, load(d)))

    ref = {}
    for name, hs in REFINE.items():
        res = []
        for h in hs:
            d = work / f"{name}_h{h}"
            p, _ = run(a.bin, ROOT / "pipeline/scenes" / f"{name}.toml", d, [f"mesh.parameters.h={h}"])
            if p.returncode != 0:
                fails.append(f"{name} h={h}: exit {p.returncode}: {p.stderr.strip()[:300]}")
                break
            res.append((h, d, load(d)))
            print(f"{name} h={h}: {load(d)['status']}", flush=True)
        ref[name] = res

    L = ["# Bodies (issue #4): general polyhedral bodies and the partition of their contact faces", "",
         "Made by `pipeline/bodies_report.py report --bin build/contact3d` (every number below is read",
         "from the runs' summary.json; figures from contact.vtu and contact_cells.vtu).",
         "All scenes: steel-like E = 2.1e11 Pa, ν = 0.3, H = 2h, clamped at x = 0; law and g per row.", ""]
    L += ["| scene | law | n_nodes | n_p | n_d | cells (merged) | it | n_mult | time (s) | max KKT | ‖w_hn⁺‖₀ | ‖w_hn⁺‖∞ (m) | max\\|u\\| on Γc (m) | F_n (N) | F_t1 (N) | status counts |",
          "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for name, s, status in rows:
        import re
        m = re.search(r"law = '(\w+)'", s.get("scene", "")) if isinstance(s.get("scene"), str) else None
        law = m.group(1) if m else ""
        g = re.search(r"slip_bound = ([0-9.e+-]+)", s.get("scene", "")) if isinstance(s.get("scene"), str) else None
        law += f", g = {float(g.group(1)):.0e}" if g else ""
        counts = {v: status.count(v) for v in sorted(set(status))}
        L.append(f"| {name} | {law} | {s['n_nodes']} | {s['n_primal']} | {s['n_dual']} | {s['n_cells']} ({s['cells_merged']}) | "
                 f"{s['fixed_point_iterations']} | {s['n_mult']} | {s['time_s']['total']:.2f} | {max(s['kkt'].values()):.1e} | "
                 f"{s['wn_plus_L2']:.2e} | {s['wn_plus_inf']:.2e} | {contact_max_u(work / name):.2e} | "
                 f"{s['contact_force']['normal']:.4e} | {s['contact_force']['t1']:.4e} | {counts} |")
    L += ["", "`status counts`: contact nodes per contact_nodes.csv status (0 separated, 1 stick, 2 slip).",
          "Every scene has both sticking and slipping nodes. `cells (merged)`: cells of T_H and how many",
          "rectangles were merged into a neighbour (slivers at slanted edges and around the hole).",
          "F_t1 < 0 on the punch is physical: the cantilevered block bends under the top load, its lower",
          "fibres shorten towards the clamp and drag the foot's sole towards -x.", ""]
    L += ["KKT residuals per scene (relative, from summary.json):", "",
          "| scene | " + " | ".join(rows[0][1]["kkt"].keys()) + " |" if rows else "",
          "|---|" + "---|" * (len(rows[0][1]["kkt"]) if rows else 0)]
    for name, s, _ in rows:
        L.append(f"| {name} | " + " | ".join(f"{v:.1e}" for v in s["kkt"].values()) + " |")
    L += ["", "## Contact faces", ""]
    for name, _, _ in rows:
        L += [f"### {name}", "", f"![{name}]({name}.png)", ""]

    L += ["## Partition demonstrations", "",
          "| run | overrides | cells | merged | it | max KKT | ‖w_hn⁺‖∞ (m) | what it shows |", "|---|---|---|---|---|---|---|---|"]
    for tag, scene, sets, what, s in demos:
        L.append(f"| {tag} | `{' '.join(sets)}` | {s['n_cells']} | {s['cells_merged']} | {s['fixed_point_iterations']} | "
                 f"{max(s['kkt'].values()):.1e} | {s['wn_plus_inf']:.2e} | {what} |")
    L += [""]
    for tag, *_ in demos:
        L += [f"![{tag}]({tag}.png)", ""]
    L += ["A partition that violates (5.1) is rejected before the solve: `contact.cell_size=\"0.25h\"` on the wedge",
          "exits with code 2 and names the cells without a free contact node of their own (tests/bodies.cmake).", ""]

    L += ["## Refinement study", "",
          "Three mesh sizes per body (`--set mesh.parameters.h=...`, H = 2h). Errors against the finest run:",
          "e_u = relative RMS over the finest contact nodes of the difference of the contact-face displacement",
          "(coarse P1 trace interpolated on its own triangles; points of the finest face outside a coarse",
          "polygonal face are skipped), e_F = relative difference of the total contact force",
          "(summary.json contact_force, normal and tangential). Observed rate between the two coarse levels:",
          "log(e(h1)/e(h2)) / log(h1/h2).", ""]
    rates = {}
    for name, res in ref.items():
        if len(res) < 3:
            continue
        hf, df, sf = res[-1]
        L += [f"### {name}", "", "| h | n_p | n_d | it | ‖w_hn⁺‖₀ | ‖w_hn⁺‖∞ (m) | F_n (N) | F_t1 (N) | e_u | e_Fn | e_Ft |", "|---|---|---|---|---|---|---|---|---|---|---|"]
        errs = []
        for h, d, s in res:
            cf, ff = s["contact_force"], sf["contact_force"]
            eu = face_error(d, df) if d != df else 0.0
            en = abs(cf["normal"] - ff["normal"]) / abs(ff["normal"])
            ft = math.hypot(ff["t1"], ff["t2"])
            et = math.hypot(cf["t1"] - ff["t1"], cf["t2"] - ff["t2"]) / ft
            errs.append((h, eu, en, et))
            L.append(f"| {h} | {s['n_primal']} | {s['n_dual']} | {s['fixed_point_iterations']} | {s['wn_plus_L2']:.2e} | {s['wn_plus_inf']:.2e} | {cf['normal']:.5e} | {cf['t1']:.5e} | "
                     + (f"{eu:.2e} | {en:.2e} | {et:.2e} |" if d != df else "(reference) | | |"))
        (h1, u1, n1, t1), (h2, u2, n2, t2) = errs[0], errs[1]
        rate = lambda e1, e2: math.log(e1 / e2) / math.log(h1 / h2) if e1 > 0 and e2 > 0 else float("nan")
        rates[name] = (rate(u1, u2), rate(n1, n2), rate(t1, t2))
        L += ["", f"Observed rates ({h1} → {h2}, against h = {hf}): displacement {rates[name][0]:.2f}, "
              f"normal force {rates[name][1]:.2f}, tangential force {rates[name][2]:.2f}.", ""]
    L += ["‖w_hn⁺‖ is the pointwise penetration allowed by the cell-averaged constraint (5.2); it falls with h.",
          "", "Comparing against the finest run rather than an exact solution overestimates the rate when the",
          "middle level is already close to the finest one; on these geometries the contact pressure has edge",
          "singularities (clamped edge, punch corners), so rates below 2 for the trace are expected.", ""]
    if fails:
        L += ["## Failures", ""] + [f"- {f}" for f in fails] + [""]
    (out / "README.md").write_text("\n".join(L))
    print("\n".join(L))
    if fails:
        sys.exit("FAIL: " + "; ".join(fails))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("report")
    r.add_argument("--bin", default=str(ROOT / "build/contact3d"))
    r.add_argument("--out", default=str(ROOT / "results/bodies"))
    r.add_argument("--work", default="/tmp/contact3d_bodies")
    c = sub.add_parser("check")
    c.add_argument("--bin", required=True)
    c.add_argument("--scene", required=True)
    c.add_argument("--out", required=True)
    c.add_argument("--set", action="append")
    s = sub.add_parser("stability")
    s.add_argument("--bin", required=True)
    s.add_argument("--scene", required=True)
    s.add_argument("--out", required=True)
    a = ap.parse_args()
    {"report": cmd_report, "check": cmd_check, "stability": cmd_stability}[a.cmd](a)


if __name__ == "__main__":
    main()
