#!/usr/bin/env bash
# Remakes the README gallery: docs/coupe1-4.png, docs/bob.png and docs/default.png, each `hairgen run` of a bundled
# coupe at 320x320 with its own density. Look at them before committing.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
mkdir -p docs
for name in default thesis/coupe1 thesis/coupe2 thesis/coupe3 thesis/coupe4 anjyo/bob; do
  out="build/gallery/$(basename "$name")"
  ./build/hairgen run "configs/$name/setup.txt" -o "$out" --quiet --set "Render.Resolution=320 320"
  cp "$out/beauty.png" "docs/$(basename "$name").png"
  echo "gallery: docs/$(basename "$name").png" >&2
done
