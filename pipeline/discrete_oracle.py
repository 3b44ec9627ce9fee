#!/usr/bin/python3
"""Independent oracle for contact3d's discrete problem (Haslinger & Ligursky 2009, sec. 5): the same
discretisation written again from design.md and the paper, sharing no code with the solver.

Usage: OPENBLAS_NUM_THREADS=1 /usr/bin/python3 pipeline/discrete_oracle.py SCENE.toml RUNDIR [--mesh F.msh] [--set k=v ...] [--cells csv|vtu] [--tol 1e-6]

(RUNDIR: a finished `contact3d solve SCENE.toml --out RUNDIR [--mesh F] [--set ...]`; pass the same --mesh/--set.)
Own P1 tetrahedral elasticity (materials per volume group), loads (traction / pressure with gradients,
outward normals from the adjacent tet; body force), Dirichlet elimination (clamped groups, per-component
values with gradients), the foundation frame (smallest rotation taking plane_normal to +z; B built with
n, t1 = R^T e_x, t2 = R^T e_y, solve in user axes), Gamma_c = the contact groups' triangles (fully held
triangles dropped), the gap d = height above the plane (P1), cells: `--cells csv` clips the rectangles of
RUNDIR/contact_cells.csv to the projected triangles itself (valid where cells are plain clipped rectangles,
e.g. the paper brick's chessboard); `--cells vtu` takes the cell pieces drawn in RUNDIR/contact_cells.vtu
(merged / graded / per-material cells) and checks they tile Gamma_c and match the csv areas.
B rows = exact cell integrals (projected measure; `--measure surface` for the other reading) of
v_n = -v.n, v_t1, v_t2 of the P1 trace, prescribed values included (they go to the linear term), gap term
int_R d.  Dual Q = B K^+ B^T dense (scipy splu); QP over half-lines and discs by FISTA with restart
(per-cell Jacobi scaling); free rigid motions (per mesh part): fixing-dof generalized inverse, equalities
G lam = e by an augmented Lagrangian in scaled variables, then a semismooth-Newton polish of the whole
KKT system; rigid displacement alpha = -multiplier.  Friction: none | constant | ramp | table, Tresca (F g)
or Coulomb (F lambda_n, first solve frictionless), plain successive approximations from phi = 0 to
--fp-tol; radii integrate F(phi_h) exactly (pieces cut at F's breakpoints); phi_h = P1 interpolant of
|w_t| at EVERY vertex of Gamma_c (prescribed components included).  Diagnostic switches that reproduce
contact3d's conventions: --slip-free-dofs-only, --phi-zero-held, --gap-snap TOL.
Prints max relative differences (u on Gamma_c, u in the body, lambda per cell, radii), one map step from
contact3d's own state, and a KKT audit of contact3d's (u, lambda) in the oracle's K, f, B, d.
"""
import sys, os, json, math, argparse, tomllib, csv, re

import numpy as np
import scipy.linalg
import scipy.sparse as sp
import scipy.sparse.linalg as spla

import c3d.vtu

# ----------------------------------------------------------------------------- mesh
def read_medit(path):
    """ASCII Medit .mesh (FreeFEM's savemesh, MMG), as read_msh: a group's name is its integer label, as in
    the solver's scenes (contact = ["5"]). Keywords in any case, '#' comments; repeated element sections
    add up; sections of normals, tangents and required entities are skipped; second-order ones refused."""
    text = re.sub(r'#[^\n]*', ' ', open(path, encoding='latin-1').read())
    tok = text.split()
    X = None
    tets, tetn, tris, trin = [], [], [], []
    widths = {'vertices': 4, 'triangles': 4, 'tetrahedra': 5, 'edges': 3, 'corners': 1, 'ridges': 1,
              'requiredvertices': 1, 'requirededges': 1, 'requiredtriangles': 1, 'normals': 3, 'tangents': 3,
              'normalatvertices': 2, 'tangentatvertices': 2, 'normalattrianglevertices': 3,
              'tangentatedgevertices': 3}
    i = 0
    while i < len(tok):
        key = tok[i].lower()
        if key in ('meshversionformatted', 'dimension'):
            i += 2
        elif key == 'end':
            break
        elif key in widths:
            n = int(tok[i + 1]); w = widths[key]
            block = tok[i + 2:i + 2 + n * w]
            if len(block) < n * w:
                raise CannotCheck(f'{path}: the {tok[i]} section ends early (truncated Medit file?)')
            rows = np.array(block, dtype=float).reshape(n, w) if n else np.zeros((0, w))
            if key == 'vertices':
                X = rows[:, :3]
            elif key == 'tetrahedra':
                tets += (rows[:, :4].astype(int) - 1).tolist(); tetn += [{str(int(r))} for r in rows[:, 4]]
            elif key == 'triangles':
                tris += (rows[:, :3].astype(int) - 1).tolist(); trin += [{str(int(r))} for r in rows[:, 3]]
            i += 2 + n * w
        elif key[0].isalpha():
            raise CannotCheck(f'{path}: Medit section {tok[i]!r} is not read by the oracle (P1 tetrahedra and '
                              'triangles only)')
        else:
            i += 1
    if X is None or len(tets) == 0:
        raise CannotCheck(f'{path}: no Vertices or Tetrahedra (is this a Medit volume mesh?)')
    return X, np.asarray(tets, int), tetn, np.asarray(tris, int).reshape(-1, 3), trin


def read_mesh(path):
    """The mesh the solver read: gmsh MSH (4.1 or 2.2, ASCII) or Medit .mesh (ASCII)."""
    if path.endswith('.meshb'):
        raise CannotCheck(f'{path}: a binary Medit mesh; the oracle reads ASCII files (FreeFEM: savemesh(Th, "x.mesh"))')
    with open(path, encoding='latin-1') as fh:
        head = fh.read(4096)
    if path.endswith('.mesh') or 'MeshVersionFormatted' in head:
        return read_medit(path)
    if '$MeshFormat' not in head:
        raise CannotCheck(f'{path}: neither a gmsh MSH nor a Medit mesh')
    return read_msh(path)


