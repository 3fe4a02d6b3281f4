#!/usr/bin/env bash
# Remakes the README gallery: docs/coupe1-4.png, docs/coupe3-volumetric.png, docs/bob.png and
# docs/default.png, each `hairgen run` of a bundled coupe at 320x320 with its own density, and the shots'
# GIFs docs/gust.gif, docs/headturn.gif and docs/target.gif (with docs/target.png, the density target) at
# 240x240 (the head turn and the target at half density: 72 frames of the full coupe take too long for a
# picture this small). Look at them before committing.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
mkdir -p docs
# Each entry: the Setup's folder under configs/, the picture's name, and any --set for the run.
entries=(
  "default default"
  "thesis/coupe1 coupe1"
  "thesis/coupe2 coupe2"
  "thesis/coupe3 coupe3"
  "thesis/coupe3 coupe3-volumetric Render.ShadingModel=volumetric"
  "thesis/coupe4 coupe4"
  "anjyo/bob bob"
)
for entry in "${entries[@]}"; do
  read -r name picture sets <<<"$entry"
  out="build/gallery/$picture"
  extra=()
  for s in $sets; do extra+=(--set "$s"); done
  ./build/hairgen run "configs/$name/setup.txt" -o "$out" --quiet --set "Render.Resolution=320 320" "${extra[@]}"
  cp "$out/beauty.png" "docs/$picture.png"
  echo "gallery: docs/$picture.png" >&2
done
# Shots: the Setup's folder, the movie's name, and any --set for the run.
shots=(
  "anjyo/gust gust"
  "shots/headturn headturn Hairstyle.HairDensity=50"
  "pixar/target target Hairstyle.HairDensity=50"
)
for entry in "${shots[@]}"; do
  read -r name movie sets <<<"$entry"
  out="build/gallery/$movie"
  extra=()
  for s in $sets; do extra+=(--set "$s"); done
  ./build/hairgen run "configs/$name/setup.txt" -o "$out" --quiet --set "Render.Resolution=240 240" "${extra[@]}"
  cp "$out/beauty.gif" "docs/$movie.gif"
  echo "gallery: docs/$movie.gif" >&2
done
# The density-targeting shot's target itself, for comparison: target.data interpolated and rendered.
out=build/gallery/target-shape
mkdir -p "$out"
target_sets=(--quiet --set "Hairstyle.HairDensity=50" --set "Render.Resolution=240 240")
./build/hairgen interpolate configs/pixar/target/setup.txt --guides configs/pixar/target/target.data \
  -o "$out/coupe.hair" "${target_sets[@]}"
./build/hairgen render configs/pixar/target/setup.txt --hair "$out/coupe.hair" -o "$out/beauty.exr" \
  --preview docs/target.png "${target_sets[@]}"
echo "gallery: docs/target.png" >&2
