#!/usr/bin/env bash
# Runs every CUDA and OpenGL path of skybake on a GPU machine that has CUDA and
# the NVIDIA driver but none of our Debian libraries, in one call, and leaves
# the logs, the benchmarks' JSON and three screenshots in $OUT.
#
#   scripts/gpu-check.sh pack [BUILD]      here: .gpu/skybake-gpu.tar.xz from BUILD (default build/)
#   scripts/gpu-check.sh run               there, in the repository root: OUT must name the output folder
#   scripts/gpu-check.sh --dry-run [--no-pack] [BUILD]  here: pack (unless --no-pack), then run against
#                                          the CPU build, GPU steps skipped (OUT default out/gpu-check-dry)
#   scripts/gpu-check.sh --selftest [BUILD] here, cheap: the lists below against the build and the tests
#
# docs/gpu-check.md says how to use it. The whole run keeps within
# GPU_CHECK_BUDGET_S seconds (default 450): each step's timeout is cut to what
# is left, and a step that would start with under 5 s left is skipped.
# GPU_CHECK_ONLY / GPU_CHECK_SKIP: regexes of the step names to run / to leave
# out (a second call that reruns only what failed); `device` and `inputs` always run.
set -uo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
archive_name=skybake-gpu.tar.xz
budget_s=${GPU_CHECK_BUDGET_S:-450}
transfer_limit_mib=64 # what travels to the GPU machine: working tree + carried paths

# --- what the package holds --------------------------------------------------
# Test executables: every *_gpu_tests and *_gl_tests that the build's
# CTestTestfile includes (found in the build, checked by --selftest).
# Programs beside them:
cli=bin/skybake
bench_programs=(bench_gpu_ao bench_gpu_sky bench_render bench_viewer bench_raster_ao)
# Benchmarks, filtered to fit the budget (Google Benchmark regexes):
#   the seed's table case with every CUDA method (Embree in the same run),
#   the network kernel, the batch paths and a 4K sky render beside their CPU runs,
#   the planet frame (1M triangles, network per pixel; bench_render draws 1280x1024)
#   and the seed's 2,000-triangle setup, the viewer frame at 1080p,
#   the raster backend's table case (cube and directional).
declare -A bench_filter=(
  [bench_gpu_ao]='^BM_GpuAo/kind:0/tris:3000/rule:5810/'
  [bench_gpu_sky]='^BM_(NetworkKernel|NetworkBatch|Reference|Render4K)/'
  [bench_render]='^BM_(Clod1M_PerPixel|SeedSetup_PerVertex_2kTriangles)/'
  [bench_viewer]='^BM_Viewer_100k_Prt4_NetworkPerPixel_1080p/'
  [bench_raster_ao]='^BM_RasterTableCase/'
)
# The files of Assimp's sample models that the GPU and GL tests read
# (skybake::test::assimp_models(), $SKYBAKE_ASSIMP_MODELS there).
models=(OBJ/spider.obj OBJ/spider.mtl OBJ/WusonOBJ.obj glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb)
# The GL loaders (glvnd), unpacked into / there with dpkg -x: they must sit where
# ldconfig and glvnd look (/usr/lib/x86_64-linux-gnu, /usr/share/glvnd), and the
# NVIDIA driver brings only the vendor libraries behind them.
gl_debs=(libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2)
# Libraries never packed: glibc, which must match the machine's dynamic loader.
base_libs='^(linux-vdso\.so\.1|ld-linux-x86-64\.so\.2|libc\.so\.6|libm\.so\.6|libdl\.so\.2|libpthread\.so\.0|librt\.so\.1|libresolv\.so\.2|libutil\.so\.1)$'
# Every other library that ldd lists is copied from this machine, as ldd resolved
# it, into lib/ of the package, rather than fetched as .debs: these are exactly
# the files (and versions) the binaries were linked and tested against, ldd has
# already followed every dependency, nothing is downloaded, and no package's
# other files (docs, plugins, configuration) travel. There they are found through
# LD_LIBRARY_PATH, and only those whose soname the machine lacks (or whose
# version it has too old, e.g. libstdc++) are put on it, so that the driver's
# tools (nvidia-smi, compute-sanitizer) keep the machine's own libraries.

