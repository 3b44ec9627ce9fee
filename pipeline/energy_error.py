#!/usr/bin/env python3
"""Energy-norm discretization error of a coarse P1 solution against a finer reference solution.

Given two contact3d result directories (each with `body.vtu`: P1 displacement on tetrahedra),
this measures

    abs = sqrt(a(e, e)),   rel = abs / sqrt(a(u_fine, u_fine)),   e = u_fine - I_fine(u_coarse),

where a(u, v) = int eps(u) : C : eps(v) is the linear-elastic energy (isotropic Hooke law) and
I_fine(u_coarse) is the P1 function on the fine mesh whose nodal values are the coarse solution
evaluated at the fine nodes. This is the standard "interpolate onto the reference mesh" estimate.
It is exact (I_fine(u_coarse) == u_coarse) only when the meshes are nested, i.e. every fine tet
lies inside one coarse tet (true for the paper_brick generator with n and 2n, checked for
n = 4 -> 8 and 8 -> 16). With non-nested meshes the interpolation adds an error of the same order
as the discretization error being measured, so the numbers are then an estimate of the error and
of its convergence rate, not the exact energy norm of u_fine - u_coarse.

Both meshes must cover the same domain: a fine node that lies in no coarse tet is an error.

Usage:
    energy_error.py --coarse DIR --fine DIR [--young E] [--poisson NU]
    energy_error.py --self-test [--bin CONTACT3D]
"""
import argparse
import os
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET

import numpy as np

import c3d.run
import c3d.vtu

VTK_TETRA = 10
BARY_TOL = 1e-9  # barycentric coordinates are dimensionless, so this tolerance is relative


def read_body_vtu(path):
    """Points (N,3), tetrahedra (T,4) and displacement (N,3) of a VTK UnstructuredGrid (ASCII or binary)."""
    arrays = c3d.vtu.read_arrays(path)
    missing = [n for n in ("Points", "displacement", "connectivity", "offsets", "types") if n not in arrays]
    if missing:
        raise ValueError(f"{path}: no DataArray named {missing[0]!r}")
    points = arrays["Points"].astype(float).reshape(-1, 3)
    disp = arrays["displacement"].astype(float).reshape(-1, 3)
    conn, offsets, types = (arrays[n].astype(np.int64).ravel() for n in ("connectivity", "offsets", "types"))
    if len(disp) != len(points) or len(offsets) != len(types):
        raise ValueError(f"{path}: inconsistent array sizes")
    # keep the tetrahedra (a cell's nodes are conn[offsets[c-1]:offsets[c]])
    ends = offsets[types == VTK_TETRA]
    if len(ends) == 0:
        raise ValueError(f"{path}: no tetrahedra")
    tets = conn[ends[:, None] - 4 + np.arange(4)]
    return points, tets, disp


def _edge_matrices(points, tets):
    """Per tet the 3x3 matrix whose rows are the edges x_i - x_0 (i = 1..3)."""
    x = points[tets]
    return x[:, 1:] - x[:, :1]


