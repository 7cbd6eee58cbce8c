#!/usr/bin/env bash
# Installs the Debian 12 packages skybake builds, tests and runs with.
# Only packages that are missing are installed. Safe to run repeatedly.
#
#   sudo scripts/install-deps.sh          # install what is missing
#   scripts/install-deps.sh --check       # list what is missing, exit 1 if any
set -euo pipefail

PACKAGES=(
  # toolchain
  build-essential cmake ninja-build pkg-config git ca-certificates
  clang libclang-rt-14-dev
  # ray tracing and threading
  libembree-dev libtbb-dev
  # mesh and image I/O
  libassimp-dev assimp-testmodels libtinygltf-dev libstb-dev libtinyexr-dev libpng-dev libjpeg62-turbo-dev
  # maths
  libglm-dev libeigen3-dev
  # CLI, formatting, JSON
  libcli11-dev libfmt-dev nlohmann-json3-dev
  # distributed bakes (mpirun)
  libopenmpi-dev openmpi-bin
  # tests and benchmarks
  libgtest-dev libgmock-dev libbenchmark-dev glslang-tools
  # OpenGL (headless EGL and windowed GLFW)
  libegl-dev libgl-dev libglfw3-dev libepoxy-dev libegl-mesa0 libgl1-mesa-dri
  # the viewer window: Dear ImGui, and a virtual X server for tests of real windows
  libimgui-dev xvfb xauth
  # Python module, its tests, and the Blender add-on's
  pybind11-dev python3-dev python3-numpy python3-pytest blender
  # the web package: node's own test runner, esbuild's bundle, headless Chromium (WebGL 2 on SwiftShader)
  nodejs chromium
)

missing=()
for p in "${PACKAGES[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  [[ "$status" == "install ok installed" ]] || missing+=("$p")
done

# npm: Debian's package where node is Debian's; a node that brings its own npm needs none.
command -v npm >/dev/null 2>&1 || dpkg-query -W -f='${Status}' npm 2>/dev/null | grep -q "install ok installed" || missing+=(npm)

if [[ ${#missing[@]} -eq 0 ]]; then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi

if [[ "${1:-}" == "--check" ]]; then
  echo "install-deps: missing: ${missing[*]}"
  exit 1
fi

if [[ $(id -u) -ne 0 ]]; then
  if command -v sudo >/dev/null 2>&1; then
    echo "install-deps: not root; run: sudo apt-get install -y --no-install-recommends ${missing[*]}" >&2
  else
    echo "install-deps: not root; run as root: apt-get install -y --no-install-recommends ${missing[*]}" >&2
  fi
  exit 1
fi

echo "install-deps: installing ${#missing[@]} package(s): ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y -qq --no-install-recommends "${missing[@]}"
