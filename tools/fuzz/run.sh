#!/usr/bin/env bash
# Builds the mesh-loader fuzzer with clang and runs it.
#   tools/fuzz/run.sh [SECONDS]      (default 60)
# The seed corpus is built from Assimp's test models and skybake's own output;
# new inputs go to tools/fuzz/corpus-run/, crashes to tools/fuzz/crash-*.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
secs=${1:-60}
build=$root/build-fuzz
CC=clang CXX=clang++ cmake -S "$here" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build "$build" --target fuzz_mesh_loader -j "$(nproc)"

corpus=$here/corpus-run
mkdir -p "$corpus"
models=/usr/share/assimp/models
# Seeds: the first byte selects the reader (see fuzz_mesh_loader.cpp).
seed() { # index file
  [ -f "$2" ] || return 0
  local size; size=$(stat -c %s "$2")
  [ "$size" -le 65536 ] || return 0
  { printf "\\x$(printf %02x "$1")"; cat "$2"; } > "$corpus/seed-$1-$(basename "$2")"
}
for f in "$models"/PLY/*.ply; do seed 0 "$f"; done
for f in "$models"/glTF2/*/*.glb; do seed 1 "$f"; done
for f in "$models"/glTF2/*/*.gltf; do seed 2 "$f"; done
for f in "$models"/OBJ/*.obj; do seed 3 "$f"; done
for f in "$models"/OFF/*.off; do seed 4 "$f"; done
for f in "$models"/STL/*.stl; do seed 5 "$f"; done
cd "$here"
ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=1 LSAN_OPTIONS=suppressions=$here/lsan.supp \
  "$build/fuzz_mesh_loader" -max_total_time="$secs" -max_len=65536 -rss_limit_mb=4096 -timeout=20 \
  -print_final_stats=1 "$corpus"
