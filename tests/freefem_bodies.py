#!/usr/bin/env python3
"""FreeFEM-made polyhedral bodies (geo/lblock.edp, geo/hexprism.edp) solve like their gmsh twins.

Each *_freefem scene has the data of its gmsh scene with FreeFEM's labels as groups. Both meshes
discretise the same body, so the total contact forces agree up to the discretisation difference:
normal within 2% and tangential within 5% of the load scale (measured: L-block 0.05% / 0.01%,
hexagonal prism 0.21% / 0.10%), both converged with balanced forces.

    freefem_bodies.py <contact3d> <repo root>
"""
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "pipeline"))
from c3d.run import solve, summary  # noqa: E402

binary, root = sys.argv[1], Path(sys.argv[2])
scenes = root / "pipeline" / "scenes"
failures = []
with tempfile.TemporaryDirectory() as tmp:
    for body in ("lblock", "hexprism"):
        runs = {}
        for variant in (body, f"{body}_freefem"):
            out = Path(tmp) / variant
            proc, _ = solve(binary, scenes / f"{variant}.toml", out)
            if proc.returncode != 0:
                print(f"FAIL: {variant}: exit {proc.returncode}: {proc.stderr}")
                sys.exit(1)
            runs[variant] = summary(out)
        g, f = runs[body], runs[f"{body}_freefem"]
        scale = max(abs(x) for x in g["forces"]["applied"])
        dn = abs(g["contact_force"]["normal"] - f["contact_force"]["normal"]) / scale
        dt = abs(g["contact_force"]["t1"] - f["contact_force"]["t1"]) / scale
        if dn > 0.02 or dt > 0.05 or f["forces"]["balance"] > 1e-8:
            failures.append(f"{body}: normal {dn:.3g}, tangential {dt:.3g} of the load apart; balance {f['forces']['balance']}")
        print(f"{body}: FreeFEM mesh {f['n_nodes']} nodes, gmsh {g['n_nodes']}; contact force normal "
              f"{f['contact_force']['normal']:.6g} / {g['contact_force']['normal']:.6g} N ({dn:.2%} of the load), "
              f"t1 {f['contact_force']['t1']:.6g} / {g['contact_force']['t1']:.6g} N ({dt:.2%})")
for msg in failures:
    print("FAIL:", msg)
sys.exit(1 if failures else 0)
