#!/usr/bin/env python3
"""Hertz validation: a quarter of an elastic hemisphere pressed onto the rigid plane.

geo/hertz_quarter.geo meshes a quarter of a hemisphere of radius R = 1 m (refined at its pole,
the spherical cap of radius 0.3 R as the curved contact face, whose height above the plane is the
initial gap); two symmetry planes ([[boundary.displacement]] x = 0 and y = 0) and the flat top
moved down by delta make the load. contact3d solves it frictionless, and from its total contact
force P (4 x the quarter's) Hertz's formulas for a sphere on a rigid plane give

    a = (3 P R / (4 E*))^(1/3),   p0 = 3 P / (2 pi a^2),   E* = E / (1 - nu^2).

The computed contact radius comes from a least-squares fit of p(r)^2 = p0^2 (1 - r^2 / a^2) to the
cells' mean pressures (cells with p > 0.2 max p and r < 0.8 a_Hertz, r the cell centre's distance to
the pole), the computed peak pressure from the same fit. Both must be within --tolerance (5%) of
Hertz's values. With --top-pressure p the top is pressed by a pressure instead of moved: nothing
prescribed then holds the body along z, the contact alone does (model/held_by_contact.hpp), and the
contact force must also equal the applied load to 1e-8. With --report the pressure profile is written as a markdown table and a figure
(p against p0 sqrt(1 - r^2/a^2)) when matplotlib is there.

Usage: hertz_hemisphere.py BIN SOURCE_DIR [--h-pole 0.01] [--fine 0.35] [--cell-size 0.02 | "2h"] [--delta 0.01 | --top-pressure 1e8]
                           [--report results/runs/hertz]
Exit 0 within tolerance, 1 not, 2 when a step fails.
"""
import argparse
import json
import math
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "pipeline"))
from c3d import run as c3d_run  # noqa: E402

YOUNG, POISSON, R = 2.0e11, 0.3, 1.0

SCENE = """# Hertz: a quarter of an elastic hemisphere (R = 1 m, steel) pressed onto the plane
[mesh]
file = "{mesh}"
[material]
young = {young}
poisson = {poisson}
[boundary]
clamped = []
contact = ["contact"]
[[boundary.displacement]]
group = "sym_x"
x = 0
[[boundary.displacement]]
group = "sym_y"
y = 0
{top_load}
[contact]
cell_size = {cell_size}
[solver]
qp_rtol = 1e-8
"""


def cell_size_value(text):
    """contact.cell_size as TOML: a number, or a string ("2h", "auto")."""
    try:
        return repr(float(text))
    except ValueError:
        return f'"{text}"'


def hertz(P, radius=R, young=YOUNG, poisson=POISSON):
    e_star = young / (1 - poisson ** 2)
    a = (3 * P * radius / (4 * e_star)) ** (1 / 3)
    return a, 3 * P / (2 * math.pi * a * a)


def fit_profile(cells, a_hertz):
    """(a, p0) from the least-squares fit of p^2 = p0^2 - (p0^2/a^2) r^2 on the loaded cells."""
    r = np.hypot(0.5 * (cells["xmin"] + cells["xmax"]), 0.5 * (cells["ymin"] + cells["ymax"]))
    p = cells["lambda_n"]
    use = (p > 0.2 * p.max()) & (r < 0.8 * a_hertz)
    if use.sum() < 3:
        raise RuntimeError(f"only {use.sum()} loaded cells inside 0.8 a: refine the cells")
    A = np.column_stack([np.ones(use.sum()), r[use] ** 2])
    c0, c1 = np.linalg.lstsq(A, p[use] ** 2, rcond=None)[0]
    if not (c0 > 0 and c1 < 0):
        raise RuntimeError(f"the pressure profile is not Hertzian (fit p^2 = {c0:.3g} + {c1:.3g} r^2)")
    return math.sqrt(-c0 / c1), math.sqrt(c0), r, p