def read_msh(path):
    """MSH 4.1 / 2.2 ASCII reader -> nodes (N,3), tets (T,4) + tet physical names (list of sets),
    triangles (S,3) + triangle physical names."""
    txt = open(path, encoding='latin-1').read()
    lines = txt.split('\n')
    i = 0
    sections = {}
    while i < len(lines):
        l = lines[i].strip()
        if l.startswith('$') and not l.startswith('$End'):
            name = l[1:]
            j = i + 1
            while not lines[j].strip().startswith('$End' + name):
                j += 1
            sections[name] = lines[i + 1:j]
            i = j + 1
        else:
            i += 1
    ver = sections['MeshFormat'][0].split()
    if ver[1] != '0':
        raise CannotCheck('binary msh: not supported by this reader')
    phys = {}
    for l in sections.get('PhysicalNames', [])[1:]:
        p = l.split(maxsplit=2)
        if len(p) == 3:
            phys[(int(p[0]), int(p[1]))] = p[2].strip().strip('"')
    v = float(ver[0])
    if v >= 4:
        ent_phys = {}
        E = sections['Entities']
        nP, nC, nS, nV = map(int, E[0].split())
        k = 1
        for dim, cnt in ((0, nP), (1, nC), (2, nS), (3, nV)):
            for _ in range(cnt):
                t = E[k].split(); k += 1
                tag = int(t[0])
                if dim == 0:
                    npt = int(t[4]); ph = [int(x) for x in t[5:5 + npt]]
                else:
                    npt = int(t[7]); ph = [int(x) for x in t[8:8 + npt]]
                ent_phys[(dim, tag)] = set(phys.get((dim, abs(p)), str(abs(p))) for p in ph)
        N = sections['Nodes']
        nb, nn, mn, mx = map(int, N[0].split())
        tags = np.zeros(nn, int); X = np.zeros((nn, 3))
        k = 1; pos = 0
        for _ in range(nb):
            ed, et, par, cnt = map(int, N[k].split()); k += 1
            tg = [int(N[k + q]) for q in range(cnt)]; k += cnt
            for q in range(cnt):
                X[pos + q] = [float(x) for x in N[k + q].split()[:3]]
            tags[pos:pos + cnt] = tg
            k += cnt; pos += cnt
        idx = {t: q for q, t in enumerate(tags)}
        El = sections['Elements']
        nb = int(El[0].split()[0])
        k = 1
        tets, tetn, tris, trin = [], [], [], []
        for _ in range(nb):
            ed, et, typ, cnt = map(int, El[k].split()); k += 1
            names = ent_phys.get((ed, et), set())
            for q in range(cnt):
                t = [int(x) for x in El[k + q].split()]
                if typ == 4 or typ == 11:
                    tets.append([idx[x] for x in t[1:5]]); tetn.append(names)
                elif typ == 2 or typ == 9:
                    tris.append([idx[x] for x in t[1:4]]); trin.append(names)
            k += cnt
    else:
        N = sections['Nodes']; nn = int(N[0])
        idx = {}; X = np.zeros((nn, 3))
        for q in range(nn):
            t = N[1 + q].split(); idx[int(t[0])] = q; X[q] = [float(x) for x in t[1:4]]
        El = sections['Elements']; ne = int(El[0])
        tets, tetn, tris, trin = [], [], [], []
        for q in range(ne):
            t = [int(x) for x in El[1 + q].split()]
            typ, ntag = t[1], t[2]
            ph = t[3] if ntag > 0 else 0
            nodes = t[3 + ntag:]
            if typ in (4, 11):
                tets.append([idx[x] for x in nodes[:4]]); tetn.append({phys.get((3, ph), str(ph))})
            elif typ in (2, 9):
                tris.append([idx[x] for x in nodes[:3]]); trin.append({phys.get((2, ph), str(ph))})
    tets = np.array(tets, int); tris = np.array(tris, int)
    # drop unused nodes? keep all (unused nodes get no dofs below)
    return X, tets, tetn, tris, trin


# ----------------------------------------------------------------------------- fem
def elasticity(X, tets, E, nu):
    """K (3N x 3N, dof 3*node+c) for P1 tets with per-tet E, nu; also volumes."""
    P = X[tets]                                   # T,4,3
    J = (P[:, 1:, :] - P[:, :1, :])               # rows: edges
    det = np.linalg.det(J)
    if np.any(det <= 0):
        # reorient negatively oriented tets
        neg = det < 0
        tets = tets.copy(); tets[neg, 1], tets[neg, 2] = tets[neg, 2].copy(), tets[neg, 1].copy()
        P = X[tets]; J = (P[:, 1:, :] - P[:, :1, :]); det = np.linalg.det(J)
    vol = det / 6.0
    Jinv = np.linalg.inv(J)                       # grad of barycentrics 1..3: columns of Jinv
    G = np.zeros((len(tets), 4, 3))
    G[:, 1:, :] = np.transpose(Jinv, (0, 2, 1))
    G[:, 0, :] = -G[:, 1:, :].sum(1)
    lam = E * nu / ((1 + nu) * (1 - 2 * nu)); mu = E / (2 * (1 + nu))
    T = len(tets)
    Bm = np.zeros((T, 6, 12))
    for a in range(4):
        gx, gy, gz = G[:, a, 0], G[:, a, 1], G[:, a, 2]
        Bm[:, 0, 3 * a] = gx; Bm[:, 1, 3 * a + 1] = gy; Bm[:, 2, 3 * a + 2] = gz
        Bm[:, 3, 3 * a] = gy; Bm[:, 3, 3 * a + 1] = gx
        Bm[:, 4, 3 * a + 1] = gz; Bm[:, 4, 3 * a + 2] = gy
        Bm[:, 5, 3 * a] = gz; Bm[:, 5, 3 * a + 2] = gx
    D = np.zeros((T, 6, 6))
    for r in range(3):
        for c in range(3):
            D[:, r, c] = lam
        D[:, r, r] = lam + 2 * mu
        D[:, 3 + r, 3 + r] = mu
    Ke = np.einsum('tij,tjk,tkl->til', np.transpose(Bm, (0, 2, 1)), D, Bm) * vol[:, None, None]
    dofs = (3 * tets[:, :, None] + np.arange(3)[None, None, :]).reshape(T, 12)
    rows = np.repeat(dofs, 12, axis=1).ravel(); cols = np.tile(dofs, (1, 12)).ravel()
    n = 3 * len(X)
    K = sp.csr_matrix((Ke.ravel(), (rows, cols)), shape=(n, n))
    return K, vol, tets


def tri_geom(X, tris):
    P = X[tris]
    cr = np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0])
    A = 0.5 * np.linalg.norm(cr, axis=1)
    return P, cr, A


# ----------------------------------------------------------------------------- polygons
def clip(poly, a, b, c):
    """keep a*x + b*y <= c (poly: list of (x,y))"""
    out = []
    n = len(poly)
    for i in range(n):
        P = poly[i]; Qp = poly[(i + 1) % n]
        fp = a * P[0] + b * P[1] - c; fq = a * Qp[0] + b * Qp[1] - c
        if fp <= 0:
            out.append(P)
        if (fp < 0 < fq) or (fq < 0 < fp):
            t = fp / (fp - fq)
            out.append((P[0] + t * (Qp[0] - P[0]), P[1] + t * (Qp[1] - P[1])))
    return out


def poly_area_centroid(poly):
    if len(poly) < 3:
        return 0.0, (0.0, 0.0)
    x = np.array([p[0] for p in poly]); y = np.array([p[1] for p in poly])
    x1 = np.roll(x, -1); y1 = np.roll(y, -1)
    cr = x * y1 - x1 * y
    A = cr.sum() / 2
    if abs(A) < 1e-300:
        return 0.0, (x.mean(), y.mean())
    cx = ((x + x1) * cr).sum() / (6 * A); cy = ((y + y1) * cr).sum() / (6 * A)
    return abs(A), (cx, cy)


# ----------------------------------------------------------------------------- friction laws
def make_law(fr):
    law = fr.get('law', 'none')
    if law == 'none':
        return None
    if law == 'constant':
        v = float(fr['value']); return ([0.0], [v], [v])   # breakpoints, left/right values
    if law == 'ramp':
        hi, lo, t0, pa = float(fr['high']), float(fr['low']), float(fr['t0']), float(fr['param'])
        return ([t0, t0 + 2.0 / pa], [hi, lo], [hi, lo])
    if law == 'table':
        pts = fr['points']
        t = [float(p[0]) for p in pts]; F = [float(p[1]) for p in pts]
        return ('table', t, F)
    raise CannotCheck('law ' + law)


