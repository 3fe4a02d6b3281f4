#!/usr/bin/env bash
# Sets up and runs hairgen on the bundled default coupe (configs/default): grows the guides,
# interpolates the coupe and renders it, into out/default. Look at out/default/beauty.png.
# Builds the hairgen program alone (build/hairgen, Release): no tests, benchmarks or sanitizer builds.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh --program-only
# build/ is shared with scripts/test.sh. A fresh one is configured without the test targets; one that
# exists keeps its configuration (test.sh's has the tests on), and only hairgen is built from it, so
# demo then test, or test then demo, compiles each object once.
if [ ! -f build/CMakeCache.txt ]; then
  cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release \
    -DHAIRGEN_BUILD_TESTS=OFF -DHAIRGEN_SANITIZER_TESTS=OFF >/dev/null
fi
cmake --build build --target hairgen
out=out/default
./build/hairgen run -o "$out" --stats "$out.json"
./build/hairgen convert "$out/guides.hair" "$out/guides.glb" --quiet
echo "demo: the picture is $out/beauty.png (linear EXR with Z, opacity and shadow AOVs: $out/beauty.exr);" \
  "the hair is $out/coupe.hair, the guides $out/guides.hair and $out/guides.glb; timings in $out.json;" \
  "the program is build/hairgen" >&2
