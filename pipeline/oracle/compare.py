"""Comparing the two solutions: nodes matched by coordinates, L2 norms on Γc, the contact forces."""
from __future__ import annotations

import numpy as np

import csv
import math
from pathlib import Path

import c3d.vtu
from oracle.errors import SideFailed


def read_csv(path: Path, required: list[str]) -> dict[str, np.ndarray]:
    if not path.exists():
        raise SideFailed(f"missing output {path}")
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    if not rows:
        raise SideFailed(f"{path}: empty")
    head = [h.strip() for h in rows[0]]
    for r in required:
        if r not in head:
            raise SideFailed(f"{path}: no column {r!r} (have {head})")
    body = [r for r in rows[1:] if r]
    out = {}
    for k, h in enumerate(head):
        try:
            out[h] = np.array([float(r[k]) for r in body], dtype=float)
        except ValueError:
            out[h] = np.array([r[k] for r in body])
    return out


def match_points(a: np.ndarray, b: np.ndarray, tol: float) -> np.ndarray:
    """For each row of a, the index of the row of b within tol (or -1)."""
    idx = np.full(len(a), -1, dtype=np.int64)
    if len(b) == 0:
        return idx
    chunk = max(1, 2_000_000 // max(len(b), 1))
    for s0 in range(0, len(a), chunk):
        d = np.linalg.norm(a[s0:s0 + chunk, None, :] - b[None, :, :], axis=2)
        j = np.argmin(d, axis=1)
        ok = d[np.arange(len(j)), j] <= tol
        idx[s0:s0 + chunk] = np.where(ok, j, -1)
    return idx


def surface_l2_sq(coords: np.ndarray, tris: np.ndarray, field: np.ndarray) -> float:
    """Exact integral of |P1 interpolant|^2 over the triangles (field: nodes x components)."""
    p0, p1, p2 = coords[tris[:, 0]], coords[tris[:, 1]], coords[tris[:, 2]]
    area = 0.5 * np.linalg.norm(np.cross(p1 - p0, p2 - p0), axis=1)
    f = field[tris]  # (ntri, 3 nodes, ncomp)
    per = (f ** 2).sum(axis=1) + f.sum(axis=1) ** 2  # (ntri, ncomp)
    return float((area[:, None] * per).sum() / 12.0)


def compare(mesh: dict, prob: dict, ff: dict, ours: dict, cells: dict, contact_tol: float) -> dict:
    contact_tris = mesh["tris"][np.isin(mesh["tri_tags"], prob["contact"])]
    # held nodes: clamped, or all three components prescribed (u given on both sides)
    held_tags = list(prob["clamped"]) + [t for t, mask, *_ in prob.get("displacement", []) if all(mask)]
    held_nodes = set(np.unique(mesh["tris"][np.isin(mesh["tri_tags"], held_tags)]).tolist())
    gnodes = np.unique(contact_tris)
    local = {int(g): k for k, g in enumerate(gnodes)}
    ltris = np.vectorize(local.get)(contact_tris) if len(contact_tris) else contact_tris
    xyz = mesh["coords"][gnodes]
    area = float(0.5 * np.linalg.norm(np.cross(xyz[ltris[:, 1]] - xyz[ltris[:, 0]],
                                               xyz[ltris[:, 2]] - xyz[ltris[:, 0]]), axis=1).sum())
    h = math.sqrt(area / max(len(gnodes), 1))
    tol = 1e-6 * h

    def place(side: dict, who: str) -> tuple[np.ndarray, np.ndarray, int]:
        pts = np.column_stack([side["x"], side["y"], side["z"]])
        j = match_points(pts, xyz, tol)
        if np.any(j < 0):
            raise SideFailed(f"{who}: {int((j < 0).sum())} contact nodes are not nodes of the contact "
                             "triangles of the mesh")
        u = np.zeros((len(gnodes), 3))
        have = np.zeros(len(gnodes), dtype=bool)
        u[j] = np.column_stack([side["u1"], side["u2"], side["u3"]])
        have[j] = True
        return u, have, len(j)

    uf, hf, nf = place(ff, "FreeFEM")
    uo, ho, no = place(ours, "contact3d")
    only_ff = int((hf & ~ho).sum())
    only_ours = int((ho & ~hf).sum())
    # nodes in neither list must be clamped ones (u = 0 on both sides)
    neither = [int(gnodes[k]) for k in np.where(~hf & ~ho)[0]]
    unclamped = [g for g in neither if g not in held_nodes]
    if unclamped:
        raise SideFailed(f"{len(unclamped)} nodes of the contact face are in neither output and not clamped")

    d = uf - uo
    nrm = lambda f: math.sqrt(surface_l2_sq(xyz, ltris, f))
    l2_ff = nrm(uf)
    rel = nrm(d) / max(l2_ff, 1e-300)
    # Each component's difference relative to that component of u_ff, but never to less than 1% of the
    # whole ‖u_ff‖: a sole pressed everywhere has almost no normal displacement in FreeFEM's answer
    # (nodal non-penetration), and one node lifting by 3e-7 m made the normal column read 17.7 where
    # the whole difference was 4e-4 (it read 8e18 with no node lifting, before any floor).
    floor = max(0.01 * l2_ff, 1e-300)
    rel_n = nrm(d[:, 2:3]) / max(nrm(uf[:, 2:3]), floor)
    rel_t = nrm(d[:, :2]) / max(nrm(uf[:, :2]), floor) if l2_ff > 0 else 0.0
    both = hf & ho
    umax_ff = float(np.linalg.norm(uf, axis=1).max())
    maxdiff = float(np.linalg.norm(d[both], axis=1).max()) if both.any() else 0.0
    # contact sets: wn - d = -u3 - z > -contact_tol * max|u| (same threshold for both sides; the
    # node's height z is its initial gap d)
    thr = contact_tol * umax_ff
    gap = xyz[:, 2]
    cf = (-uf[:, 2] - gap > -thr) & both
    co = (-uo[:, 2] - gap > -thr) & both
    # forces
    Fn_ff = float((ff["mass"] * ff["lambda_n"]).sum())
    Ft_ff = np.array([(ff["mass"] * ff["lambda_t1"]).sum(), (ff["mass"] * ff["lambda_t2"]).sum()])
    Fn_o = float((cells["area"] * cells["lambda_n"]).sum())
    Ft_o = np.array([(cells["area"] * cells["lambda_t1"]).sum(), (cells["area"] * cells["lambda_t2"]).sum()])
    rel_fn = abs(Fn_o - Fn_ff) / max(abs(Fn_ff), 1e-300)
    # judged against the gross friction (the sum of |λ_t| over the face) as well as the net: where
    # friction cancels by symmetry (an annulus pressed down) the net is rounding on both sides
    gross_ff = float((ff["mass"] * np.hypot(ff["lambda_t1"], ff["lambda_t2"])).sum())
    gross_o = float((cells["area"] * np.hypot(cells["lambda_t1"], cells["lambda_t2"])).sum())
    ft_scale = max(np.linalg.norm(Ft_ff), np.linalg.norm(Ft_o), gross_ff, gross_o)
    rel_ft = float(np.linalg.norm(Ft_o - Ft_ff) / ft_scale) if ft_scale > 0 else 0.0
    return {
        "n_face_nodes": int(len(gnodes)), "n_contact_nodes_ff": nf, "n_contact_nodes_ours": no,
        "nodes_only_ff": only_ff, "nodes_only_ours": only_ours, "h": h, "contact_area": area,
        "l2_u_ff": l2_ff, "l2_u_ours": nrm(uo), "rel_l2": rel,
        "l2_un_ff": nrm(uf[:, 2:3]), "l2_un_ours": nrm(uo[:, 2:3]),
        "l2_ut_ff": nrm(uf[:, :2]), "l2_ut_ours": nrm(uo[:, :2]), "rel_l2_normal": rel_n, "rel_l2_tangential": rel_t,
        "max_abs_u_ff": umax_ff, "max_diff": maxdiff, "rel_max_diff": maxdiff / max(umax_ff, 1e-300),
        "contact_threshold": thr, "in_contact_ff": int(cf.sum()), "in_contact_ours": int(co.sum()),
        "contact_ff_only": int((cf & ~co).sum()), "contact_ours_only": int((co & ~cf).sum()),
        "max_penetration_ours": float(max(0.0, (-uo[ho, 2] - gap[ho]).max())) if ho.any() else 0.0,
        "Fn_ff": Fn_ff, "Fn_ours": Fn_o, "rel_Fn": rel_fn,
        "Ft_ff": Ft_ff.tolist(), "Ft_ours": Ft_o.tolist(), "rel_Ft": rel_ft,
    }


def read_vtu_points_and_displacement(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """Points and the "displacement" array of contact3d's body.vtu (ASCII or binary)."""
    if not path.exists():
        raise SideFailed(f"missing output {path}")
    arrays = c3d.vtu.read_arrays(path)
    for name in ("Points", "displacement"):
        if name not in arrays:
            raise SideFailed(f"{path}: no array {name!r}")
    return arrays["Points"].astype(float).reshape(-1, 3), arrays["displacement"].astype(float).reshape(-1, 3)


def body_difference(ff_field: dict, points: np.ndarray, u_ours: np.ndarray, tol: float) -> dict:
    """The two displacements over the whole body, nodes matched by coordinates: the relative
    largest nodal difference max|Δu| / max|u_ff| and the relative nodal l2 difference. On Γc a
    solution that is nearly zero there (a stuck, pressed face) makes relative face norms meaningless;
    these say how far apart the two solutions of the body are."""
    ff_pts = np.column_stack([ff_field["x"], ff_field["y"], ff_field["z"]])
    u_ff = np.column_stack([ff_field["u1"], ff_field["u2"], ff_field["u3"]])
    idx = match_points(ff_pts, points, tol)
    if (idx < 0).any():
        raise SideFailed(f"{int((idx < 0).sum())} FreeFEM nodes have no contact3d node within {tol:g}")
    diff = np.linalg.norm(u_ours[idx] - u_ff, axis=1)
    scale = float(np.linalg.norm(u_ff, axis=1).max())
    return {"body_max_abs_u_ff": scale,
            "body_rel_max_diff": float(diff.max() / scale) if scale > 0 else float("nan"),
            "body_rel_l2": float(np.sqrt((diff ** 2).sum() / max((u_ff ** 2).sum(), 1e-300)))}
