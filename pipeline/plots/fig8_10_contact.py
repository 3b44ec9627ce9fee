#!/usr/bin/python3
"""Figs. 8–10 of the paper, on Γc seen from above:
  8 a) −w_hn = u_3 (nodal, P1)            8 b) λ_nH (piecewise constant per cell of T_H)
  9 a) ‖w_ht‖ (nodal, P1)                 9 b) ‖λ_tH‖ (per cell)
  10   F(‖w_ht‖) (nodal)
Nodal fields come from contact.vtu (all nodes of Γc, including those on Γu), cell fields from
contact_cells.csv, each cell drawn as its polygon (contact_cells.vtu). Values are shown in µm and MPa
whatever the scene's consistent units (summary.json "units").
usage: fig8_10_contact.py RUN_DIR [--out DIR]"""

import numpy as np

from common import run_one, cell_patches, face_axes, face_triangulation, plt, save


def _nodal(ax, fig, run, tri, values, label, cmap="viridis"):
    tc = ax.tripcolor(tri, values, shading="gouraud", cmap=cmap)
    fig.colorbar(tc, ax=ax, label=label, shrink=0.85)
    face_axes(ax, run)
    ax.set_xlim(tri.x.min(), tri.x.max())
    ax.set_ylim(tri.y.min(), tri.y.max())


def _cellwise(ax, fig, run, values, label, cmap="viridis"):
    pc = cell_patches(ax, run, values, cmap=cmap)
    fig.colorbar(pc, ax=ax, label=label, shrink=0.85)
    face_axes(ax, run)


def _pair(title, name, left, right, out_dir):
    fig, axes = plt.subplots(2, 1, figsize=(8, 6.4))
    left(axes[0], fig)
    right(axes[1], fig)
    fig.suptitle(title)
    fig.tight_layout()
    return save(fig, out_dir, name)


def plot(run, out_dir):
    tri, m = face_triangulation(run)
    u = np.asarray(m.point_data["displacement"], dtype=float)
    cells = run.cells()
    paths = []
    ln = cells["lambda_n"]
    lt = np.hypot(cells["lambda_t1"], cells["lambda_t2"])

    def a8(ax, fig):
        _nodal(ax, fig, run, tri, run.length_in_um(u[:, 2]), "−w_hn = u₃ [µm]", cmap="coolwarm")
        ax.set_title("a) normal displacement −w_hn on Γc")

    def b8(ax, fig):
        _cellwise(ax, fig, run, run.stress_in_mpa(ln), "λ_nH [MPa]")
        ax.set_title("b) Lagrange multiplier λ_nH (contact pressure)")

    paths.append(_pair("Fig. 8 — normal displacement and normal multiplier", "fig08_normal.png", a8, b8, out_dir))

    def a9(ax, fig):
        _nodal(ax, fig, run, tri, run.length_in_um(np.hypot(u[:, 0], u[:, 1])), "‖w_ht‖ [µm]")
        ax.set_title("a) norm of the tangential displacement ‖w_ht‖")

    def b9(ax, fig):
        _cellwise(ax, fig, run, run.stress_in_mpa(lt), "‖λ_tH‖ [MPa]")
        ax.set_title("b) norm of the Lagrange multiplier ‖λ_tH‖")

    paths.append(_pair("Fig. 9 — tangential displacement and tangential multiplier", "fig09_tangential.png", a9, b9,
                       out_dir))

    fig, ax = plt.subplots(figsize=(8, 3.4))
    F = np.asarray(m.point_data["friction_coefficient"], dtype=float).ravel()
    _nodal(ax, fig, run, tri, F, "F(‖w_ht‖) [–]")
    ax.set_title("Fig. 10 — coefficient of friction F on Γc")
    paths.append(save(fig, out_dir, "fig10_friction_on_contact.png"))
    return paths


if __name__ == "__main__":
    run_one(plot, __doc__)
