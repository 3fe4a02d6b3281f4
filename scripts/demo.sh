#!/usr/bin/env bash
# Sets up and runs hairgen on the bundled default coupe (configs/default): grows the guides,
# interpolates the coupe and renders it, into out/default. Look at out/default/beauty.png.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
out=out/default
./build/hairgen run -o "$out" --stats "$out.json"
./build/hairgen convert "$out/guides.hair" "$out/guides.glb" --quiet
echo "demo: the picture is $out/beauty.png (linear EXR with Z, opacity and shadow AOVs: $out/beauty.exr);" \
  "the hair is $out/coupe.hair, the guides $out/guides.hair and $out/guides.glb; timings in $out.json" >&2
