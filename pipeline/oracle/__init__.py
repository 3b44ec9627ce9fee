"""The parts of the FreeFEM cross-check (pipeline/crosscheck.py), one module per concern:
errors (shared failure type, logging), meshes, laws, freefem (the reference side), compare."""
