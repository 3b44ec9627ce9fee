#!/usr/bin/env python3
"""Stress suite for contact3d: numerical stability under scale changes, extreme parameters and
awkward meshes (issue #6). Run by `make stress`:

    /usr/bin/python3 pipeline/stress.py --bin build/contact3d [--out results/stress] [--only NAME...]

Every case is the base scene pipeline/scenes/stress/base.toml (or another scene under
pipeline/scenes/stress/) on a coarse brick mesh (`contact3d mesh brick --n N`, n = 4..8),
possibly transformed here (rescaled, flattened, graded), plus `--set` overrides. Each case
states its expectation; the suite checks it, checks that no output holds NaN/inf and that the
run ends within a timeout, and writes results/stress/README.md (one row per case) and
results/stress/stress.json. Exit status: 0 when every case passes, 1 otherwise.

Scale invariance: with E and every stress-like input (tractions, body force, g) multiplied by
s, the displacement is unchanged; with lengths multiplied by L (mesh, friction t0, 1/param) and
stresses fixed, the displacement is multiplied by L. Those cases compare the contact-node
displacements with the reference run (relative max difference <= 1e-6... 1e-5 allowed).
"""
import argparse
import csv
import json
import os
import shutil
import subprocess
import sys
import time

import numpy as np

import c3d.run
import c3d.vtu

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = os.path.join(ROOT, "pipeline", "scenes", "stress")
BASE = os.path.join(SCENES, "base.toml")

REF = dict(E=21.19e10, end=(1e7, 0.0, 2e7), top=(0.0, 0.0, -3e7), g=2e7, t0=1e-5, param=6e4)
TIMEOUT = 300
SCALE_TOL = 1e-5


# ---------------------------------------------------------------- meshes
def transform_msh41(src, dst, fn):
    """Copies an ASCII MSH 4.1 file, mapping every node coordinate (and entity bounding box
    corner) through fn(x, y, z) -> (x, y, z). fn must keep z = 0 at z = 0."""
    with open(src) as f:
        lines = f.read().split("\n")
    out, i = [], 0

    def fmt(v):
        return repr(float(v))

    while i < len(lines):
        line = lines[i]
        out.append(line)
        i += 1
        if line == "$Nodes":
            head = lines[i].split()
            out.append(lines[i])
            i += 1
            nblocks = int(head[0])
            for _ in range(nblocks):
                b = lines[i].split()
                out.append(lines[i])
                i += 1
                n = int(b[3])
                out.extend(lines[i:i + n])  # tags
                i += n
                for k in range(n):
                    c = [float(t) for t in lines[i + k].split()[:3]]
                    out.append(" ".join(fmt(t) for t in fn(*c)))
                i += n
        elif line == "$Entities":
            counts = [int(t) for t in lines[i].split()]
            out.append(lines[i])
            i += 1
            for dim, cnt in enumerate(counts):
                for _ in range(cnt):
                    t = lines[i].split()
                    if dim == 0:
                        p = fn(*[float(v) for v in t[1:4]])
                        t[1:4] = [fmt(v) for v in p]
                    else:
                        lo = fn(*[float(v) for v in t[1:4]])
                        hi = fn(*[float(v) for v in t[4:7]])
                        t[1:7] = [fmt(v) for v in list(map(min, lo, hi)) + list(map(max, lo, hi))]
                    out.append(" ".join(t))
                    i += 1
    with open(dst, "w") as f:
        f.write("\n".join(out))


class Meshes:
    def __init__(self, binary, work):
        self.bin, self.work, self.cache = binary, work, {}

    def brick(self, n):
        path = os.path.join(self.work, f"brick_n{n}.msh")
        if path not in self.cache:
            subprocess.run([self.bin, "mesh", "brick", "--n", str(n), "-o", path], check=True,
                           stdout=subprocess.DEVNULL, timeout=120)
            self.cache[path] = True
        return path

    def transformed(self, n, name, fn):
        path = os.path.join(self.work, f"brick_n{n}_{name}.msh")
        if path not in self.cache:
            transform_msh41(self.brick(n), path, fn)
            self.cache[path] = True
        return path