def against_hertz(cells, P, radius=R, young=YOUNG, poisson=POISSON):
    """Hertz's (a, p0) for the force P and the fitted (a, p0, r, p) of the cells; RuntimeError if no fit."""
    a_h, p0_h = hertz(P, radius, young, poisson)
    return (a_h, p0_h, *fit_profile(cells, a_h))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("bin")
    ap.add_argument("source")
    ap.add_argument("--h-pole", type=float, default=0.01)
    ap.add_argument("--cell-size", default="0.02", help='H in m, or a multiple of h such as "2h", or "auto"')
    ap.add_argument("--fine", type=float, help="radius of the refined zone around the pole / R (geo default 0.35)")
    ap.add_argument("--delta", type=float, default=0.01)
    ap.add_argument("--top-pressure", type=float, help="Pa on the top instead of moving it by delta")
    ap.add_argument("--tolerance", type=float, default=0.05)
    ap.add_argument("--report", help="folder for hertz.md, hertz.json and hertz_profile.png")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory(prefix="c3d_hertz_") as work:
        work = Path(work)
        msh = work / "hertz.msh"
        geo = Path(args.source) / "geo" / "hertz_quarter.geo"
        fine = ["-setnumber", "fine", str(args.fine)] if args.fine else []
        gm = subprocess.run(["gmsh", "-3", str(geo), "-setnumber", "h_pole", str(args.h_pole), *fine, "-o", str(msh)],
                            capture_output=True, text=True)
        if gm.returncode != 0 or not msh.exists():
            print(f"error: gmsh failed on {geo}: {gm.stderr[-500:]}", file=sys.stderr)
            return 2
        scene = work / "hertz.toml"
        top_load = (f'[[boundary.pressure]]\ngroup = "top"\nvalue = {args.top_pressure}' if args.top_pressure else
                    f'[[boundary.displacement]]\ngroup = "top"\nz = {-args.delta}')
        scene.write_text(SCENE.format(mesh=msh, young=YOUNG, poisson=POISSON, top_load=top_load,
                                      cell_size=cell_size_value(args.cell_size)))
        proc, seconds = c3d_run.solve(args.bin, scene, work / "out")
        if proc.returncode != 0:
            print(f"error: contact3d failed: {proc.stderr.strip()}", file=sys.stderr)
            return 2
        summary = c3d_run.summary(work / "out")
        cells = np.genfromtxt(work / "out" / "contact_cells.csv", delimiter=",", names=True)
    P = 4 * summary["contact_force"]["normal"]
    if args.top_pressure:
        applied = -4 * summary["forces"]["applied"][2]
        print(f"held by contact alone: contact force {P:.10g} N, applied {applied:.10g} N")
        if abs(P - applied) > 1e-8 * applied:
            print("HERTZ FAILED: the contact force does not balance the applied load")
            return 1
    try:
        a_h, p0_h, a_c, p0_c, r, p = against_hertz(cells, P)
    except RuntimeError as e:
        print(f"error: {e}", file=sys.stderr)
        return 1
    err_a, err_p = abs(a_c / a_h - 1), abs(p0_c / p0_h - 1)
    row = {"h_pole": args.h_pole, "fine": args.fine, "cell_size": json.loads(cell_size_value(args.cell_size)),
           "cells_graded": summary.get("cells_graded", False), "cell_sides_smallest": summary.get("cell_sides_smallest"),
           "cell_sides_largest": summary.get("cell_sides_largest"), "delta": None if args.top_pressure else args.delta,
           "top_pressure": args.top_pressure, "n_primal": summary["n_primal"],
           "n_cells": summary["n_cells"], "force_P": P, "a_hertz": a_h, "a_computed": a_c, "p0_hertz": p0_h,
           "p0_computed": p0_c, "p_max_cell": float(p.max()), "err_a": err_a, "err_p0": err_p,
           "wn_plus_inf": summary["wn_plus_inf"], "kkt_max": max(v for v in summary["kkt"].values() if v is not None),
           "seconds": seconds}
    print(f"P = {P:.4g} N, a: {a_c:.4f} vs Hertz {a_h:.4f} m ({err_a:.1%}), p0: {p0_c:.4g} vs Hertz {p0_h:.4g} Pa "
          f"({err_p:.1%}); {summary['n_primal']} unknowns, {summary['n_cells']} cells, {seconds:.1f} s")
    if args.report:
        write_report(Path(args.report), row, r, p)
    ok = err_a <= args.tolerance and err_p <= args.tolerance
    if not ok:
        print(f"HERTZ FAILED: contact radius or peak pressure more than {args.tolerance:.0%} from Hertz's")
    return 0 if ok else 1


def cells_text(row):
    if not row["cells_graded"]:
        return f"cells H = {row['cell_size']} m"
    small, large = row["cell_sides_smallest"], row["cell_sides_largest"]
    return (f"cells of {row['cell_size']} following the graded mesh (sides {min(small):.3g} to {max(large):.3g} m, "
            "contact/grid_boxes.hpp)")


def write_report(folder, row, r, p):
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "hertz.json").write_text(json.dumps(row, indent=1) + "\n")
    a, p0 = row["a_hertz"], row["p0_hertz"]
    lines = ["# Hertz: a quarter hemisphere (R = 1 m, E = 200 GPa, nu = 0.3) pressed onto the rigid plane", "",
             (f"Top pressed by {row['top_pressure']} Pa (the body held by contact alone)" if row["top_pressure"] else
              f"Top moved down by {row['delta']} m") + f"; mesh size {row['h_pole']} m at the pole" +
             (f" (refined within {row['fine']} R, coarser away from it)" if row["fine"] else "") + ", " +
             cells_text(row) + f"; {row['n_primal']} unknowns, {row['n_cells']} cells, {row['seconds']:.1f} s.", "",
             "| | contact3d | Hertz (from the computed force) | difference |", "|---|---|---|---|",
             f"| total force P (N) | {row['force_P']:.4e} | | |",
             f"| contact radius a (m) | {row['a_computed']:.4f} | {a:.4f} | {row['err_a']:.1%} |",
             f"| peak pressure p0 (Pa) | {row['p0_computed']:.4e} | {p0:.4e} | {row['err_p0']:.1%} |", "",
             "a and p0 of contact3d: least-squares fit of p^2 = p0^2 (1 - r^2/a^2) to the cells' mean pressures.", "",
             "Cell pressures against r (about 40 of the cells with r <= 1.3 a, evenly spread over r):", "",
             "| r (m) | p (Pa) | Hertz p0 sqrt(1 - r^2/a^2) (Pa) |", "|---|---|---|"]
    order = [k for k in np.argsort(r) if r[k] <= 1.3 * a]
    for k in order[::max(1, len(order) // 40)]:
        lines.append(f"| {r[k]:.4f} | {p[k]:.4e} | {p0 * math.sqrt(max(0.0, 1 - (r[k] / a) ** 2)):.4e} |")
    (folder / "hertz.md").write_text("\n".join(lines) + "\n")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(r / a, p / p0, ".", ms=3, label="contact3d (cell mean pressure)")
    s = np.linspace(0, 1, 200)
    ax.plot(s, np.sqrt(1 - s ** 2), "-", label="Hertz  p0 sqrt(1 - r²/a²)")
    ax.set_xlabel("r / a (Hertz)")
    ax.set_ylabel("p / p0 (Hertz)")
    ax.set_xlim(0, 1.4)
    ax.legend()
    fig.tight_layout()
    fig.savefig(folder / "hertz_profile.png", dpi=120)


if __name__ == "__main__":
    sys.exit(main())