die() {
  echo "gpu-check: $*" >&2
  exit 1
}
usage() {
  sed -n '5,9p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit 2
}
abs_build() {
  local b=${1:-build}
  case "$b" in /*) ;; *) b=$root/$b ;; esac
  [ -d "$b" ] || die "no build folder $b"
  (cd "$b" && pwd)
}
mib() { awk -v b="$1" 'BEGIN { printf "%.1f MiB", b / 1048576 }'; }

# The *_gpu_tests and *_gl_tests executables the build's CTestTestfiles include, relative to BUILD.
test_executables() {
  local build=$1
  grep -ho 'include("[^"]*_g[pl][ul]*_tests\[1\]_include\.cmake")' "$build"/src/CTestTestfile.cmake \
    "$build"/tests/CTestTestfile.cmake 2>/dev/null |
    sed -e 's/^include("//' -e 's/\[1\]_include\.cmake")$//' -e "s|^$build/||" | grep -E '_(gpu|gl)_tests$' | sort -u
}

# Every binary of the package, relative to BUILD.
packed_binaries() {
  local build=$1 b
  test_executables "$build"
  echo "$cli"
  for b in "${bench_programs[@]}"; do echo "bench/$b"; done
}

# Libraries ldd resolves for the given files, "soname path", glibc left out.
needed_libs() {
  ldd "$@" 2>/dev/null | awk '$2 == "=>" && $3 ~ /^\// { print $1, $3 }' | sort -u |
    while read -r name path; do [[ "$name" =~ $base_libs ]] || echo "$name $path"; done
}

models_dir() { echo "${SKYBAKE_ASSIMP_MODELS:-/usr/share/assimp/models}"; }

# Bytes that travel without carry: tracked files and untracked ones git does not ignore.
tree_bytes() {
  (cd "$root" && { git ls-files -z; git ls-files -z -o --exclude-standard; } |
    xargs -0 stat -c %s 2>/dev/null | awk '{ s += $1 } END { print s + 0 }')
}

# --- pack ----------------------------------------------------------------------
cmd_pack() {
  local build
  build=$(abs_build "${1:-build}")
  local t0=$SECONDS
  [ -x "$build/$cli" ] || die "$build/$cli is missing: build first (make build)"
  grep -q '^SKYBAKE_WITH_CUDA' "$build/CMakeCache.txt" || die "$build is not a skybake build"
  local missing=() f
  mapfile -t bins < <(packed_binaries "$build")
  [ "${#bins[@]}" -gt 3 ] || die "no GPU or GL test executables in $build (a build without CUDA or tests?)"
  for f in "${bins[@]}"; do [ -x "$build/$f" ] || missing+=("$f"); done
  [ "${#missing[@]}" -eq 0 ] || die "not built: ${missing[*]} (cmake --build $build)"
  echo "== pack: $build"
  # The test lists ctest reads (gtest_discover_tests writes them on the first ctest run).
  ctest --test-dir "$build" -N -L 'gpu|gl' >/dev/null || die "ctest -N failed in $build"

  local gpu=$root/.gpu
  local stage=$gpu/stage/skybake-gpu
  rm -rf "$gpu/stage" && mkdir -p "$stage"/{build,lib,debs,models} || die "cannot write $gpu"
  # The build tree's layout: the CTestTestfiles, the test lists of the packed
  # executables and the stripped binaries. Paths in them stay those of BUILD;
  # `run` rewrites them to where the package is unpacked.
  (cd "$build" && find . -name CTestTestfile.cmake -printf '%P\n') | while read -r f; do
    mkdir -p "$stage/build/$(dirname "$f")" && cp "$build/$f" "$stage/build/$f"
  done
  local inc exe
  for inc in "$build"/src/*_include.cmake "$build"/tests/*_include.cmake; do
    [ -e "$inc" ] || continue
    exe=${inc%\[1\]_include.cmake}
    f=${inc#"$build"/}
    if grep -qx "${exe#"$build"/}" <<<"$(printf '%s\n' "${bins[@]}")"; then
      # Only the list: no re-discovery there (it would need CMake 3.25's modules).
      [ -s "${exe}[1]_tests.cmake" ] || die "no test list ${exe}[1]_tests.cmake (run ctest -N in $build)"
      cp "${exe}[1]_tests.cmake" "$stage/build/${f%_include.cmake}_tests.cmake"
      echo "include(\"${exe}[1]_tests.cmake\")" >"$stage/build/$f"
    else
      : >"$stage/build/$f" # not packed: no tests
    fi
  done
  for f in "${bins[@]}"; do
    mkdir -p "$stage/build/$(dirname "$f")"
    strip --strip-unneeded -o "$stage/build/$f" "$build/$f" || die "strip $f failed"
  done
  # Runtime libraries.
  local name path nlibs=0
  while read -r name path; do
    cp -L "$path" "$stage/lib/$name" && nlibs=$((nlibs + 1))
  done < <(needed_libs "${bins[@]/#/$build/}")
  # GL loaders, cached in .gpu/debs.
  mkdir -p "$gpu/debs"
  local have=1 d
  for d in "${gl_debs[@]}"; do compgen -G "$gpu/debs/${d}_*.deb" >/dev/null || have=0; done
  if [ $have = 0 ]; then
    (cd "$gpu/debs" && apt-get download "${gl_debs[@]}" 2>&1 | grep -v 'unsandboxed' >&2) ||
      die "apt-get download ${gl_debs[*]} failed (put the .debs in .gpu/debs by hand)"
  fi
  for d in "${gl_debs[@]}"; do cp "$gpu/debs/${d}"_*.deb "$stage/debs/"; done
  # Models.
  local mdir
  mdir=$(models_dir)
  for f in "${models[@]}"; do
    [ -f "$mdir/$f" ] || die "model $mdir/$f is missing (Debian package assimp-testmodels)"
    mkdir -p "$stage/models/$(dirname "$f")" && cp "$mdir/$f" "$stage/models/$f"
  done
  # Manifest: where the build was, what it needs, every file with its size.
  local glibc
  glibc=$(cd "$stage" && objdump -T build/bin/skybake build/src/*_tests build/tests/*_tests build/bench/* lib/* 2>/dev/null |
    grep -o 'GLIBC_2\.[0-9]*' | sort -t. -k2 -n -u | tail -1)
  {
    echo "# skybake GPU package: scripts/gpu-check.sh pack"
    echo "source_dir $root"
    echo "build_dir $build"
    echo "commit $(cd "$root" && git describe --always --dirty 2>/dev/null || echo unknown)"
    echo "packed $(date -u +%Y-%m-%dT%H:%M:%SZ)"
    echo "glibc_needed ${glibc#GLIBC_}"
    echo "cuda_architectures $(sed -n 's/^CMAKE_CUDA_ARCHITECTURES:[A-Z]*=//p' "$build/CMakeCache.txt")"
    echo "nvcc $(sed -n 's/^set(CMAKE_CUDA_COMPILER_VERSION "\(.*\)")/\1/p' "$build"/CMakeFiles/*/CMakeCUDACompiler.cmake | head -1)"
    (cd "$stage" && find build lib debs models -type f -printf 'file %p %s\n' | sort)
  } >"$stage/manifest.txt"
  local out=$gpu/$archive_name
  tar -C "$gpu/stage" -cf - skybake-gpu | xz -T2 -6 >"$out.tmp" && mv "$out.tmp" "$out" || die "tar failed"
  cp "$stage/manifest.txt" "$gpu/manifest.txt"
  local raw packed tree
  raw=$(du -sb "$stage" | cut -f1)
  packed=$(stat -c %s "$out")
  tree=$(tree_bytes)
  echo "packed ${#bins[@]} binaries, $nlibs libraries, ${#gl_debs[@]} .debs, ${#models[@]} model files: $(mib "$raw") -> ${out#"$root"/} $(mib "$packed")"
  echo "what travels: working tree $(mib "$tree") + archive $(mib "$packed") = $(mib $((tree + packed))) of $transfer_limit_mib MiB"
  echo "pack took $((SECONDS - t0)) s"
  [ $((tree + packed)) -lt $((transfer_limit_mib * 1048576)) ] || die "over the $transfer_limit_mib MiB that travel"
  rm -rf "$gpu/stage"
}

