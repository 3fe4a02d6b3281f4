#!/usr/bin/env bash
# Installs every Debian package hairgen's build, tests and tools need, then configures build/ with the
# tests on and builds everything. Idempotent: when everything is present it only (re)builds, and
# `apt-get update` runs only when a package is missing.
# Usage: scripts/setup.sh [--no-build]   everything, for the tests (scripts/test.sh)
#        scripts/setup.sh --program-only   only the packages the hairgen program needs to build and
#                                          run; configures and builds nothing (scripts/demo.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
mode="${1:-}"

# What the hairgen program needs to build and run.
packages=(
  build-essential cmake ninja-build pkg-config
  libglm-dev libcli11-dev libtinyobjloader-dev libtinygltf-dev nlohmann-json3-dev libstb-dev
  libopenexr-dev openexr libopenimageio-dev openimageio-tools libpng-dev libtbb-dev zlib1g-dev
  libopenvdb-dev libopenvdb-tools libboost-dev  # OpenVDB's headers include Boost's; its package does not pull them
  libegl-dev libgl-dev libopengl-dev libegl1 libopengl0 libegl-mesa0 libgl1-mesa-dri libgbm1
)
# What the tests, benchmarks and tools add.
if [ "$mode" != --program-only ]; then
  packages+=(
    git clang-format
    libgtest-dev libgmock-dev libbenchmark-dev
    clang libclang-rt-14-dev llvm  # the fuzz build (scripts/fuzz.sh): libFuzzer, ASan, UBSan, llvm-symbolizer
    ffmpeg  # a shot's preview movie (beauty.mp4, beauty.gif); without it `run` writes the frames alone
    slurm-wlm munge  # the farm's scheduler: a one-node Slurm for the tests (scripts/slurm-local.sh)
    glslang-tools  # the Khronos reference compiler checks every shader stage (tests/glsl_reference_test.sh)
  )
  # Node.js with npm runs the glTF validator; the image may ship its own Node (then Debian's npm conflicts).
  command -v npm >/dev/null 2>&1 || packages+=(nodejs npm)
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}" >&2
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq
  $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

[ "$mode" = --program-only ] && exit 0

# The Khronos glTF validator (npm package gltf-validator), used by the test suite.
if [ ! -f tools/node_modules/gltf-validator/package.json ]; then
  echo "setup: installing gltf-validator (npm)" >&2
  mkdir -p tools
  npm install --silent --no-audit --no-fund --prefix tools gltf-validator@2.0.0-dev.3.10 >/dev/null
fi

# ajv-cli, an independent JSON Schema validator the tests check farm plans with (docs/farm-plan.schema.json).
if [ ! -f tools/node_modules/ajv-cli/dist/index.js ]; then
  echo "setup: installing ajv-cli (npm)" >&2
  mkdir -p tools
  npm install --silent --no-audit --no-fund --prefix tools ajv-cli@5.0.0 >/dev/null
fi

# TinyUSDZ's WebAssembly build (npm package tinyusdz), an independent USD reader the tests check the
# .usda export with.
if [ ! -f tools/node_modules/tinyusdz/tinyusdz.wasm ]; then
  echo "setup: installing tinyusdz (npm)" >&2
  mkdir -p tools
  npm install --silent --no-audit --no-fund --prefix tools tinyusdz@0.9.0-rc10 >/dev/null
fi

[ "$mode" = --no-build ] && exit 0
# The tests on, explicitly: build/ is shared with scripts/demo.sh, which configures a fresh build/ with
# them off, and a plain configure would keep that cached choice.
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DHAIRGEN_BUILD_TESTS=ON -DHAIRGEN_SANITIZER_TESTS=ON >/dev/null
cmake --build build
