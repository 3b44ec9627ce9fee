#!/usr/bin/python3
"""End-to-end check of run_scene.py: solve the brick (n = 4) with figures, then check the exit
code, that every paper figure exists as a non-trivial PNG, that report.md links each of them and
has one convergence-table row per history.csv row, and that a combined Fig. 6 can be made.
usage: check_figures.py --bin build/contact3d --scene pipeline/scenes/paper_brick.toml"""
import argparse
import csv
import os
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FIGURES = ["fig03_friction_law.png", "fig06_convergence.png", "fig07_deformed_body.png", "fig08_normal.png",
           "fig09_tangential.png", "fig10_friction_on_contact.png", "fig11_tangential_multiplier.png"]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--scene", required=True)
    a = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="contact3d_fig_")
    out = os.path.join(tmp, "run")
    fails = []
    rc = subprocess.call([sys.executable, os.path.join(ROOT, "pipeline", "run_scene.py"), "--bin", a.bin, "--scene",
                          a.scene, "--out", out, "--args", "--quiet --set mesh.generator=paper_brick --set mesh.n=4"])
    if rc != 0:
        fails.append(f"run_scene.py exited {rc}")
    text = open(os.path.join(out, "report.md")).read() if os.path.isfile(os.path.join(out, "report.md")) else ""
    if not text:
        fails.append("no report.md")
    for f in FIGURES:
        p = os.path.join(out, "figures", f)
        if not os.path.isfile(p):
            fails.append(f"missing figure {f}")
            continue
        with open(p, "rb") as fh:
            head = fh.read(8)
        if head != b"\x89PNG\r\n\x1a\n" or os.path.getsize(p) < 5000:
            fails.append(f"{f} is not a real PNG")
        if f"(figures/{f})" not in text:
            fails.append(f"report.md does not show {f}")
    with open(os.path.join(out, "history.csv")) as fh:
        hist = list(csv.DictReader(fh))
    rows = [l for l in text.splitlines() if l.startswith("| ") and l.count("|") == 8 and l[2].isdigit()]
    if len(hist) < 2 or len(rows) != len(hist):
        fails.append(f"report has {len(rows)} convergence rows, history.csv {len(hist)}")
    for key in ("## KKT residuals", "| equilibrium |", "## Timings per stage", "| factorization |"):
        if key not in text:
            fails.append(f"report.md lacks '{key}'")
    # Combined convergence plot over two runs.
    rc = subprocess.call([sys.executable, os.path.join(ROOT, "pipeline", "plots", "fig6_convergence.py"), out, out,
                          "--out", tmp, "--name", "combined.png"], stdout=subprocess.DEVNULL)
    if rc != 0 or not os.path.isfile(os.path.join(tmp, "combined.png")):
        fails.append("combined Fig. 6 failed")
    if fails:
        print(f"FAIL (output kept in {tmp}):\n  - " + "\n  - ".join(fails))
        return 1
    shutil.rmtree(tmp, ignore_errors=True)
    print("ok: run_scene.py wrote the report and all figures")
    return 0


if __name__ == "__main__":
    sys.exit(main())