# --- run -------------------------------------------------------------------------
# Globals of a run: mode (device|dry), pkg, log, out, start, results.
results=()
failed=0
remaining() { echo $((budget_s - (SECONDS - start))); }

# step NAME TIMEOUT CLASS COMMAND...: runs COMMAND with its output in $log/NAME.log,
# under `timeout` (TIMEOUT cut to the budget left). CLASS gpu: needs the CUDA
# device, skipped in a dry run.
step() {
  local name=$1 limit=$2 class=$3
  shift 3
  local left
  left=$(remaining)
  if [ "$name" != device ] && [ "$name" != inputs ] &&
    { { [ -n "${GPU_CHECK_ONLY:-}" ] && ! [[ "$name" =~ $GPU_CHECK_ONLY ]]; } ||
      { [ -n "${GPU_CHECK_SKIP:-}" ] && [[ "$name" =~ $GPU_CHECK_SKIP ]]; }; }; then
    record "$name" "skipped (GPU_CHECK_ONLY / GPU_CHECK_SKIP)" 0
    return 0
  fi
  if [ "$class" = gpu ] && [ "$mode" = dry ]; then
    record "$name" "skipped (dry run: needs the GPU)" 0
    return 0
  fi
  if [ "$left" -lt 5 ]; then
    record "$name" "skipped (out of time)" 0
    failed=1
    return 1
  fi
  [ "$limit" -le "$left" ] || limit=$left
  local t=$SECONDS rc
  echo "== $name (timeout ${limit} s)"
  {
    env | grep -E '^(CUDA_LAUNCH_BLOCKING|SKYBAKE_REQUIRE_GPU)=' | sed 's/^/# /'
    echo "\$ $*"
    timeout -k 10 "$limit" "$@"
  } >"$log/$name.log" 2>&1
  rc=$?
  local s=$((SECONDS - t))
  if [ $rc -eq 0 ]; then
    record "$name" ok "$s"
  elif [ $rc -eq 124 ] || [ $rc -eq 137 ]; then
    record "$name" "TIMEOUT after ${limit} s" "$s"
    failed=1
  else
    record "$name" "FAIL (exit $rc)" "$s"
    failed=1
  fi
  return $rc
}
record() {
  results+=("$(printf '%-34s %-40s %5s s' "$1" "$2" "$3")")
  echo "   $1: $2 ($3 s)"
}
# A note in the summary that is not a step.
note() { results+=("$(printf '%-34s %s' "$1" "$2")"); }

find_tool() { # NAME [candidates...]: the first that runs
  local n=$1 c
  shift
  if command -v "$n" >/dev/null 2>&1; then command -v "$n"; return 0; fi
  for c in "$@"; do [ -x "$c" ] && { echo "$c"; return 0; }; done
  return 1
}

