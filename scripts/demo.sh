#!/usr/bin/env bash
# Sets up and runs hairgen on the bundled default coupe (configs/default), writing into out/default.
# Today that validates the coupe's configuration and grows its guides; the interpolate, shade and
# render stages join as they land.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
out=out/default
mkdir -p "$out"
./build/hairgen check configs/default/setup.txt --stats "$out/check.json"
./build/hairgen grow configs/default/setup.txt -o "$out/guides.glb" --stats "$out/grow.json"
./build/hairgen info "$out/guides.glb"
echo "demo: wrote $out/guides.glb (open it in any glTF viewer), $out/grow.json and $out/check.json" >&2
