#!/usr/bin/python3
"""Fig. 11 of the paper: per cell R of T_H, a circle of radius c_R = ∫_R F(‖w_ht‖) g dS / meas(R)
centred at the cell's centre and the segment λ_tH(R) from that centre, both drawn with one
length scale (stress → length), so a segment reaching its circle is a slipping cell (‖λ_t‖ = c).
usage: fig11_multipliers.py RUN_DIR [--out DIR]"""

import numpy as np
from matplotlib import colors
from matplotlib.collections import PatchCollection, PolyCollection
from matplotlib.patches import Circle

from common import run_one, face_axes, plt, save


def plot(run, out_dir):
    c = run.cells()
    cx, cy = 0.5 * (c["xmin"] + c["xmax"]), 0.5 * (c["ymin"] + c["ymax"])
    size = np.minimum(c["xmax"] - c["xmin"], c["ymax"] - c["ymin"])
    rmax = max(c["radius"].max(), np.hypot(c["lambda_t1"], c["lambda_t2"]).max())
    frictionless = rmax <= 0
    rmax = rmax if not frictionless else 1.0
    scale = 0.48 * np.median(size) / rmax  # plot length per stress unit
    lt = np.hypot(c["lambda_t1"], c["lambda_t2"])
    ratio = np.where(c["radius"] > 0, lt / np.maximum(c["radius"], 1e-300), 0.0)
    fig, ax = plt.subplots(figsize=(10, 4.2))
    ax.add_collection(PolyCollection([p for _, p in run.cell_polygons()], facecolor="none", edgecolor="0.9", linewidth=0.3))
    ax.add_collection(PatchCollection([Circle((x, y), scale * r) for x, y, r in zip(cx, cy, c["radius"])],
                                      facecolor="none", edgecolor="tab:blue", linewidth=0.7))
    norm = colors.Normalize(0, 1)
    q = ax.quiver(cx, cy, scale * c["lambda_t1"], scale * c["lambda_t2"], ratio, cmap="plasma", norm=norm,
                  angles="xy", scale_units="xy", scale=1, width=0.0025, headwidth=3, headlength=3, headaxislength=2.7)
    fig.colorbar(q, ax=ax, label="‖λ_tH‖ / c_R [–]  (1 = slip)", shrink=0.85)
    ax.set_xlim(c["xmin"].min() - 0.02, c["xmax"].max() + 0.02)
    ax.set_ylim(c["ymin"].min() - 0.02, c["ymax"].max() + 0.02)
    face_axes(ax, run)
    if frictionless:
        ax.set_title("Fig. 11 — λ_tH per cell: frictionless scene, no tangential multipliers")
    else:
        unit = run.length_label()
        ax.set_title(f"Fig. 11 — λ_tH per cell and disc radii c_R (1 {unit} on the plot = "
                     f"{run.stress_in_mpa(1 / scale):.3g} MPa)")
    return [save(fig, out_dir, "fig11_tangential_multiplier.png")]


if __name__ == "__main__":
    run_one(plot, __doc__)
