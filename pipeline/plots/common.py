"""Shared helpers for the figure scripts: reading a run folder written by `contact3d solve`
(summary.json, contact_nodes.csv, contact_cells.csv, history.csv, body.vtu, contact.vtu) and
the friction law of its scene (the TOML echo in summary.json)."""
import argparse
import csv
import json
import os
import tomllib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


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
        """A CSV table as a dict of numpy columns (empty dict when the file is missing or empty)."""
        p = self.path(name)
        if not os.path.isfile(p):
            return {}
        with open(p) as f:
            rows = list(csv.DictReader(f))
        if not rows:
            return {}
        return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}

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


def cell_rectangles(ax, cells, values, cmap="viridis", label="", vmin=None):
    """Draws the cells of T_H as rectangles coloured by a piecewise-constant value; returns the collection."""
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Rectangle
    patches = [Rectangle((x0, y0), x1 - x0, y1 - y0)
               for x0, x1, y0, y1 in zip(cells["xmin"], cells["xmax"], cells["ymin"], cells["ymax"])]
    pc = PatchCollection(patches, cmap=cmap, edgecolor="k", linewidth=0.3)
    pc.set_array(np.asarray(values))
    if vmin is not None:
        pc.set_clim(vmin=vmin)
    ax.add_collection(pc)
    ax.set_xlim(cells["xmin"].min(), cells["xmax"].max())
    ax.set_ylim(cells["ymin"].min(), cells["ymax"].max())
    return pc


def face_axes(ax):
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")


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
