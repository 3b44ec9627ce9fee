#!/usr/bin/env python3
"""Fails when tests/errors.cmake does not register every c_<name> case of tests/bad_inputs.py."""
import re
import sys

driver, cmake = open(sys.argv[1]).read(), open(sys.argv[2]).read()
cases = set(re.findall(r"^def c_(\w+)\(", driver, re.M))
listed = set(re.search(r"set\(CONTACT3D_BAD_INPUT_CASES(.*?)\)", cmake, re.S).group(1).split())
missing, extra = cases - listed, listed - cases
if missing or extra:
    print("not registered:", sorted(missing), "unknown:", sorted(extra))
    sys.exit(1)
print(f"{len(cases)} cases registered")
