#!/usr/bin/env python3
"""Fault injection for the output folder (issue 13): a solve that cannot finish never leaves files
that look like a finished solve, and says why.

1. full disk: a file-size limit (RLIMIT_FSIZE) makes a write fail -> exit 2, `error:` naming the
   file, no summary.json, the RUNNING marker left, no *.partial file;
2. failed rerun: a good solve, then a rerun into the same folder with a bad scene -> exit 2 and the
   earlier summary.json is gone (RUNNING marks the folder);
3. interrupted: SIGTERM and SIGINT during a solve -> no summary.json, RUNNING left, a line on stderr
   saying so, and the signal's own exit;
4. two solves at once on one folder -> the second is refused (exit 2, `another contact3d solve`);
5. an unwritable file mid-run: summary.json's name taken by a directory -> exit 2 naming it;
6. a run that stops without converging (fixed-point iteration limit 2) -> exit 1, its last iterate
   written with NOT_CONVERGED beside it naming the exit, and a converged rerun into the same folder
   removes that marker;
7. a folder whose steps/ holds a user's own files (`--out .` in a project): only the run's step files
   (steps/body_<k>.vtu, steps/contact_<k>.vtu) are replaced, and the .partial files a killed run left
   are removed; the user's files stay;
8. the meshers' files an earlier run left (mesh.msh, gmsh.log) are removed by a run that did not write
   them, unless it reads that mesh.msh itself; a user's own mesh.msh (no gmsh.log beside it, or a gmsh.log
   of their own) stays;
9. a solve killed while gmsh meshes takes gmsh with it (an orphaned gmsh wrote mesh.msh into the folder
   after a later run had finished there);
10. `contact3d mesh brick` under a file-size limit: exit 2, and neither the mesh nor its .partial left;
    through a symbolic link it writes the link's target;
11. stdout closed by its reader (`| head -1`): the solve finishes its results, exit 0;
12. stdout and stderr closed by the caller (`>&- 2>&-`): the results are clean, the lock file empty.
usage: check_output_integrity.py CONTACT3D SOURCE_DIR
"""
import json
import os
import resource
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

binary, root = sys.argv[1], Path(sys.argv[2])
scene = root / "pipeline" / "scenes" / "paper_brick.toml"
failures = []


def check(ok, what):
    if not ok:
        failures.append(what)
        print("FAIL:", what)


def solve(out, n=4, extra=(), **kw):
    cmd = [binary, "solve", str(scene), "--out", str(out), "--quiet", "--set", "mesh.generator=paper_brick",
           "--set", f"mesh.n={n}", *extra]
    return subprocess.run(cmd, capture_output=True, text=True, **kw)


def gmsh_children(parent):
    """The pids of gmsh processes whose parent is `parent` (read from /proc: no procps needed)."""
    pids = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            text = stat.read_text()
        except OSError:
            continue
        name, rest = text[text.index("(") + 1:text.rindex(")")], text[text.rindex(")") + 2:].split()
        if name == "gmsh" and int(rest[1]) == parent:
            pids.append(int(stat.parent.name))
    return pids


def unfinished(out):
    return not (out / "summary.json").exists() and (out / "RUNNING").exists() and not list(out.glob("*.partial"))


