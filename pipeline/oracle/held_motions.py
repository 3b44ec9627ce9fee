"""Which rigid motions the FreeFEM reference can hold: those its prescribed conditions hold, and those
with a part along the foundation's normal on Γc (the contact pushes back on them). A motion left free
by the conditions that only slides or turns in the foundation's plane (a cylinder lying free along
its line of contact, a plate on the ground) is held by friction or by nothing; the reference starts
every variant with a frictionless Newton solve whose matrix is then singular, and it runs its 100
Newton steps into a failure (a cylinder of 5 000 nodes: 75 s). contact3d solves such bodies
(model/held_by_contact.hpp); the cross-check refuses them up front instead."""
from __future__ import annotations

import numpy as np

# Singular values below this fraction of the largest are zero (the modes are scaled to the body's size).
RANK_TOL = 1e-8


def rigid_modes(coords: np.ndarray) -> np.ndarray:
    """(n, 3, 6): the three translations and the three rotations (about axes through the centroid,
    scaled by the body's size so that all six have displacements of order one) at each node."""
    centre = coords.mean(axis=0)
    size = float(np.max(np.ptp(coords, axis=0))) or 1.0
    r = (coords - centre) / size
    modes = np.zeros((len(coords), 3, 6))
    for c in range(3):
        modes[:, c, c] = 1.0
        axis = np.zeros(3)
        axis[c] = 1.0
        modes[:, :, 3 + c] = np.cross(axis, r)
    return modes


def null_space(A: np.ndarray, basis: np.ndarray) -> np.ndarray:
    """The combinations of `basis`'s columns that A maps to zero (as columns in the original 6 modes)."""
    if A.shape[0] == 0:
        return basis
    _, s, vt = np.linalg.svd(A @ basis)
    rank = int(np.sum(s > RANK_TOL * s[0])) if s.size and s[0] > 0 else 0
    return basis @ vt[rank:].T


def describe(motion: np.ndarray) -> str:
    t, w = motion[:3], motion[3:]
    v, kind = (w, "a rotation about the axis along") if np.linalg.norm(w) > 1e-6 else (t, "a translation along")
    v = v / np.linalg.norm(v)
    if v[np.argmax(np.abs(v))] < 0:
        v = -v
    v[np.abs(v) < 1e-9] = 0.0
    return f"{kind} ({', '.join(f'{x:.3g}' for x in v + 0.0)})"


def motions_held_by_friction_alone(mesh: dict, prob: dict) -> list[str]:
    """The rigid motions (described) that the prescribed conditions leave free and that move no
    contact node along the foundation's normal (z in the frame FreeFEM solves in)."""
    coords, tris, tags = mesh["coords"], mesh["tris"], mesh["tri_tags"]
    modes = rigid_modes(coords)

    def nodes_of(group_tags) -> np.ndarray:
        return np.unique(tris[np.isin(tags, list(group_tags))].ravel())

    rows = [modes[nodes_of(prob["clamped"])].reshape(-1, 6)]
    for tag, mask, _, _ in prob["displacement"]:
        nodes = nodes_of([tag])
        rows += [modes[nodes, c, :] for c in range(3) if mask[c]]
    free = null_space(np.vstack(rows), np.eye(6))
    if free.shape[1] == 0:
        return []
    normal_part = modes[nodes_of(prob["contact"]), 2, :]
    sliding = null_space(normal_part, free)
    return [describe(sliding[:, k]) for k in range(sliding.shape[1])]
