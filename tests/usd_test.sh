#!/usr/bin/env bash
# The .usda of the bundled default coupe, read by an independent USD reader (TinyUSDZ, npm package
# tinyusdz, installed into tools/ by scripts/setup.sh): the same curve count, vertex count, points and
# widths as hairgen's own description of the coupe. Skipped (exit 77) when the reader is not installed.
# Usage: usd_test.sh HAIRGEN NODE TINYUSDZ_DIR WORK
set -euo pipefail
hairgen=$1 node=$2 reader=$3 work=$4
here=$(cd "$(dirname "$0")" && pwd)
[ -f "$reader/tinyusdz.wasm" ] || { echo "tinyusdz is not installed (scripts/setup.sh installs it): skipped"; exit 77; }
rm -rf "$work" && mkdir -p "$work"
"$hairgen" run -o "$work" --no-render --quiet
"$hairgen" convert "$work/coupe.hair" "$work/coupe.usda" --quiet
"$hairgen" info "$work/coupe.hair" --json > "$work/coupe.json"
"$node" --max-old-space-size=8192 "$here/validate_usd.mjs" "$reader" "$work/coupe.usda" "$work/coupe.json"
# A file made elsewhere whose units were not given: no metersPerUnit, and still a valid layer.
"$hairgen" convert "$work/guides.hair" "$work/guides.data" --quiet
"$hairgen" convert "$work/guides.data" "$work/guides.usda" --quiet
"$hairgen" info "$work/guides.data" --json > "$work/guides.json"
"$node" "$here/validate_usd.mjs" "$reader" "$work/guides.usda" "$work/guides.json"
if grep -q metersPerUnit "$work/guides.usda"; then echo "FAIL: a file of unknown units claims metersPerUnit"; exit 1; fi
rm -rf "$work"
