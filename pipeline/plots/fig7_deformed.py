#!/usr/bin/python3
"""Fig. 7 of the paper: the deformed body (displacement × 500 by default), boundary triangles of
body.vtu coloured by |u|.
usage: fig7_deformed.py RUN_DIR [--out DIR] [--scale 500]"""
import argparse

import numpy as np
from matplotlib import cm, colors
from mpl_toolkits.mplot3d.art3d import Poly3DCollection

from common import Run, boundary_triangles, plt, read_vtu, save


def plot(run, out_dir, scale=500.0):
    m = read_vtu(run.path("body.vtu"))
    tets = np.concatenate([c.data for c in m.cells if c.type == "tetra"])
    u = np.asarray(m.point_data["displacement"], dtype=float)
    tris = boundary_triangles(tets)
    x = m.points + scale * u
    mag = run.length_in_um(np.linalg.norm(u, axis=1))
    face_mag = mag[tris].mean(axis=1)
    norm = colors.Normalize(vmin=mag.min(), vmax=mag.max())
    cmap = plt.get_cmap("viridis")
    fig = plt.figure(figsize=(8, 5))
    ax = fig.add_subplot(projection="3d")
    poly = Poly3DCollection(x[tris], facecolors=cmap(norm(face_mag)), edgecolors=(0, 0, 0, 0.15), linewidths=0.1)
    ax.add_collection3d(poly)
    lo, hi = x.min(axis=0), x.max(axis=0)
    ax.set_xlim(lo[0], hi[0]); ax.set_ylim(lo[1], hi[1]); ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect(hi - lo)
    ax.view_init(elev=22, azim=-60)
    unit = run.length_label()
    ax.set_xlabel(f"x [{unit}]"); ax.set_ylabel(f"y [{unit}]"); ax.set_zlabel(f"z [{unit}]", labelpad=-2)
    sm = cm.ScalarMappable(norm=norm, cmap=cmap)
    fig.colorbar(sm, ax=ax, shrink=0.6, pad=0.1, label="|u| [µm]")
    ax.set_title(f"Fig. 7 — deformed body (displacement × {scale:g})")
    return [save(fig, out_dir, "fig07_deformed_body.png")]


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("run")
    ap.add_argument("--out", default=None)
    ap.add_argument("--scale", type=float, default=500.0)
    a = ap.parse_args()
    print("\n".join(plot(Run(a.run), a.out or a.run + "/figures", a.scale)))
