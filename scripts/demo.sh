#!/usr/bin/env bash
# The main job on generated and bundled data. Called by `make demo`.
#   scripts/demo.sh [BUILD_DIR]     (default: build)
# Everything is written under out/demo/; the last lines summarise it.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-build}
case "$build" in /*) ;; *) build=$root/$build ;; esac
sky=$build/bin/skybake
out=$root/out/demo
rm -rf "$out" # the summary lists what this run wrote, nothing older
mkdir -p "$out"
models=/usr/share/assimp/models

step() { printf '\n== %s\n' "$*"; }

# Runs a command that must be refused: prints its one error line as an
# expected result, and stops the demo if it succeeds instead.
expect_refusal() {
  local err
  if err=$("$@" 2>&1 >/dev/null); then
    echo "expected an error from: $*" >&2
    exit 1
  fi
  printf '  refused, as expected: %s\n' "${err#skybake: error: }"
}
export -f expect_refusal

"$sky" --version

step "procedural meshes"
"$sky" mesh generate --kind city --triangles 200000 --seed 1 -o "$out/city.glb"
"$sky" mesh generate --kind terrain --triangles 200000 --seed 1 -o "$out/terrain.ply"
"$sky" mesh generate --kind bowl --triangles 20000 -o "$out/bowl.glb"

step "a real mesh, flattened and converted"
"$sky" mesh convert "$models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb" -o "$out/engine.glb"
"$sky" mesh info "$out/engine.glb"

step "a broken file is refused with one line"
expect_refusal "$sky" mesh info "$models/glTF2/IndexOutOfRange/IndexOutOfRange.gltf"

# Further stages (sky, baking) append here as they exist.
for stage in "$root"/scripts/demo.d/*.sh; do
  [ -f "$stage" ] || continue
  step "$(basename "$stage" .sh)"
  SKYBAKE="$sky" OUT="$out" bash "$stage"
done

step "summary: wrote $(find "$out" -type f | wc -l) files to ${out#$root/}"
find "$out" -type f -printf '%P %s\n' | sort | awk '{ printf "  %-28s %12d bytes\n", $1, $2 }'
