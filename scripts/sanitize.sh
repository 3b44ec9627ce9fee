#!/usr/bin/env bash
# Builds contact3d and the unit tests with AddressSanitizer + UBSan (-DCONTACT3D_SANITIZE=ON)
# in build-asan/ and runs the unit tests there. Exit status: that of the test run.
# Warnings are not errors here: GCC 12 reports false maybe-uninitialized warnings inside
# libstdc++ (std::regex) once the sanitizers instrument it; the normal build keeps -Werror.
#   scripts/sanitize.sh [gtest args]     e.g. scripts/sanitize.sh --gtest_filter='Regression*'
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${BUILD_ASAN:-$root/build-asan}"
jobs="${JOBS:-2}"
# -g1: line tables only, enough for the sanitizers' file:line stack traces; full -g made build-asan
# about 3 GB, which a CI machine with little disk left could not link.
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" \
  -DCONTACT3D_SANITIZE=ON -DCONTACT3D_WERROR=OFF >/dev/null
cmake --build "$build" -j "$jobs" --target unit_tests contact3d
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:strict_string_checks=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
export OPENBLAS_NUM_THREADS="${OPENBLAS_NUM_THREADS:-1}"
# Every gtest in one process (the CLI binary in build-asan is sanitized too; tests that call it use it).
"$build/unit_tests" "$@"
