#!/usr/bin/env bash
# Fuzzes every parser with libFuzzer (clang, ASan + UBSan; undefined behaviour
# stops the run like a crash), then merges what
# found new coverage into the corpus kept in the repository.
#   tools/fuzz/run.sh [TARGET...]          (default: every target)
#   FUZZ_SECONDS=120 make fuzz             (seconds per target; default 120)
#   FUZZ_JOBS=2                            (targets fuzzed at once; default: cores)
#   FUZZ_TIMEOUT=20                        (seconds one input may take; raise it on a loaded machine)
# Per target: tools/fuzz/corpus/NAME is the kept corpus (seeds, every past
# crash, merged coverage), corpus-run/NAME the working set, crashes land in
# crashes/NAME/. The last lines are a table: executions, coverage, crashes.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
secs=${FUZZ_SECONDS:-120}
jobs=${FUZZ_JOBS:-$(nproc)}
timeout=${FUZZ_TIMEOUT:-20}
build=$root/build-fuzz
source_targets() { sed -n 's/^set(SKYBAKE_FUZZ_TARGETS \(.*\))$/\1/p' "$here/targets.cmake"; }
targets=("$@")
[ ${#targets[@]} -gt 0 ] || read -r -a targets <<<"$(source_targets)"

CC=clang CXX=clang++ cmake -S "$here" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build "$build" -j "$(nproc)" --target $(printf 'fuzz_%s ' "${targets[@]}")

# Assimp's test models seed the mesh loader (the first byte picks the reader).
seed_mesh_loader() {
  local dir=$1 models=/usr/share/assimp/models i f size
  local -a globs=("PLY/*.ply" "glTF2/*/*.glb" "glTF2/*/*.gltf" "OBJ/*.obj" "OFF/*.off" "STL/*.stl")
  for i in "${!globs[@]}"; do
    for f in $models/${globs[$i]}; do
      [ -f "$f" ] || continue
      size=$(stat -c %s "$f"); [ "$size" -le 65536 ] || continue
      { printf "\\x$(printf %02x "$i")"; cat "$f"; } > "$dir/seed-$i-$(basename "$f")"
    done
  done
}

run_one() {
  local t=$1 work=$here/corpus-run/$t crashes=$here/crashes/$t log=$here/crashes/$t.log dict=()
  rm -rf "$crashes" # this run's findings only; earlier ones are in the corpus
  mkdir -p "$work" "$crashes"
  cp -n "$here/corpus/$t"/* "$work"/ 2>/dev/null || true
  [ "$t" = mesh_loader ] && seed_mesh_loader "$work"
  [ -f "$here/$t.dict" ] && dict=(-dict="$here/$t.dict")
  # The merge below runs every input again: it needs the same options (the
  # leak suppressions above all), or a known third-party leak stops it.
  local -a env=(ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=1 "LSAN_OPTIONS=suppressions=$here/lsan.supp"
                UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1)
  env "${env[@]}" "$build/fuzz_$t" "${dict[@]}" -max_total_time="$secs" -max_len=65536 -rss_limit_mb=4096 -timeout="$timeout" \
    -print_final_stats=1 -artifact_prefix="$crashes/" "$work" >"$log" 2>&1 || true
  # Keep what adds coverage (and every crash) in the repository's corpus.
  env "${env[@]}" "$build/fuzz_$t" -merge=1 -artifact_prefix="$crashes/" "$here/corpus/$t" "$work" >>"$log" 2>&1 || true
  for c in "$crashes"/crash-* "$crashes"/leak-* "$crashes"/timeout-* "$crashes"/oom-*; do
    [ -f "$c" ] && cp -n "$c" "$here/corpus/$t/"
  done
  return 0
}

pids=()
for t in "${targets[@]}"; do
  run_one "$t" &
  pids+=($!)
  while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do sleep 1; done
done
wait "${pids[@]}"

printf '\n%-12s %12s %8s %8s %8s\n' target executions cov ft crashes
for t in "${targets[@]}"; do
  log=$here/crashes/$t.log
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | cut -d' ' -f2)
  ft=$(grep -o 'ft: [0-9]*' "$log" | tail -1 | cut -d' ' -f2)
  crashes=$(find "$here/crashes/$t" -type f | wc -l)
  printf '%-12s %12s %8s %8s %8s\n' "$t" "${execs:-?}" "${cov:-?}" "${ft:-?}" "$crashes"
done
