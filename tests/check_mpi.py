#!/usr/bin/python3
"""The distributed backend equals the serial one: the same scene solved by the serial binary
(CHOLMOD) and by `mpirun -np 2 contact3d-mpi` (MUMPS's Schur complement on the multipliers, MUMPS
called directly with our ordering and through PETSc's interface) must give the same displacement
on Γc and the same multipliers to 1e-8 (relative to their largest entries), the same fixed-point
steps, an equilibrium residual under 1e-8 (rank 0 forms K·w element by element, having freed K),
and a summary naming the backend, the ranks, each rank's peak memory and (PETSc route) the six
rigid-body modes attached to its matrix as the near-null space, and each rank's BLAS threads within
its share of the machine's cores. Cases: the paper's
brick (n = 8, slip-dependent law; both routes) and an unstructured body with a hole (hexagonal
prism, gmsh; also on 3 ranks, so the mesh is cut into three parts), and the quarter block on a
spherical cap (two materials, rollers, a prescribed displacement, a pressure, a gap), the brick
with Coulomb's bound, and two pads in one mesh of two parts. One rank bound to one core must get
summary.json's note on unbinding. The brick n = 12 with its factor out of core (solver.out_of_core_dir) must give the in-memory answer
with less memory per rank and leave no file behind. The executable must not link PETSc (a module
loaded by the PETSc route only), and that route without its module is an error (exit 2) naming the
module, also when only another rank than rank 0 lacks it; a bad input ends every rank with exit 2.
A negative check compares the serial
solution with one for a Young's modulus 1e-6 larger and requires the comparison to see it.

usage: check_mpi.py --serial build/contact3d --mpi build/contact3d-mpi --mpiexec mpirun --source DIR
"""
import argparse
import csv
import json
import os
import shutil
import subprocess
import sys
import tempfile
import tomllib

import numpy as np

TOL = 1e-8
# (label, scene, overrides, the backend summary.json must name[, ranks instead of --np]). The
# default route calls MUMPS directly with our nested dissection; solver.schur = "mumps_petsc" goes
# through PETSc's interface. Three ranks cut the mesh into three parts (one of them in the middle).
CASES = [
    ("paper brick n=8, slip-dependent", "paper_brick.toml", ["mesh.generator=paper_brick", "mesh.n=8"], "mumps"),
    ("hexagonal prism with a hole (gmsh)", "hexprism.toml", ["mesh.parameters.h=0.06"], "mumps"),
    ("paper brick n=8 through PETSc", "paper_brick.toml", ["mesh.generator=paper_brick", "mesh.n=8"], "petsc-mumps"),
    ("hexagonal prism with a hole, 3 ranks", "hexprism.toml", ["mesh.parameters.h=0.06"], "mumps", 3),
    # two materials (each rank's mesh part carries its tets' material), prescribed non-zero
    # displacement and rollers instead of a clamp, a pressure, gravity, a curved Γc with a gap
    ("quarter block on a cap, two materials", "capblock.toml", ["mesh.parameters.h=0.05"], "mumps"),
    # no clamp: rollers on x = 0 hold u_x, u_y, the contact alone the lift (the ranks add rank 0's
    # spring to K; model/held_by_contact.hpp)
    ("paper brick n=8 held by contact alone", "paper_brick.toml",
     ["mesh.generator=paper_brick", "mesh.n=8", "boundary.clamped=[]",
      'boundary.displacement=[{group="clamped", x=0.0, y=0.0}]'], "mumps"),
    # nothing prescribed: the lift and tilts held by the pressure, the slides and the turn about the
    # normal by friction (six equality rows, six springs)
    ("paper brick n=8 with nothing prescribed", "paper_brick.toml",
     ["mesh.generator=paper_brick", "mesh.n=8", "boundary.clamped=[]"], "mumps"),
    # a mesh in two parts (geo/pads.geo), nothing prescribed: each pad held by its own contact, twelve
    # equality rows and springs, each part's on its own dofs
    ("two pads, a mesh in two parts held by their own contact", "pads.toml", [], "mumps"),
    # Coulomb's bound F(φ)·λ_n: the fixed point on (φ, λ_n), each step a MUMPS solve
    ("paper brick n=8, Coulomb", "paper_brick.toml",
     ["mesh.generator=paper_brick", "mesh.n=8", "friction.model=coulomb", "friction.slip_bound=0"], "mumps"),
]


