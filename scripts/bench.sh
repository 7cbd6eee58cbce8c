#!/usr/bin/env bash
# Runs every benchmark program in BUILD/bench and keeps its JSON report.
#   scripts/bench.sh [BUILD_DIR] [FILTER]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-build}
case "$build" in /*) ;; *) build=$root/$build ;; esac
filter=${2:-}
out=$root/out/bench
mkdir -p "$out"
echo "machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) threads"
for b in "$build"/bench/bench_*; do
  [ -x "$b" ] || continue
  name=$(basename "$b")
  [ -z "$filter" ] || [[ "$name" == *"$filter"* ]] || continue
  echo "== $name"
  "$b" --benchmark_out="$out/$name.json" --benchmark_out_format=json
done
echo "JSON reports in ${out#$root/}/"