# ---------------------------------------------------------------- cases
def vec(v):
    return "[" + ", ".join(repr(float(x)) for x in v) + "]"


def stress_scaled(s):
    """--set overrides multiplying E, tractions and g by s (dimensionless solution unchanged)."""
    return [f"material.young={REF['E'] * s!r}",
            f"boundary.traction=[{{group=\"load_end\", value={vec([s * x for x in REF['end']])}}}, "
            f"{{group=\"load_top\", value={vec([s * x for x in REF['top']])}}}]",
            f"friction.slip_bound={REF['g'] * s!r}"]


def loads_scaled(s, with_law=True):
    """Loads and g times s with E fixed; with_law: slip scales t0 and 1/param too (u -> s u)."""
    sets = [f"boundary.traction=[{{group=\"load_end\", value={vec([s * x for x in REF['end']])}}}, "
            f"{{group=\"load_top\", value={vec([s * x for x in REF['top']])}}}]",
            f"friction.slip_bound={REF['g'] * s!r}"]
    if with_law:
        sets += [f"friction.t0={REF['t0'] * s!r}", f"friction.param={REF['param'] / s!r}"]
    return sets


def length_scaled(L):
    return [f"friction.t0={REF['t0'] * L!r}", f"friction.param={REF['param'] / L!r}"]


def tractions(end, top):
    return [f"boundary.traction=[{{group=\"load_end\", value={vec(end)}}}, {{group=\"load_top\", value={vec(top)}}}]"]