def columns(path, names):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return np.array([[float(r[n]) for n in names] for r in rows])


def solve(cmd, out, sets):
    argv = cmd + ["--quiet", "--out", out] + [a for s in sets for a in ("--set", s)]
    p = subprocess.run(argv, capture_output=True, text=True, timeout=300)
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(argv)} exited {p.returncode}: {p.stderr.strip()[:400]}")
    return json.load(open(os.path.join(out, "summary.json")))


def relative_difference(a, b, what):
    ua = columns(os.path.join(a, "contact_nodes.csv"), ["u1", "u2", "u3"])
    ub = columns(os.path.join(b, "contact_nodes.csv"), ["u1", "u2", "u3"])
    la = columns(os.path.join(a, "contact_cells.csv"), ["lambda_n", "lambda_t1", "lambda_t2"])
    lb = columns(os.path.join(b, "contact_cells.csv"), ["lambda_n", "lambda_t1", "lambda_t2"])
    if ua.shape != ub.shape or la.shape != lb.shape:
        raise RuntimeError(f"{what}: the two runs have different contact faces or partitions")
    du = np.abs(ua - ub).max() / np.abs(ua).max()
    dl = np.abs(la - lb).max() / np.abs(la).max()
    return du, dl


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--serial", required=True)
    ap.add_argument("--mpi", required=True)
    ap.add_argument("--mpiexec", default="mpirun")
    ap.add_argument("--source", required=True)
    ap.add_argument("--np", type=int, default=2)
    args = ap.parse_args()
    env_ok = os.environ.get("OMPI_ALLOW_RUN_AS_ROOT") == "1" or os.geteuid() != 0
    if not env_ok:
        print("FAIL: as root, Open MPI needs OMPI_ALLOW_RUN_AS_ROOT=1 and OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1")
        return 1
    tmp = tempfile.mkdtemp(prefix="contact3d_mpi_")
    fails = []
    try:
        for k, (label, scene, sets, route, *ranks) in enumerate(CASES):
            np_run = ranks[0] if ranks else args.np
            oversubscribe = ["--oversubscribe"] if np_run > (os.cpu_count() or 1) else []
            path = os.path.join(args.source, "pipeline", "scenes", scene)
            ser, par = os.path.join(tmp, f"serial{k}"), os.path.join(tmp, f"mpi{k}")
            s = solve([args.serial, "solve", path], ser, sets)
            schur = [] if route == "mumps" else ["solver.schur=mumps_petsc"]
            p = solve([args.mpiexec, "-np", str(np_run), *oversubscribe, args.mpi, "solve", path], par, sets + schur)
            du, dl = relative_difference(ser, par, label)
            ok = du <= TOL and dl <= TOL
            backend = p.get("backend", {})
            if not ok:
                fails.append(f"{label}: u on Γc differs by {du:.2e}, λ by {dl:.2e} (tolerance {TOL:g})")
            # Rank 0 frees K before the factorization and forms K·w element by element for the
            # residuals: the equilibrium residual must still be the serial run's order.
            if p["kkt"]["equilibrium"] > 1e-8 or s["kkt"]["equilibrium"] > 1e-8:
                fails.append(f"{label}: equilibrium residual {p['kkt']['equilibrium']:.1e} distributed, "
                             f"{s['kkt']['equilibrium']:.1e} serial")
            if s["fixed_point_iterations"] != p["fixed_point_iterations"]:
                fails.append(f"{label}: {s['fixed_point_iterations']} serial steps, {p['fixed_point_iterations']} distributed")
            if backend.get("name") != route or backend.get("ranks") != np_run or \
                    backend.get("processes") != np_run or len(backend.get("peak_memory_mib_per_rank", [])) != np_run:
                fails.append(f"{label}: summary.json backend {backend}, expected {route} on {np_run} ranks")
            # The ranks on this machine share its cores: each rank's OpenBLAS gets at most its share
            # (threads × ranks ≤ cores, at least one), however mpirun bound them (blas_threads.hpp).
            blas = backend.get("blas_threads", {})
            if not blas.get("user_set") and blas.get("before", 0) > 0:
                share = max(1, (os.cpu_count() or 1) // np_run)
                if blas.get("ranks_on_machine") != np_run or not 1 <= blas.get("threads", 0) <= share:
                    fails.append(f"{label}: BLAS threads {blas} on {np_run} ranks and {os.cpu_count()} cores "
                                 f"(at most {share} per rank)")
            # The PETSc route's matrix carries the six rigid-body modes as its near-null space (the
            # backend checks the ranks' copy against rank 0's K·R); the direct route has no matrix.
            if backend.get("near_null_space") != (6 if route == "petsc-mumps" else 0):
                fails.append(f"{label}: near-null space of {backend.get('near_null_space')} vectors on {route}")
            print(f"{label}: serial (CHOLMOD) vs {np_run} ranks (MUMPS): u {du:.1e}, λ {dl:.1e}; steps "
                  f"{s['fixed_point_iterations']} / {p['fixed_point_iterations']}; peak memory per rank (MiB) "
                  f"{backend.get('peak_memory_mib_per_rank')}")
        # One rank bound to one core on a machine with more: summary.json's notes say how to unbind;
        # unbound, they do not.
        if (os.cpu_count() or 1) > 1:
            label, scene, sets, _ = CASES[0]
            path = os.path.join(args.source, "pipeline", "scenes", scene)
            for bind, expected in (("core", True), ("none", False)):
                out = os.path.join(tmp, f"bind_{bind}")
                notes = solve([args.mpiexec, "-np", "1", "--bind-to", bind, args.mpi, "solve", path], out,
                              sets)["notes"]
                if any("--bind-to none" in n for n in notes) != expected:
                    fails.append(f"np = 1 bound to {bind}: notes {notes}")
        # The factor out of core (solver.out_of_core_dir: MUMPS writes it to files and reads them back
        # in every solve): the in-memory run's answer, less memory on every rank (brick n = 12: 76 / 71
        # MiB against 99 / 92 in memory), and no file left behind.
        path = os.path.join(args.source, "pipeline", "scenes", "paper_brick.toml")
        sets = ["mesh.generator=paper_brick", "mesh.n=12"]
        ooc_dir = os.path.join(tmp, "ooc_files")
        os.mkdir(ooc_dir)
        mpi = [args.mpiexec, "-np", "2", args.mpi, "solve", path]
        in_core = solve(mpi, os.path.join(tmp, "in_core"), sets)
        out_of_core = solve(mpi, os.path.join(tmp, "out_of_core"), sets + [f"solver.out_of_core_dir={ooc_dir}"])
        du, dl = relative_difference(os.path.join(tmp, "in_core"), os.path.join(tmp, "out_of_core"), "out of core")
        peak_in = max(in_core["backend"]["peak_memory_mib_per_rank"])
        peak_out = max(out_of_core["backend"]["peak_memory_mib_per_rank"])
        if du > TOL or dl > TOL:
            fails.append(f"out of core: u on Γc differs from the in-memory run by {du:.2e}, λ by {dl:.2e}")
        if out_of_core["settings"]["out_of_core_dir"] != ooc_dir:
            fails.append(f"out of core: summary.json settings say {out_of_core['settings'].get('out_of_core_dir')!r}")
        if not peak_out < 0.9 * peak_in:
            fails.append(f"out of core: largest rank peak {peak_out:.0f} MiB against {peak_in:.0f} in memory")
        if os.listdir(ooc_dir):
            fails.append(f"out of core: MUMPS's files left in {ooc_dir}: {os.listdir(ooc_dir)}")
        print(f"brick n=12 out of core vs in memory (2 ranks): u {du:.1e}, λ {dl:.1e}; largest rank peak "
              f"{peak_out:.0f} against {peak_in:.0f} MiB")
        # Without a contact group the solve is one CHOLMOD solve on rank 0: the option cannot act there
        # and is refused (exit 2) rather than ignored.
        argv = mpi + ["--quiet", "--out", os.path.join(tmp, "no_contact")] + [
            a for s in sets + [f"solver.out_of_core_dir={ooc_dir}", "boundary.contact=[]"] for a in ("--set", s)]
        refused = subprocess.run(argv, capture_output=True, text=True, timeout=300)
        if refused.returncode != 2 or "out_of_core_dir" not in refused.stderr:
            fails.append(f"out of core without a contact group: exit {refused.returncode}, {refused.stderr.strip()[:200]}")
        # PETSc is a module loaded only by the PETSc route (solver/distributed/petsc_route.hpp): the
        # executable does not link it, and without the module beside it that route is an input error
        # naming the module (exit 2), on every rank alike.
        linked = subprocess.run(["ldd", args.mpi], capture_output=True, text=True).stdout
        if "libpetsc" in linked:
            fails.append("contact3d-mpi links PETSc itself: " + [l for l in linked.splitlines() if "libpetsc" in l][0])
        alone = os.path.join(tmp, "alone")
        os.mkdir(alone)
        shutil.copy2(os.path.realpath(args.mpi), os.path.join(alone, "contact3d-mpi"))
        argv = [args.mpiexec, "-np", "2", os.path.join(alone, "contact3d-mpi"), "solve", path, "--quiet", "--out",
                os.path.join(tmp, "no_module")] + [a for s in sets + ["solver.schur=mumps_petsc"] for a in ("--set", s)]
        refused = subprocess.run(argv, capture_output=True, text=True, timeout=300)
        if refused.returncode != 2 or "libcontact3d_petsc.so" not in refused.stderr:
            fails.append(f"PETSc route without its module: exit {refused.returncode}, {refused.stderr.strip()[:200]}")
        # Only rank 1 without the module (rank 0, which prints the errors, has it): rank 0 must still
        # say which rank failed and why.
        tail = ["--quiet", "--out", os.path.join(tmp, "no_module_rank1")] + [
            a for s in sets + ["solver.schur=mumps_petsc"] for a in ("--set", s)]
        argv = [args.mpiexec, "-np", "1", args.mpi, "solve", path, *tail, ":", "-np", "1",
                os.path.join(alone, "contact3d-mpi"), "solve", path, *tail]
        refused = subprocess.run(argv, capture_output=True, text=True, timeout=300)
        if refused.returncode != 2 or "rank 1 failed to open the PETSc module" not in refused.stderr or \
                "libcontact3d_petsc.so" not in refused.stderr:
            fails.append(f"PETSc module missing on rank 1 only: exit {refused.returncode}, {refused.stderr.strip()[:300]}")
        # A bad input ends every rank with rank 0's exit code 2 (the others ended with 0), seen with
        # mpirun told not to abort the job on the first non-zero exit.
        bad = os.path.join(tmp, "bad.toml")
        with open(bad, "w") as f:
            f.write('[mesh]\nfile = "missing.msh"\n')
        each = subprocess.run([args.mpiexec, "-np", "2", "--mca", "orte_abort_on_non_zero_status", "0", "sh", "-c",
                               f'"{args.mpi}" solve "{bad}" --quiet --out "{os.path.join(tmp, "bad_out")}"; '
                               'echo "rank $OMPI_COMM_WORLD_RANK exit $?"'],
                              capture_output=True, text=True, timeout=120)
        codes = sorted(line for line in each.stdout.splitlines() if line.startswith("rank "))
        if codes != ["rank 0 exit 2", "rank 1 exit 2"]:
            fails.append(f"bad input under mpirun: {codes}, expected exit 2 on both ranks")
        # Negative check: a 1e-6 change of the input must be seen by the same comparison.
        label, scene, sets, _ = CASES[0]
        path = os.path.join(args.source, "pipeline", "scenes", scene)
        with open(path, "rb") as f:
            young = tomllib.load(f)["material"]["young"]
        pert = os.path.join(tmp, "perturbed")
        solve([args.serial, "solve", path], pert, sets + [f"material.young={young * (1 + 1e-6)!r}"])
        du, dl = relative_difference(os.path.join(tmp, "serial0"), pert, "perturbed")
        if du <= TOL:
            fails.append(f"negative check: a Young's modulus 1e-6 larger changed u by only {du:.1e}")
    except RuntimeError as e:
        fails.append(str(e))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    if fails:
        print("FAIL:\n  " + "\n  ".join(fails))
        return 1
    print(f"ok: the distributed solve on {args.np} (and 3) ranks equals the serial one to {TOL:g}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
