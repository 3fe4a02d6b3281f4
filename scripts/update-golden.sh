#!/usr/bin/env bash
# Regenerates golden references on purpose: scripts/update-golden.sh [CASE ...] (default: every case).
# Look at each new image (a PNG preview is written beside it in the build tree) before committing it.
set -euo pipefail
cd "$(dirname "$0")/.."
src=$(pwd)
bash scripts/setup.sh
cases=("$@")
[ ${#cases[@]} -gt 0 ] || mapfile -t cases < <(find golden -mindepth 2 -maxdepth 2 -name case.sh -printf '%h\n' | xargs -n1 basename | sort)
for case in "${cases[@]}"; do
  [ -f "golden/$case/case.sh" ] || { echo "update-golden: no golden/$case/case.sh" >&2; exit 2; }
  out="$src/build/golden-update/$case"
  rm -rf "$out" && mkdir -p "$out"
  # shellcheck source=/dev/null
  source "golden/$case/case.sh"
  ./build/hairgen "${args[@]}"
  cp "$image" "golden/$case/reference.exr"
  echo "update-golden: golden/$case/reference.exr (preview: ${image%.exr}.png)" >&2
done
