#!/usr/bin/python3
"""All figures of one run (Figs. 3, 6, 7, 8, 9, 10, 11 of the paper) into OUT (default RUN/figures).
--compare RUN2 RUN3 ... adds a combined convergence plot (fig06_convergence_combined.png).
A figure whose data the run does not have (e.g. no contact face) is skipped with a note.
usage: make_figures.py RUN_DIR [--out DIR] [--compare RUN_DIR...]"""
import argparse
import os
import sys
import traceback

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import fig3_friction  # noqa: E402
import fig6_convergence  # noqa: E402
import fig7_deformed  # noqa: E402
import fig8_10_contact  # noqa: E402
import fig11_multipliers  # noqa: E402
from common import Run  # noqa: E402


def make_all(run_dir, out_dir=None, compare=()):
    """Returns (list of written figure paths, list of messages about skipped figures)."""
    run = Run(run_dir)
    out = out_dir or os.path.join(run_dir, "figures")
    has_contact = os.path.isfile(run.path("contact.vtu")) and bool(run.cells())
    jobs = [("Fig. 3", lambda: fig3_friction.plot(run, out)),
            ("Fig. 6", lambda: fig6_convergence.plot([run], out)),
            ("Fig. 7", lambda: fig7_deformed.plot(run, out))]
    if has_contact:
        jobs += [("Figs. 8-10", lambda: fig8_10_contact.plot(run, out)),
                 ("Fig. 11", lambda: fig11_multipliers.plot(run, out))]
    if compare:
        jobs.append(("Fig. 6 combined", lambda: fig6_convergence.plot(
            [run] + [Run(c) for c in compare], out, "fig06_convergence_combined.png")))
    paths, notes = [], []
    if not has_contact:
        notes.append("Figs. 8-11 skipped: the run has no contact face")
    for name, job in jobs:
        try:
            paths += job()
        except Exception as e:  # a figure must not hide the others; say what went wrong
            notes.append(f"{name} failed: {e}")
            traceback.print_exc()
    return paths, notes


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("run")
    ap.add_argument("--out", default=None)
    ap.add_argument("--compare", nargs="*", default=[])
    a = ap.parse_args()
    paths, notes = make_all(a.run, a.out, a.compare)
    for p in paths:
        print(p)
    for n in notes:
        print("note:", n, file=sys.stderr)
    sys.exit(1 if any("failed" in n for n in notes) else 0)