with tempfile.TemporaryDirectory() as tmp:
    tmp = Path(tmp)
    # 1. full disk through a 16 KiB file-size limit
    out = tmp / "full"
    p = solve(out, 8, preexec_fn=lambda: resource.setrlimit(resource.RLIMIT_FSIZE, (16384, 16384)))
    check(p.returncode == 2 and "error: cannot write" in p.stderr and str(out) in p.stderr,
          f"file-size limit: exit {p.returncode}, stderr {p.stderr!r}")
    check(unfinished(out), f"file-size limit left {sorted(x.name for x in out.iterdir())}")

    # 2. a failed rerun removes the earlier result
    out = tmp / "rerun"
    p = solve(out)
    check(p.returncode == 0 and (out / "summary.json").exists() and not (out / "RUNNING").exists(), "good solve")
    p = solve(out, extra=["--set", "friction.law=bogus"])
    check(p.returncode == 2 and "error:" in p.stderr, f"bad rerun exit {p.returncode}")
    check(unfinished(out), f"failed rerun left {sorted(x.name for x in out.iterdir())}")

    # 3. SIGTERM / SIGINT during a solve (n = 16 runs for a second or more)
    for sig in (signal.SIGTERM, signal.SIGINT):
        out = tmp / f"signal{int(sig)}"
        proc = subprocess.Popen([binary, "solve", str(scene), "--out", str(out), "--quiet", "--set",
                                 "mesh.generator=paper_brick", "--set", "mesh.n=16"],
                                stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        deadline = time.time() + 30  # the solve has started (its folder marked) before it is stopped
        while not (out / "RUNNING").exists() and time.time() < deadline and proc.poll() is None:
            time.sleep(0.02)
        time.sleep(0.2)
        proc.send_signal(sig)
        _, err = proc.communicate(timeout=120)
        rc = proc.returncode
        # The signal's own end (rc -sig from Python), and a line saying the folder holds no answer.
        check(rc == -int(sig), f"signal {sig}: exit {rc}")
        check("stopped; the output folder holds no answer" in err, f"signal {sig}: stderr {err[-300:]!r}")
        check(unfinished(out), f"signal {sig} left {sorted(x.name for x in out.iterdir())}")

    # 4. two solves on one folder
    out = tmp / "twice"
    first = subprocess.Popen([binary, "solve", str(scene), "--out", str(out), "--quiet", "--set",
                              "mesh.generator=paper_brick", "--set", "mesh.n=16"],
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    time.sleep(0.3)
    p = solve(out)
    first.wait(timeout=300)
    check(p.returncode == 2 and "another contact3d solve" in p.stderr, f"second solve: {p.returncode} {p.stderr!r}")
    check(first.returncode == 0 and (out / "summary.json").exists() and not (out / "RUNNING").exists(),
          "the first solve must finish normally")

    # 5. summary.json cannot be written (its name is a directory)
    out = tmp / "blocked"
    out.mkdir()
    (out / "summary.json").mkdir()  # the run removes stale files but not a non-empty directory
    (out / "summary.json" / "keep").write_text("x")
    p = solve(out)
    check(p.returncode == 2 and "summary.json" in p.stderr, f"blocked summary.json: {p.returncode} {p.stderr!r}")
    check((out / "RUNNING").exists(), "blocked summary.json: RUNNING must stay")

    # 6. a run that stops without converging is marked so; a converged rerun clears the mark
    out = tmp / "unconverged"
    p = solve(out, extra=["--set", "solver.fixed_point_max_iter=2"])
    marker = out / "NOT_CONVERGED"
    check(p.returncode == 1 and marker.exists() and "iteration_limit" in marker.read_text()
          and (out / "summary.json").exists() and not (out / "RUNNING").exists(),
          f"unconverged run: exit {p.returncode}, left {sorted(x.name for x in out.iterdir())}")
    p = solve(out)
    check(p.returncode == 0 and not marker.exists(), f"converged rerun: exit {p.returncode}, marker {marker.exists()}")

    # 7. the user's own files under steps/ survive a run; a stale step file of an earlier run does not
    out = tmp / "project"
    (out / "steps").mkdir(parents=True)
    (out / "steps" / "notes.txt").write_text("mine")
    (out / "steps" / "body_wide.vtu").write_text("mine too")
    (out / "steps" / "body_099.vtu").write_text("a stale step")
    (out / "steps" / "contact_004.vtu.partial").write_text("a killed write")
    (out / "summary.json.partial").write_text("a killed write")
    p = solve(out)
    check(p.returncode == 0 and (out / "steps" / "notes.txt").read_text() == "mine"
          and (out / "steps" / "body_wide.vtu").exists() and not (out / "steps" / "body_099.vtu").exists()
          and not (out / "steps" / "contact_004.vtu.partial").exists() and not (out / "summary.json.partial").exists()
          and (out / "steps" / "body_001.vtu").exists(),
          f"user files under steps/: exit {p.returncode}, left {sorted(x.name for x in (out / 'steps').iterdir())}")


    # 8. the meshers' files of an earlier run: a gmsh run, then a run of a mesh file into the same folder
    # -> the earlier mesh.msh and gmsh.log are gone; a run that reads that mesh.msh itself keeps it
    out = tmp / "mesher_files"
    gmsh_run = [binary, "solve", str(scene), "--out", str(out), "--quiet", "--set", "mesh.parameters.n=4"]
    p = subprocess.run(gmsh_run, capture_output=True, text=True)
    check(p.returncode == 0 and (out / "mesh.msh").exists(), f"gmsh run: exit {p.returncode} {p.stderr[-300:]}")
    own = tmp / "own.msh"
    own.write_bytes((out / "mesh.msh").read_bytes())
    p = subprocess.run([binary, "solve", str(scene), "--mesh", str(own), "--out", str(out), "--quiet"],
                       capture_output=True, text=True)
    check(p.returncode == 0 and not (out / "mesh.msh").exists() and not (out / "gmsh.log").exists(),
          f"a mesh file's run left {sorted(x.name for x in out.iterdir())}")
    subprocess.run(gmsh_run, capture_output=True, text=True)
    p = subprocess.run([binary, "solve", str(scene), "--mesh", str(out / "mesh.msh"), "--out", str(out), "--quiet"],
                       capture_output=True, text=True)
    check(p.returncode == 0 and (out / "mesh.msh").exists(), f"the mesh read was removed: exit {p.returncode}")
    mine = tmp / "users_folder"  # a user's own mesh.msh, no gmsh.log beside it: not a run's, kept
    mine.mkdir()
    (mine / "mesh.msh").write_bytes(own.read_bytes())
    p = subprocess.run([binary, "solve", str(scene), "--mesh", str(own), "--out", str(mine), "--quiet"],
                       capture_output=True, text=True)
    check(p.returncode == 0 and (mine / "mesh.msh").exists(), f"a user's own mesh.msh was removed: exit {p.returncode}")
    # ... and with a gmsh.log of their own beside it (`gmsh -log gmsh.log`; output.dir = "."): both kept
    (mine / "gmsh.log").write_text("Info    : Running 'gmsh -3 body.geo -log gmsh.log'\n")
    p = subprocess.run([binary, "solve", str(scene), "--mesh", str(mine / "mesh.msh"), "--out", str(mine), "--quiet"],
                       capture_output=True, text=True)
    check(p.returncode == 0 and (mine / "gmsh.log").exists() and (mine / "mesh.msh").exists(),
          f"a user's own gmsh.log was removed: exit {p.returncode}")

    # 9. a solve killed while gmsh meshes: gmsh dies with it (it wrote mesh.msh into the folder afterwards)
    out = tmp / "killed_meshing"
    slab = root / "pipeline" / "scenes" / "slab.toml"
    run = subprocess.Popen([binary, "solve", str(slab), "--out", str(out), "--quiet", "--set",
                            "mesh.parameters.h=0.0175"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    mesher = None
    for _ in range(200):
        found = gmsh_children(run.pid)
        if found:
            mesher = found[0]
            break
        time.sleep(0.05)
    run.kill()
    run.wait()
    alive = False
    if mesher is not None:
        time.sleep(1.0)
        try:
            state = Path(f"/proc/{mesher}/status").read_text()
            alive = "State:\tZ" not in state  # a zombie is dead, waiting for init to reap it
        except FileNotFoundError:
            alive = False
    check(mesher is not None and not alive, f"gmsh {'never seen' if mesher is None else 'outlived the killed solve'}")

    # 10. `contact3d mesh brick` on a full disk leaves no truncated mesh under the file's name
    out = tmp / "mesh_full"
    out.mkdir()
    p = subprocess.run([binary, "mesh", "brick", "--n", "12", "-o", str(out / "x.msh")], capture_output=True, text=True,
                       preexec_fn=lambda: resource.setrlimit(resource.RLIMIT_FSIZE, (16384, 16384)))
    check(p.returncode == 2 and "cannot write mesh file" in p.stderr and not any(out.iterdir()),
          f"mesh brick under a file-size limit: exit {p.returncode}, left {sorted(x.name for x in out.iterdir())}")
    # ... and writes through a symbolic link to its target, the link kept (the rename replaced the link)
    (out / "target.msh").write_text("old")
    (out / "link.msh").symlink_to("target.msh")
    p = subprocess.run([binary, "mesh", "brick", "--n", "2", "-o", str(out / "link.msh")], capture_output=True)
    check(p.returncode == 0 and (out / "link.msh").is_symlink() and (out / "target.msh").read_text().startswith("$MeshFormat"),
          f"mesh brick through a symbolic link: exit {p.returncode}, link kept {(out / 'link.msh').is_symlink()}")

    # 11. stdout closed by its reader mid-run (`contact3d solve … | head -1`): the console's lines are
    # dropped, the solve goes on to its results (SIGPIPE ended it, exit 141, RUNNING left)
    out = tmp / "stdout_closed"
    proc = subprocess.Popen([binary, "solve", str(scene), "--out", str(out), "--set", "mesh.generator=paper_brick",
                             "--set", "mesh.n=8"], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)
    proc.stdout.readline()
    proc.stdout.close()
    code = proc.wait(timeout=300)
    check(code == 0 and (out / "summary.json").exists() and not (out / "RUNNING").exists(),
          f"stdout closed by its reader: exit {code}, left {sorted(x.name for x in out.iterdir()) if out.exists() else []}")

    # 12. stdout and stderr closed by the caller (`contact3d solve … >&- 2>&-`): the files the run opens
    # took descriptors 1 and 2, its console report went into the lock file and a warning could land in a
    # result file; the results are clean, the lock file empty, summary.json valid JSON
    out = tmp / "streams_closed"
    p = subprocess.run([binary, "solve", str(scene), "--out", str(out), "--set", "mesh.generator=paper_brick",
                        "--set", "mesh.n=4"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                       preexec_fn=lambda: (os.close(1), os.close(2)))
    lock = out / ".contact3d.lock"
    try:
        summary_ok = isinstance(json.loads((out / "summary.json").read_text()), dict)
    except (OSError, ValueError):
        summary_ok = False
    check(p.returncode == 0 and summary_ok and lock.exists() and lock.stat().st_size == 0,
          f"streams closed: exit {p.returncode}, summary.json valid {summary_ok}, lock file "
          f"{lock.stat().st_size if lock.exists() else 'missing'} bytes")

print(f"{len(failures)} checks failed" if failures else "all 12 cases held")
sys.exit(1 if failures else 0)
