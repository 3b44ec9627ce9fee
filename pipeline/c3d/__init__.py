"""The pipeline's one Python package: how the scripts in pipeline/ call contact3d and read what it writes.

- `c3d.run`: the `contact3d solve` command line (the only place that spells it) and summary.json.
- `c3d.law`: F(t) of a scene's [friction] table, the same formulas as solver/friction/friction_law.cpp.

The FreeFEM cross-check's parts live in `pipeline/oracle/` (errors, meshes, laws, freefem, compare),
driven by `pipeline/crosscheck.py` (cases, report, the FreeFEM self-validation).

Scripts in pipeline/ import it directly (their folder is on sys.path); scripts in subfolders add
pipeline/ to sys.path first.
"""
