#!/usr/bin/env python3
"""Includes only point down the layers of solver/ (README, "How it works"):

    base -> mesh -> fem -> contact -> linalg -> qp -> friction -> model -> io -> app

A file may include its own folder and any folder before it, never one after it. Prints the
include graph between folders and exits 1 on the first upward include it lists.
usage: check_layers.py SOURCE_DIR
"""
import re
import sys
from pathlib import Path

LAYERS = ["base", "mesh", "fem", "contact", "linalg", "distributed", "qp", "friction", "model", "io", "app"]
INCLUDE = re.compile(r'^\s*#\s*include\s+"([a-z_]+)/[^"]+"', re.M)


def main():
    solver = Path(sys.argv[1]) / "solver"
    rank = {name: k for k, name in enumerate(LAYERS)}
    edges, upward = {}, []
    for f in sorted(solver.rglob("*.[ch]pp")):
        here = f.relative_to(solver).parts[0]
        if here not in rank:
            upward.append(f"{f}: folder '{here}' is not a known layer (add it to tests/check_layers.py)")
            continue
        for target in INCLUDE.findall(f.read_text(errors="replace")):
            if target not in rank:
                continue
            edges.setdefault(here, set()).add(target)
            if rank[target] > rank[here]:
                upward.append(f"{f.relative_to(solver.parent)} includes {target}/ (layer {rank[target]}) from {here}/ (layer {rank[here]})")
    for here in LAYERS:
        below = sorted(edges.get(here, set()) - {here}, key=rank.get)
        if below:
            print(f"{here:>12} -> {', '.join(below)}")
    if upward:
        print("upward includes:\n  " + "\n  ".join(upward))
        return 1
    print("no upward includes")
    return 0


if __name__ == "__main__":
    sys.exit(main())
