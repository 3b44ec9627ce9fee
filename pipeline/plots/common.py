"""Shared helpers for the figure scripts: reading a run folder written by `contact3d solve`
(summary.json, contact_nodes.csv, contact_cells.csv, history.csv, body.vtu, contact.vtu) and
the friction law of its scene (the TOML echo in summary.json)."""
import argparse
import csv
import json
import os
import sys
import tomllib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from c3d.vtu import read_arrays as read_vtu_arrays  # noqa: E402  (pipeline/c3d: ASCII or binary VTU)


class Run:
    """One solver output folder."""

    def __init__(self, folder):
        self.dir = folder
        with open(os.path.join(folder, "summary.json")) as f:
            self.summary = json.load(f)
        self.scene = tomllib.loads(self.summary.get("scene", "")) if self.summary.get("scene") else {}

    def path(self, name):
        return os.path.join(self.dir, name)

    def table(self, name):
        """A CSV table as a dict of numpy columns (empty dict when the file is missing or empty); a
        column of words (history.csv's `update`) stays a column of strings."""
        p = self.path(name)
        if not os.path.isfile(p):
            return {}
        with open(p) as f:
            rows = list(csv.DictReader(f))
        if not rows:
            return {}
        def column(k):
            try:
                return np.array([float(r[k]) for r in rows])
            except ValueError:
                return np.array([r[k] for r in rows])
        return {k: column(k) for k in rows[0]}

    def history(self):
        return self.table("history.csv")

    def cells(self):
        return self.table("contact_cells.csv")

    def nodes(self):
        return self.table("contact_nodes.csv")

    def label(self):
        fr = self.scene.get("friction", {})
        if fr.get("law") == "ramp":
            return f"param = {fr.get('param', 0):.0e}".replace("e+0", "e")
        return os.path.basename(os.path.normpath(self.dir))

    def units(self):
        """The scene's unit system (summary.json "units"; SI for runs written before it existed)."""
        return self.summary.get("units", {"system": "m-N-Pa", "length": "m", "force": "N", "stress": "Pa"})

    def stress_in_mpa(self, values):
        """Stresses (multipliers, pressures) converted to MPa, whatever the scene's units."""
        factor = {"Pa": 1e-6, "kPa": 1e-3, "MPa": 1.0}[self.units()["stress"]]
        return np.asarray(values, dtype=float) * factor

    def length_in_um(self, values):
        """Small lengths (displacements, slips) converted to µm."""
        factor = {"m": 1e6, "mm": 1e3}[self.units()["length"]]
        return np.asarray(values, dtype=float) * factor

    def length_label(self):
        return self.units()["length"]

    def cell_polygons(self):
        """The pieces of the cells of T_H as drawn in contact_cells.vtu: a list of (cell, (k, 2) array of
        x, y) — each cell's true polygon (clipped to Γc), not its bounding rectangle."""
        arrays = read_vtu_arrays(self.path("contact_cells.vtu"))
        points = arrays["Points"].astype(float).reshape(-1, 3)
        conn = arrays["connectivity"].astype(int).ravel()
        offsets = arrays["offsets"].astype(int).ravel()
        owner = arrays["cell"].astype(int).ravel()
        starts = np.concatenate([[0], offsets[:-1]])
        return [(owner[k], points[conn[a:b], :2]) for k, (a, b) in enumerate(zip(starts, offsets))]

    def mesh_text(self):
        s = self.summary
        return f"{s.get('mesh', '?')}: {s.get('n_nodes')} nodes, {s.get('n_tets')} tets"


def friction_law(friction):
    """F(t) as a vectorised function from the scene's [friction] table (mirrors solver/friction)."""
    law = friction.get("law", "none")
    if law == "none" or friction.get("slip_bound", 0) == 0:
        return lambda t: np.zeros_like(np.asarray(t, dtype=float))
    if law == "constant":
        v = float(friction.get("value", 0))
        return lambda t: np.full_like(np.asarray(t, dtype=float), v)
    if law == "ramp":
        hi, lo = float(friction.get("high", 0.3)), float(friction.get("low", 0.2))
        t0, p = float(friction.get("t0", 1e-5)), float(friction.get("param", 6e4))
        width = 2.0 / p
        return lambda t: hi + (lo - hi) * np.clip((np.asarray(t, dtype=float) - t0) / width, 0.0, 1.0)
    if law == "table":
        pts = np.array(friction["points"], dtype=float)
        return lambda t: np.interp(np.asarray(t, dtype=float), pts[:, 0], pts[:, 1])
    raise ValueError(f"unknown friction law '{law}'")


def read_vtu(path):
    import meshio
    return meshio.read(path)


def boundary_triangles(tets):
    """Faces of a tetrahedral mesh that belong to exactly one tetrahedron."""
    faces = np.concatenate([tets[:, [0, 1, 2]], tets[:, [0, 1, 3]], tets[:, [0, 2, 3]], tets[:, [1, 2, 3]]])
    key = np.sort(faces, axis=1)
    _, idx, counts = np.unique(key, axis=0, return_index=True, return_counts=True)
    return faces[idx[counts == 1]]


def face_triangulation(run):
    """(matplotlib Triangulation of Γc in the (x, y) plane, contact.vtu mesh)."""
    import matplotlib.tri as mtri
    m = read_vtu(run.path("contact.vtu"))
    tris = np.concatenate([c.data for c in m.cells if c.type == "triangle"])
    return mtri.Triangulation(m.points[:, 0], m.points[:, 1], tris), m


def cell_patches(ax, run, values, cmap="viridis", vmin=None):
    """Draws the cells of T_H as their polygons (contact_cells.vtu) coloured by a piecewise-constant
    value per cell; returns the collection."""
    from matplotlib.collections import PolyCollection
    polys = run.cell_polygons()
    values = np.asarray(values)
    pc = PolyCollection([p for _, p in polys], cmap=cmap, edgecolor="face", linewidth=0.2)  # pieces: no inner edges
    pc.set_array(values[[c for c, _ in polys]])
    if vmin is not None:
        pc.set_clim(vmin=vmin)
    ax.add_collection(pc)
    xy = np.concatenate([p for _, p in polys])
    ax.set_xlim(xy[:, 0].min(), xy[:, 0].max())
    ax.set_ylim(xy[:, 1].min(), xy[:, 1].max())
    return pc


def face_axes(ax, run=None):
    unit = run.length_label() if run is not None else "m"
    ax.set_aspect("equal")
    ax.set_xlabel(f"x [{unit}]")
    ax.set_ylabel(f"y [{unit}]")


def save(fig, out_dir, name):
    os.makedirs(out_dir, exist_ok=True)
    path = os.path.join(out_dir, name)
    fig.savefig(path, dpi=130, bbox_inches="tight")
    plt.close(fig)
    return path


def run_one(plot, description):
    """Command line of a one-run figure script: `script.py RUN [--out DIR]`; prints the files written."""
    ap = argparse.ArgumentParser(description=description)
    ap.add_argument("run")
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    print("\n".join(plot(Run(a.run), a.out or a.run + "/figures")))
