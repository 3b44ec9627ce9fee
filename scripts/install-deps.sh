#!/usr/bin/env bash
# Installs the Debian 12 packages contact3d needs (run as root). Skips the install when all
# are present, so every make target can call it cheaply.
set -euo pipefail
PKGS=(build-essential cmake pkg-config libeigen3-dev libsuitesparse-dev libopenblas0-pthread
      libopenblas-pthread-dev libtomlplusplus-dev libcli11-dev libfmt-dev libgtest-dev
      libbenchmark-dev gmsh freefem++ libfreefem++ python3-numpy python3-scipy python3-matplotlib python3-meshio python3-pyflakes
      python3-getfem  # GetFEM: the independent Coulomb-friction oracle (tests/cli.cmake)
      python3-vtk9    # VTK's own XML reader for the ParaView collection test (tests/vtu_meshio.cmake)
      clang-format)   # the C++ layout check (tests/lint.cmake)
# `install-deps.sh --dev` adds the fuzzing toolchain (fuzz/build.sh: clang 14 + libFuzzer runtime).
if [ "${1:-}" = "--dev" ]; then PKGS+=(clang-14 libclang-rt-14-dev); fi
# `install-deps.sh --mpi` adds the distributed backend's PETSc 3.18 (MUMPS, hypre, PT-Scotch, ScaLAPACK),
# MUMPS's own headers (the backend also calls MUMPS directly) and Open MPI (`make build-mpi`); the
# default build and its tests do not need them.
if [ "${1:-}" = "--mpi" ]; then PKGS+=(petsc-dev libmumps-dev libopenmpi-dev openmpi-bin); fi
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then exit 0; fi
echo "install-deps: installing ${missing[*]}"
SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
