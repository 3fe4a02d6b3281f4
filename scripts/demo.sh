#!/usr/bin/env bash
# Sets up and runs hairgen on the bundled default coupe (configs/default), writing into out/default.
# Today that validates the coupe's configuration and meshes and describes the bundled assets; the
# grow, interpolate, shade and render stages join as they land.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
out=out/default
mkdir -p "$out"
./build/hairgen check configs/default/setup.txt --stats "$out/check.json"
./build/hairgen info configs/assets/wick.obj
./build/hairgen info configs/assets/head.obj
echo "demo: wrote $out/check.json" >&2