def cases(meshes):
    """(name, what it does, expectation text, mesh path, scene, sets, check)."""
    b4 = meshes.brick(4)
    C = []

    def add(name, what, expect, mesh, sets=(), check=None, scene=BASE, n=4):
        C.append(dict(name=name, what=what, expect=expect, mesh=mesh, sets=list(sets), check=check, scene=scene, n=n))

    add("reference", "paper brick problem, n=4", "converged", b4, check=expect_converged())
    for s, label in [(1.0 / REF["E"], "E=1Pa"), (1e3 / REF["E"], "E=1e3Pa"), (1e12 / REF["E"], "E=1e12Pa")]:
        add(f"units_{label}", f"E and all stresses x{s:.3g}", "converged; u equal to reference (rel. diff <= 1e-5)",
            b4, stress_scaled(s), expect_scaled("reference", 1.0))
    for s in (1e-3, 1e3):
        add(f"loads_x{s:g}_lawscaled", f"loads and g x{s:g}, t0 x{s:g}, param /{s:g}",
            f"converged; u = {s:g} x reference (rel. diff <= 1e-5)", b4, loads_scaled(s), expect_scaled("reference", s))
    for s in (1e-3, 1e-1, 10.0, 1e3):
        add(f"loads_x{s:g}", f"loads and g x{s:g}, law unchanged (other slip regime)",
            "solved (converged or a named non-convergence exit 1), finite output", b4, loads_scaled(s, False),
            expect_solved())
    for L in (1e-3, 1e3):
        m = meshes.transformed(4, f"L{L:g}", lambda x, y, z, L=L: (L * x, L * y, L * z))
        add(f"size_L{L:g}m", f"body scaled x{L:g} (mesh rescaled), t0 x{L:g}, param /{L:g}",
            f"converged; u = {L:g} x reference (rel. diff <= 1e-5)", m, length_scaled(L), expect_scaled("reference", L))
    for nu in (0.0, 0.25, 0.45, 0.49, 0.4999):
        add(f"poisson_{nu:g}", f"nu = {nu:g} (P1 locks near 0.5)", "converged, KKT max <= 1e-4, finite",
            b4, [f"material.poisson={nu!r}"], expect_converged(kkt=1e-4))
    for E in (1e300, 1e-300):
        add(f"extreme_E{E:g}", f"E = {E:g} Pa, loads unchanged (u underflows/overflows)",
            "converged with finite output, or exit 2 with an `error:` message (never NaN)", b4,
            [f"material.young={E!r}"], expect_converged_or_error())
    add("g_zero", "g = 0 (frictionless)", "converged in one QP solve, n_dual = n_cells", b4,
        ["friction.slip_bound=0.0"], expect_converged(frictionless=True))
    add("g_huge", "g = 1e13 Pa (full stick)", "converged; max slip < 10% of the reference's", b4,
        ["friction.slip_bound=1e13"], expect_stick("reference"))
    for p in (2e4, 6e4, 1e6, 1e8):
        for fp in ("plain", "anderson"):
            add(f"ramp_param{p:g}_{fp}", f"ramp param = {p:g}, fixed point {fp}",
                "solved: converged, or stagnation/iteration_limit (exit 1) reported; finite", b4,
                [f"friction.param={p!r}", f"solver.fixed_point=\"{fp}\""], expect_solved())
    add("iteration_limit", "fixed_point_max_iter = 2 on the reference problem",
        "exit 1, status iteration_limit, outputs written and finite", b4, ["solver.fixed_point_max_iter=2"],
        expect_exit1("iteration_limit"))
    add("steep_big_slip", "ramp param = 1e8, loads and g x3 (large slip across the jump)",
        "solved: converged or named exit 1; finite", b4, ["friction.param=1e8"] + loads_scaled(3.0, False), expect_solved())
    add("table_jump", "table law with a jump at t0 = 1e-5 (table_jump.toml)",
        "solved: converged or named exit 1; finite", b4, [], expect_solved(), scene=os.path.join(SCENES, "table_jump.toml"))
    add("table_jump_anderson", "table law with a jump, Anderson", "solved: converged or named exit 1; finite", b4,
        ["solver.fixed_point=\"anderson\""], expect_solved(), scene=os.path.join(SCENES, "table_jump.toml"))
    add("lift_off", "end and top pulled up (+z): no contact", "converged; every lambda_n = 0, max wn+ = 0", b4,
        tractions((0, 0, 2e7), (0, 0, 3e7)), expect_lift())
    add("full_contact", "top pressed down 1e8 Pa, no end load", "converged; every cell has lambda_n > 0", b4,
        tractions((0, 0, 0), (0, 0, -1e8)), expect_full_contact())
    add("single_cell", "cell_size = 1e3 m (one contact cell)", "converged; n_cells = 1", b4,
        ["contact.cell_size=1e3"], expect_converged(cells=1))
    add("H_coarse", "H = 6h", "converged", b4, ["contact.cell_size=\"6h\""], expect_converged())
    add("H_h", "H = h (borderline for (5.1))", "converged, or exit 2 naming (5.1)", b4, ["contact.cell_size=\"1h\""],
        expect_converged_or_stability())
    add("H_too_fine", "H = 0.25h", "exit 2, stderr names the stability condition (5.1)", b4,
        ["contact.cell_size=\"0.25h\""], expect_stability_error())
    add("fine_n8", "n = 8 mesh", "converged", meshes.brick(8), check=expect_converged(), n=8)
    m = meshes.transformed(4, "flat", lambda x, y, z: (x, y, 0.02 * z))
    add("aspect_50", "brick flattened to 3 x 1 x 0.02 (tet aspect ratio ~50)", "converged, KKT max <= 1e-4", m,
        check=expect_converged(kkt=1e-4))
    m = meshes.transformed(4, "long", lambda x, y, z: (x, 0.05 * y, z))
    add("aspect_20_y", "brick squeezed to 3 x 0.05 x 1 (aspect ~20 in the contact face)",
        "converged, or exit 2 naming (5.1)", m, check=expect_converged_or_stability())
    m = meshes.transformed(6, "graded", lambda x, y, z: (3.0 * (x / 3.0) ** 3, y, z))
    add("graded_x", "n = 6, x -> 3 (x/3)^3 (elements 30x smaller near the clamp)",
        "converged, or exit 2 naming (5.1) and the cells", m, check=expect_converged_or_stability(), n=6)
    m = meshes.transformed(6, "graded_abs", lambda x, y, z: (3.0 * (x / 3.0) ** 3, y, z))
    add("graded_x_absH", "graded mesh with H = 0.5 m absolute", "converged", m, ["contact.cell_size=0.5"],
        expect_converged(), n=6)
    return C