def F_eval(law, s):
    """F(s) for s array (piecewise linear, constant beyond ends; a jump takes the value after it, except
    a jump at the first t, where the first value holds at and below it: a static coefficient at rest,
    as the README states the table law)"""
    if law[0] == 'table':
        t, F = law[1], law[2]
    else:
        t, F = law[0], law[1]
    s = np.asarray(s, float)
    out = np.full(s.shape, F[0])
    for k in range(len(t) - 1):
        if t[k + 1] > t[k]:
            m = (s >= t[k]) & (s < t[k + 1])
            out[m] = F[k] + (F[k + 1] - F[k]) * (s[m] - t[k]) / (t[k + 1] - t[k])
    out[s >= t[-1]] = F[-1]
    if len(t) > 1 and t[1] == t[0]:
        out[s <= t[0]] = F[0]
    return out


def law_breaks(law):
    return sorted(set(law[1] if law[0] == 'table' else law[0]))


def integrate_F_poly(law, poly, phi_lin):
    """exact int_poly F(phi) dA, phi(x,y) = p0 + px*x + py*y (affine), F piecewise linear"""
    br = law_breaks(law)
    p0, px, py = phi_lin
    tot = 0.0
    A, c = poly_area_centroid(poly)
    xs = [p[0] for p in poly]; ys = [p[1] for p in poly]
    span = abs(px) * (max(xs) - min(xs)) + abs(py) * (max(ys) - min(ys))
    phc = p0 + px * c[0] + py * c[1]
    if span <= 1e-14 * max(abs(phc), 1e-300) or span == 0.0:   # phi constant on the piece
        return A * F_eval(law, np.array([phc]))[0]
    bounds = [-np.inf] + br + [np.inf]
    for k in range(len(bounds) - 1):
        pc = poly
        if np.isfinite(bounds[k]):     # phi >= bounds[k]  <=> -px x - py y <= p0 - bounds[k]
            pc = clip(pc, -px, -py, p0 - bounds[k])
        if np.isfinite(bounds[k + 1]):  # phi <= bounds[k+1]
            pc = clip(pc, px, py, bounds[k + 1] - p0)
        A, c = poly_area_centroid(pc)
        if A > 0:
            ph = p0 + px * c[0] + py * c[1]
            # value of the affine piece in this band (avoid jump ambiguity: evaluate at band centroid)
            tot += A * F_eval(law, np.array([ph]))[0]
    return tot


# ----------------------------------------------------------------------------- QP
def solve_qp(Q, b, r, rad, lam0=None, tol=1e-14, maxit=200000, eqG=None):
    """min 1/2 l'Ql - b'l, l = [ln (r), lt1 (r), lt2 (r)] (or [ln] if rad is None):
    ln >= 0, ||(lt1_i, lt2_i)|| <= rad_i.  FISTA with gradient restart, per-cell scaling."""
    m = len(b)
    d = np.sqrt(np.diag(Q).copy())
    if rad is not None:
        st = np.sqrt(0.5 * (np.diag(Q)[r:2 * r] + np.diag(Q)[2 * r:]))
        d[r:2 * r] = st; d[2 * r:] = st
    # variables y = d * l ; Qs = D^-1 Q D^-1
    Qs = Q / d[:, None] / d[None, :]
    bs = b / d
    rs = None if rad is None else rad * st

    def proj(y):
        y = y.copy()
        y[:r] = np.maximum(y[:r], 0)
        if rs is not None:
            t1 = y[r:2 * r]; t2 = y[2 * r:]
            nr = np.hypot(t1, t2)
            s = np.where(nr > rs, rs / np.maximum(nr, 1e-300), 1.0)
            y[r:2 * r] = t1 * s; y[2 * r:] = t2 * s
        return y
    L = np.linalg.eigvalsh(Qs)[-1] * 1.0000001
    y = proj(np.zeros(m) if lam0 is None else lam0 * d)
    z = y.copy(); t = 1.0
    scale = max(np.linalg.norm(bs), 1e-300)
    for it in range(maxit):
        g = Qs @ z - bs
        ynew = proj(z - g / L)
        tn = (1 + math.sqrt(1 + 4 * t * t)) / 2
        # restart if objective direction bad
        if np.dot(z - ynew, ynew - y) > 0:
            tn = 1.0; z = ynew.copy()
        else:
            z = ynew + (t - 1) / tn * (ynew - y)
        y = ynew; t = tn
        if it % 50 == 0:
            gy = Qs @ y - bs
            res = np.linalg.norm(y - proj(y - gy / L)) * L
            if res <= tol * scale:
                break
    gy = Qs @ y - bs
    res = np.linalg.norm(y - proj(y - gy / L)) * L / scale
    return y / d, res, it



def newton_direction(J, F):
    """least-squares solution of J d = -F: SVD-based (gelsd), else complete orthogonal (gelsy); None where
    J or F is not finite or LAPACK fails on both (the caller then keeps its iterate and reports its residual)."""
    if not (np.isfinite(J).all() and np.isfinite(F).all()):
        return None
    try:
        return np.linalg.lstsq(J, -F, rcond=None)[0]
    except (np.linalg.LinAlgError, SystemError):
        pass
    try:
        return scipy.linalg.lstsq(J, -F, lapack_driver='gelsy')[0]
    except (np.linalg.LinAlgError, SystemError, ValueError):
        return None


def ssn_polish(Q, b, r, rad, G, e, y, mu, iters=60, tol=1e-15):
    """semismooth Newton on F = [l - P(l - g(Ql - b + G'mu)); G l - e] (scaled variables), from (y, mu)."""
    m = len(b); k = G.shape[0]
    gam = 1.0 / np.linalg.eigvalsh(Q)[-1]

    def proj_and_jac(z):
        p = z.copy(); Dd = np.zeros((m, m))
        p[:r] = np.maximum(z[:r], 0); Dd[np.arange(r), np.arange(r)] = (z[:r] > 0).astype(float)
        if rad is not None:
            t = np.stack([z[r:2 * r], z[2 * r:]], 1); nt = np.linalg.norm(t, axis=1)
            for i in range(r):
                i1, i2 = r + i, 2 * r + i
                if nt[i] <= rad[i]:
                    Dd[i1, i1] = Dd[i2, i2] = 1.0
                else:
                    u = t[i] / nt[i]; s_ = rad[i] / nt[i]
                    p[i1], p[i2] = rad[i] * u
                    Jl = s_ * (np.eye(2) - np.outer(u, u))
                    Dd[i1, i1], Dd[i1, i2], Dd[i2, i1], Dd[i2, i2] = Jl[0, 0], Jl[0, 1], Jl[1, 0], Jl[1, 1]
        return p, Dd

    def Fval(y, mu):
        z = y - gam * (Q @ y - b + G.T @ mu)
        p, Dd = proj_and_jac(z)
        return np.concatenate([y - p, G @ y - e]), Dd
    F, Dd = Fval(y, mu)
    nf = np.linalg.norm(F)
    scale = max(np.linalg.norm(b), np.linalg.norm(e), 1e-300)
    for it in range(iters):
        if nf <= tol * scale:
            break
        J = np.zeros((m + k, m + k))
        J[:m, :m] = np.eye(m) - Dd @ (np.eye(m) - gam * Q)
        J[:m, m:] = gam * Dd @ G.T
        J[m:, :m] = G
        d = newton_direction(J, F)
        if d is None:  # LAPACK failed on J twice (the free plate at 3 468 multipliers): keep the iterate
            break
        t = 1.0
        while t > 1e-6:
            yn = y + t * d[:m]; mun = mu + t * d[m:]
            Fn, Ddn = Fval(yn, mun)
            if np.linalg.norm(Fn) < (1 - 1e-4 * t) * nf:
                break
            t *= 0.5
        y, mu, F, Dd, nf = yn, mun, Fn, Ddn, np.linalg.norm(Fn)
    return y, mu, nf / scale