# The library folder: the packed libraries whose soname the machine lacks, and
# those whose version it has too old (ldd says "version ... not found").
setup_libs() {
  local use=$pkg/lib-use f name
  rm -rf "$use" && mkdir -p "$use"
  if [ "$mode" = dry ]; then
    # Here every library is on the system: use all packed ones, so the dry run tests them.
    ln -s "$pkg"/lib/* "$use"/
  else
    local cache
    cache=$(ldconfig -p)
    for f in "$pkg"/lib/*; do
      name=${f##*/}
      grep -q "^[[:space:]]*$name " <<<"$cache" || ln -s "$f" "$use/$name"
    done
  fi
  export LD_LIBRARY_PATH=$use${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
  local pass bad
  for pass in 1 2; do
    # shellcheck disable=SC2046 # one binary a line, no spaces in the names
    bad=$(cd "$pkg/build" && ldd $(packed_binaries "$pkg/build") 2>&1 |
      sed -n "s/.*: \(\/[^:]*\): version .* not found.*/\1/p; s/^[[:space:]]*\([^ ]*\) => not found.*/\1/p" | sort -u)
    [ -n "$bad" ] || return 0
    for f in $bad; do
      name=${f##*/}
      if [ -e "$pkg/lib/$name" ] && [ ! -e "$use/$name" ]; then
        ln -s "$pkg/lib/$name" "$use/$name"
      elif [ $pass = 2 ]; then
        echo "gpu-check: $name: not found or too old, and not in the package" >&2
      fi
    done
  done
  [ -z "$bad" ]
}

# EGL: the loaders from the package, the NVIDIA vendor library, the probe.
setup_egl() {
  if [ "$mode" = device ]; then
    local d
    for d in "$pkg"/debs/*.deb; do dpkg -x "$d" / || return 1; done
    ldconfig
    if ! grep -q libEGL_nvidia <<<"$(ldconfig -p)"; then
      for d in /usr/local/nvidia/lib64 /usr/local/nvidia/lib; do
        [ -d "$d" ] && export LD_LIBRARY_PATH=$LD_LIBRARY_PATH:$d
      done
    fi
    if ! compgen -G '/usr/share/glvnd/egl_vendor.d/*nvidia*' >/dev/null &&
      [ -z "${__EGL_VENDOR_LIBRARY_FILENAMES:-}" ] &&
      [ -f /usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json ]; then
      export __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
    fi
  fi
  # skybake's GL code takes EGL's device platform, as on NVIDIA's driver.
  export SKYBAKE_EGL_PLATFORM=device
}

# The compiled-in paths of the binaries (the CLI the tests start, the source
# tree's test data) are those of the build machine: there they are made to
# point at the repository and the package.
setup_layout() {
  local src build
  src=$(sed -n 's/^source_dir //p' "$pkg/manifest.txt")
  build=$(sed -n 's/^build_dir //p' "$pkg/manifest.txt")
  # CTestTestfiles: the build folder becomes the package's, the source folder the repository.
  find "$pkg/build" -name '*.cmake' -exec sed -i -e "s|$build/|$pkg/build/|g" -e "s|$build\"|$pkg/build\"|g" \
    -e "s|$src/|$root/|g" {} +
  [ "$mode" = device ] || return 0
  if [ "$(cd "$src" 2>/dev/null && pwd -P)" != "$(cd "$root" && pwd -P)" ]; then
    if [ -e "$src" ] && [ ! -L "$src" ]; then
      echo "gpu-check: $src exists and is not this repository: the tests would read its data" >&2
      return 1
    fi
    mkdir -p "$(dirname "$src")" && ln -sfn "$root" "$src"
  fi
  # $build is now inside the repository (or $src): it must be the package's build.
  if [ -L "$build" ] || [ ! -e "$build" ]; then
    ln -sfn "$pkg/build" "$build"
  else
    mv "$build" "$build.moved-$(date +%s)" && ln -s "$pkg/build" "$build"
  fi
}

# The machine, the driver and EGL; device-summary.txt: a few lines for the summary.
device_info() {
  local sum=$log/device-summary.txt
  : >"$sum"
  echo "kernel: $(uname -r), $(getconf GNU_LIBC_VERSION) (the package needs glibc $(sed -n 's/^glibc_needed //p' "$pkg/manifest.txt"))" >>"$sum"
  echo "## uname -r"
  uname -r
  echo "## glibc"
  getconf GNU_LIBC_VERSION
  echo "## package"
  sed -n '1,8p' "$pkg/manifest.txt"
  if [ "$mode" = device ]; then
    echo "## nvidia-smi"
    "$nvidia_smi" --query-gpu=name,driver_version,memory.total,compute_cap,clocks.max.sm --format=csv
    echo "gpu: $("$nvidia_smi" --query-gpu=name,driver_version,memory.total,compute_cap --format=csv,noheader | head -1)" >>"$sum"
    "$nvidia_smi"
  else
    echo "gpu: none (dry run)" >>"$sum"
  fi
  echo "## skybake --version"
  "$pkg/build/$cli" --version
  echo "## LD_LIBRARY_PATH: $LD_LIBRARY_PATH"
  ls "$pkg/lib-use"
  echo "## EGL vendor files"
  ls /usr/share/glvnd/egl_vendor.d/ /usr/local/nvidia/share/glvnd/egl_vendor.d/ 2>/dev/null
  echo "__EGL_VENDOR_LIBRARY_FILENAMES=${__EGL_VENDOR_LIBRARY_FILENAMES:-}"
  echo "## EGL"
  local egl rc
  egl=$(python3 "$root/scripts/gpu-check.d/egl_probe.py" 2>&1)
  rc=$?
  echo "$egl"
  echo "egl: $(echo "$egl" | grep -m1 '^egl device 0' | sed 's/, extensions.*//; s/^egl device 0: //')" >>"$sum"
  echo "gl: $(echo "$egl" | sed -n 's/^gl renderer: //p' | head -1), $(echo "$egl" | sed -n 's/^gl version: //p' | head -1)" >>"$sum"
  return $rc
}

# ctest on the package's build tree, label LABEL; on a failure the failed tests
# run again with CUDA_LAUNCH_BLOCKING=1 (NAME-rerun.log).
ctest_step() {
  local name=$1 limit=$2 class=$3
  shift 3
  if [ -n "$ctest" ]; then
    step "$name" "$limit" "$class" "$ctest" --test-dir "$pkg/build" --output-on-failure --no-tests=error \
      --output-junit "$log/$name.xml" "$@"
  else
    step "$name" "$limit" "$class" bash "$0" _gtest-direct "$@"
  fi
  local rc=$?
  [ $rc -ne 0 ] && [ $rc -ne 124 ] && [ $rc -ne 137 ] || return $rc
  [ -n "$ctest" ] || return $rc
  CUDA_LAUNCH_BLOCKING=1 step "$name-rerun" 45 "$class" "$ctest" --test-dir "$pkg/build" --rerun-failed \
    --output-on-failure -V
  return $rc
}

# Without ctest: the label's executables, straight (all their tests have the
# label); -R / -E are matched against the tests' prefix ("bake.", "e2e.").
gtest_direct() {
  local label="" only="" leave="" rc=0 exe prefix
  while [ $# -gt 0 ]; do
    case $1 in
      -L) label=$2; shift 2 ;;
      -R) only=$2; shift 2 ;;
      -E) leave=$2; shift 2 ;;
      *) shift ;;
    esac
  done
  for exe in $(test_executables "$pkg/build" | grep "_${label}_tests$"); do
    prefix=${exe##*/}
    prefix=${prefix%%_*}.
    [ -z "$only" ] || [[ "$prefix" =~ $only ]] || continue
    [ -z "$leave" ] || ! [[ "$prefix" =~ $leave ]] || continue
    echo "== $exe"
    (cd "$pkg/build/$(dirname "$exe")" && "./${exe##*/}" --gtest_output="xml:$log/gtest-${exe##*/}.xml") || rc=1
  done
  return $rc
}