# ---------------------------------------------------------------- checks
def expect_converged(kkt=None, frictionless=False, cells=None):
    def check(r, runs):
        if r["rc"] != 0 or r.get("status") != "converged":
            return False, f"exit {r['rc']}, status {r.get('status')}"
        if kkt is not None and not (r["kkt_max"] <= kkt):
            return False, f"KKT max {r['kkt_max']:.2e} > {kkt:g}"
        if frictionless and r["n_dual"] != r["n_cells"]:
            return False, f"n_dual {r['n_dual']} != n_cells {r['n_cells']}"
        if cells is not None and r["n_cells"] != cells:
            return False, f"n_cells = {r['n_cells']}"
        return True, ""
    return check


def expect_solved():
    def check(r, runs):
        if r["rc"] == 0 and r.get("status") == "converged":
            return True, ""
        if r["rc"] == 1 and r.get("status") in ("stagnation", "iteration_limit"):
            return True, f"exit 1 ({r['status']})"
        return False, f"exit {r['rc']}, status {r.get('status')}"
    return check


def expect_exit1(status):
    def check(r, runs):
        return r["rc"] == 1 and r.get("status") == status, f"exit {r['rc']}, status {r.get('status')}"
    return check


def max_rel_diff(a, b, s):
    scale = max(abs(v) for v in b.values() for v in v) * abs(s)
    d = 0.0
    for k, ua in a.items():
        ub = b[k]
        d = max(d, max(abs(x - s * y) for x, y in zip(ua, ub)))
    return d / scale


def expect_scaled(ref, s):
    def check(r, runs):
        ok, why = expect_converged()(r, runs)
        if not ok:
            return ok, why
        base = runs.get(ref)
        if not base or "u" not in base:
            return False, "no reference run"
        if set(r["u"]) != set(base["u"]):
            return False, "different contact nodes"
        d = max_rel_diff(r["u"], base["u"], s)
        r["scale_diff"] = d
        return d <= SCALE_TOL, f"rel. diff {d:.1e}"
    return check


def expect_stick(ref):
    def check(r, runs):
        ok, why = expect_converged()(r, runs)
        if not ok:
            return ok, why
        ref_slip = runs[ref]["max_slip"]
        return r["max_slip"] < 0.1 * ref_slip, f"max slip {r['max_slip']:.2e} vs ref {ref_slip:.2e}"
    return check


def expect_lift():
    def check(r, runs):
        ok, why = expect_converged()(r, runs)
        if not ok:
            return ok, why
        lmax = max(abs(v) for v in r["lambda_n"]) if r["lambda_n"] else 0.0
        return lmax == 0.0 and r["wn_plus_inf"] == 0.0, f"max lambda_n {lmax:.2e}, |wn+|_inf {r['wn_plus_inf']:.1e}"
    return check


def expect_full_contact():
    def check(r, runs):
        ok, why = expect_converged()(r, runs)
        if not ok:
            return ok, why
        n_pos = sum(1 for v in r["lambda_n"] if v > 0)
        return n_pos == len(r["lambda_n"]), f"{n_pos}/{len(r['lambda_n'])} cells pressed"
    return check


def expect_stability_error():
    def check(r, runs):
        err = r.get("stderr", "")
        ok = r["rc"] == 2 and err.startswith("error:") and "5.1" in err
        return ok, err.strip().splitlines()[0][:160] if err.strip() else f"exit {r['rc']}"
    return check


def expect_converged_or_error():
    def check(r, runs):
        if r["rc"] == 2:
            err = r.get("stderr", "")
            return err.startswith("error:"), err.strip().splitlines()[0][:160] if err.strip() else "no message"
        return expect_converged()(r, runs)
    return check