# ----------------------------------------------------------------------------- helpers
def frame_of(normal):
    n = np.asarray(normal, float); n = n / np.linalg.norm(n)
    ez = np.array([0, 0, 1.0])
    c = float(n @ ez)
    ax = np.cross(n, ez); s = np.linalg.norm(ax)
    if s < 1e-15:
        R = np.eye(3) if c > 0 else np.diag([1.0, -1.0, -1.0])
    else:
        k = ax / s
        Kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
        R = np.eye(3) + s * Kx + (1 - c) * Kx @ Kx       # rotation by angle acos(c) about k
    # R n = ez
    return R


def set_key(scene, key, val):
    v = tomllib.loads('v = ' + val)['v'] if not val.isidentifier() or val in ('true', 'false') else None
    if v is None:
        try:
            v = tomllib.loads('v = ' + val)['v']
        except Exception:
            v = val
    parts = key.split('.')
    d = scene
    for p in parts[:-1]:
        d = d.setdefault(p, {})
    d[parts[-1]] = v


def read_vtu_arrays(path):
    """Every array of a VTU file (ASCII or binary, c3d.vtu), as floats."""
    return {name: values.astype(float) for name, values in c3d.vtu.read_arrays(path).items()}


# ----------------------------------------------------------------------------- main
def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('scene'); ap.add_argument('rundir')
    ap.add_argument('--mesh'); ap.add_argument('--set', action='append', default=[])
    ap.add_argument('--measure', default='projected', choices=['projected', 'surface'])
    ap.add_argument('--cells', default='csv', choices=['csv', 'vtu'])
    ap.add_argument('--fp-tol', type=float, default=1e-12)
    ap.add_argument('--fp-max', type=int, default=400)
    ap.add_argument('--qp-tol', type=float, default=1e-14)
    ap.add_argument('--phi-zero-held', action='store_true',
                    help='phi = 0 at Gamma_c nodes with all components prescribed (instead of |w_t| there)')
    ap.add_argument('--gap-snap', type=float, default=0.0, help='diagnostic: heights below this taken as 0')
    ap.add_argument('--slip-free-dofs-only', action='store_true',
                    help='diagnostic: slip phi from the free dofs only (prescribed components taken as 0)')
    ap.add_argument('--json', help='write results json here')
    ap.add_argument('--tol', type=float, default=None,
                    help='exit 1 (ORACLE FAILED) where u on Γc, λ or the radii differ by more than this (relative)')
    a = ap.parse_args()
    scene = tomllib.load(open(a.scene, 'rb'))
    for s in a.set:
        k, v = s.split('=', 1); set_key(scene, k, v)
    meshfile = a.mesh
    if not meshfile and 'file' in scene.get('mesh', {}):
        meshfile = os.path.join(os.path.dirname(os.path.abspath(a.scene)), scene['mesh']['file'])
    if not meshfile:  # the mesh a generated scene (geo, edp) left beside its results
        meshfile = next((os.path.join(a.rundir, m) for m in ('mesh.msh', 'mesh.mesh')
                         if os.path.exists(os.path.join(a.rundir, m))), os.path.join(a.rundir, 'mesh.msh'))
    X, tets, tetn, tris, trin = read_mesh(meshfile)
    N = len(X)
    mat = scene.get('material', {})
    E = np.full(len(tets), float(mat.get('young', 0))); nu = np.full(len(tets), float(mat.get('poisson', 0.3)))
    bf = np.tile(np.array(mat.get('body_force', [0, 0, 0]), float), (len(tets), 1))  # per tetrahedron
    for reg in mat.get('region', []):
        m = np.array([reg['group'] in s for s in tetn])
        if not m.any():
            raise CannotCheck('no tets in region ' + reg['group'])
        E[m] = float(reg['young']); nu[m] = float(reg['poisson'])
        if 'body_force' in reg:
            bf[m] = np.array(reg['body_force'], float)
    K, vol, tets = elasticity(X, tets, E, nu)
    f = np.zeros(3 * N)
    for c in range(3):
        np.add.at(f, 3 * tets[:, :].ravel() + c, np.repeat(vol / 4 * bf[:, c], 4))
    bnd = scene.get('boundary', {})
    # outward normals of boundary triangles from their tets
    facemap = {}
    for ti, t in enumerate(tets):
        for q in range(4):
            key = tuple(sorted(np.delete(t, q)))
            facemap.setdefault(key, []).append((ti, t[q]))

    def group_tris(name):
        idx = [i for i, s in enumerate(trin) if name in s]
        if not idx:
            raise CannotCheck('no triangles in group ' + name)
        return np.array(idx)

    def outward(ti):
        tr = tris[ti]
        P = X[tr]
        cr = np.cross(P[1] - P[0], P[2] - P[0])
        adj = facemap.get(tuple(sorted(tr)), [])
        if len(adj) != 1:
            raise CannotCheck('load triangle not on the boundary (%d tets)' % len(adj))
        opp = X[adj[0][1]]
        if cr @ (opp - P[0]) > 0:
            cr = -cr
        return cr / np.linalg.norm(cr), 0.5 * np.linalg.norm(cr)
    Mloc = (np.ones((3, 3)) + np.eye(3)) / 12.0
    for tr_ in bnd.get('traction', []):
        val = np.array(tr_['value'], float); G = np.array(tr_.get('gradient', np.zeros((3, 3))), float)
        for ti in group_tris(tr_['group']):
            tr = tris[ti]; _, A = outward(ti)
            tv = val[None, :] + X[tr] @ G.T        # 3 nodes x 3 comps
            fl = A * Mloc @ tv
            for q in range(3):
                f[3 * tr[q]:3 * tr[q] + 3] += fl[q]
    for fo in bnd.get('force', []):   # a resultant (N) spread uniformly over the group's area
        tis = group_tris(fo['group'])
        areas = [outward(ti)[1] for ti in tis]
        tv = np.array(fo['value'], float) / sum(areas)
        for ti, A in zip(tis, areas):
            tr = tris[ti]
            for q in range(3):
                f[3 * tr[q]:3 * tr[q] + 3] += A * tv / 3.0
    for pr in bnd.get('pressure', []):
        val = float(pr['value']); G = np.array(pr.get('gradient', [0, 0, 0]), float)
        for ti in group_tris(pr['group']):
            tr = tris[ti]; n, A = outward(ti)
            pv = val + X[tr] @ G
            tv = -pv[:, None] * n[None, :]
            fl = A * Mloc @ tv
            for q in range(3):
                f[3 * tr[q]:3 * tr[q] + 3] += fl[q]
    # Dirichlet
    presc = {}
    for g in bnd.get('clamped', []):
        for ti in group_tris(g):
            for nd in tris[ti]:
                for c in range(3):
                    presc[3 * nd + c] = 0.0
    for dd in bnd.get('displacement', []):
        G = np.array(dd.get('gradient', np.zeros((3, 3))), float)
        nodes = set(tris[group_tris(dd['group'])].ravel())
        for c, cn in enumerate('xyz'):
            if cn in dd:
                for nd in nodes:
                    presc[3 * nd + c] = float(dd[cn]) + G[c] @ X[nd]
    used = np.zeros(N, bool); used[tets.ravel()] = True
    pd = np.array(sorted(presc), int); pv = np.array([presc[k] for k in pd])
    isfree = np.ones(3 * N, bool); isfree[pd] = False
    for nd in np.where(~used)[0]:
        isfree[3 * nd:3 * nd + 3] = False
    fd = np.where(isfree)[0]
    wD = np.zeros(3 * N); wD[pd] = pv
    Kff = K[fd][:, fd].tocsc()
    ff = f[fd] - K[fd] @ wD
    # frame
    cs = scene.get('contact', {})
    nrm = np.array(cs.get('plane_normal', [0, 0, 1.0]), float); nrm /= np.linalg.norm(nrm)
    p0 = np.array(cs.get('plane_point', [0, 0, 0.0]), float)
    R = frame_of(nrm)
    t1 = R.T @ np.array([1, 0, 0.0]); t2 = R.T @ np.array([0, 1, 0.0])
    XF = (X - p0) @ R.T                              # frame coordinates
    # contact face
    ctri = sorted(set(i for g in bnd.get('contact', []) for i in group_tris(g)))
    # drop triangles whose every node is fully prescribed
    def fully(nd):
        return all((3 * nd + c) in presc for c in range(3))
    ctri = [i for i in ctri if not all(fully(nd) for nd in tris[i])]
    ctri = np.array(ctri, int)
    CT = tris[ctri]
    cnodes = np.unique(CT.ravel())
    # projected triangles
    gap = XF[:, 2].copy()
    if a.gap_snap > 0:
        gap[np.abs(gap) < a.gap_snap] = 0.0
    # cells
    rows = list(csv.DictReader(open(os.path.join(a.rundir, 'contact_cells.csv'))))
    r = len(rows)
    cell_pieces = [[] for _ in range(r)]   # (tri index into CT, polygon)
    if a.cells == 'csv':
        for ci, row in enumerate(rows):
            x0, x1, y0, y1 = (float(row[k]) for k in ('xmin', 'xmax', 'ymin', 'ymax'))
            for k, tr in enumerate(CT):
                P = XF[tr, :2]
                if P[:, 0].max() <= x0 or P[:, 0].min() >= x1 or P[:, 1].max() <= y0 or P[:, 1].min() >= y1:
                    continue
                poly = [tuple(p) for p in P]
                poly = clip(poly, 1, 0, x1); poly = clip(poly, -1, 0, -x0)
                poly = clip(poly, 0, 1, y1); poly = clip(poly, 0, -1, -y0)
                A, _ = poly_area_centroid(poly)
                if A > 1e-14 * (x1 - x0) * (y1 - y0):
                    cell_pieces[ci].append((k, poly))
    else:
        va = read_vtu_arrays(os.path.join(a.rundir, 'contact_cells.vtu'))
        pts = va['Points']; conn = va['connectivity'].astype(int); offs = va['offsets'].astype(int)
        cid = va['cell'].astype(int)
        # points are in user coordinates? detect: if all |z| of frame coords ~ 0 use frame
        start = 0
        TP = XF[CT][:, :, :2]
        M = np.stack([TP[:, 1] - TP[:, 0], TP[:, 2] - TP[:, 0]], 2)
        Minv = np.linalg.inv(M)

        def bary_all(c):
            l12 = np.einsum('tij,tj->ti', Minv, c[None, :] - TP[:, 0])
            return np.concatenate([1 - l12.sum(1, keepdims=True), l12], 1)
        for q in range(len(offs)):
            ids = conn[start:offs[q]]; start = offs[q]
            Pp = pts[ids]
            PF = (Pp - p0) @ R.T if np.ptp(Pp[:, 2]) > 1e-12 or abs(Pp[:, 2]).max() > 1e-12 else Pp
            poly = [tuple(p[:2]) for p in PF]
            A, c = poly_area_centroid(poly)
            # a sliver's shoelace centroid is rounding (wavy at h = 0.04, cells of 0.08: a 1.7e-14 m²
            # piece fell outside every triangle): its vertices' mean instead
            if A < 1e-9 * max(np.ptp(PF[:, 0]) * np.ptp(PF[:, 1]), 1e-300) or not (min(p[0] for p in poly) <= c[0] <= max(p[0] for p in poly)):
                c = (float(np.mean([p[0] for p in poly])), float(np.mean([p[1] for p in poly])))
            # find triangle containing c (vectorised barycentrics)
            lam = bary_all(np.array(c))
            ok = np.where((lam.min(1) > -1e-9))[0]
            if len(ok) == 0:
                raise CannotCheck('vtu piece %d not in any contact triangle' % q)
            best = int(ok[np.argmax(lam[ok].min(1))])
            cell_pieces[cid[q]].append((best, poly))
    # coverage check: every contact triangle's projected area is covered exactly once
    tri_cov = np.zeros(len(CT))
    for ci in range(r):
        for k, poly in cell_pieces[ci]:
            tri_cov[k] += poly_area_centroid(poly)[0]
    PA = np.array([poly_area_centroid([tuple(p) for p in XF[tr, :2]])[0] for tr in CT])
    cov_err = np.abs(tri_cov - PA).max() / PA.max()
    # cos of each triangle against the plane (for the surface measure)
    Pn = XF[CT]; crn = np.cross(Pn[:, 1] - Pn[:, 0], Pn[:, 2] - Pn[:, 0])
    cosT = np.abs(crn[:, 2]) / np.linalg.norm(crn, axis=1)
    wmeas = np.ones(len(CT)) if a.measure == 'projected' else 1.0 / cosT
    # B rows
    Bn = sp.lil_matrix((r, 3 * N)); Bt1 = sp.lil_matrix((r, 3 * N)); Bt2 = sp.lil_matrix((r, 3 * N))
    meas = np.zeros(r); Dg = np.zeros(r); csv_area = np.array([float(w['area']) for w in rows])
    for ci in range(r):
        for k, poly in cell_pieces[ci]:
            tr = CT[k]; P = XF[tr, :2]
            A, c = poly_area_centroid(poly)
            A *= wmeas[k]
            M = np.array([P[1] - P[0], P[2] - P[0]]).T
            l12 = np.linalg.solve(M, np.array(c) - P[0])
            phi = np.array([1 - l12.sum(), l12[0], l12[1]])
            meas[ci] += A
            Dg[ci] += A * phi @ gap[tr]
            for q in range(3):
                for cc in range(3):
                    Bn[ci, 3 * tr[q] + cc] += -A * phi[q] * nrm[cc]
                    Bt1[ci, 3 * tr[q] + cc] += A * phi[q] * t1[cc]
                    Bt2[ci, 3 * tr[q] + cc] += A * phi[q] * t2[cc]
    area_err = np.abs(meas - csv_area).max() / csv_area.max()
    if a.cells == 'csv' and max(cov_err, area_err) > 1e-8:
        # merged cells are unions of rectangles that csv's bounding boxes overlap (pads: an L-shaped cell
        # at a sole's edge took whole triangles of its neighbours, and the oracle "disagreed" by 80%)
        raise CannotCheck('--cells csv: the rectangles of contact_cells.csv do not tile Gamma_c (coverage error '
                          '%.1e, areas %.1e off the csv): merged or graded cells, use --cells vtu' % (cov_err, area_err))
    fr = scene.get('friction', {})
    model = fr.get('model', 'tresca')
    law = make_law(fr)
    g = float(fr.get('slip_bound', 0.0))
    frictional = law is not None and (model == 'coulomb' or g > 0)
    Bfull = sp.vstack([Bn, Bt1, Bt2]).tocsr() if frictional else Bn.tocsr()
    B = Bfull[:, fd]
    # rigid motions left free by the prescribed dofs (kernel of K_ff for a connected body)
    # rigid motions per connected part of the mesh (parts share no node)
    from scipy.sparse.csgraph import connected_components
    ei = np.concatenate([tets[:, [0, q]] for q in (1, 2, 3)])
    adj = sp.coo_matrix((np.ones(len(ei)), (ei[:, 0], ei[:, 1])), shape=(N, N))
    ncomp, comp = connected_components(adj, directed=False)
    parts = [pc for pc in range(ncomp) if used[comp == pc].any()]
    R6 = np.zeros((3 * N, 6 * len(parts)))
    for pi_, pc in enumerate(parts):
        sel = (comp == pc) & used
        ctr = X[sel].mean(0)
        # along and about the plane's frame axes: the motions in the plane (held by friction alone)
        # apart from those with a normal part, whatever the plane's tilt (along the user's axes a free
        # body on an incline mixed the slide into the frictionless first solve's equalities)
        frame_axes = np.array([t1, t2, nrm])
        for j, ax in enumerate(frame_axes):
            for c in range(3):
                R6[3 * np.where(sel)[0] + c, 6 * pi_ + j] = ax[c]
        Xc_ = X - ctr
        for j, ax in enumerate(frame_axes):
            col = np.cross(ax[None, :], Xc_)
            col[~sel] = 0
            R6[:, 6 * pi_ + 3 + j] = col.ravel()
    if len(parts) > 1:
        print('note: %d mesh parts' % len(parts), file=sys.stderr)
    import scipy.linalg as sla
    if len(pd):
        Cn = sla.null_space(R6[pd] / np.abs(R6[pd]).max(), rcond=1e-10)
    else:
        Cn = np.eye(R6.shape[1])
    kdim = Cn.shape[1]
    Rk = R6[fd] @ Cn if kdim else np.zeros((len(fd), 0))
    fix = np.array([], int)
    if kdim:
        _, _, piv = sla.qr(Rk.T, pivoting=True, mode='economic')
        fix = np.sort(piv[:kdim])
        print('note: %d free rigid motion(s); fixing dofs' % kdim, fd[fix], file=sys.stderr)
    keep = np.setdiff1d(np.arange(len(fd)), fix)
    lu = spla.splu(Kff[keep][:, keep].tocsc())

    def Kplus(rhs):
        rhs = np.asarray(rhs)
        out = np.zeros(rhs.shape)
        out[keep] = lu.solve(np.ascontiguousarray(rhs[keep]))
        return out
    KiBt = Kplus(B.T.toarray())
    Q = B @ KiBt; Q = 0.5 * (Q + Q.T)
    Kif = Kplus(ff)
    hvec = B @ Kif + Bfull @ wD
    hvec[:r] -= Dg
    condQ = np.linalg.cond(Q)
    # equalities G lam = e (loads balanced along the free motions)
    Geq = (B @ Rk).T if kdim else np.zeros((0, B.shape[0]))
    eeq = Rk.T @ ff if kdim else np.zeros(0)
    if kdim:
        # consistency check: K_ff Rk ~ 0
        kr = np.abs(Kff @ Rk).max() / abs(Kff).max()
        print('note: |K Rk|/|K| = %.2e' % kr, file=sys.stderr)
    alpha_last = [np.zeros(kdim)]

    def dual_solve(Qm, hv, rad, lam0):
        m = len(hv)
        G = Geq[:, :m]; e = eeq.copy()
        if G.shape[0] == 0:
            return solve_qp(Qm, hv, r, rad, lam0=lam0, tol=a.qp_tol)
        gn = np.linalg.norm(G, axis=1)
        zero = gn <= 1e-12 * max(gn.max(), 1e-300)
        if zero.any():
            print('note: motions not seen by the multipliers (loads along them: %s)' % e[zero], file=sys.stderr)
        # scaled variables y = Dl (tangential pairs share a scale), rows of G D^-1 orthonormalised
        dq = np.sqrt(np.diag(Qm).copy())
        if rad is not None:
            st = np.sqrt(0.5 * (np.diag(Qm)[r:2 * r] + np.diag(Qm)[2 * r:])); dq[r:2 * r] = st; dq[2 * r:] = st
        Qh = Qm / dq[:, None] / dq[None, :]; bh = hv / dq
        Gh = G[~zero] / dq[None, :]; eh = e[~zero].copy()
        Uq, Sq, Vq = np.linalg.svd(Gh, full_matrices=False)
        # Combinations of the motions these multipliers cannot hold (Coulomb's normal-only start on a
        # body that friction alone holds in the plane: its slide, seen by no normal force): left out
        seen = Sq > 1e-8 * Sq.max()
        if not seen.all():
            print('note: %d combination(s) of the held motions not seen by these multipliers: left out' %
                  (~seen).sum(), file=sys.stderr)
        T = (Uq[:, seen] / Sq[None, seen]).T     # T Gh has orthonormal rows
        Gh = T @ Gh; eh = T @ eh
        rho = np.linalg.eigvalsh(Qh)[-1]
        nu = np.zeros(len(eh)); y = None if lam0 is None else lam0 * dq
        radh = None if rad is None else rad * st
        for outer in range(40):
            lam_y, res, it = solve_qp(Qh + rho * Gh.T @ Gh, bh - Gh.T @ nu + rho * Gh.T @ eh, r, radh, lam0=y, tol=1e-9, maxit=20000)
            y = lam_y
            viol = Gh @ y - eh
            nu = nu + rho * viol
            if np.linalg.norm(viol) <= 1e-9 * max(np.linalg.norm(eh), np.linalg.norm(y)):
                break
        y, nu, fres = ssn_polish(Qh, bh, r, radh, Gh, eh, y, nu)
        print('note: SSN polish residual %.2e' % fres, file=sys.stderr)
        lam = y / dq
        print('note: AL outer %d, |G lam - e| / |e| = %.2e' % (outer + 1, np.linalg.norm(G[~zero] @ lam - e[~zero]) / max(np.linalg.norm(e[~zero]), 1e-300)), file=sys.stderr)
        # multipliers of the original rows: nu_h = T^T-combination; G^T mu = D Gh^T nu  =>  mu = T^T nu (rows of G[~zero])
        nu = T.T @ nu
        gn = np.ones_like(gn)
        al = np.zeros(kdim); al[~zero] = -nu / gn[~zero]
        alpha_last[0] = al
        return lam, res, it

    def displacement(lam):
        w = wD.copy(); w[fd] = Kif - KiBt @ lam[:KiBt.shape[1]] + (Rk @ alpha_last[0] if kdim else 0)
        return w

    fullpres = np.array([all((3 * nd + c) in presc for c in range(3)) for nd in range(N)])

    def slip(w):
        if a.slip_free_dofs_only:
            w = w.copy(); w[pd] = 0.0
        W = w.reshape(N, 3)
        s_ = np.hypot(W @ t1, W @ t2)
        if a.phi_zero_held:
            s_[fullpres] = 0.0
        return s_

    def radii(phi, gvec):
        """c_i = int_Ri F(phi_h) g dS / meas(R_i), g per cell (constant on the cell)"""
        c = np.zeros(r)
        for ci in range(r):
            s = 0.0
            for k, poly in cell_pieces[ci]:
                tr = CT[k]; P = XF[tr, :2]
                M = np.array([[1, P[0, 0], P[0, 1]], [1, P[1, 0], P[1, 1]], [1, P[2, 0], P[2, 1]]])
                coef = np.linalg.solve(M, phi[tr])
                s += integrate_F_poly(law, poly, coef) * wmeas[k]
            c[ci] = s * gvec[ci] / meas[ci]
        return c
    hist = []
    if not frictional:
        lam, res, it = dual_solve(Q, hvec, None, None)
        w = displacement(lam)
        lam_full = np.concatenate([lam, np.zeros(2 * r)])
    else:
        lamp = None; phi = np.zeros(N)
        if model == 'coulomb':
            l0, res, it = dual_solve(Q[:r, :r], hvec[:r], None, None)
            gcell = l0.copy()
            lamp = np.concatenate([l0, np.zeros(2 * r)])
        else:
            gcell = np.full(r, g)
        for k in range(1, a.fp_max + 1):
            c = radii(phi, gcell)
            lam, res, it = dual_solve(Q, hvec, c, lamp)
            w = displacement(lam)
            phin = slip(w)
            err_phi = np.linalg.norm(phin[cnodes] - phi[cnodes]) / max(np.linalg.norm(phin[cnodes]), 1e-300)
            err = err_phi
            if model == 'coulomb':
                err_l = np.linalg.norm(lam[:r] - gcell) / max(np.linalg.norm(lam[:r]), 1e-300)
                err = max(err_phi, err_l)
                gcell = lam[:r].copy()
            hist.append((k, err, res, it))
            phi = phin; lamp = lam
            if law[0] != 'table' and len(law[0]) == 1 and model != 'coulomb':
                break  # constant coefficient: one Tresca solve
            if err <= a.fp_tol:
                break
        lam_full = lam
        # final consistency: radii from the final state
    # ---------------------------------------------------------------- compare
    out = {'n_primal': int(len(fd)), 'n_cells': r, 'n_dual': int(B.shape[0]), 'cond_Q': float(condQ),
           'cell_area_vs_csv': float(area_err), 'tri_coverage_err': float(cov_err),
           'qp_residual': float(res), 'fixed_point': hist[-3:] if hist else None}
    cn = list(csv.DictReader(open(os.path.join(a.rundir, 'contact_nodes.csv'))))
    Xc = np.array([[float(q[k]) for k in 'xyz'] for q in cn])
    Uc = np.array([[float(q[k]) for k in ('u1', 'u2', 'u3')] for q in cn])
    from scipy.spatial import cKDTree
    tree = cKDTree(X)
    dist, idn = tree.query(Xc)
    scale = np.abs(X).max()
    out['node_match_maxdist'] = float(dist.max() / scale)
    W = w.reshape(N, 3)
    du = np.abs(W[idn] - Uc).max() / np.abs(Uc).max()
    out['u_contact_rel'] = float(du)
    out['u_contact_rel_L2'] = float(np.linalg.norm(W[idn] - Uc) / np.linalg.norm(Uc))
    out['n_contact_nodes_csv'] = len(cn); out['n_contact_nodes_oracle'] = int(len(cnodes))
    lc = np.array([[float(q['lambda_n']), float(q['lambda_t1']), float(q['lambda_t2'])] for q in rows])
    lo = np.stack([lam_full[:r], lam_full[r:2 * r], lam_full[2 * r:]], 1)
    out['lambda_n_rel'] = float(np.abs(lo[:, 0] - lc[:, 0]).max() / max(np.abs(lc[:, 0]).max(), 1e-300))
    lt_scale = max(np.abs(lc[:, 1:]).max(), 1e-300)
    out['lambda_t_rel'] = float(np.abs(lo[:, 1:] - lc[:, 1:]).max() / lt_scale) if frictional else None
    out['lambda_t_abs_max'] = float(np.abs(lc[:, 1:]).max())
    # contact3d's lambda through the oracle's K, f, B: its displacement and its constraint residuals
    lam_c = np.concatenate([lc[:, 0], lc[:, 1], lc[:, 2]]) if frictional else lc[:, 0].copy()
    wc_ = displacement(lam_c)
    out['u_from_c3d_lambda_vs_c3d_u'] = float(np.abs(wc_.reshape(N, 3)[idn] - Uc).max() / np.abs(Uc).max())
    Wc_full = np.zeros(3 * N); Wc_full[:] = w
    Wc_full.reshape(N, 3)[idn] = Uc
    gn_cu = (Bfull @ Wc_full)[:r] - Dg      # with contact3d's own nodal u on the face
    act = lc[:, 0] > 0
    out['c3d_active_cells_gap_residual_rel'] = float(np.abs(gn_cu[act]).max() / (np.abs(w).max() * meas.max() + np.abs(Dg).max())) if act.any() else None
    out['c3d_max_feasibility_violation_rel'] = float(max(gn_cu.max(), 0) / (np.abs(w).max() * meas.max() + np.abs(Dg).max()))
    if frictional:
        rc = np.array([float(q['radius']) for q in rows])
        c_fin = radii(slip(w), gcell if model == 'coulomb' else np.full(r, g))
        out['radius_rel'] = float(np.abs(c_fin - rc).max() / max(rc.max(), 1e-300))
        # radii from contact3d's own nodal slips and (Coulomb) its own lambda_n: isolates the radius integral
        phic = np.zeros(N)
        phic[idn] = np.array([float(q['wt_norm']) for q in cn])
        c_c3d = radii(phic, lc[:, 0] if model == 'coulomb' else np.full(r, g))
        dr = np.abs(c_c3d - rc)
        out['radius_from_c3d_state_rel'] = float(dr.max() / max(rc.max(), 1e-300))
        out['radius_from_c3d_state_worst'] = (int(np.argmax(dr)), float(c_c3d[np.argmax(dr)]), float(rc[np.argmax(dr)]))
        # one map step from contact3d's state: Psi(phi_c3d) against phi_c3d, and its QP answer against lambda_c3d
        lam1, _, _ = dual_solve(Q, hvec, c_c3d, None)
        w1 = displacement(lam1)
        phi1 = slip(w1)
        out['Psi_c3d_state_step'] = float(np.linalg.norm(phi1[cnodes] - phic[cnodes]) / np.linalg.norm(phic[cnodes]))
        l1 = np.stack([lam1[:r], lam1[r:2 * r], lam1[2 * r:]], 1)
        out['qp_at_c3d_radii_vs_c3d_lambda_rel'] = float(np.abs(l1 - lc).max() / np.abs(lc).max())
        if model == 'coulomb':
            out['coulomb_lambda_n_step'] = float(np.abs(lam1[:r] - lc[:, 0]).max() / np.abs(lc[:, 0]).max())
        # and the oracle's own state through the same map
        c_o = radii(slip(w), gcell if model == 'coulomb' else np.full(r, g))
        lam2, _, _ = dual_solve(Q, hvec, c_o, None)
        phi2 = slip(displacement(lam2)); phio = slip(w)
        out['Psi_oracle_state_step'] = float(np.linalg.norm(phi2[cnodes] - phio[cnodes]) / np.linalg.norm(phio[cnodes]))
    try:
        va = read_vtu_arrays(os.path.join(a.rundir, 'body.vtu'))
        Pb = va['Points']; Ub = va['displacement']
        dist, idb = tree.query(Pb)
        out['u_body_rel'] = float(np.abs(W[idb] - Ub).max() / np.abs(Ub).max())
        out['body_match_maxdist'] = float(dist.max() / scale)
        # audit of contact3d's whole state (u from body.vtu, lambda from the csv) in the oracle's K, f, B, D
        Uall = np.zeros((N, 3)); Uall[idb] = Ub
        ua = Uall.ravel()
        Kfull = K.tocsr()
        lam_cf = np.concatenate([lc[:, 0], lc[:, 1], lc[:, 2]])
        lam_of = np.concatenate([lo[:, 0], lo[:, 1], lo[:, 2]])
        B3 = sp.vstack([Bn, Bt1, Bt2]).tocsr()

        def audit(u_, l_, rad_):
            res = (Kfull @ u_ - f + B3.T @ l_)[fd]
            scl = np.abs(f[fd]).max() + np.abs((B3.T @ l_)[fd]).max()
            gN = (B3 @ u_)[:r] - Dg
            sT = np.stack([(B3 @ u_)[r:2 * r], (B3 @ u_)[2 * r:]], 1)
            ln = l_[:r]; lt = np.stack([l_[r:2 * r], l_[2 * r:]], 1)
            gs = np.abs(u_).max() * meas.max() + np.abs(Dg).max()
            nres = np.abs(ln - np.maximum(0, ln + gN * (np.abs(ln).max() / gs))).max() / np.abs(ln).max()
            fres = 0.0
            if rad_ is not None:
                # weighed like the normal condition (by the motion's scale, not the slip's: a
                # sticking face's rounding-sized slip would otherwise be blown up to the disc's size)
                z = lt + sT * (max(np.abs(lt).max(), rad_.max()) / gs)
                nz = np.linalg.norm(z, axis=1)
                pz = z * np.minimum(1, rad_ / np.maximum(nz, 1e-300))[:, None]
                fres = np.abs(lt - pz).max() / max(np.abs(lt).max(), 1e-300)
            return {'equilibrium': float(np.abs(res).max() / scl), 'dirichlet': float(np.abs(u_[pd] - pv).max() if len(pd) else 0.0),
                    'normal_kkt': float(nres), 'friction_kkt': float(fres), 'max_gap_violation': float(gN.max() / gs)}
        rc_ = np.array([float(q['radius']) for q in rows]) if frictional else None
        out['audit_c3d_state'] = audit(ua, lam_cf, rc_)
        out['audit_oracle_state'] = audit(w, lam_of, radii(slip(w), gcell if model == 'coulomb' else np.full(r, g)) if frictional else None)
    except Exception as e:
        out['u_body_rel'] = 'n/a ' + str(e)
    out['forces_oracle'] = {'normal': float(lo[:, 0] @ meas), 't1': float(lo[:, 1] @ meas), 't2': float(lo[:, 2] @ meas)}
    try:
        sm = json.load(open(os.path.join(a.rundir, 'summary.json')))
        out['forces_contact3d'] = sm.get('contact_force')
        out['c3d_converged'] = sm.get('converged')
        out['c3d_qp_projected_gradient'] = sm.get('qp_last_projected_gradient')
    except Exception:
        pass
    # worst cell
    dl = np.abs(lo - lc).max(1)
    wc = int(np.argmax(dl))
    out['worst_cell'] = {'cell': wc, 'oracle': lo[wc].tolist(), 'contact3d': lc[wc].tolist(),
                         'meas_oracle': float(meas[wc]), 'area_csv': float(csv_area[wc])}
    if a.json:
        json.dump({**out, 'lam': lo.tolist(), 'meas': meas.tolist()}, open(a.json, 'w'), indent=1)
    for k, v in out.items():
        print(f'{k}: {v}')
    if a.tol is not None:
        judged = {k: out.get(k) for k in ('u_contact_rel', 'u_body_rel', 'lambda_n_rel', 'lambda_t_rel', 'radius_rel')}
        over = {k: v for k, v in judged.items() if isinstance(v, float) and not v <= a.tol}
        no_verdict = own_answer_unsound(out, a) if over else None
        if no_verdict:
            print(f'oracle error: no verdict on {over}: {no_verdict}', file=sys.stderr)
            sys.exit(3)
        if over or not out.get('c3d_converged', True):
            print(f'ORACLE FAILED: beyond {a.tol:g}: {over}' + ('' if out.get('c3d_converged', True) else '; contact3d did not converge')
                  + lambda_only_hint(out, over, a.tol))
            sys.exit(1)
        print(f'oracle agrees within {a.tol:g}: ' + ', '.join(f'{k} {v:.1e}' for k, v in judged.items() if isinstance(v, float)))