cmd_run() {
  mode=${1:-device}
  start=$SECONDS
  [ -n "${OUT:-}" ] || die "OUT must name the output folder"
  mkdir -p "$OUT" || die "cannot write $OUT"
  out=$(cd "$OUT" && pwd)
  local work=${GPU_CHECK_WORK:-/tmp/skybake-gpu-check}
  [ "$mode" = device ] || work=$root/.gpu/dry-run
  rm -rf "$work" && mkdir -p "$work/logs" "$work/tmp" || die "cannot write $work"
  log=$work/logs
  local tarball=$root/.gpu/$archive_name
  [ -f "$tarball" ] || die "no $tarball: run 'scripts/gpu-check.sh pack' here and carry .gpu/$archive_name"
  echo "gpu-check ($mode): budget $budget_s s, logs in $log, results in $out"

  # Unpacking: tar with xz, or Python's tarfile where xz is missing.
  local t=$SECONDS
  if command -v xz >/dev/null; then
    tar -C "$work" -xJf "$tarball"
  else
    python3 -c 'import sys, tarfile; tarfile.open(sys.argv[1]).extractall(sys.argv[2])' "$tarball" "$work"
  fi || die "cannot unpack $tarball"
  pkg=$work/skybake-gpu
  record unpack ok $((SECONDS - t))
  t=$SECONDS
  setup_layout || die "cannot lay out the build tree (see above)"
  setup_egl || die "cannot unpack the GL loaders"
  setup_libs || note libraries "some are missing (see $log/device.log)"
  export SKYBAKE_ASSIMP_MODELS=$pkg/models
  export TMPDIR=$work/tmp
  ctest=$(find_tool ctest /opt/torch/.venv/bin/ctest /usr/local/bin/ctest ||
    python3 -c 'import cmake, os; print(os.path.join(cmake.CMAKE_BIN_DIR, "ctest"))' 2>/dev/null || true)
  [ -x "$ctest" ] || ctest=""
  nvidia_smi=$(find_tool nvidia-smi /usr/local/nvidia/bin/nvidia-smi || echo nvidia-smi)
  sanitizer=$(find_tool compute-sanitizer /usr/local/cuda/bin/compute-sanitizer /usr/local/cuda/compute-sanitizer \
    /usr/local/cuda-*/bin/compute-sanitizer || echo compute-sanitizer)
  record setup ok $((SECONDS - t))
  note tools "ctest ${ctest:-none (test executables run straight)}, compute-sanitizer $sanitizer"

  local B=$pkg/build/$cli S=$pkg/build/bench W=$work/tmp net=$root/tests/data/planet/sky_paper.json
  export root pkg mode log nvidia_smi
  step device 30 any bash "$0" _device-info

  # Tests. Dry run: the GPU tests skip themselves (no SKYBAKE_REQUIRE_GPU), which
  # checks the packed tree; the rerun path is exercised on one test that fails.
  if [ "$mode" = device ]; then
    SKYBAKE_REQUIRE_GPU=1 ctest_step ctest-gpu 150 gpu -L gpu -E '^e2e\.' -j 4
    SKYBAKE_REQUIRE_GPU=1 ctest_step ctest-gpu-cli 60 gpu -L gpu -R '^e2e\.' -j 2
  else
    ctest_step ctest-gpu-skips 60 any -L gpu -j 2
    if [ -n "$ctest" ]; then
      local before=$failed
      local n=${#results[@]}
      if SKYBAKE_REQUIRE_GPU=1 ctest_step dry-rerun-path 30 any -R '^core\.CudaDevice\.KernelRuns$'; then
        note "  (unexpected)" "passed without a GPU"
        before=1
      elif grep -q 'SKYBAKE_REQUIRE_GPU is set' "$log/dry-rerun-path-rerun.log" 2>/dev/null &&
        grep -q 'CUDA_LAUNCH_BLOCKING' "$log/dry-rerun-path-rerun.log"; then
        results=("${results[@]:0:$n}") # the two planned failures, as one line
        record dry-rerun-path "ok: failed with SKYBAKE_REQUIRE_GPU=1, rerun" 0
      else
        note "  (unexpected)" "no rerun log"
        before=1
      fi
      failed=$before # the planned failure is no failure of the run
    fi
  fi
  if [ "$mode" = device ]; then
    ctest_step ctest-gl 100 any -L gl -j 4
  else
    # llvmpipe: the GL tests take minutes on two cores; list them, and run the raster backend's.
    ctest_step ctest-gl-list 30 any -N -L gl
    ctest_step ctest-gl-raster 60 any -L gl -R \
      'RasterBake\.(OneTriangleSeesItsWholeHemisphere|VertexInsideAClosedMeshSeesNothing|RefusesWhatItCannotDo)$' -j 2
  fi

  # Inputs: meshes (2,000 triangles for compute-sanitizer, the 3k table case,
  # the viewer's 100k terrain) and 4,096 sky samples.
  step inputs 60 any bash -c "'$B' -q mesh generate --kind city --triangles 2000 -o '$W/city2k.glb' &&
    '$B' -q mesh generate --kind city --triangles 3000 -o '$W/city3k.glb' &&
    '$B' -q mesh generate --kind terrain --triangles 100000 -o '$W/terrain100k.glb' &&
    awk 'BEGIN { print \"cos_view_zenith,cos_view_sun,cos_sun_zenith,density\"; pi = atan2(0, -1);
      for (i = 0; i < 4096; i++) { v = pi * ((i * 37) % 4096) / 4096; s = 0.6 * pi * ((i * 101) % 4096) / 4096;
        p = 2 * pi * ((i * 211) % 4096) / 4096;
        printf \"%.6f,%.6f,%.6f,%.3f\n\", cos(v), cos(v) * cos(s) + sin(v) * sin(s) * cos(p), cos(s),
          0.25 + 0.75 * (i % 4) / 3 } }' >'$W/sky.csv'"
  # Benchmarks, Google Benchmark JSON. Dry run: each filter must select benchmarks.
  mkdir -p "$log/bench"
  local b n
  for b in "${bench_programs[@]}"; do
    if [ "$mode" = device ]; then
      # A benchmark that skipped itself with an error (no device...) fails the step.
      step "bench-$b" 120 gpu bash -c '"$1" --benchmark_filter="$2" --benchmark_out="$3" --benchmark_out_format=json &&
        ! grep -q "\"error_occurred\": true" "$3"' bench "$S/$b" "${bench_filter[$b]}" "$log/bench/$b.json"
    else
      n=$("$S/$b" --benchmark_list_tests --benchmark_filter="${bench_filter[$b]}" 2>/dev/null | grep -c .)
      if [ "$n" -gt 0 ]; then
        record "bench-$b" "skipped (dry run: needs the GPU); $n selected" 0
      else
        record "bench-$b" "FAIL: the filter selects nothing" 0
        failed=1
      fi
    fi
  done
  if compgen -G "$log/bench/*.json" >/dev/null; then
    python3 "$root/scripts/gpu-check.d/merge_bench.py" "$out/bench.json" "$log"/bench/*.json >"$log/merge.log" 2>&1 ||
      note bench.json "could not merge (see merge.log)"
  fi

  # Screenshots: the planet (1M-triangle budget, network per pixel), the viewer,
  # a raster bake of the seed's table case. Dry run: small, on llvmpipe.
  local size=1920x1080 tris=1000000
  local raster=(--rule lebedev:5810)
  [ "$mode" = device ] || { size=320x180; tris=20000; raster=(--rule lebedev:50 --method directional --resolution 256); }
  step shot-planet 60 any bash -c "mkdir -p '$W/fly' && '$B' fly --model '$net' --frames 3 --size $size --shading pixel \
    --relief 6 --max-error-px 0.02 --max-triangles $tris -o '$W/fly' --json && cp '$W/fly/frame_0001.png' '$out/planet.png'"
  step shot-viewer 60 any "$B" view "$W/terrain100k.glb" --model "$net" --sun-elevation-deg 15 --size "$size" \
    --screenshot "$out/viewer.png"
  step shot-raster-bake 90 any "$B" ao "$W/city3k.glb" --backend raster "${raster[@]}" -o "$W/city_raster.glb" \
    --preview "$out/raster_bake.png" --preview-size "$size" --json


  # compute-sanitizer, last: the benchmarks and screenshots matter more if time runs short.
  local cs=(timeout 120 "$sanitizer" --error-exitcode 1 --print-limit 20)
  local ao=("$B" -q ao "$W/city2k.glb" --device cuda --rule lebedev:110+rotate)
  local m
  for m in bvh per-vertex per-polygon; do
    sanitize "memcheck-ao-$m" "${cs[@]}" --tool memcheck "${ao[@]}" --method $m --bits "$W/$m.bits" -o "$W/$m.glb"
  done
  sanitize memcheck-sky-eval "${cs[@]}" --tool memcheck "$B" -q sky eval --preset earth --input "$W/sky.csv" \
    --output "$W/eval.csv" --device cuda
  sanitize memcheck-sky-eval-network "${cs[@]}" --tool memcheck "$B" -q sky eval --model "$net" \
    --input "$W/sky.csv" --output "$W/eval_net.csv" --device cuda
  sanitize memcheck-sky-render "${cs[@]}" --tool memcheck "$B" -q sky render --preset earth --altitude-km 0 \
    --sun-elevation-deg 20 --view panorama --size 512x256 -o "$W/sky.exr" --device cuda
  sanitize memcheck-sky-render-network "${cs[@]}" --tool memcheck "$B" -q sky render --model "$net" \
    --altitude-km 0 --sun-elevation-deg 20 --view panorama --size 512x256 -o "$W/sky_net.exr" --device cuda
  sanitize initcheck-ao-bvh "${cs[@]}" --tool initcheck "${ao[@]}" --method bvh --bits "$W/i.bits" -o "$W/i.glb"
  sanitize racecheck-ao-per-polygon "${cs[@]}" --tool racecheck "${ao[@]}" --method per-polygon \
    --bits "$W/r.bits" -o "$W/r.glb"
  sanitize synccheck-ao-per-polygon "${cs[@]}" --tool synccheck "${ao[@]}" --method per-polygon \
    --bits "$W/s.bits" -o "$W/s.glb"
  summary
}

# sanitize NAME COMMAND...: a compute-sanitizer run (class gpu). Dry run: the
# same skybake command without the sanitizer must get as far as the missing
# device (exit 1, a line naming CUDA): its arguments are then valid.
sanitize() {
  local name=$1
  shift
  if [ "$mode" = device ]; then
    step "$name" 125 gpu "$@"
    return
  fi
  local args=("$@") i=0
  while [ "${args[$i]}" != "$pkg/build/$cli" ]; do i=$((i + 1)); done
  local cmd=("${args[@]:$i}") rc
  "${cmd[@]}" >"$log/$name.log" 2>&1
  rc=$?
  if [ $rc -eq 1 ] && grep -q 'no usable CUDA device\|no CUDA device' "$log/$name.log"; then
    record "$name" "skipped (dry run: needs the GPU); flags ok" 0
  else
    record "$name" "FAIL: exit $rc without a device (see $name.log)" 0
    failed=1
  fi
}

summary() {
  local total=$((SECONDS - start))
  {
    echo "skybake gpu-check, $mode run, $(date -u +%Y-%m-%dT%H:%M:%SZ)"
    sed -n 's/^commit /package of commit /p; s/^packed /packed /p' "$pkg/manifest.txt"
    cat "$log/device-summary.txt" 2>/dev/null
    echo
    printf '%s\n' "${results[@]}"
    echo
    echo "total: $total s of a $budget_s s budget"
    [ $failed = 0 ] && echo "result: every step passed or was skipped as planned" || echo "result: FAILURES (logs.tar.gz)"
  } | tee "$out/summary.txt"
  cp "$pkg/manifest.txt" "$log/"
  tar -C "$(dirname "$log")" -czf "$out/logs.tar.gz" logs
  return $failed
}

# --- selftest --------------------------------------------------------------------
# Cheap checks that the lists above still describe the build and the tests.
# Exit 77 (skip) for a build without CUDA or without the GPU tests.
cmd_selftest() {
  local build
  build=$(abs_build "${1:-build}")
  local bad=0 f b
  bash -n "$0" || bad=1
  python3 -m py_compile "$root/scripts/gpu-check.d/egl_probe.py" "$root/scripts/gpu-check.d/merge_bench.py" || bad=1
  mapfile -t exes < <(test_executables "$build")
  if [ "${#exes[@]}" -eq 0 ] || ! grep -q gpu_tests <<<"${exes[*]}"; then
    echo "selftest: $build has no GPU test executables (no CUDA?): skipped"
    exit 77
  fi
  for f in "${exes[@]}" "$cli"; do
    [ -x "$build/$f" ] || { echo "selftest: $build/$f is not built: skipped"; exit 77; }
  done
  # Every model file that a GPU or GL test (or a helper header it includes) names is packed.
  local srcs=() inc
  mapfile -t srcs < <(cd "$root" && find src tests -name '*_gpu_test.c*' -o -name '*_gl_test.cpp' -o -name '*_gpu_test.cu')
  local queue=("${srcs[@]}") seen=" "
  while [ ${#queue[@]} -gt 0 ]; do
    f=${queue[0]}
    queue=("${queue[@]:1}")
    [[ "$seen" == *" $f "* ]] && continue
    seen+="$f "
    for inc in $(sed -n 's/^#include "\([^"]*\)"/\1/p' "$root/$f"); do
      for b in "src/$inc" "tests/$inc"; do [ -f "$root/$b" ] && queue+=("$b"); done
    done
  done
  # The literals beside assimp_models() or a variable set from it ("models + "/OBJ/x.obj"").
  local used=() m pattern v
  for f in $seen; do
    grep -q 'assimp_models()' "$root/$f" || continue
    pattern='assimp_models\(\)'
    for v in $(grep -o '[A-Za-z_][A-Za-z0-9_]* = skybake::test::assimp_models()' "$root/$f" | cut -d' ' -f1); do
      pattern+="|\\b${v}[[:space:]]*[+/]"
    done
    mapfile -t -O ${#used[@]} used < <(grep -E "$pattern" "$root/$f" | grep -o '"/[A-Za-z0-9_./-]*\.[A-Za-z0-9]*"' |
      tr -d '"' | sed 's|^/||')
  done
  mapfile -t used < <(printf '%s\n' "${used[@]}" | sort -u | grep .)
  for m in "${used[@]}"; do
    grep -qx "$m" <<<"$(printf '%s\n' "${models[@]}")" || { echo "selftest: a GPU/GL test reads $m, which is not packed (models=)"; bad=1; }
  done
  [ ${#used[@]} -gt 0 ] || { echo "selftest: found no model that the GPU/GL tests read (the scan is broken)"; bad=1; }
  local mdir
  mdir=$(models_dir)
  if [ -d "$mdir" ]; then
    for m in "${models[@]}"; do [ -f "$mdir/$m" ] || { echo "selftest: $mdir/$m is missing"; bad=1; }; done
  fi
  # Every benchmark filter selects benchmarks.
  if [ -d "$build/bench" ]; then
    for b in "${bench_programs[@]}"; do
      if [ ! -x "$build/bench/$b" ]; then
        echo "selftest: $build/bench/$b is not built"; bad=1; continue
      fi
      [ "$("$build/bench/$b" --benchmark_list_tests --benchmark_filter="${bench_filter[$b]}" | grep -c .)" -gt 0 ] ||
        { echo "selftest: $b: the filter '${bench_filter[$b]}' selects nothing"; bad=1; }
    done
  else
    echo "selftest: no benchmarks in $build (Google Benchmark missing): filters not checked"
  fi
  # ldd resolves every library of every binary that would be packed, and the
  # package lists each one but glibc.
  local bins=() present=()
  mapfile -t bins < <(packed_binaries "$build")
  for f in "${bins[@]}"; do [ -x "$build/$f" ] && present+=("$build/$f"); done
  if grep -q 'not found' <<<"$(ldd "${present[@]}" 2>&1)"; then
    echo "selftest: ldd finds no library for:"; ldd "${present[@]}" 2>&1 | grep 'not found' | sort -u; bad=1
  fi
  local libs
  libs=$(needed_libs "${present[@]}" | wc -l)
  [ "$libs" -gt 0 ] || { echo "selftest: no library to pack (ldd failed?)"; bad=1; }
  # A pack made earlier that the build has since outdated.
  local tarball=$root/.gpu/$archive_name
  if [ -f "$tarball" ] && [ -n "$(find "${present[@]}" -newer "$tarball" 2>/dev/null | head -1)" ]; then
    echo "selftest: note: .gpu/$archive_name is older than the build: run 'scripts/gpu-check.sh pack' again"
  fi
  [ $bad = 0 ] && echo "selftest: ${#exes[@]} test executables, ${#used[@]} model files read, $libs libraries, ${#bench_programs[@]} benchmark filters: ok"
  return $bad
}

# --- main --------------------------------------------------------------------------
case "${1:-}" in
  pack) shift; cmd_pack "$@" ;;
  run) shift; [ $# -eq 0 ] || usage; cmd_run device ;;
  --dry-run)
    shift
    t0=$SECONDS
    if [ "${1:-}" = --no-pack ]; then
      shift
    else
      cmd_pack "$@" || exit 1
    fi
    OUT=${OUT:-$root/out/gpu-check-dry} cmd_run dry
    rc=$?
    echo "dry run, pack included: $((SECONDS - t0)) s"
    exit $rc
    ;;
  --selftest) shift; cmd_selftest "$@" ;;
  _device-info) device_info ;;
  _gtest-direct) shift; gtest_direct "$@" ;;
  *) usage ;;
esac