def expect_converged_or_stability():
    def check(r, runs):
        if r["rc"] == 2:
            return expect_stability_error()(r, runs)
        return expect_converged()(r, runs)
    return check


# ---------------------------------------------------------------- running
def nonfinite_in(path):
    with open(path, "rb") as f:
        raw = f.read()
    if path.endswith(".vtu") and b"<AppendedData" in raw:  # raw values (output.vtu = binary): no text to search
        return any(not np.all(np.isfinite(v)) for v in c3d.vtu.read_arrays(path).values())
    text = raw.decode(errors="replace").lower()
    for bad in ("nan", "inf"):
        i = text.find(bad)
        while i >= 0:
            before = text[i - 1] if i > 0 else " "
            after = text[i + len(bad)] if i + len(bad) < len(text) else " "
            # a bare token (not part of a word such as "info" or "infinite" or "name")
            if not before.isalpha() and not after.isalpha() and before not in "_\"" and after not in "_\"":
                return True
            i = text.find(bad, i + 1)
    return False


def read_results(out, r):
    with open(os.path.join(out, "summary.json")) as f:
        s = json.load(f)
    r["summary"] = s
    for key in ("status", "n_mult", "n_dual", "n_cells", "fixed_point_iterations", "wn_plus_inf", "wn_plus_L2",
                "time_s", "kkt"):
        if key in s:
            r[key] = s[key]
    if isinstance(r.get("time_s"), dict):
        r["time_s"] = r["time_s"].get("total")
    r["kkt_max"] = max(v for v in s.get("kkt", {}).values() if isinstance(v, (int, float))) if s.get("kkt") else 0.0
    u, slip = {}, 0.0
    with open(os.path.join(out, "contact_nodes.csv")) as f:
        for row in csv.DictReader(f):
            u[row["node"]] = (float(row["u1"]), float(row["u2"]), float(row["u3"]))
            slip = max(slip, float(row["wt_norm"]))
    r["u"], r["max_slip"] = u, slip
    lam = []
    with open(os.path.join(out, "contact_cells.csv")) as f:
        for row in csv.DictReader(f):
            lam.append(float(row["lambda_n"]))
    r["lambda_n"] = lam
    bad = []
    for d, _, files in os.walk(out):  # also the per-step files under steps/
        bad += [os.path.relpath(os.path.join(d, n), out) for n in sorted(files)
                if n.endswith((".json", ".csv", ".vtu", ".vtp", ".pvd")) and nonfinite_in(os.path.join(d, n))]
    r["nonfinite_files"] = bad


def run_case(binary, c, work):
    out = os.path.join(work, "runs", c["name"])
    shutil.rmtree(out, ignore_errors=True)
    cmd = c3d.run.solve_command(binary, c["scene"], out, c["sets"], mesh=c["mesh"])
    r = dict(name=c["name"], cmd=cmd)
    t0 = time.time()
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=TIMEOUT)
        r["rc"], r["stderr"] = p.returncode, p.stderr
    except subprocess.TimeoutExpired:
        r["rc"], r["stderr"] = "timeout", ""
    r["wall_s"] = time.time() - t0
    if r["rc"] in (0, 1):
        try:
            read_results(out, r)
        except (OSError, ValueError, KeyError) as e:
            r["read_error"] = str(e)
    return r


def verdict(c, r, runs):
    if r["rc"] == "timeout":
        return False, f"timeout after {TIMEOUT} s"
    if isinstance(r["rc"], int) and r["rc"] < 0:
        return False, f"crashed (signal {-r['rc']})"
    if r["rc"] not in (0, 1, 2):
        return False, f"unexpected exit {r['rc']}"
    if r.get("read_error"):
        return False, "outputs unreadable: " + r["read_error"]
    if r.get("nonfinite_files"):
        return False, "NaN/inf in " + ", ".join(r["nonfinite_files"])
    if r["rc"] in (0, 1) and r.get("stderr", "").strip():
        pass  # warnings are allowed
    return c["check"](r, runs)


def fmt_num(v, f="{:.1e}"):
    return "–" if v is None else f.format(v)


