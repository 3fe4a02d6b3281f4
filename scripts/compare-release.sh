#!/usr/bin/env bash
# Runs every bundled config with two hairgen builds and compares what they write: every cache byte for
# byte, every EXR with `hairgen diff` (the golden thresholds). For refactors that must not change
# output. Usage:
#   scripts/compare-release.sh REV            builds REV (a commit, tag or branch) beside this tree
#   scripts/compare-release.sh --binary OLD   compares against an existing hairgen executable
# The current build (build/hairgen) is the new side; run scripts/setup.sh first.
set -euo pipefail
cd "$(dirname "$0")/.."
src=$(pwd)
[ $# -ge 1 ] || { sed -n '2,7p' "$0" >&2; exit 2; }
if [ "$1" = "--binary" ]; then
  old=$(realpath "$2")
else
  rev=$1
  work="$src/build-release/$(git rev-parse --short "$rev")"
  if [ ! -x "$work/build/hairgen" ]; then
    rm -rf "$work" && mkdir -p "$(dirname "$work")"
    git worktree add --detach "$work" "$rev" >/dev/null
    cmake -S "$work" -B "$work/build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DHAIRGEN_BUILD_TESTS=OFF >/dev/null
    cmake --build "$work/build" --target hairgen
  fi
  old="$work/build/hairgen"
fi
new="$src/build/hairgen"
out="$src/build/compare-release"
rm -rf "$out" && mkdir -p "$out"

# Each entry: the Setup's folder under configs/, a name, and the --set arguments of the run.
entries=(
  "default default"
  "thesis/coupe1 coupe1"
  "thesis/coupe2 coupe2"
  "thesis/coupe3 coupe3"
  "thesis/coupe3 coupe3-volumetric Render.ShadingModel=volumetric"
  "thesis/coupe4 coupe4"
  "anjyo/bob bob"
)
status=0
for entry in "${entries[@]}"; do
  read -r config name sets <<<"$entry"
  extra=(--set "Render.Resolution=200 200")
  for s in $sets; do extra+=(--set "$s"); done
  for side in old new; do
    bin=$old
    [ "$side" = new ] && bin=$new
    "$bin" run "configs/$config/setup.txt" -o "$out/$side/$name" --quiet "${extra[@]}"
  done
  for file in "$out/old/$name"/*.hair; do
    base=$(basename "$file")
    if cmp -s "$file" "$out/new/$name/$base"; then
      echo "same   $name/$base"
    else
      echo "DIFFER $name/$base"
      status=1
    fi
  done
  if "$new" diff "$out/old/$name/beauty.exr" "$out/new/$name/beauty.exr" --quiet >/dev/null; then
    echo "same   $name/beauty.exr (within the golden thresholds)"
  else
    echo "DIFFER $name/beauty.exr"
    status=1
  fi
done
exit $status
