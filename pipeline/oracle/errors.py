"""What every part of the cross-check shares: the failure of one side (SideFailed), logging, CPU time of child processes."""
from __future__ import annotations

import numpy as np

import resource


class SideFailed(Exception):
    """One of the two solvers (or the input) failed: exit 2."""


def log(msg: str) -> None:
    print(msg, flush=True)


def children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def finite_or_fail(arr: np.ndarray, what: str) -> None:
    if not np.all(np.isfinite(arr)):
        raise SideFailed(f"{what}: non-finite values (NaN/inf)")
