#!/usr/bin/env bash
# Builds the libFuzzer targets into build-fuzz/ (clang++ -fsanitize=fuzzer,address,undefined).
#   fuzz/build.sh                 # builds build-fuzz/fuzz_msh, fuzz_scene and fuzz_medit
#   build-fuzz/fuzz_msh -jobs=1 -max_total_time=900 build-fuzz/corpus_msh fuzz/corpus/msh
# Needs clang 14 and its fuzzer runtime (Debian package libclang-rt-14-dev).
# Only the sources a target needs are compiled (the reader and scene parser have no solver deps).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-$root/build-fuzz}"
mkdir -p "$out"
CXX="${CXX:-clang++-14}"
flags=(-std=c++20 -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined
       -fno-omit-frame-pointer -I"$root/solver" -I/usr/include/eigen3 $(pkg-config --cflags tomlplusplus))
libs=($(pkg-config --libs tomlplusplus))
"$CXX" "${flags[@]}" -o "$out/fuzz_msh" "$root/fuzz/fuzz_msh.cpp" \
  "$root/solver/mesh/msh_reader.cpp" "$root/solver/mesh/mesh.cpp"
"$CXX" "${flags[@]}" -o "$out/fuzz_scene" "$root/fuzz/fuzz_scene.cpp" \
  "$root/solver/model/scene.cpp" "$root/solver/friction/friction_law.cpp" "$root/solver/contact/foundation_frame.cpp" \
  "$root/solver/mesh/mesh.cpp" "${libs[@]}"
"$CXX" "${flags[@]}" -o "$out/fuzz_medit" "$root/fuzz/fuzz_medit.cpp" \
  "$root/solver/mesh/medit_reader.cpp" "$root/solver/mesh/mesh.cpp"
echo "built $out/fuzz_msh $out/fuzz_scene $out/fuzz_medit"