def _bucket_tets(lo, hi, n_cells_target):
    """Uniform grid over the tets' bounding boxes [lo, hi]; returns (origin, h, dims, start, ids):
    the tets overlapping cell c are ids[start[c]:start[c+1]]."""
    origin, top = lo.min(axis=0), hi.max(axis=0)
    extent = np.maximum(top - origin, 1e-300)
    # cells about half the mean tet size (0.55: not aligned with structured meshes): a cell then
    # overlaps the boxes of only a few dozen tets
    h = np.maximum(0.55 * (hi - lo).mean(axis=0), extent * 1e-6)
    dims = np.ceil(extent / h).astype(np.int64)
    while dims.prod() > n_cells_target:  # cap the memory of the grid
        h *= 1.26
        dims = np.ceil(extent / h).astype(np.int64)
    pad = 1e-9 * extent  # so that points within the barycentric tolerance stay in range
    i0 = np.clip(((lo - pad - origin) // h).astype(np.int64), 0, dims - 1)
    i1 = np.clip(((hi + pad - origin) // h).astype(np.int64), 0, dims - 1)
    span = i1 - i0 + 1
    count = span.prod(axis=1)
    # enumerate every (tet, cell) pair: local index k -> offsets (a, b, c) in the tet's cell box
    tet = np.repeat(np.arange(len(lo)), count)
    k = np.arange(len(tet)) - np.repeat(np.cumsum(count) - count, count)
    s = span[tet]
    ijk = i0[tet] + np.stack([k // (s[:, 1] * s[:, 2]), (k // s[:, 2]) % s[:, 1], k % s[:, 2]], 1)
    cell = (ijk[:, 0] * dims[1] + ijk[:, 1]) * dims[2] + ijk[:, 2]
    order = np.argsort(cell, kind="stable")
    start = np.searchsorted(cell[order], np.arange(dims.prod() + 1))
    return origin, h, dims, start, tet[order]


def interpolate_p1(points, tets, values, targets):
    """Values (M,3) at `targets` of the P1 field `values` (N,3) on the mesh (points, tets)."""
    x = points[tets]
    inv = np.linalg.inv(_edge_matrices(points, tets))  # lambda_{1..3} = (x - x0) @ inv
    origin, h, dims, start, ids = _bucket_tets(x.min(axis=1), x.max(axis=1), 8 * len(tets) + 64)
    ijk = np.clip(((targets - origin) // h).astype(np.int64), 0, dims - 1)
    cell = (ijk[:, 0] * dims[1] + ijk[:, 1]) * dims[2] + ijk[:, 2]
    first, n_cand = start[cell], start[cell + 1] - start[cell]
    found = np.full(len(targets), -1)
    bary = np.zeros((len(targets), 4))
    for slot in range(int(n_cand.max(initial=0))):  # loop over candidate slots, not points
        p = np.nonzero((found < 0) & (n_cand > slot))[0]
        if len(p) == 0:
            break
        t = ids[first[p] + slot]
        lam = np.einsum("pj,pji->pi", targets[p] - x[t, 0], inv[t])
        lam = np.column_stack([1.0 - lam.sum(axis=1), lam])
        inside = (lam >= -BARY_TOL).all(axis=1)
        found[p[inside]], bary[p[inside]] = t[inside], lam[inside]
    missing = np.nonzero(found < 0)[0]
    if len(missing):
        raise ValueError(f"{len(missing)} of {len(targets)} target points lie in no tet of the "
                         f"coarse mesh (first: {targets[missing[0]]}); the meshes do not cover "
                         "the same domain")
    return np.einsum("mi,mic->mc", bary, values[tets[found]])


def _lame(young, poisson):
    return young * poisson / ((1 + poisson) * (1 - 2 * poisson)), young / (2 * (1 + poisson))


def energy_norm_sq(points, tets, u, young, poisson):
    """a(u, u) = sum_T |T| eps(u):C:eps(u) for the P1 field u (N,3), isotropic Hooke law."""
    edges = _edge_matrices(points, tets)
    vol = np.abs(np.linalg.det(edges)) / 6.0
    g = np.linalg.inv(edges)  # column i-1 is grad lambda_i (i = 1..3)
    grads = np.concatenate([-g.sum(axis=2, keepdims=True), g], axis=2)  # (T, 3, 4)
    du = np.einsum("tic,tbi->tcb", u[tets], grads)  # du[t, c, b] = d u_c / d x_b
    eps = 0.5 * (du + du.transpose(0, 2, 1))
    lam, mu = _lame(young, poisson)
    tr = np.trace(eps, axis1=1, axis2=2)
    return float(np.sum(vol * (lam * tr**2 + 2 * mu * np.einsum("tab,tab->t", eps, eps))))


def energy_error_fields(coarse, fine, young, poisson):
    """Energy error of the coarse field; coarse and fine are (points, tets, u) triples."""
    (pc, tc, uc), (pf, tf, uf) = coarse, fine
    e = uf - interpolate_p1(pc, tc, uc, pf)
    ref = energy_norm_sq(pf, tf, uf, young, poisson)
    err = energy_norm_sq(pf, tf, e, young, poisson)
    return dict(abs=float(np.sqrt(err)), rel=float(np.sqrt(err / ref)), ref_energy=ref)


def energy_error(coarse_dir, fine_dir, young, poisson):
    """Energy error of the solution in coarse_dir against the reference in fine_dir."""
    return energy_error_fields(read_body_vtu(os.path.join(coarse_dir, "body.vtu")),
                               read_body_vtu(os.path.join(fine_dir, "body.vtu")), young, poisson)


def _solve_brick(binary, n, out):
    scene = os.path.join(os.path.dirname(os.path.abspath(__file__)), "scenes", "paper_brick.toml")
    proc, _ = c3d.run.solve(binary, scene, out, ["mesh.generator=paper_brick", f"mesh.n={n}"])
    if proc.returncode != 0:
        raise RuntimeError(f"solve failed ({' '.join(proc.args)}):\n{proc.stderr}")
    return read_body_vtu(os.path.join(out, "body.vtu"))


def self_test(binary, young, poisson):
    """Linear fields are reproduced exactly: interpolation, zero energy error, analytic energy."""
    failures = []

    def check(ok, what):
        print(("ok    " if ok else "FAIL  ") + what)
        failures.extend([] if ok else [what])

    with tempfile.TemporaryDirectory() as tmp:
        pc, tc, _ = _solve_brick(binary, 4, os.path.join(tmp, "n4"))
        pf, tf, _ = _solve_brick(binary, 8, os.path.join(tmp, "n8"))
        real = energy_error(os.path.join(tmp, "n4"), os.path.join(tmp, "n8"), young, poisson)
    check(0 < real["rel"] < 1, f"paper brick n=4 vs n=8: rel energy error {real['rel']:.4f} in (0, 1)")
    a = np.array([[1.0, 0.3, -0.2], [0.1, -0.5, 0.4], [0.7, 0.2, 0.9]]) * 1e-4
    linear = lambda p: p @ a.T + np.array([1e-4, -2e-4, 3e-4])
    err = np.abs(interpolate_p1(pc, tc, linear(pc), pf) - linear(pf)).max() / np.abs(linear(pf)).max()
    check(err < 1e-12, f"linear field interpolated n=4 -> n=8: max rel error {err:.2e} < 1e-12")
    rel = energy_error_fields((pc, tc, linear(pc)), (pf, tf, linear(pf)), young, poisson)["rel"]
    check(rel < 1e-10, f"energy error of a linear field: rel {rel:.2e} < 1e-10")
    eps, (lam, mu) = 0.5 * (a + a.T), _lame(young, poisson)
    volume = np.abs(np.linalg.det(_edge_matrices(pf, tf))).sum() / 6.0
    exact = volume * (lam * np.trace(eps) ** 2 + 2 * mu * np.sum(eps * eps))
    got = energy_norm_sq(pf, tf, linear(pf), young, poisson)
    check(abs(got - exact) <= 1e-12 * exact, f"a(u,u) of a linear field = volume * eps:C:eps "
          f"(volume {volume:.6g}): {got:.12e} vs {exact:.12e}")
    try:
        interpolate_p1(pc, tc, linear(pc), np.array([[-1.0, 0.5, 0.5]]))
        check(False, "a target outside the coarse mesh raises ValueError")
    except ValueError:
        check(True, "a target outside the coarse mesh raises ValueError")
    print("self-test " + ("FAILED" if failures else "passed"))
    return not failures


def main():
    repo = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    default_bin = next((b for b in (os.path.join(repo, d, "contact3d") for d in ("build", "build-perf"))
                        if os.path.exists(b)), os.path.join(repo, "build", "contact3d"))
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--self-test", action="store_true", help="check on linear fields and exit")
    ap.add_argument("--bin", default=default_bin, help="contact3d binary for --self-test")
    ap.add_argument("--coarse", help="result directory of the coarse solution")
    ap.add_argument("--fine", help="result directory of the reference (fine) solution")
    ap.add_argument("--young", type=float, default=21.19e10, help="Young's modulus (Pa)")
    ap.add_argument("--poisson", type=float, default=0.277, help="Poisson's ratio")
    args = ap.parse_args()
    if not (args.self_test or (args.coarse and args.fine)):
        ap.error("give --coarse DIR --fine DIR, or --self-test")
    try:
        if args.self_test:
            return 0 if self_test(args.bin, args.young, args.poisson) else 1
        t0 = time.perf_counter()
        r = energy_error(args.coarse, args.fine, args.young, args.poisson)
    except (OSError, ValueError, ET.ParseError, subprocess.CalledProcessError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    print(f"energy error: abs {r['abs']:.6e}  rel {r['rel']:.6e}  (a(u_fine,u_fine) "
          f"{r['ref_energy']:.6e}, {time.perf_counter() - t0:.2f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