def lambda_only_hint(out, over, tol):
    """Where only λ differs and u agrees: the QP's stop at ‖gᴾ‖ ≤ ε‖h‖ bounds λ only to about cond(Q)·ε
    (README), so an ill-conditioned dual cannot give λ to a tighter --tol (a helper's T-plate two elements
    thick, cond(Q) 5.6e7, its last QP at ε = 8e-12: λ_t 5.5e-6 from the oracle, 7e-6 from contact3d's own
    answer at qp_rtol = 1e-13, u 4e-7). The failure stands; the hint says why and how to judge λ."""
    if not over or not all(k.startswith('lambda') for k in over):
        return ''
    eps, cond = out.get('c3d_qp_projected_gradient'), out.get('cond_Q')
    if not isinstance(eps, float) or not isinstance(cond, float) or cond * eps <= tol:
        return ''
    return (f'; u agrees within {tol:g}, and contact3d\'s last QP stopped at a projected gradient of {eps:.1e} of ‖h‖, '
            f'which bounds λ only to about cond(Q) times that ({cond:.1e} x {eps:.1e}): solve with --set '
            f'solver.qp_rtol=1e-13 to judge λ at --tol {tol:g}')


def own_answer_unsound(out, a):
    """Why the oracle's own answer cannot judge a difference (None where it can): its fixed point
    stopped at --fp-max short of --fp-tol, or its answer meets the optimality conditions in its own
    matrices clearly worse than contact3d's (ill-conditioned duals: the difference may be its own)."""
    fp = out.get('fixed_point') or []
    if fp and len(fp[-1]) >= 2 and not fp[-1][1] <= max(a.fp_tol, 1e-3 * a.tol) and fp[-1][0] >= a.fp_max:
        return f'its fixed point stopped at --fp-max {a.fp_max} with err {fp[-1][1]:.1e} > --fp-tol {a.fp_tol:g}'
    own, theirs = out.get('audit_oracle_state'), out.get('audit_c3d_state')
    if not own or not theirs:
        return None
    keys = ('normal_kkt', 'friction_kkt')
    own_max, theirs_max = max(own[k] for k in keys), max(theirs[k] for k in keys)
    if own_max > max(10 * theirs_max, 1e-3 * a.tol):
        return (f'its own answer meets the optimality conditions to {own_max:.1e} against contact3d\'s {theirs_max:.1e} '
                f'(cond(Q) {out.get("cond_Q", float("nan")):.1e}); tighten --qp-tol or check with a looser --tol')
    return None


class CannotCheck(Exception):
    """An input the oracle cannot read or state: no verdict (exit 3)."""


if __name__ == '__main__':
    try:
        main()
    except CannotCheck as e:
        print(f'oracle error: the run could not be checked: {e}', file=sys.stderr)
        sys.exit(3)
    except Exception:  # a crash is no verdict: exit 3, never 1 (a disagreement) nor 0
        import traceback
        traceback.print_exc()
        print('oracle error: the run could not be checked (see the traceback above)', file=sys.stderr)
        sys.exit(3)
