#!/usr/bin/python3
"""Fig. 6 of the paper: err(k) = ‖φ^k − φ^{k−1}‖/‖φ^k‖ against the fixed-point step k (log scale),
for one run, or several runs in one plot (e.g. param = 2e4, 6e4, 3e5).
usage: fig6_convergence.py RUN_DIR [RUN_DIR...] [--out DIR] [--name fig06_convergence.png]"""
import argparse

from common import Run, plt, save


def plot(runs, out_dir, name="fig06_convergence.png"):
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    tol = None
    drew = False
    for run in runs:
        h = run.history()
        if not h or len(h["k"]) < 2:  # a single solve (constant or no friction): err is 0, nothing to plot
            continue
        ax.semilogy(h["k"], h["err"], "o-", label=f"{run.label()} ({len(h['k'])} steps)")
        tol = run.scene.get("solver", {}).get("fixed_point_tol", tol)
        drew = True
    if tol:
        ax.axhline(tol, color="k", ls=":", lw=1, label=f"stopping tolerance {tol:g}")
    if not drew:
        ax.text(0.5, 0.5, "no fixed point in this run\n(constant or no friction)", ha="center", va="center",
                transform=ax.transAxes)
    ax.set_xlabel("fixed-point iteration k [–]")
    ax.set_ylabel("err(k) [–]")
    ax.set_title("Fig. 6 — convergence history of the successive approximations")
    ax.grid(alpha=0.3, which="both")
    ax.xaxis.get_major_locator().set_params(integer=True)
    if ax.get_legend_handles_labels()[0]:
        ax.legend()
    return [save(fig, out_dir, name)]


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--out", default=None)
    ap.add_argument("--name", default="fig06_convergence.png")
    a = ap.parse_args()
    print("\n".join(plot([Run(r) for r in a.runs], a.out or a.runs[0] + "/figures", a.name)))