def write_report(path, rows, binary):
    lines = ["# Stress suite (issue #6)", "",
             "Written by `make stress` (`/usr/bin/python3 pipeline/stress.py --bin build/contact3d`).",
             "Every case is `pipeline/scenes/stress/base.toml` (or the named scene there) on a coarse",
             "`contact3d mesh brick --n N` mesh, possibly rescaled/distorted by stress.py, plus `--set`",
             "overrides; the expectation is stated before the run and checked by the script. Every run",
             f"also must end within {TIMEOUT} s, without a signal, and with no NaN/inf in any output file.",
             "`it` = fixed-point iterations (QP solves), `KKT max` = largest of the residuals in",
             "summary.json `kkt`, time = summary.json `time_s`.", "",
             "| case | n | what | expected | exit / status | it | n_mult | KKT max | abs(wn+) inf | time s | result |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    npass = 0
    for c, r, ok, why in rows:
        npass += ok
        status = f"{r['rc']} / {r.get('status', '–')}" if r["rc"] in (0, 1) else str(r["rc"])
        note = "PASS" if ok else "**FAIL**"
        if why:
            note += f" ({why.replace('|', '/')})"
        lines.append(f"| {c['name']} | {c['n']} | {c['what'].replace('|', '/')} | {c['expect'].replace('|', '/')} | {status} | "
                     f"{r.get('fixed_point_iterations', '–')} | {r.get('n_mult', '–')} | {fmt_num(r.get('kkt_max'))} | "
                     f"{fmt_num(r.get('wn_plus_inf'))} | {fmt_num(r.get('time_s'), '{:.2f}')} | {note} |")
    lines += ["", f"**{npass} / {len(rows)} cases pass.**", "",
              "See also: [findings.md](findings.md) (what the failures and odd rows mean, fuzzing, sanitizers),",
              "[bad_inputs.md](bad_inputs.md) (every rejected input with its message, `tests/bad_inputs.py --all`).", ""]
    with open(path, "w") as f:
        f.write("\n".join(lines))
    return npass


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bin", default=os.path.join(ROOT, "build", "contact3d"))
    ap.add_argument("--out", default=os.path.join(ROOT, "results", "stress"))
    ap.add_argument("--work", default=None, help="scratch folder (default: <out>/work, git-ignored)")
    ap.add_argument("--only", nargs="*", help="run only these cases (and the reference)")
    a = ap.parse_args()
    binary = os.path.abspath(a.bin)
    os.makedirs(a.out, exist_ok=True)
    work = a.work or os.path.join("/tmp", f"contact3d_stress_{os.getpid()}")
    os.makedirs(work, exist_ok=True)
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "2")
    meshes = Meshes(binary, work)
    rows, runs = [], {}
    for c in cases(meshes):
        if a.only and c["name"] not in a.only and c["name"] != "reference":
            continue
        r = run_case(binary, c, work)
        runs[c["name"]] = r
        ok, why = verdict(c, r, runs)
        rows.append((c, r, ok, why))
        print(f"{'PASS' if ok else 'FAIL'} {c['name']:<28} exit={r['rc']} status={r.get('status', '-')} "
              f"it={r.get('fixed_point_iterations', '-')} n_mult={r.get('n_mult', '-')} "
              f"kkt={fmt_num(r.get('kkt_max'))} {r['wall_s']:.1f}s {why}", flush=True)
    npass = write_report(os.path.join(a.out, "README.md"), rows, binary)
    with open(os.path.join(a.out, "stress.json"), "w") as f:
        json.dump([{k: v for k, v in dict(r, passed=ok, note=why).items() if k not in ("u", "summary", "lambda_n")}
                   for c, r, ok, why in rows], f, indent=1, default=str)
    if not a.work:
        shutil.rmtree(work, ignore_errors=True)
    print(f"{npass}/{len(rows)} cases pass; report in {os.path.join(a.out, 'README.md')}")
    return 0 if npass == len(rows) else 1


if __name__ == "__main__":
    sys.exit(main())
