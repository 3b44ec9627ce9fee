#!/usr/bin/python3
"""Fig. 3 of the paper: the coefficient of friction F(t) against the slip t = ‖u_t‖.
For a ramp law (6.1) it draws the paper's three laws (param = 2e4, 6e4, 3e5) with the scene's
high/low/t0, and highlights the scene's own param; any other law is drawn as it is.
usage: fig3_friction.py RUN_DIR [--out DIR]"""

import numpy as np

from common import run_one, friction_law, plt, save

PAPER_PARAMS = (2e4, 6e4, 3e5)


def plot(run, out_dir):
    fr = dict(run.scene.get("friction", {}))
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    if fr.get("law") == "ramp":
        t0 = float(fr.get("t0", 1e-5))
        params = sorted(set(PAPER_PARAMS) | {float(fr.get("param", 6e4))})
        t = np.linspace(0, t0 + 2.0 / min(params) * 1.25, 600)
        for p in params:
            law = friction_law({**fr, "param": p})
            own = abs(p - float(fr.get("param", 0))) <= 1e-9 * p
            ax.plot(run.length_in_um(t), law(t), lw=2.4 if own else 1.4, ls="-" if own else "--",
                    label=f"param = {p:.0e} 1/{run.length_label()}" + (" (this scene)" if own else ""))
        ax.axvline(run.length_in_um(t0), color="0.6", lw=0.8)
        ax.text(run.length_in_um(t0), float(fr.get("low", 0.2)), " t0", color="0.4", va="bottom")
    else:
        law = friction_law(fr)
        nodes = run.nodes()
        tmax = max(1e-5 if run.length_label() == "m" else 1e-2, 1.2 * float(nodes["wt_norm"].max())) if nodes else 1e-4
        if fr.get("law") == "table":
            tmax = max(tmax, 1.2 * max(p[0] for p in fr["points"]))
        t = np.linspace(0, tmax, 600)
        ax.plot(run.length_in_um(t), law(t), lw=2, label=f"law = {fr.get('law', 'none')}")
    ax.set_xlabel("slip t = ‖u_t‖ [µm]")
    ax.set_ylabel("coefficient of friction F(t) [–]")
    ax.set_title("Fig. 3 — coefficients of friction")
    ax.grid(alpha=0.3)
    ax.legend()
    return [save(fig, out_dir, "fig03_friction_law.png")]


if __name__ == "__main__":
    run_one(plot, __doc__)
